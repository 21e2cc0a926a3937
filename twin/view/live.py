"""The live page on a running cell: `twin view STATION` and `twin serve STATION --view [PORT]`.

The runner (`twin.pacing`) steps the twin through the Modbus bridge (`TwinBridge`) in the event loop's
thread, as `twin serve` does. A `FramePublisher` device takes a frame after a step whenever the page
has asked for one; the page's own thread shows the latest frame 30 times a second. A value set on the
page is checked (the same checks and messages as `Twin.write`) and handed to the event loop, which
queues it in the bridge like a Modbus write: it takes effect at the next step. Pause, run and step go
to the runner in the event loop's thread too. Nothing here steps the twin from another thread.
"""
from __future__ import annotations

import asyncio
import signal
import sys
from pathlib import Path

from twin.core.errors import TwinError
from twin.core.signals import SignalSpec

PAGE_START_TIMEOUT = 60.0  # s the cell waits for the page's process to listen before it runs without it


def check_write(spec: dict, value) -> str | None:
    """Why the twin would refuse `value` (SI) for the signal `spec` (a Scene signal), or None when it takes it.

    The one write validation, `SignalSpec.check`, so the same rule and the same message as `Twin.write`, the
    exchange and every other front end (its error's text is the page's message)."""
    try:
        SignalSpec(spec["name"], spec["direction"], spec["type"], spec.get("unit") or "", spec.get("min"),
                   spec.get("max"), choices=tuple(spec.get("choices") or ())).check(value)
    except TwinError as exc:
        return str(exc)
    return None


class LiveControls:
    """The page's handle on a running cell: state from the runner and exchange, writes and buttons via the loop."""

    def __init__(self, publisher: FramePublisher, exchange, runner, loop: asyncio.AbstractEventLoop):
        self.publisher, self.exchange, self.runner, self.loop = publisher, exchange, runner, loop
        self.mode = runner.mode
        self.writes = 0

    def state(self) -> dict:
        r = self.runner
        return {"speed": getattr(r, "speed", 1.0), "paused": bool(getattr(r, "paused", False)),
                "late_steps": getattr(r, "late_steps", 0), "fault": bool(self.exchange.fault)}

    def write(self, name: str, value) -> str | None:
        """None when the cell takes `value` (SI) at its next step, else why not (the exchange's message)."""
        try:
            self.exchange.check(name, value)
        except TwinError as exc:
            return str(exc)
        self.loop.call_soon_threadsafe(self._submit, name, value)
        self.writes += 1
        return None

    def _submit(self, name: str, value) -> None:
        try:
            self.exchange.submit([(name, value)])
        except TwinError as exc:
            print(f"twin view: write of {name} refused: {exc}", file=sys.stderr)

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
    """A page on a cell's twin, written through `exchange` and paced by `runner` (create it in the event loop's
    thread).

    The page runs in its own process (`twin.view.process`); this process only publishes frames to it. The
    log says `view on http://HOST:PORT` once the page is up."""

    def __init__(self, twin, exchange, runner, *, host: str = "127.0.0.1", port: int = 8080, fps: float = 25.0):
        from twin.observe import FramePublisher, attach

        from .process import PageProcess

        try:
            import viser  # noqa: F401
        except ImportError as exc:
            raise TwinError(f"the live view needs viser ({exc}): pip install 'gripper-twin[view]'") from None
        self.twin, self.host = twin, host
        self.publisher = FramePublisher(twin)
        self.controls = LiveControls(self.publisher, exchange, runner, asyncio.get_running_loop())
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
class ViewFrontEnd:
    """The live page as a front end of a cell (`twin_app.cell`)."""

    name = "view"

    def __init__(self, *, host: str = "127.0.0.1", port: int = 8080, on_ready=None):
        self.host, self.port, self.on_ready = host, port, on_ready
        self.live: LiveView | None = None

    async def start(self, cell) -> list[str]:
        self.live = LiveView(cell.twin, cell.exchange, cell.runner, host=self.host, port=self.port)
        if self.on_ready is not None:
            self.on_ready(self.live)
        # the page's process is up (or failed) before the cell runs, so `ready` can say where it is
        await asyncio.get_running_loop().run_in_executor(None, self.live.page.ready.wait, PAGE_START_TIMEOUT)
        return []  # the page says "view on URL" once it is up

    def endpoints(self) -> list[dict]:
        """Where the page is, for the `ready` event (`twin.events`); nothing if it did not start."""
        if self.live is None or self.live.page.port is None:
            return []
        return [{"name": self.name, "protocol": "http", "host": self.host, "port": self.live.page.port,
                 "url": self.live.url}]

    async def close(self) -> None:
        if self.live is not None:
            self.live.close()


class RecorderFrontEnd:
    """`--record FILE` as a front end of a cell: every signal and body pose at every step."""

    name = "record"

    def __init__(self, path: str):
        self.path = path
        self.recorder = None

    async def start(self, cell) -> list[str]:
        from twin.recording import Recorder

        self.recorder = Recorder(cell.twin, self.path, exchange=cell.exchange)  # the values it publishes anyway
        return [f"recording every step into {self.path}"]

    def endpoints(self) -> list[dict]:
        return [{"name": self.name, "file": str(self.path)}]

    async def close(self) -> None:
        if self.recorder is not None:
            from twin.modbus.log import announce

            self.recorder.close()
            announce(f"recording: {self.recorder.rows} rows in {self.path}")


def front_ends_from_args(args) -> list:
    """The front ends `twin serve --record FILE --view [PORT]` asks for (in that order)."""
    fronts = []
    if getattr(args, "record", None) is not None:
        fronts.append(RecorderFrontEnd(args.record))
    if getattr(args, "view", None) is not None:
        fronts.append(ViewFrontEnd(host=args.view_host, port=args.view))
    return fronts


# -- `twin view STATION` ---------------------------------------------------------------------------------------------
def cmd_view(args, open_cell) -> int:
    """`twin view`: `open_cell(station, events)` (the application's) gives the cell; the page (and a recorder)
    serve it. `--events FILE|-`: the machine interface (`twin.events`)."""
    from twin.events import Events
    from twin.modbus.log import announce as log

    try:
        events = Events.open(getattr(args, "events", None))
    except OSError as exc:
        raise TwinError(f"--events {args.events}: {exc.strerror or exc}") from None
    try:
        if args.replay is not None:
            from .replay import run_replay

            return run_replay(args.replay, host=args.host, port=args.port, at=args.at, events=events)
        if args.station is None:
            raise TwinError("twin view needs a STATION (or --replay FILE)")
        try:
            import viser  # noqa: F401
        except ImportError:
            raise TwinError("the live view needs viser: pip install 'gripper-twin[view]'") from None
        log(f"loading station {args.station}")
        cell = open_cell(Path(args.station), events)
        try:
            if args.record is not None:
                cell.add_front_end(RecorderFrontEnd(args.record))
            cell.add_front_end(ViewFrontEnd(host=args.host, port=args.port))
            return asyncio.run(cell.serve(lockstep=args.lockstep, speed=args.speed, paused=args.paused))
        finally:
            cell.close()
    finally:
        events.close()
