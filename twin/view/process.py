"""The live page in a process of its own, so that drawing it never holds up the simulation.

The page's work (viser's websocket server, turning frames into messages for each browser) is Python
under the GIL: in the simulation's process it would take turns with the steps and make a real-time
server late. So the simulation's process keeps only a small link thread: every page frame it asks the
`FramePublisher` for a frame and sends it, with the run state, down a pipe (a few kilobytes); the page
process draws it. What the page asks for comes back up the same pipe: a write (already checked with the
twin's rules, checked again on arrival) or a button; the link thread hands it to the event loop, which
queues it like a Modbus write. If the page process dies the simulation goes on.
"""
from __future__ import annotations

import multiprocessing
import sys
import threading
import time


class RemoteControls:
    """In the page's process: the `Controls` of the page, by message to the simulation's process."""

    def __init__(self, conn, mode: str, scene):
        from .live import check_write

        self.conn, self.mode, self._check = conn, mode, check_write
        self._specs = {s["name"]: s for s in scene.signals}
        self._state: dict = {}
        self._buttons: tuple[str, ...] = ()
        self._lock = threading.Lock()

    def state(self) -> dict:
        return self._state

    def buttons(self) -> tuple[str, ...]:
        return self._buttons

    def write(self, name: str, value) -> str | None:
        spec = self._specs.get(name)
        if spec is None:
            return f"signal {name!r}: no such signal"
        refusal = self._check(spec, value)
        if refusal is None:
            self._send(("write", name, value))
        return refusal

    def press(self, button: str) -> None:
        self._send(("press", button))

    def _send(self, msg) -> None:
        with self._lock:
            try:
                self.conn.send(msg)
            except (BrokenPipeError, EOFError, OSError):
                pass


def page_main(scene_dict: dict, mode: str, host: str, port: int, fps: float, conn) -> None:
    """The page process: draw the frames that arrive until told to stop (or the simulation is gone)."""
    from twin.observe import Scene

    from .page import CellPage

    scene = Scene.from_dict(scene_dict)
    controls = RemoteControls(conn, mode, scene)
    try:
        page = CellPage(scene, controls, host=host, port=port, fps=fps)
    except Exception as exc:  # noqa: BLE001 - report any start-up failure to the simulation's log
        controls._send(("error", f"{type(exc).__name__}: {exc}"))
        return
    controls._send(("ready", page.port))
    try:
        while True:
            if not conn.poll(1.0):
                continue
            msg = conn.recv()
            while conn.poll(0):  # draw only the newest frame
                newer = conn.recv()
                if newer[0] != "frame":
                    msg = newer
                    break
                msg = newer
            if msg[0] == "stop":
                break
            if msg[0] == "frame":
                _, frame, state, buttons = msg
                controls._state, controls._buttons = state, buttons
                page.show(frame)
    except (EOFError, OSError, KeyboardInterrupt):
        pass
    finally:
        page.close()


class PageProcess:
    """In the simulation's process: the page process, and the link thread that feeds it frames."""

    def __init__(self, publisher, controls, *, host: str, port: int, fps: float, on_ready=None):
        self.publisher, self.controls, self.period = publisher, controls, 1.0 / fps
        self.on_ready = on_ready
        self.port: int | None = None
        self.ready = threading.Event()
        self.error: str | None = None
        self.frames_sent = 0
        ctx = multiprocessing.get_context("spawn")  # a clean interpreter: no pybullet, no event loop copied
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(target=page_main, name="twin-view-page", daemon=True,
                                   args=(publisher.scene.as_dict(), controls.mode, host, port, fps, child))
        self.process.start()
        child.close()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._link, name="view-link", daemon=True)
        self._thread.start()

    def _link(self) -> None:
        next_t = time.perf_counter()
        last = None
        steps_seen = -1
        try:
            while not self._stop.is_set():
                while self.conn.poll(0):
                    self._handle(self.conn.recv())
                if self.ready.is_set():
                    count = self.publisher.observer.twin.step_count
                    if self.publisher.stale and count == steps_seen:
                        # no step since the last tick, but the frame is older than the last step (a burst
                        # ended between two requests): take the last state, in the stepping thread
                        self.controls.loop.call_soon_threadsafe(self.publisher.refresh_if_stale)
                    steps_seen = count
                    self.publisher.request()
                    frame = self.publisher.latest
                    state, buttons = self.controls.state(), self.controls.buttons()
                    key = (frame.step, tuple(sorted(state.items())), buttons)
                    if key != last:
                        self.conn.send(("frame", frame, state, buttons))
                        self.frames_sent += 1
                        last = key
                next_t += self.period
                delay = next_t - time.perf_counter()
                if delay < 0:
                    next_t, delay = time.perf_counter(), 0.0
                self._stop.wait(delay)
        except (BrokenPipeError, EOFError, OSError):
            if not self._stop.is_set():
                print("twin view: the page process is gone; the simulation goes on without it", file=sys.stderr)

    def _handle(self, msg) -> None:
        kind = msg[0]
        if kind == "ready":
            self.port = msg[1]
            self.ready.set()
            if self.on_ready is not None:
                self.on_ready(self)
        elif kind == "error":
            self.error = msg[1]
            self.ready.set()
            print(f"twin view: the page did not start: {msg[1]}", file=sys.stderr)
        elif kind == "write":
            refusal = self.controls.write(msg[1], msg[2])
            if refusal is not None:
                print(f"twin view: {refusal}", file=sys.stderr)
        elif kind == "press":
            self.controls.press(msg[1])

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        try:
            self.conn.send(("stop",))
        except (BrokenPipeError, EOFError, OSError):
            pass
        self.process.join(timeout=5.0)
        if self.process.is_alive():
            self.process.terminate()
            self.process.join(timeout=2.0)
        self.conn.close()
