"""The `twin serve` and `twin map` subcommands (added to the `twin` command by `add_commands`).

    twin serve STATION [--host 127.0.0.1] [--port 5020] [--unit-id 1] [--realtime | --lockstep] [--speed X]
                       [--log-level info] [--max-connections 64] [--idle-timeout S] [--requests-per-step 400]
                       [--watchdog S] [--read-only] [--allow CIDR,...] [--gaps error|zero]
                       [--tls-cert PEM --tls-key PEM --tls-ca PEM [--tls-port 802] [--tls-only]]
    twin map STATION [--format json|csv|md]

`serve` logs to stderr through a non-blocking handler (`twin.modbus.log`): a line when it starts loading
the station, one when listening (with the bound port, so `--port 0` is usable; these two and the last
are shown at every --log-level), one per client connect, refusal and disconnect (info), watchdog
events (warning). It stops cleanly on Ctrl-C or SIGTERM (exit 0); one that comes while the station is
loading stops it once it is loaded. What each option does next to a real network: the Modbus README.
"""
from __future__ import annotations

import argparse
import asyncio
import signal
import logging
import sys
from pathlib import Path

from .log import LEVELS, announce, log as _log

MAX_CONNECTIONS, REQUESTS_PER_STEP, TLS_PORT = 64, 400, 802  # as twin.modbus.server (not imported: start-up speed)


def open_twin(station, on_event=None):
    """The cell `serve` runs for a station (the same one `map` describes, so both agree): the twin and,
    when the station has a `[controller]`, its RAPID program as the robot controller."""
    from twin.cell import open_cell

    return open_cell(Path(station), on_event=on_event)


def controller_log(event: dict) -> None:
    """What the robot controller says, in the server's log: TPWrite lines, a runtime error, the end."""
    kind, t = event.get("type"), event.get("t", 0.0)
    if kind == "print":
        _log(f"[t={t:.3f} s] robot: {event['text']}")
    elif kind == "error":
        _log(f"[t={t:.3f} s] robot program error at line {event['line']}: {event['message']}")
    elif kind == "end":
        _log(f"[t={t:.3f} s] robot program ended ({event['reason']})")


def _positive(text: str) -> float:
    v = float(text)
    if not v > 0:
        raise argparse.ArgumentTypeError(f"must be positive, not {text}")
    return v


def _port(text: str) -> int:
    v = int(text)
    if not 0 <= v <= 0xFFFF:
        raise argparse.ArgumentTypeError(f"a TCP port is 0..65535, not {text}")
    return v


def _unit(text: str) -> int:
    v = int(text)
    if not 0 <= v <= 255:
        raise argparse.ArgumentTypeError(f"a unit id is 0..255, not {text}")
    return v


def _nonnegative(text: str) -> float:
    v = float(text)
    if not v >= 0 or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be 0 or more seconds, not {text}")
    return v


def _count(text: str) -> int:
    v = int(text)
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, not {text}")
    return v


