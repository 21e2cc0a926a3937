"""The Modbus side of `twin serve` and `twin map` (added to the `twin` command by `add_commands`; the
application, `twin_app.cli`, runs `serve`: it assembles the cell and plugs `front_end.ModbusFrontEnd` in).

    twin serve STATION [--host 127.0.0.1] [--port 5020] [--unit-id 1] [--realtime | --lockstep] [--speed X]
                       [--log-level info] [--max-connections 64] [--idle-timeout S] [--requests-per-step 400]
                       [--watchdog S] [--read-only] [--allow CIDR,...] [--gaps error|zero]
                       [--tls-cert PEM --tls-key PEM --tls-ca PEM [--tls-port 802] [--tls-only]]
    twin map STATION [--format json|csv|md]

`serve` logs to stderr through a non-blocking handler (`twin.frontends.modbus.log`): a line when it starts loading
the station, one when listening (with the bound port, so `--port 0` is usable; these two and the last
are shown at every --log-level), one per client connect, refusal and disconnect (info), watchdog
events (warning). It stops cleanly on Ctrl-C or SIGTERM (exit 0); one that comes while the station is
loading stops it once it is loaded. What each option does next to a real network: the Modbus README.
"""
from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from twin_app.cli_args import nonnegative_float, positive_float, positive_int, tcp_port

from twin.frontends.modbus.log import LEVELS, log as _log
from twin.frontends.modbus.protocol import DEFAULT_PORT, MAX_CONNECTIONS, REQUESTS_PER_STEP, TLS_PORT
from twin.frontends.modbus.register_map import POLL_HOLD


def _unit(text: str) -> int:
    v = int(text)
    if not 0 <= v <= 255:
        raise argparse.ArgumentTypeError(f"a unit id is 0..255, not {text}")
    return v


