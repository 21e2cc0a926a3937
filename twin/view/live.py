"""The live page on a running twin: `twin view STATION` and `twin serve STATION --view [PORT]`.

The runner (`twin.pacing`) steps the twin through the Modbus bridge (`TwinBridge`) in the event loop's
thread, as `twin serve` does. A `FramePublisher` device takes a frame after a step whenever the page
has asked for one; the page's own thread shows the latest frame 30 times a second. A value set on the
page is checked (the same checks and messages as `Twin.write`) and handed to the event loop, which
queues it in the bridge like a Modbus write: it takes effect at the next step. Pause, run and step go
to the runner in the event loop's thread too. Nothing here steps the twin from another thread.
"""
from __future__ import annotations

import asyncio
import math
import signal
import sys
from pathlib import Path

from twin.core.errors import SignalError, SignalRangeError, TwinError


def check_write(spec: dict, value) -> str | None:
    """Why the twin would refuse `value` (SI) for the signal `spec` (a Scene signal), or None when it takes it.

    The same rule and the same message as `Twin.write` (its errors are raised and their text returned)."""
    name = spec["name"]
    try:
        if spec["direction"] != "input":
            raise SignalError(name, "is an output of the twin and cannot be written")
        if spec["type"] in ("float", "int"):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
                raise SignalError(name, f"needs a number, not {value!r}")
            lo, hi = spec.get("min"), spec.get("max")
            if lo is not None and hi is not None and not lo <= value <= hi:
                raise SignalRangeError(name, value, lo, hi, spec.get("unit") or "")
        if spec["type"] == "enum" and value not in spec.get("choices", ()):
            raise SignalError(name, f"{value!r} is not one of {', '.join(repr(c) for c in spec['choices'])}")
    except TwinError as exc:
        return str(exc)
    return None


class LiveControls:
    """The page's handle on a running twin: state from the runner and bridge, writes and buttons via the loop."""

    def __init__(self, publisher, bridge, runner, loop: asyncio.AbstractEventLoop, rmap):
        self.publisher, self.bridge, self.runner, self.loop, self.rmap = publisher, bridge, runner, loop, rmap
        self.mode = runner.mode
        self._specs = {s["name"]: s for s in publisher.scene.signals}
        self.writes = 0

    def state(self) -> dict:
        r = self.runner
        return {"speed": getattr(r, "speed", 1.0), "paused": bool(getattr(r, "paused", False)),
                "late_steps": getattr(r, "late_steps", 0), "fault": bool(getattr(self.bridge, "fault", False))}

    def write(self, name: str, value) -> str | None:
        spec = self._specs.get(name)
        if spec is None:
            return str(SignalError(name, "no such signal in station " + repr(self.publisher.scene.station)))
        refusal = check_write(spec, value)
        if refusal is not None:
            return refusal
        if name not in self.rmap:
            return f"signal {name!r}: not served by this server"
        entry = self.rmap[name]
        self.loop.call_soon_threadsafe(self._submit, entry, value)
        self.writes += 1
        return None

    def _submit(self, entry, value) -> None:
        code = self.bridge.submit([(entry, value)])
        if code:
            print(f"twin view: write of {entry.name} refused by the server (Modbus exception {code})", file=sys.stderr)

    def buttons(self) -> tuple[str, ...]:
        if self.mode == "lockstep":
            return ("step", "advance")
        return ("run", "step") if getattr(self.runner, "paused", False) else ("pause",)

    def press(self, button: str) -> None:
        r = self.runner
        if self.mode == "lockstep":
            n = {"step": 1, "advance": max(1, round(1.0 / self.publisher.scene.dt))}.get(button)
            if n:
                self.loop.call_soon_threadsafe(r.request, n)
            return
        action = {"pause": r.pause, "run": r.resume, "step": r.single_step}.get(button)
        if action is not None:
            self.loop.call_soon_threadsafe(action)


class LiveView:
    """A page on a twin served by `bridge` and paced by `runner` (create it in the event loop's thread).

    The page runs in its own process (`twin.view.process`); this process only publishes frames to it. The
    log says `view on http://HOST:PORT` once the page is up."""

    def __init__(self, twin, bridge, runner, rmap, *, host: str = "127.0.0.1", port: int = 8080, fps: float = 25.0):
        from twin.observe import FramePublisher, attach

        from .process import PageProcess

        try:
            import viser  # noqa: F401
        except ImportError as exc:
            raise TwinError(f"the live view needs viser ({exc}): pip install 'gripper-twin[view]'") from None
        self.twin, self.host = twin, host
        self.publisher = FramePublisher(twin)
        self.controls = LiveControls(self.publisher, bridge, runner, asyncio.get_running_loop(), rmap)
        attach(twin, self.publisher)
        self.page = PageProcess(self.publisher, self.controls, host=host, port=port, fps=fps, on_ready=self._ready)

    def _ready(self, page) -> None:
        from twin.modbus.log import announce

        announce(f"view on {self.url}")

    @property
    def url(self) -> str:
        return f"http://{self.host}:{self.page.port}"

    def close(self) -> None:
        from twin.observe import detach

        self.page.close()
        detach(self.twin, self.publisher)