def _networks(text: str):
    from .server import parse_networks

    try:
        return parse_networks(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_commands(subparsers) -> None:
    p = subparsers.add_parser("serve", help="serve a station's signals on Modbus/TCP",
                              description="Run a station and serve every signal on Modbus/TCP (map: `twin map`).")
    p.add_argument("station", help="a station folder or station.toml")
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default: loopback only)")
    p.add_argument("--port", type=_port, default=5020, help="TCP port (default 5020; 0 = any free port, printed)")
    p.add_argument("--unit-id", type=_unit, default=None,
                   help="Modbus unit id answered (default 1; 0 and 255 too); with --profile: the profile's unit id "
                        "(default: every unit id but --map-unit-id)")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--realtime", dest="lockstep", action="store_false",
                      help="step paced to the wall clock at the station's step (the default)")
    mode.add_argument("--lockstep", action="store_true",
                      help="step only when a client writes N to the holding register sim.advance")
    p.add_argument("--speed", type=_positive, default=1.0, help="real time: X times real time (default 1)")
    p.add_argument("--frame-timeout", type=_positive, default=1.0,
                   help="s a client may take to complete a frame it started (default 1)")
    p.add_argument("--log-level", choices=LEVELS, default="info",
                   help="debug, info (connections: the default), warning (watchdog, refusals of note), error")
    g = p.add_argument_group("running next to a real network (see the Modbus README)")
    g.add_argument("--max-connections", type=_count, default=MAX_CONNECTIONS,
                   help=f"connections served at once; one more is refused and logged (default {MAX_CONNECTIONS})")
    g.add_argument("--idle-timeout", type=_nonnegative, default=0.0,
                   help="close a connection with no request for S seconds (default 0: never)")
    g.add_argument("--requests-per-step", type=_count, default=REQUESTS_PER_STEP,
                   help=f"requests answered per step period over all connections, shared fairly (default {REQUESTS_PER_STEP})")
    g.add_argument("--watchdog", type=_nonnegative, default=None, metavar="S",
                   help="comm-loss watchdog: no request for S s puts the gripper in the station's safe state and "
                        "raises comm.lost (default: the station's [watchdog] timeout, else off; 0: off)")
    g.add_argument("--read-only", action="store_true",
                   help="refuse every write (functions 5, 6, 15, 16, 22, 23) with exception 01; reads are served")
    g.add_argument("--allow", type=_networks, default=None, metavar="CIDR[,CIDR...]",
                   help="accept connections only from these addresses or networks; others are closed at once")
    g.add_argument("--gaps", choices=("error", "zero"), default="error",
                   help="reads across unmapped addresses: exception 02 (default) or zeros")
    g.add_argument("--tls-cert", metavar="PEM", help="Modbus/TCP Security: the server's certificate")
    g.add_argument("--tls-key", metavar="PEM", help="the server certificate's private key")
    g.add_argument("--tls-ca", metavar="PEM", help="CA certificate(s) client certificates must chain to (required)")
    g.add_argument("--tls-port", type=_port, default=TLS_PORT, help=f"the TLS port (default {TLS_PORT}; 0 = any free)")
    g.add_argument("--tls-only", action="store_true", help="with TLS: do not listen on plain Modbus/TCP (--port)")
    _add_profile_arguments(p)
    from twin.view.live import add_serve_options  # --view [PORT], --record FILE (twin.view, twin.recording)

    add_serve_options(p)
    from twin.opcua.serve import add_arguments as add_opcua_arguments  # --opcua [PORT], --no-modbus, --opcua-*

    add_opcua_arguments(p)
    p.set_defaults(func=cmd_serve, lockstep=False)

    p = subparsers.add_parser("map", help="print the Modbus register map of a station",
                              description="Print the register map `twin serve` serves for a station.")
    p.add_argument("station", help="a station folder or station.toml")
    p.add_argument("--format", choices=("json", "csv", "md"), default="md", help="output format (default md)")
    p.set_defaults(func=cmd_map)


def _add_profile_arguments(p) -> None:
    from twin.profiles.robotiq import PROFILES

    from .profile import MAP_UNIT_ID

    g = p.add_argument_group("device profiles (see twin/modbus/README.md, Device profiles)")
    g.add_argument("--profile", choices=PROFILES, default=None,
                   help="answer as a real gripper: Robotiq's registers at their published addresses, mapped onto the "
                        "station by its [profile] table")
    g.add_argument("--map-unit-id", type=_unit, default=MAP_UNIT_ID,
                   help=f"with --profile: the unit id that keeps the generated map and sim.* (default {MAP_UNIT_ID})")
    p.add_argument("--faults", metavar="FILE", default=None,
                   help="inject the plant faults of FILE ([faults.NAME] tables as in a campaign: docs/campaigns.md)")


def cmd_map(args) -> int:
    from .register_map import build_map

    rmap = build_map(args.station)
    text = {"json": rmap.to_json, "csv": rmap.to_csv, "md": rmap.to_markdown}[args.format]()
    sys.stdout.write(text if text.endswith("\n") else text + "\n")
    return 0


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


