"""The `twin` command: inspect grippers and stations, run the demo, serve a station, run campaigns.

    twin info STATION_OR_URDF [--json]
    twin serve STATION [Modbus flags: twin_app.cli_modbus] [--realtime | --lockstep] [--speed X]
    twin map STATION [--format json|csv|md|st|openplc] [--layout signals|plc]
    twin demo [STATION] [OPTIONS]  (a station's demo: its station.toml's [plugins] twin_demo)
    twin campaign ... (twin_app.campaign)
    twin check STATION [-o grip.png] [--json FILE] [--hold S]  (the station doctor: twin.observe.doctor)

`serve` assembles the cell (`twin_app.cell.Cell`) and plugs its front ends in (Modbus/TCP:
`twin.frontends.modbus.front_end`). It logs to stderr through `twin.frontends.modbus.log`: a line when it starts loading the
station, one when listening, one when stopped (a program reads `--events FILE|-` instead: JSON lines with
the bound ports, clients, the robot's words, stopped; docs/events.md); it stops
cleanly on Ctrl-C or SIGTERM (exit 0); one that comes while the station is loading stops it once loaded.

User errors (a wrong station file, an unknown URDF, a bad signal) print one line on stderr and exit
with status 2; data goes to stdout.
"""
from __future__ import annotations

import argparse
import json
import logging
import signal
import sys
from pathlib import Path

from twin_app.cli_args import positive_float
from twin.core.errors import TwinError, one_line
from twin_app.cli_modbus import add_commands as add_modbus_commands, tls_from_args
from twin.frontends.modbus.log import announce, log as _log


INFO_TARGETS = "a gripper .urdf, a station folder or a station.toml"


def _mechanism_of(target: str):
    from twin.core.errors import StationError
    from twin.core.mechanism import load_mechanism
    from twin.core.station import gripper_mechanism, load_station

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
    # the station's physics is loaded before anything is printed: a station that does not load (a mesh not found)
    # prints its one error line, not half a report
    drives = _drive_lines(args.target) if Path(args.target).suffix.lower() != ".urdf" and not args.json else []
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
    for line in drives:
        print(line)
    return 0


