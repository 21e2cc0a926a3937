"""`twin view --replay FILE`: a recording in the live page, with a timeline to scrub, play, pause and step.

The page is the same as for a running twin (the cell, the signal table, the state line); nothing can be
written. The timeline is a slider over the recording's simulated time; Play runs it at the chosen speed
against the wall clock, Pause stops it, Step and Back move one recorded step.
"""
from __future__ import annotations

import os
import signal
import threading
import time

from twin.observe.recording import Recording


class ReplayControls:
    """The page's handle on a recording: a playhead (row index) moved by the timeline and the buttons."""

    mode = "replay"

    def __init__(self, rec: Recording):
        self.rec = rec
        self.index = 0
        self.playing = False
        self.speed = 1.0
        self._t0: tuple[float, float] | None = None  # (wall clock, recording time) when play started
        self._slider = None
        self._moving_slider = False

    # -- Controls ---------------------------------------------------------------------------------------------------
    def state(self) -> dict:
        return {"speed": self.speed, "paused": not self.playing}

    def write(self, name: str, value) -> str | None:
        return f"signal {name!r}: a recording is played back, not written"

    def buttons(self) -> tuple[str, ...]:
        return ("pause", "step") if self.playing else ("run", "step")

    def press(self, button: str) -> None:
        if button == "run":
            if self.index >= len(self.rec) - 1:
                self.index = 0
            self.playing = True
            self._t0 = (time.perf_counter(), float(self.rec.time[self.index]))
        elif button == "pause":
            self.playing = False
        elif button == "step":
            self.playing = False
            self.seek_index(self.index + 1)
        elif button == "back":
            self.playing = False
            self.seek_index(self.index - 1)

    def add_widgets(self, gui) -> None:
        rec = self.rec
        t_end = float(rec.time[-1]) if len(rec) else 0.0
        dt = rec.scene.dt
        self._slider = gui.add_slider("time [s]", min=float(rec.time[0]), max=max(t_end, float(rec.time[0]) + dt),
                                      step=dt, initial_value=float(rec.time[0]))
        self._speed = gui.add_dropdown("speed", ["0.1x", "0.25x", "0.5x", "1x", "2x", "5x"], initial_value="1x")
        back = gui.add_button("Back one step")
        back.on_click(lambda _e: self.press("back"))
        gui.add_markdown(f"{len(rec)} steps, {t_end:.3f} s, step {dt * 1000:g} ms: `{rec.path.name}`")

        @self._slider.on_update
        def _(_event):
            if not self._moving_slider:
                self.playing = False
                self.index = rec.index_at(float(self._slider.value))

        @self._speed.on_update
        def _(_event):
            self.speed = float(self._speed.value.rstrip("x"))
            if self.playing:
                self._t0 = (time.perf_counter(), float(rec.time[self.index]))

    def seek_index(self, i: int) -> None:
        self.index = max(0, min(len(self.rec) - 1, i))

    # -- the frame loop ------------------------------------------------------------------------------------------------
    def advance(self) -> None:
        """Move the playhead with the wall clock while playing; keep the slider on it."""
        if self.playing and self._t0 is not None:
            wall0, t0 = self._t0
            t = t0 + (time.perf_counter() - wall0) * self.speed
            self.index = self.rec.index_at(t)
            if self.index >= len(self.rec) - 1:
                self.playing = False
        if self._slider is not None:
            t = float(self.rec.time[self.index])
            if abs(float(self._slider.value) - t) > 1e-9:
                self._moving_slider = True
                try:
                    self._slider.value = t
                finally:
                    self._moving_slider = False

    def frame(self):
        return self.rec.frame(self.index)


def run_replay(path, *, host: str = "127.0.0.1", port: int = 8080, at: float | None = None,
               stop: threading.Event | None = None, on_ready=None, events=None) -> int:
    """Serve a recording's page until stopped; `events` (`twin.observe.events.Events`): `ready` with the page's address,
    `stopped` at the end."""
    from twin.core.errors import TwinError

    try:
        import viser  # noqa: F401
    except ImportError:
        raise TwinError("the view needs viser: pip install 'gripper-twin[view]'") from None
    from twin.frontends.modbus.log import announce

    from .page import CellPage, FrameLoop

    rec = Recording.open(path)
    controls = ReplayControls(rec)
    if at is not None:
        if not rec.time[0] - 1e-9 <= at <= rec.time[-1] + 1e-9:
            raise TwinError(f"{rec.path}: --at {at:g} s is outside the recording ({rec.time[0]:g} to {rec.time[-1]:g} s)")
        controls.seek_index(rec.index_at(at))
    page = CellPage(rec.scene, controls, host=host, port=port, title=f"replay: {rec.path.name}")
    loop = FrameLoop(page, controls.frame, before=controls.advance).start()
    announce(f"replaying {rec.path} ({len(rec)} steps, {rec.time[-1]:.3f} s)")
    announce(f"view on http://{host}:{page.port}")
    if events is not None:
        events.emit("ready", pid=os.getpid(), recording=str(rec.path), front_ends=[
            {"name": "view", "protocol": "http", "host": host, "port": page.port, "url": f"http://{host}:{page.port}"}])
    stop = stop or threading.Event()
    previous = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            previous[sig] = signal.signal(sig, lambda *_: stop.set())
    if on_ready is not None:
        on_ready(page, controls)
    try:
        while not stop.wait(0.2):
            pass
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        loop.stop()
        page.close()
        if events is not None:
            events.emit("stopped", steps=len(rec), requests=0)
    return 0
