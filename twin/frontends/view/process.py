"""The live page in a process of its own (`twin.frontends.process`), so that drawing it never holds up the
simulation.

The page's work (viser's websocket server, turning frames into messages for each browser) is Python under the
GIL: in the simulation's process it would take turns with the steps and make a real-time server late. So the
page runs behind the front-end adapter, like every front end but Modbus:

- the page's process (`PageFront`) asks for a frame `fps` times a second; in the simulation's process the
  adapter's companion (`PageFeed`) answers after the next step (or at once, when a step ran since the last
  frame, or the run state changed) with the frame (every body's pose, taken from the twin in the stepping
  thread), the run state and the buttons that apply: a few kilobytes. No thread in the simulation's process.
- a value typed on the page is submitted through the adapter: validated in the simulation's process by the
  exchange (`SignalSpec.check`), and a refusal's message is the page's message; a button is the runner's
  pause, resume, single step or request.
If the page's process dies the simulation goes on.
"""
from __future__ import annotations

import asyncio
import threading

WRITE_TIMEOUT = 5.0  # s the page waits for the simulation's answer to a write


# -- the simulation's process ----------------------------------------------------------------------------------
class PageFeed:
    """The page's companion in the simulation's process (the adapter's `local`): frames when the page asks."""

    def __init__(self, twin, fps: float):
        from twin.observe.scene import FramePublisher

        self.twin, self.fps = twin, fps
        self.publisher = FramePublisher(twin)
        self.scene = self.publisher.scene
        self.cell = None
        self.send = None
        self.wanted = False
        self.last = None
        self.frames_sent = 0

    def start(self, cell, send) -> None:
        from twin.observe.scene import attach

        self.cell, self.send = cell, send
        attach(self.twin, self.publisher)

    def state(self) -> dict:
        r, ex = self.cell.runner, self.cell.exchange
        return {"speed": getattr(r, "speed", 1.0), "paused": bool(getattr(r, "paused", False)),
                "late_steps": getattr(r, "late_steps", 0), "fault": bool(ex.fault)}

    def buttons(self) -> tuple[str, ...]:
        r = self.cell.runner
        if getattr(r, "mode", "lockstep") == "lockstep":
            return ("step", "advance")
        return ("run", "step") if getattr(r, "paused", False) else ("pause",)

    def on_message(self, payload) -> None:
        if payload == "want":
            self.wanted = True
            self._offer()

    def after_snapshot(self, snapshot) -> None:
        if self.wanted:
            self._offer()

    def _offer(self) -> None:
        """Send the newest frame if the page has not seen it (nor this run state)."""
        self.publisher.refresh_if_stale()
        frame, state, buttons = self.publisher.latest, self.state(), self.buttons()
        key = (frame.step, tuple(sorted(state.items())), buttons)
        if key != self.last:
            self.send(("frame", frame, state, buttons))
            self.frames_sent += 1
            self.last, self.wanted = key, False

    def close(self) -> None:
        from twin.observe.scene import detach

        detach(self.twin, self.publisher)


# -- the page's process ------------------------------------------------------------------------------------------
class RemoteControls:
    """In the page's process: the page's `Controls`, by the adapter to the simulation's process."""

    def __init__(self, remote, loop: asyncio.AbstractEventLoop, scene):
        self.remote, self.loop, self.mode = remote, loop, remote.mode
        self.dt = scene.dt
        self._state: dict = {}
        self._buttons: tuple[str, ...] = ()

    def state(self) -> dict:
        return self._state

    def buttons(self) -> tuple[str, ...]:
        return self._buttons

    def write(self, name: str, value) -> str | None:
        """None when the cell takes `value` (SI) at its next step, else its refusal's message (viser's thread)."""
        from twin.core.errors import TwinError

        if threading.current_thread() is threading.main_thread():  # never wait for the loop in the loop's thread
            asyncio.ensure_future(self.remote.submit([(name, value)]))
            return None
        fut = asyncio.run_coroutine_threadsafe(self.remote.submit([(name, value)]), self.loop)
        try:
            fut.result(WRITE_TIMEOUT)
        except TwinError as exc:
            return str(exc)
        except TimeoutError:
            return "the simulation did not answer"
        return None

    def press(self, button: str) -> None:
        self.loop.call_soon_threadsafe(self._press, button)

    def _press(self, button: str) -> None:
        if self.mode == "lockstep":
            n = {"step": 1, "advance": max(1, round(1.0 / self.dt))}.get(button)
            if n:
                self.remote.control("request", n)
            return
        action = {"pause": "pause", "run": "resume", "step": "single_step"}.get(button)
        if action is not None:
            self.remote.control(action)


class PageFront:
    """The page as the adapter's front end, in its own process: `FrontEndProcess("view", "twin.frontends.view.process:page", ...)`."""

    def __init__(self, options: dict):
        self.options = options
        self.page = None
        self.task = None

    async def start(self, remote):
        from twin.observe.scene import Scene

        from .page import CellPage

        o = self.options
        scene = Scene.from_dict(o["scene"])
        loop = asyncio.get_running_loop()
        self.controls = RemoteControls(remote, loop, scene)
        self.page = await loop.run_in_executor(None, lambda: CellPage(scene, self.controls, host=o["host"],
                                                                      port=o["port"], fps=o["fps"]))
        remote.on_local(self._local)
        self.remote = remote
        self.task = asyncio.ensure_future(self._ask(1.0 / o["fps"]))
        url = f"http://{o['host']}:{self.page.port}"
        return [f"view on {url}"], [{"name": "view", "protocol": "http", "host": o["host"], "port": self.page.port,
                                     "url": url}]

    async def _ask(self, period: float) -> None:
        while True:
            self.remote.send_local("want")
            await asyncio.sleep(period)

    def _local(self, payload) -> None:
        if payload[0] == "frame":
            _, frame, state, buttons = payload
            self.controls._state, self.controls._buttons = state, buttons
            self.page.show(frame)

    async def close(self) -> int:
        if self.task is not None:
            self.task.cancel()
        if self.page is not None:
            self.page.close()
        return 0


def page(options: dict) -> PageFront:
    return PageFront(options)