def cmd_serve(args) -> int:
    from . import log as serve_log

    serve_log.setup(args.log_level)
    from twin.opcua.serve import check_arguments as check_opcua_arguments

    if (problem := check_opcua_arguments(args)) is not None:
        print(f"twin serve: error: {problem}", file=sys.stderr)
        return 2
    stop = asyncio.Event()
    signals = _StartUpSignals(stop)  # first thing: loading the station (pybullet) takes a while
    twin = None
    try:
        tls = _tls_from(args)
        if isinstance(tls, int):
            return tls
        from .register_map import build_register_map

        if args.profile and args.unit_id is not None and args.unit_id == args.map_unit_id:
            _log(f"error: --unit-id {args.unit_id} is also the --map-unit-id: give them different unit ids", logging.ERROR)
            return 2
        announce(f"loading station {args.station}")
        twin = open_twin(args.station, on_event=controller_log)
        if getattr(args, "faults", None):
            from twin.campaign.faultfile import load_fault_file
            from twin.campaign.spec import SpecError
            from twin.faults import FaultInjector

            try:
                FaultInjector.attach(twin, load_fault_file(args.faults, twin))
            except SpecError as exc:
                _log(f"error: --faults: {exc}", logging.ERROR)
                return 2
        rmap = build_register_map(twin.signals, twin.station.name)
        profile = None
        if args.profile:
            from twin.core.errors import StationError
            from twin.profiles.robotiq import open_profile

            try:
                profile = open_profile(twin, args.profile)
            except StationError as exc:
                _log(f"error: --profile {args.profile}: {exc}", logging.ERROR)
                return 2
        if signals.received is not None:
            raise StopRequested(signals.received)
        return asyncio.run(serve(twin, rmap, host=args.host, port=args.port,
                                 unit_id=1 if args.unit_id is None else args.unit_id,
                                 lockstep=args.lockstep, speed=args.speed, frame_timeout=args.frame_timeout, stop=stop,
                                 options=args, tls=tls, profile=profile))
    except BaseException:
        if signals.received is None:
            raise
        announce(f"stopped by {signal.Signals(signals.received).name} while starting")
        return 0
    finally:
        signals.ignore()
        try:
            if twin is not None:
                twin.close()
        finally:
            signals.restore()
            serve_log.flush()


def _tls_from(args):
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

    from .server import tls_context

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


def device_identity(twin, rmap):
    """What function 43/14 answers: vendor, product code, version, the station's name."""
    from importlib import metadata

    from .pdu import MAP_CRC_OBJECT, STATION_NAME_OBJECT, DeviceIdentity

    try:
        version = metadata.version("gripper-twin")
    except metadata.PackageNotFoundError:
        version = "0.1.0"
    name = twin.station.name
    return DeviceIdentity(vendor="gripper-twin", product_code="GT-TWIN-SERVE", revision=version,
                          product_name="gripper-twin Modbus/TCP server", model_name="twin serve",
                          user_application_name=name,
                          extended={STATION_NAME_OBJECT: name, MAP_CRC_OBJECT: f"{rmap.crc:08x}"})