def _networks(text: str):
    from twin.frontends.modbus.server import parse_networks

    try:
        return parse_networks(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_commands(subparsers, cmd_serve):
    """`twin serve` (run by `cmd_serve`, the application's: it assembles the cell) and `twin map`. Returns the
    `serve` parser, for the other front ends' flags."""
    p = subparsers.add_parser("serve", help="serve a station's signals on Modbus/TCP",
                              description="Run a station and serve every signal on Modbus/TCP (map: `twin map`).")
    p.add_argument("station", help="a station folder or station.toml")
    add_serve_arguments(p)
    p.set_defaults(func=cmd_serve, lockstep=False)
    serve = p

    p = subparsers.add_parser("map", help="print the Modbus register map of a station",
                              description="Print the register map `twin serve` serves for a station (from the station's "
                                          "files: no physics, no robot program).")
    p.add_argument("station", help="a station folder or station.toml")
    p.add_argument("--format", choices=("json", "csv", "md", "st", "openplc"), default="md",
                   help="output format (default md); st: the PLC's I/O declarations in Structured Text; openplc: "
                        "OpenPLC v3's slave-device configuration (mbconfig.cfg); both on the PLC layout")
    _add_layout_argument(p, "the layout (default: signals; plc for --format st and openplc)")
    g = p.add_argument_group("--format st and openplc (see docs/plc-on-real-hardware.md)")
    g.add_argument("--program", metavar="NAME", default=None,
                   help="st: the PROGRAM the configuration runs (default: a minimal one, `main`, comes along)")
    g.add_argument("--task-ms", type=positive_int, default=10, help="st: the cyclic task's interval (default 10)")
    g.add_argument("--address", default="127.0.0.1", help="openplc: the twin server's address as the PLC reaches it")
    g.add_argument("--port", type=tcp_port, default=DEFAULT_PORT, help=f"openplc: its port (default {DEFAULT_PORT})")
    g.add_argument("--unit-id", type=_unit, default=1, help="openplc: the slave id (default 1)")
    g.add_argument("--polling-ms", type=positive_int, default=10, help="openplc: the polling period (default 10)")
    p.set_defaults(func=cmd_map)
    return serve


def _add_layout_argument(p, help_text: str) -> None:
    from twin.frontends.modbus.register_map import LAYOUTS

    p.add_argument("--layout", choices=LAYOUTS, default=None, help=help_text)


def add_serve_arguments(p) -> None:
    """The Modbus front end's flags of `twin serve` (and the runner's: --realtime/--lockstep, --speed)."""
    _add_layout_argument(p, "the register map's layout: signals (the default: station signals from address 16, "
                            "the simulator's below) or plc (for a Modbus master PLC: what it writes in one block per "
                            "table and nothing else there, what it reads in one block without gaps, no float32)")
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default: loopback only)")
    p.add_argument("--port", type=tcp_port, default=DEFAULT_PORT, help=f"TCP port (default {DEFAULT_PORT}; 0 = any free port, printed)")
    p.add_argument("--unit-id", type=_unit, default=None,
                   help="Modbus unit id answered (default 1; 0 and 255 too); with --profile: the profile's unit id "
                        "(default: every unit id but --map-unit-id)")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--realtime", dest="lockstep", action="store_false",
                      help="step paced to the wall clock at the station's step (the default)")
    mode.add_argument("--lockstep", action="store_true",
                      help="step only when a client writes N to the holding register sim.advance")
    p.add_argument("--speed", type=positive_float, default=1.0, help="real time: X times real time (default 1)")
    p.add_argument("--no-rt-priority", dest="rt_priority", action="store_false",
                   help="real time: do not ask the OS for real-time scheduling (default: ask, SCHED_RR at the lowest "
                        "priority where allowed; see twin.runtime.pacing)")
    p.add_argument("--frame-timeout", type=positive_float, default=1.0,
                   help="s a client may take to complete a frame it started (default 1)")
    p.add_argument("--log-level", choices=LEVELS, default="info",
                   help="debug, info (connections: the default), warning (watchdog, refusals of note), error")
    g = p.add_argument_group("running next to a real network (see the Modbus README)")
    g.add_argument("--max-connections", type=positive_int, default=MAX_CONNECTIONS,
                   help=f"connections served at once; one more is refused and logged (default {MAX_CONNECTIONS})")
    g.add_argument("--idle-timeout", type=nonnegative_float, default=0.0,
                   help="close a connection with no request for S seconds (default 0: never)")
    g.add_argument("--requests-per-step", type=positive_int, default=REQUESTS_PER_STEP,
                   help=f"requests answered per step period over all connections, shared fairly (default {REQUESTS_PER_STEP})")
    g.add_argument("--watchdog", type=nonnegative_float, default=None, metavar="S",
                   help="comm-loss watchdog: no request for S s puts the gripper in the station's safe state and "
                        "raises comm.lost (default: the station's [watchdog] timeout, else off; 0: off)")
    g.add_argument("--read-only", action="store_true",
                   help="refuse every write (functions 5, 6, 15, 16, 22, 23) with exception 01; reads are served")
    g.add_argument("--allow", type=_networks, default=None, metavar="CIDR[,CIDR...]",
                   help="accept connections only from these addresses or networks; others are closed at once")
    g.add_argument("--poll-hold", type=nonnegative_float, default=POLL_HOLD, metavar="S",
                   help="a client's reads are answered from the step of its first read until it reads an address "
                        "again, writes sim.advance or reads nothing for S s (default %(default)g; 0: every read "
                        "from the latest step)")
    g.add_argument("--gaps", choices=("error", "zero"), default="error",
                   help="reads across unmapped addresses: exception 02 (default) or zeros")
    g.add_argument("--tls-cert", metavar="PEM", help="Modbus/TCP Security: the server's certificate")
    g.add_argument("--tls-key", metavar="PEM", help="the server certificate's private key")
    g.add_argument("--tls-ca", metavar="PEM", help="CA certificate(s) client certificates must chain to (required)")
    g.add_argument("--tls-port", type=tcp_port, default=TLS_PORT, help=f"the TLS port (default {TLS_PORT}; 0 = any free)")
    g.add_argument("--tls-only", action="store_true", help="with TLS: do not listen on plain Modbus/TCP (--port)")
    _add_profile_arguments(p)