def _drive_lines(target: str) -> list[str]:
    """The station's drives as the twin derives them (docs/station-format.md, "Drives"), and the URDF data it
    replaced: this loads the station's physics."""
    import logging as _logging

    from twin.core import Twin

    quiet = _logging.getLogger("twin")
    level, quiet.disabled = quiet.disabled, True  # its warnings are listed below, once
    try:
        with Twin.from_station(target) as twin:
            drives = twin.gripper.drives
            notes = [note for _, _, note in twin.world.urdf_fixes] + twin.gripper.effort_notes
            unit, derived = twin.gripper.unit, twin.gripper.derived_notes()
            ratio, iterations, spring = twin.gripper.mass_ratio, twin.world.iterations, twin.gripper.spring_sweeps
    finally:
        quiet.disabled = level
    rows = [("drive", "velocity", "effort", "stiffness", "damping", "full force at", "moves", "stable up to")]
    for name, d in drives.items():
        u, m = unit[name], unit[name] == "m"
        rows.append((name, f"{d.velocity:g} {u}/s", f"{d.effort:g} {'N' if m else 'N m'}",
                     f"{d.stiffness:.4g} {'N/m' if m else 'N m/rad'}" + (" (rigid)" if d.stiffness > d.limit else ""),
                     f"{d.damping:.4g} {'N s/m' if m else 'N m s/rad'}",
                     f"{d.full_error * (1000 if m else 1):.3g} {'mm' if m else 'rad'}",
                     f"{d.mass:.4g} {'kg' if m else 'kg m^2'}", f"{d.limit:.4g}"))
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    out = ["drives (derived from the masses, the effort and the step; docs/station-format.md, Drives):"]
    for n, row in enumerate(rows):
        out.append("  " + "  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
        if n == 0:
            out.append("  " + "  ".join("-" * w for w in widths))
    out += derived
    out.append(f"solver: up to {iterations} sweeps a substep (a finger's drive moves {ratio:.3g} times the lightest "
               f"part's mass, heavier fingers need more; its spring builds its force on its own links in {spring:.3g} "
               "sweeps, lighter fingers need more: docs/station-format.md, The solver's sweeps)")
    return out + [f"warning: {note}" for note in notes]


def cmd_demo(args) -> int:
    from twin_app.plugins import run_station_demo

    return run_station_demo("twin_demo", args.demo_options, prog="twin demo", positional=True)


def cmd_check(args) -> int:
    """The station doctor: exit 0 when every check passes (warnings allowed), 1 when one fails."""
    from twin.observe.doctor import check_station, format_report, save_pictures

    if args.output and Path(args.output).suffix.lower() != ".png":
        print(f"twin check: error: -o {args.output}: the picture is a .png", file=sys.stderr)
        return 2
    report, pictures = check_station(args.station, hold=args.hold, picture=bool(args.output))
    print(format_report(report))
    if args.output and pictures:
        print(f"picture: {save_pictures(pictures, args.output)}")
    if args.json:
        Path(args.json).write_text(json.dumps(report.as_dict(), indent=2) + "\n", encoding="utf-8")
    return 1 if report.failed else 0


def controller_log(event: dict) -> None:
    """What the robot controller says, in the server's log: TPWrite lines, a runtime error, the end."""
    kind, t = event.get("type"), event.get("t", 0.0)
    if kind == "print":
        _log(f"[t={t:.3f} s] robot: {event['text']}")
    elif kind == "error":
        _log(f"[t={t:.3f} s] robot program error at line {event['line']}: {event['message']}")
    elif kind == "end":
        _log(f"[t={t:.3f} s] robot program ended ({event['reason']})")


class StopRequested(BaseException):
    """A second SIGINT or SIGTERM while the station is loading: cut the loading short. A BaseException,
    so that no `except Exception` on the way out of the loaders swallows it."""


class _StartUpSignals:
    """SIGINT/SIGTERM before the event loop takes them over (loading the station takes a while).

    The first one is remembered (and sets `stop`): the server stops cleanly as soon as the station is
    loaded. It does not raise, for an exception raised there lands in whatever is loading: numpy's
    import turns it into an ImportError, which pybullet prints. A second one cuts the loading short
    (StopRequested). Once stopping, signals are ignored, so none can interrupt the shutdown."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self, stop: asyncio.Event):
        self.stop = stop
        self.received: int | None = None
        self.stopping = False
        self.previous = {}
        try:
            for sig in self.SIGNALS:
                self.previous[sig] = signal.signal(sig, self._on_signal)
        except ValueError:  # not the main thread: signals are the caller's business
            pass

    def _on_signal(self, signum, frame) -> None:
        if self.stopping:
            return
        if self.received is None:
            self.received = signum
            self.stop.set()
            return
        self.stopping = True
        raise StopRequested(signum)

    def ignore(self) -> None:
        """Stopping: the event loop has put back the default handlers; take the signals again."""
        self.stopping = True
        for sig in self.previous:
            signal.signal(sig, self._on_signal)

    def restore(self) -> None:
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)


def open_served_cell(station, events=None, layout: str = ""):
    """A station's cell as the servers run it, its robot controller's words in the log (and, with `events`,
    in the machine interface: `twin.observe.events`); `layout`: the register map's (`twin serve --layout`)."""
    from .cell import Cell

    return Cell(Path(station), on_event=controller_log, events=events, layout=layout)


def cmd_serve(args) -> int:
    import asyncio

    from twin.frontends.modbus import log as serve_log

    serve_log.setup(args.log_level)
    from twin.frontends.opcua.serve import check_arguments as check_opcua_arguments

    if (problem := check_opcua_arguments(args)) is not None:
        print(f"twin serve: error: {problem}", file=sys.stderr)
        return 2
    from twin.observe.events import Events

    try:
        events = Events.open(args.events)
    except OSError as exc:
        print(f"twin serve: error: --events {args.events}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    stop = asyncio.Event()
    signals = _StartUpSignals(stop)  # first thing: loading the station (pybullet) takes a while
    cell = None
    try:
        tls = tls_from_args(args)
        if isinstance(tls, int):
            return tls
        if args.profile and args.unit_id is not None and args.unit_id == args.map_unit_id:
            _log(f"error: --unit-id {args.unit_id} is also the --map-unit-id: give them different unit ids", logging.ERROR)
            return 2
        announce(f"loading station {args.station}")
        from twin.frontends.modbus.front_end import ModbusFrontEnd

        cell = open_served_cell(args.station, events, getattr(args, "layout", None) or "")
        if getattr(args, "faults", None):
            from twin.runtime.faults import FaultInjector

            from .campaign.faultfile import load_fault_file
            from .campaign.spec import SpecError

            try:
                FaultInjector.attach(cell.twin, load_fault_file(args.faults, cell.twin))
            except SpecError as exc:
                _log(f"error: --faults: {exc}", logging.ERROR)
                return 2
        if not (getattr(args, "no_modbus", False) and tls is None):
            cell.add_front_end(ModbusFrontEnd.from_args(args, tls=tls))
        from twin.frontends.opcua.serve import OpcUaFrontEnd

        opcua = OpcUaFrontEnd.from_args(args)
        if opcua is not None:
            cell.add_front_end(opcua)
        from twin.frontends.view.live import front_ends_from_args  # --record, --view

        for front in front_ends_from_args(args):
            cell.add_front_end(front)
        if signals.received is not None:
            raise StopRequested(signals.received)
        return asyncio.run(cell.serve(lockstep=args.lockstep, speed=args.speed, stop=stop,
                                      priority=getattr(args, "rt_priority", True)))
    except BaseException:
        if signals.received is None:
            raise
        announce(f"stopped by {signal.Signals(signals.received).name} while starting")
        events.emit("stopped", steps=0, requests=0, error=f"stopped by {signal.Signals(signals.received).name} while starting")
        return 0
    finally:
        signals.ignore()
        try:
            if cell is not None:
                cell.close()
        finally:
            signals.restore()
            events.close()
            serve_log.flush()


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="twin", description="gripper-twin: a digital twin of a gripper cell")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("info", help="show the inputs, fingers and base link of a gripper URDF or a station's gripper")
    p.add_argument("target", help="a gripper .urdf file, a station.toml or a station folder")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=cmd_info)
    p = sub.add_parser("demo", add_help=False, help="a station's demo through the simulation API, headless (its "
                       "station.toml's [plugins] twin_demo; without STATION, the shipped one; `twin demo --help` lists "
                       "its options)")
    p.set_defaults(func=cmd_demo, takes_options=True)
    p = sub.add_parser("check", help="the station doctor: grip every target, measure contacts, forces, noise, creep "
                       "and friction capacity against the thresholds of a ready gripper (exit 1 if one fails)",
                       description="Grip every target of the station (from outside, and into a bore where the "
                                   "geometry allows), lift it where the station has a robot, and judge each finger "
                                   "(docs/check.md). Exit 0: every check passes (warnings allowed); 1: one fails; "
                                   "2: bad usage or a station that does not load.")
    p.add_argument("station", help="a station folder or station.toml")
    p.add_argument("-o", "--output", metavar="PNG", default=None, help="write a picture of each grip (side by side)")
    p.add_argument("--json", metavar="FILE", default=None, help="also write the full report as JSON")
    p.add_argument("--hold", type=positive_float, default=5.0, metavar="S",
                   help="seconds a part rests and is held at rest for the creep checks (default 5)")
    p.set_defaults(func=cmd_check)
    from .campaign.cli import add_command as add_campaign

    add_campaign(sub)
    serve = add_modbus_commands(sub, cmd_serve)
    from twin_app.cli_view import add_commands as add_view_commands  # view, plot, snapshot
    from twin_app.cli_view import add_serve_options  # serve --view [PORT], --record FILE

    add_serve_options(serve)
    from .cli_opcua import add_arguments as add_opcua_arguments  # --opcua [PORT], --no-modbus, --opcua-*

    add_opcua_arguments(serve)
    serve.add_argument("--events", metavar="FILE|-", default=None,
                       help="write what happens (ready with each front end's address, clients, comm lost, the robot "
                            "controller's events, fault, stopped) as JSON lines to FILE or stdout: docs/events.md")
    add_view_commands(sub, open_served_cell)
    return parser


def main(argv: list[str] | None = None) -> int:
    from twin_app.plugins import parse_command_line

    args = parse_command_line(build_parser(), argv)  # a station's demo keeps its own options
    try:
        return args.func(args)
    except TwinError as exc:  # one line (the station's RAPID program: FILE:LINE:COL: error: ...)
        print(f"twin: {one_line(exc)}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `twin info ... | head`: the reader left; no traceback, and none at exit either
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
