"""The `twin` command: inspect grippers and stations, run the demo, serve a station on Modbus/TCP.

User errors (a wrong station file, an unknown URDF, a bad signal) print one line on stderr and exit
with status 2; data goes to stdout.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .core.errors import TwinError


INFO_TARGETS = "a gripper .urdf, a station folder or a station.toml"


def _mechanism_of(target: str):
    from .core.errors import StationError
    from .core.mechanism import load_mechanism
    from .core.station import gripper_mechanism, load_station

    path = Path(target)
    if path.suffix.lower() == ".urdf":
        return load_mechanism(path)
    if path.is_dir() and not (path / "station.toml").exists():
        raise StationError(target, "", f"a folder without station.toml: twin info needs {INFO_TARGETS}")
    if not path.is_dir() and path.suffix.lower() != ".toml":
        raise StationError(target, "", f"twin info needs {INFO_TARGETS}, not a {path.suffix or 'file without suffix'}")
    return gripper_mechanism(load_station(path))


def _remarks(mech) -> list[str]:
    """What `twin info` adds below the table: choices the twin made, and why a station may refuse it."""
    lines = [f"note: input {i.name}: {i.note}" for i in mech.inputs if i.note]
    if mech.rigid_joints:
        lines.append("note: " + ", ".join(f"joint {j} ({t})" for j, t in mech.rigid_joints)
                     + ": treated as rigid (only prismatic, revolute and continuous joints become inputs)")
    if not mech.fingers:
        lines.append("warning: no finger detected (no movable link, with the links fixed to it, has collision "
                     "geometry): a station with this gripper must name its fingers (gripper.fingers)")
    return lines


def cmd_info(args) -> int:
    mech = _mechanism_of(args.target)
    if args.json:
        print(json.dumps(mech.as_dict(), indent=2))
        for line in _remarks(mech):
            print(line, file=sys.stderr)  # stdout stays pure JSON
        return 0
    print(f"gripper: {mech.robot_name} ({mech.urdf})")
    print(f"base link (attach point): {mech.base_link}")
    rows = [("input", "joint", "type", "min", "max", "unit")]
    rows += [(i.name, i.joint, i.type, f"{i.min:g}", f"{i.max:g}", i.unit) for i in mech.inputs]
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    for n, row in enumerate(rows):
        print("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
        if n == 0:
            print("  ".join("-" * w for w in widths))
    for m in mech.mimics:
        print(f"mimic: {m.joint} follows {m.master} (x{m.multiplier:g} {m.offset:+g}), no input of its own")
    print(f"fingers ({len(mech.fingers)}): " + ", ".join(f.label for f in mech.fingers))
    for line in _remarks(mech):
        print(line)
    return 0


def cmd_demo(args) -> int:
    from .demo import run_demo

    return run_demo(args.station, cycles=args.cycles)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="twin", description="gripper-twin: a digital twin of a gripper cell")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("info", help="show the inputs, fingers and base link of a gripper URDF or a station's gripper")
    p.add_argument("target", help="a gripper .urdf file, a station.toml or a station folder")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=cmd_info)
    p = sub.add_parser("demo", help="run the headless demo of the ring rig (stations/ring_rig or a station like it) and print what happens")
    p.add_argument("station", nargs="?", default=str(Path(__file__).resolve().parent.parent / "stations" / "ring_rig"))
    p.add_argument("--cycles", type=int, default=1, help="how many full cycles to run")
    p.set_defaults(func=cmd_demo)
    from .campaign.cli import add_command as add_campaign

    add_campaign(sub)
    try:
        from .modbus.cli import add_commands
    except ImportError:
        pass
    else:
        add_commands(sub)
    from .view.cli import add_commands as add_view_commands  # view, plot, snapshot

    add_view_commands(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except TwinError as exc:
        print(f"twin: error: {exc}", file=sys.stderr)
        return 2
    except Exception as exc:
        from rapid_like.errors import RapidError

        if not isinstance(exc, RapidError):
            raise
        print(f"twin: {exc.headline()}", file=sys.stderr)  # the station's RAPID program: FILE:LINE:COL
        return 2
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