# -- `twin serve --view/--record` ----------------------------------------------------------------------------------
def add_serve_options(p) -> None:
    """The `twin serve` options of this package: --view [PORT], --view-host, --record FILE."""
    p.add_argument("--view", nargs="?", type=int, const=8080, default=None, metavar="PORT",
                   help="also serve the live 3D page (default port 8080; needs the [view] extra)")
    p.add_argument("--view-host", default="127.0.0.1", help="address the page binds (default loopback)")
    p.add_argument("--record", metavar="FILE", default=None,
                   help="record every signal and body pose at every step into FILE (.parquet, or .csv)")


def serve_front_ends(args):
    """What `twin serve` attaches after creating its bridge and runner: a function (twin, bridge, runner, rmap)
    that starts the recorder and the page asked for by `args` and returns a function that stops them."""
    record, view = getattr(args, "record", None), getattr(args, "view", None)
    if record is None and view is None:
        return None

    def start(twin, bridge, runner, rmap):
        from twin.modbus.log import announce as log

        stoppers = []
        if record is not None:
            from twin.recording import Recorder

            rec = Recorder(twin, record)
            log(f"recording every step into {record}")
            stoppers.append(lambda: (rec.close(), log(f"recording: {rec.rows} rows in {record}")))
        if view is not None:
            live = LiveView(twin, bridge, runner, rmap, host=args.view_host, port=view)  # logs "view on URL"
            stoppers.append(live.close)

        def stop():
            for s in reversed(stoppers):
                s()
        return stop

    return start


# -- `twin view STATION` ---------------------------------------------------------------------------------------------
async def run_view(twin, rmap, *, host: str, port: int, lockstep: bool, speed: float, paused: bool,
                   record: str | None = None, stop: asyncio.Event | None = None, on_ready=None) -> int:
    """Run `twin` paced by a runner, with the page (and a recorder), until SIGINT/SIGTERM or `stop`."""
    from twin.modbus.bridge import TwinBridge
    from twin.modbus.log import announce as log
    from twin.pacing import LockstepRunner, RealtimeRunner

    loop = asyncio.get_running_loop()
    stop = stop or asyncio.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        try:
            loop.add_signal_handler(sig, stop.set)
        except (NotImplementedError, RuntimeError, ValueError):
            pass
    bridge = TwinBridge(twin, rmap, log=log)
    runner = LockstepRunner(bridge.step) if lockstep else RealtimeRunner(bridge.step, twin.dt, speed)
    bridge.runner = runner
    if paused and not lockstep:
        runner.pause()
    recorder = None
    if record is not None:
        from twin.recording import Recorder

        recorder = Recorder(twin, record)
    live = LiveView(twin, bridge, runner, rmap, host=host, port=port)
    how = "lockstep (Step / Advance on the page)" if lockstep else f"real time x{speed:g}" + (", paused" if paused else "")
    log(f"station {twin.station.name!r}: {how}, step {twin.dt * 1000:g} ms")
    if on_ready is not None:
        on_ready(live)
    task = asyncio.ensure_future(runner.run())
    stopper = asyncio.ensure_future(stop.wait())
    await asyncio.wait({task, stopper}, return_when=asyncio.FIRST_COMPLETED)
    if task.done() and not stop.is_set():
        await stop.wait()  # faulted: keep showing the last state until stopped
    runner.stop()
    for t in (task, stopper):
        if not t.done():
            t.cancel()
    await asyncio.gather(task, stopper, return_exceptions=True)
    live.close()
    if recorder is not None:
        recorder.close()
        log(f"recording: {recorder.rows} rows in {record}")
    log(f"stopped after {twin.step_count} steps ({twin.time:.3f} s simulated)")
    return 0


def cmd_view(args) -> int:
    from twin.modbus.log import announce as log

    if args.replay is not None:
        from .replay import run_replay

        return run_replay(args.replay, host=args.host, port=args.port, at=args.at)
    if args.station is None:
        raise TwinError("twin view needs a STATION (or --replay FILE)")
    try:
        import viser  # noqa: F401
    except ImportError:
        raise TwinError("the live view needs viser: pip install 'gripper-twin[view]'") from None
    from twin.cell import open_cell
    from twin.modbus.cli import controller_log
    from twin.modbus.register_map import build_register_map

    log(f"loading station {args.station}")
    twin = open_cell(Path(args.station), on_event=controller_log)
    try:
        rmap = build_register_map(twin.signals, twin.station.name)
        return asyncio.run(run_view(twin, rmap, host=args.host, port=args.port, lockstep=args.lockstep,
                                    speed=args.speed, paused=args.paused, record=args.record))
    finally:
        twin.close()