async def serve(twin, rmap, *, host: str = "127.0.0.1", port: int = 5020, unit_id: int = 1, lockstep: bool = False,
                speed: float = 1.0, frame_timeout: float = 1.0, stop: asyncio.Event | None = None,
                options=None, tls=None, profile=None) -> int:
    """Serve `twin` with `rmap` until `stop` is set (or SIGINT/SIGTERM). Returns the exit code.
    `options`: the parsed `twin serve` flags (limits, access, watchdog); `tls`: an ssl.SSLContext.
    `profile`: a device profile's gripper (`twin.profiles.robotiq.open_profile`): it answers on `options.unit_id`
    if given, else on every unit id but `options.map_unit_id`, which keeps `rmap` (see `twin.modbus.profile`)."""
    from twin.pacing import LockstepRunner, RealtimeRunner

    from .bridge import TwinBridge
    from .server import ModbusServer

    opt = options
    get = (lambda name, default: getattr(opt, name, default)) if opt is not None else (lambda name, default: default)
    loop = asyncio.get_running_loop()
    loop.set_exception_handler(lambda _loop, ctx: _log(f"event loop: {ctx.get('message')}: "
                                                       f"{ctx.get('exception')!r}", logging.DEBUG))
    stop = stop or asyncio.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        try:
            loop.add_signal_handler(sig, stop.set)
        except (NotImplementedError, RuntimeError, ValueError):  # not the main thread, or Windows
            pass
    bridge = TwinBridge(twin, rmap)
    opcua = None
    if get("opcua", None) is not None:  # OPC UA on the same cell: the bridge's step, then its publication
        from twin.opcua.cell_link import CellLink

        opcua = CellLink(twin, bridge)
    step = opcua.step if opcua is not None else bridge.step
    runner = LockstepRunner(step) if lockstep else RealtimeRunner(step, twin.dt, speed)
    bridge.runner = runner
    watchdog = getattr(twin, "watchdog", None)
    on_request = None
    if watchdog is not None:
        timeout = get("watchdog", None)
        if timeout is not None:
            watchdog.timeout = timeout or None
        watchdog.log = lambda text: _log(text, logging.WARNING)
        if not lockstep:
            watchdog.clock = runner.clock  # real time: the wall clock; lockstep: simulated time
        bridge.extra_status["comm.watchdog_ms"] = round((watchdog.timeout or 0) * 1000)
        on_request = lambda peer, clock_only: watchdog.feed(f"modbus {peer}", clock_only=lockstep and clock_only)  # noqa: E731
    bridge.publish()
    server = ModbusServer(rmap, bridge, unit_id=unit_id, frame_timeout=frame_timeout,
                          requests_per_step=get("requests_per_step", REQUESTS_PER_STEP),
                          step_period=twin.dt / (speed if not lockstep else 1.0),
                          max_connections=get("max_connections", MAX_CONNECTIONS),
                          idle_timeout=get("idle_timeout", 0.0) or None, allow=get("allow", None),
                          read_only=get("read_only", False), gaps_zero=get("gaps", "error") == "zero",
                          identity=device_identity(twin, rmap), on_request=on_request,
                          behind=(lambda: runner.last_late) if not lockstep else None)
    if profile is not None:
        from .profile import MAP_UNIT_ID, serve_profile

        profile_unit = get("unit_id", None)
        unit_id = get("map_unit_id", MAP_UNIT_ID)
        serve_profile(server, profile, bridge, unit_id=profile_unit, map_unit_id=unit_id)
    listening = []
    try:
        if not get("tls_only", False) and not get("no_modbus", False):
            listening.append(("", *await server.start(host, port)))
        if tls is not None:
            tls_port = get("tls_port", TLS_PORT)
            port = tls_port
            listening.append((" (Modbus/TCP Security, TLS)", *await server.start(host, tls_port, ssl=tls)))
    except OSError as exc:
        _log(f"error: cannot listen on {host}:{port}: {exc.strerror or exc}", logging.ERROR)
        await server.close()
        return 2
    how = "lockstep (steps on sim.advance)" if lockstep else f"real time x{speed:g}"
    notes = [f"{len(rmap)} entries", f"unit {unit_id}", how, f"step {twin.dt * 1000:g} ms"]
    if get("read_only", False):
        notes.append("read-only")
    if watchdog is not None and watchdog.timeout:
        notes.append(f"watchdog {watchdog.timeout:g} s ({watchdog.safe_state})")
    announce(f"station {twin.station.name!r}: " + ", ".join(notes))
    if profile is not None:
        where = f"unit {profile_unit}" if profile_unit is not None else f"every unit id but {unit_id}"
        announce(f"profile {profile.kind} on {where}")
    for what, bound_host, bound_port in listening:
        announce(f"listening on {bound_host}:{bound_port}{what}")
    from twin.view.live import serve_front_ends  # --view, --record: the page and the recorder

    start_front_ends = serve_front_ends(opt)
    stop_front_ends = start_front_ends(twin, bridge, runner, rmap) if start_front_ends is not None else None
    ua_server = None
    if opcua is not None:
        from twin.opcua.serve import options_from, start_opcua_logged

        opcua.runner = runner
        ua_server = await start_opcua_logged(opcua, **options_from(opt))
        if ua_server is None:
            if stop_front_ends is not None:
                stop_front_ends()
            await server.close()
            return 2
    task = asyncio.ensure_future(runner.run())
    stopper = asyncio.ensure_future(stop.wait())
    await asyncio.wait({task, stopper}, return_when=asyncio.FIRST_COMPLETED)
    if task.done() and task.exception() is not None:
        _log(f"error: the runner failed: {task.exception()!r}", logging.ERROR)
    if task.done() and not stop.is_set():
        await stop.wait()  # faulted: keep serving the last state until stopped
    runner.stop()
    await server.close()
    if stop_front_ends is not None:
        stop_front_ends()
    if ua_server is not None:
        await ua_server.close()
    for t in (task, stopper):
        if not t.done():
            t.cancel()
    await asyncio.gather(task, stopper, return_exceptions=True)
    late = f", {runner.late_steps} late" if not lockstep else ""
    announce(f"stopped after {twin.step_count} steps ({twin.time:.3f} s simulated{late}, {server.requests} requests)")
    return 0