def _add_profile_arguments(p) -> None:
    from twin.devices.robotiq import PROFILES

    from twin.frontends.modbus.register_map import MAP_UNIT_ID

    g = p.add_argument_group("device profiles (see twin/frontends/modbus/README.md, Device profiles)")
    g.add_argument("--profile", choices=PROFILES, default=None,
                   help="answer as a real gripper: Robotiq's registers at their published addresses, mapped onto the "
                        "station by its [profile] table")
    g.add_argument("--map-unit-id", type=_unit, default=MAP_UNIT_ID,
                   help=f"with --profile: the unit id that keeps the generated map and sim.* (default {MAP_UNIT_ID})")
    p.add_argument("--faults", metavar="FILE", default=None,
                   help="inject the plant faults of FILE ([faults.NAME] tables as in a campaign: docs/campaigns.md)")


def cmd_map(args) -> int:
    from twin.frontends.modbus.register_map import PLC_LAYOUT, SIGNALS, build_map

    for_plc = args.format in ("st", "openplc")
    layout = args.layout or (PLC_LAYOUT if for_plc else SIGNALS)
    if for_plc and layout != PLC_LAYOUT:
        _log(f"error: --format {args.format} is for a Modbus master PLC: only on the plc layout (--layout plc); "
             "the signals layout mixes what the PLC writes with what others own", logging.ERROR)
        return 2
    rmap = build_map(args.station, layout)
    if args.format == "st":
        from twin.frontends.modbus.plc_export import to_structured_text

        text = to_structured_text(rmap, program=args.program, task_ms=args.task_ms,
                                  serve=f"twin serve {args.station} --layout plc")
    elif args.format == "openplc":
        from twin.frontends.modbus.plc_export import to_openplc

        text = to_openplc(rmap, host=args.address, port=args.port, unit_id=args.unit_id, polling_ms=args.polling_ms)
    else:
        text = {"json": rmap.to_json, "csv": rmap.to_csv, "md": rmap.to_markdown}[args.format]()
    sys.stdout.write(text if text.endswith("\n") else text + "\n")
    return 0


def tls_from_args(args):
    """The TLS context from --tls-cert/--tls-key/--tls-ca, None without them, or exit status 2 (logged)."""
    given = {k: getattr(args, k, None) for k in ("tls_cert", "tls_key", "tls_ca")}
    if not any(given.values()):
        if getattr(args, "tls_only", False):
            _log("error: --tls-only needs --tls-cert, --tls-key and --tls-ca", logging.ERROR)
            return 2
        return None
    missing = [f"--{k.replace('_', '-')}" for k, v in given.items() if not v]
    if missing:
        _log(f"error: Modbus/TCP Security needs --tls-cert, --tls-key and --tls-ca (client certificates are "
             f"required); missing {', '.join(missing)}", logging.ERROR)
        return 2
    import ssl

    from twin.frontends.modbus.server import tls_context

    try:
        import cryptography  # noqa: F401  (the client certificates' roles are read with it: twin.frontends.modbus.roles)
    except ImportError:
        _log("error: Modbus/TCP Security reads each client certificate's role and needs cryptography: "
             "pip install 'gripper-twin[tls]'", logging.ERROR)
        return 2
    for k, v in given.items():
        if not Path(v).is_file():
            _log(f"error: --{k.replace('_', '-')} {v}: no such file", logging.ERROR)
            return 2
    try:
        return tls_context(given["tls_cert"], given["tls_key"], given["tls_ca"])
    except (ssl.SSLError, OSError, ValueError) as exc:
        _log(f"error: cannot use the TLS certificate {given['tls_cert']} / key {given['tls_key']} / "
             f"CA {given['tls_ca']}: {exc}", logging.ERROR)
        return 2
