"""The live page on a running cell: `twin view STATION` and `twin serve STATION --view [PORT]`.

The runner (`twin.runtime.pacing`) steps the cell in the event loop's thread, as `twin serve` does; the page runs in
a process of its own behind the front-end adapter (`twin.frontends.view.process`, `twin.frontends.process`): it gets a
frame when it asks, after a step; a value set on the page is validated by the exchange in the simulation's
process and takes effect at the next step, like a Modbus write; pause, run and step go to the runner.
Nothing steps the twin from another thread or process.
"""
from __future__ import annotations

import asyncio
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


# -- `twin serve --view/--record` ----------------------------------------------------------------------------------
class ViewFrontEnd:
    """The live page as a front end of a cell (`twin_app.cell`): in a process of its own, behind the front-end
    adapter (`twin.frontends.process`; the page's side: `twin.frontends.view.process`)."""

    name = "view"

    def __init__(self, *, host: str = "127.0.0.1", port: int = 8080, fps: float = 25.0):
        self.host, self.port, self.fps = host, port, fps
        self.process = None

    async def start(self, cell) -> list[str]:
        import importlib.util

        from twin.frontends.process import FrontEndProcess

        from .process import PageFeed

        if importlib.util.find_spec("viser") is None:
            raise TwinError("the live view needs viser: pip install 'gripper-twin[view]'")
        feed = PageFeed(cell.twin, self.fps)
        self.process = FrontEndProcess(self.name, "twin.frontends.view.process:page", {
            "scene": feed.scene.as_dict(), "host": self.host, "port": self.port, "fps": self.fps},
            local=feed, start_timeout=PAGE_START_TIMEOUT)
        try:
            return await self.process.start(cell)  # "view on URL" once the page is up
        except (OSError, TwinError) as exc:  # the cell runs without its page
            cell.log(f"twin view: the page did not start: {exc}", 30)
            self.process = None
            return []

    def endpoints(self) -> list[dict]:
        """Where the page is, for the `ready` event (`twin.observe.events`); nothing if it did not start."""
        return [] if self.process is None else self.process.endpoints()

    async def close(self) -> None:
        if self.process is not None:
            await self.process.close()


class RecorderFrontEnd:
    """`--record FILE` as a front end of a cell: every signal and body pose at every step."""

    name = "record"

    def __init__(self, path: str):
        self.path = path
        self.recorder = None

    async def start(self, cell) -> list[str]:
        from twin.observe.recording import Recorder

        self.recorder = Recorder(cell.twin, self.path, exchange=cell.exchange)  # the values it publishes anyway
        return [f"recording every step into {self.path}"]

    def endpoints(self) -> list[dict]:
        return [{"name": self.name, "file": str(self.path)}]

    async def close(self) -> None:
        if self.recorder is not None:
            from twin.frontends.modbus.log import announce

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
    serve it. `--events FILE|-`: the machine interface (`twin.observe.events`)."""
    from twin.observe.events import Events
    from twin.frontends.modbus.log import announce as log

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
