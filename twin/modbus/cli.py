"""The `twin serve` and `twin map` subcommands (added to the `twin` command by `add_commands`).

    twin serve STATION [--host 127.0.0.1] [--port 5020] [--unit-id 1] [--realtime | --lockstep] [--speed X]
    twin map STATION [--format json|csv|md]

`serve` logs to stderr: one line when it starts loading the station, one when listening (with the bound
port, so `--port 0` is usable), one per client connect and disconnect, one when stopped. It stops cleanly
on Ctrl-C or SIGTERM (exit 0); one that comes while the station is loading stops it once it is loaded.
"""
from __future__ import annotations

import argparse
import asyncio
import signal
import sys
from pathlib import Path

from .log import log as _log


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


def add_commands(subparsers) -> None:
    p = subparsers.add_parser("serve", help="serve a station's signals on Modbus/TCP",
                              description="Run a station and serve every signal on Modbus/TCP (map: `twin map`).")
    p.add_argument("station", help="a station folder or station.toml")
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default: loopback only)")
    p.add_argument("--port", type=_port, default=5020, help="TCP port (default 5020; 0 = any free port, printed)")
    p.add_argument("--unit-id", type=_unit, default=1, help="Modbus unit id answered (default 1; 0 and 255 too)")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--realtime", dest="lockstep", action="store_false",
                      help="step paced to the wall clock at the station's step (the default)")
    mode.add_argument("--lockstep", action="store_true",
                      help="step only when a client writes N to the holding register sim.advance")
    p.add_argument("--speed", type=_positive, default=1.0, help="real time: X times real time (default 1)")
    p.add_argument("--frame-timeout", type=_positive, default=1.0,
                   help="s a client may take to complete a frame it started (default 1)")
    p.set_defaults(func=cmd_serve, lockstep=False)

    p = subparsers.add_parser("map", help="print the Modbus register map of a station",
                              description="Print the register map `twin serve` serves for a station.")
    p.add_argument("station", help="a station folder or station.toml")
    p.add_argument("--format", choices=("json", "csv", "md"), default="md", help="output format (default md)")
    p.set_defaults(func=cmd_map)


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
    stop = asyncio.Event()
    signals = _StartUpSignals(stop)  # first thing: loading the station (pybullet) takes a while
    twin = None
    try:
        from .register_map import build_register_map

        _log(f"loading station {args.station}")
        twin = open_twin(args.station, on_event=controller_log)
        rmap = build_register_map(twin.signals, twin.station.name)
        if signals.received is not None:
            raise StopRequested(signals.received)
        return asyncio.run(serve(twin, rmap, host=args.host, port=args.port, unit_id=args.unit_id,
                                 lockstep=args.lockstep, speed=args.speed, frame_timeout=args.frame_timeout, stop=stop))
    except BaseException:
        if signals.received is None:
            raise
        _log(f"stopped by {signal.Signals(signals.received).name} while starting")
        return 0
    finally:
        signals.ignore()
        try:
            if twin is not None:
                twin.close()
        finally:
            signals.restore()


async def serve(twin, rmap, *, host: str = "127.0.0.1", port: int = 5020, unit_id: int = 1, lockstep: bool = False,
                speed: float = 1.0, frame_timeout: float = 1.0, stop: asyncio.Event | None = None) -> int:
    """Serve `twin` with `rmap` until `stop` is set (or SIGINT/SIGTERM). Returns the exit code."""
    from twin.pacing import LockstepRunner, RealtimeRunner

    from .bridge import TwinBridge
    from .server import ModbusServer

    loop = asyncio.get_running_loop()
    stop = stop or asyncio.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        try:
            loop.add_signal_handler(sig, stop.set)
        except (NotImplementedError, RuntimeError, ValueError):  # not the main thread, or Windows
            pass
    bridge = TwinBridge(twin, rmap)
    runner = LockstepRunner(bridge.step) if lockstep else RealtimeRunner(bridge.step, twin.dt, speed)
    bridge.runner = runner
    bridge.publish()
    server = ModbusServer(rmap, bridge, unit_id=unit_id, frame_timeout=frame_timeout)
    try:
        bound_host, bound_port = await server.start(host, port)
    except OSError as exc:
        _log(f"error: cannot listen on {host}:{port}: {exc.strerror or exc}")
        return 2
    how = "lockstep (steps on sim.advance)" if lockstep else f"real time x{speed:g}"
    _log(f"station {twin.station.name!r}: {len(rmap)} entries, unit {unit_id}, {how}, step {twin.dt * 1000:g} ms")
    _log(f"listening on {bound_host}:{bound_port}")
    task = asyncio.ensure_future(runner.run())
    stopper = asyncio.ensure_future(stop.wait())
    await asyncio.wait({task, stopper}, return_when=asyncio.FIRST_COMPLETED)
    if task.done() and task.exception() is not None:
        _log(f"error: the runner failed: {task.exception()!r}")
    if task.done() and not stop.is_set():
        await stop.wait()  # faulted: keep serving the last state until stopped
    runner.stop()
    await server.close()
    for t in (task, stopper):
        if not t.done():
            t.cancel()
    await asyncio.gather(task, stopper, return_exceptions=True)
    late = f", {runner.late_steps} late" if not lockstep else ""
    _log(f"stopped after {twin.step_count} steps ({twin.time:.3f} s simulated{late}, {server.requests} requests)")
    return 0
