"""Runners that pace a stepped simulation: the only module that knows the wall clock.

The core (`twin.core`) has no clock: its time is step count x dt. Something has to decide *when* to
step. Two runners do, both on the event loop they share with the server that exposes the simulation
(so a step and a request never interleave: a read sees a completed step):

- `RealtimeRunner(step, dt, speed)`: step k is due at t0 + k * dt / speed on the wall clock. The runner
  sleeps until a step's start time, runs it, and counts it *late* when it finishes after its due time
  (the state for simulated time t was not ready when the wall clock reached t). A late runner catches
  up by running the following steps back to back; when it is more than `max_lag` behind it stops
  catching up and restarts its schedule from now (like a PLC that skips cycles), still counting.
- `LockstepRunner(step)`: steps only when asked. `request(n)` adds n steps; `remaining` is how many are
  still to run. The simulation never moves on its own, so a scripted client gets the same results,
  bit for bit, run after run.

Real-time scheduling (`RealtimeRunner(..., priority=True)`, what `twin serve --realtime` asks for): while it
runs, the runner's thread asks the operating system for SCHED_RR at the lowest real-time priority, as soft-PLC
runtimes do, so a busy machine's ordinary processes cannot push its steps late; processes it starts afterwards
do not inherit it (SCHED_RESET_ON_FORK). It always sleeps at least `MIN_SLEEP` of a period between steps, so a
late simulation catching up cannot starve the machine. Where the OS does not allow it (no CAP_SYS_NICE, no
RLIMIT_RTPRIO, not Linux) the runner quietly runs as before; it puts the old policy back when it stops. Never
in lockstep, nor in a campaign's workers (they step cells in process and run no runner).

`step` is a callable that runs one simulation step and returns False when the simulation cannot go on
(a fault): the runner then stops stepping.
"""
from __future__ import annotations

import asyncio
import os
import time
from collections.abc import Callable

Step = Callable[[], bool]
MIN_SLEEP = 0.1  # share of a period slept between steps under real-time scheduling


def ask_realtime_scheduling() -> Callable[[], None] | None:
    """SCHED_RR at the lowest real-time priority for this thread, not inherited by processes it starts.
    Returns what puts the old policy back, or None when the OS does not allow it (nothing changed)."""
    try:
        policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
        rr = os.SCHED_RR
        os.sched_setscheduler(0, rr | os.SCHED_RESET_ON_FORK, os.sched_param(os.sched_get_priority_min(rr)))
    except (AttributeError, OSError):
        return None

    def restore() -> None:
        try:
            os.sched_setscheduler(0, policy, param)
        except OSError:
            pass
    return restore


class RealtimeRunner:
    """Step at `speed` times real time against the wall clock (see the module docstring)."""

    mode = "realtime"

    def __init__(self, step: Step, dt: float, speed: float = 1.0, *, max_lag: float = 0.5,
                 clock: Callable[[], float] = time.perf_counter, priority: bool = False):
        """`priority`: ask for real-time scheduling while running (see the module docstring); `scheduled`
        tells whether the OS granted it."""
        if not dt > 0 or not speed > 0:
            raise ValueError("dt and speed must be positive")
        self.priority, self.scheduled = priority, False
        self.step, self.dt, self.speed, self.max_lag, self.clock = step, dt, speed, max_lag, clock
        self.period = dt / speed
        self.steps = 0
        self.late_steps = 0
        self.last_late = False
        self.resyncs = 0
        self.max_late = 0.0  # s, the worst lateness seen
        self._stop = False
        self.paused = False  # pause(): no steps until resume(); single_step() runs one meanwhile
        self._resumed: asyncio.Event | None = None

    @property
    def remaining(self) -> int:
        return 0

    def stop(self) -> None:
        self._stop = True
        self.resume()

    def pause(self) -> None:
        """Stop stepping (from the event loop's thread) until `resume()`; paused time is not late time."""
        self.paused = True

    def resume(self) -> None:
        self.paused = False
        if self._resumed is not None:
            self._resumed.set()

    def single_step(self) -> None:
        """While paused: run one step now."""
        if self.paused and not self._stop:
            if self.step():
                self.steps += 1

    async def run(self) -> None:
        restore = ask_realtime_scheduling() if self.priority else None
        self.scheduled = restore is not None
        try:
            await self._run(period=self.period, least=self.period * MIN_SLEEP if restore is not None else 0.0)
        finally:
            if restore is not None:
                restore()
            self.scheduled = False

    async def _run(self, period: float, least: float) -> None:
        clock = self.clock
        self._resumed = asyncio.Event()
        t0 = clock()
        k = 0  # steps run since t0
        while not self._stop:
            if self.paused:
                self._resumed.clear()
                await self._resumed.wait()
                t0, k = clock(), 0  # the schedule starts again from now
                continue
            delay = t0 + k * period - clock()
            # Sleep until the step's start; never run two steps without letting the server answer (nor,
            # under real-time scheduling, without letting the machine run: at least `least`).
            await asyncio.sleep(delay if delay > least else least)
            if self._stop:
                break
            if self.paused:
                continue
            if not self.step():
                return
            k += 1
            self.steps += 1
            lateness = clock() - (t0 + k * period)
            self.last_late = lateness > 0
            if self.last_late:
                self.late_steps += 1
                self.max_late = max(self.max_late, lateness)
                if lateness > self.max_lag:
                    t0, k = clock(), 0
                    self.resyncs += 1


class LockstepRunner:
    """Step only on request (`request(n)`), as fast as possible, yielding to the server between slices of steps.

    It runs as plain callbacks of the event loop (`call_soon`), not as a task woken through an event: a request
    costs one turn of the loop before its steps, and the answer waiting for them goes out from the last one.
    A server answering requests holds the runner meanwhile (`hold`) and releases it at the end of its turn
    (`release`), which runs the steps asked for at once: a turn of the loop in between would only poll the
    sockets again."""

    mode = "lockstep"
    speed = 0.0
    late_steps = 0
    last_late = False

    def __init__(self, step: Step, *, slice_s: float = 0.002, clock: Callable[[], float] = time.perf_counter):
        self.step, self.slice_s, self.clock = step, slice_s, clock
        self.steps = 0
        self.target = 0
        self._done: list[Callable[[], None]] = []  # called when the steps asked for are done (or failed)
        self._loop: asyncio.AbstractEventLoop | None = None  # while `run()` runs
        self._scheduled = False  # a slice is due on the loop
        self._finished: asyncio.Future | None = None  # `run()` waits on it: stopped, or the simulation failed
        self._stop = False
        self.failed = False
        self._held = False

    @property
    def remaining(self) -> int:
        return self.target - self.steps

    def hold(self) -> None:
        """Steps asked for from now wait for `release()` (from the loop's thread, in the same turn of the loop)."""
        self._held = True

    def release(self) -> None:
        """End `hold()`: the steps asked for meanwhile run now (a slice; the rest in later turns of the loop)."""
        if self._held:
            self._held = False
            if self._loop is not None and not self._scheduled and not self._stop and self.steps < self.target:
                self._slice()

    def request(self, n: int) -> None:
        if self.failed:
            return
        self.target += n
        self._schedule()

    def when_done(self, callback: Callable[[], None]) -> None:
        """Call `callback()` once every step asked for so far has run (at once when none is left)."""
        if self.steps >= self.target or self.failed:
            callback()
        else:
            self._done.append(callback)

    def _call_done(self) -> None:
        done, self._done = self._done, []
        for callback in done:
            callback()

    def _schedule(self) -> None:
        if self._loop is not None and not self._held and not self._scheduled and not self._stop and self.steps < self.target:
            self._scheduled = True
            self._loop.call_soon(self._slice)

    def _slice(self) -> None:
        """Steps back to back for up to `slice_s` of wall time; then the loop's turn (the server answers) and
        the next slice."""
        self._scheduled = False
        if self._stop:
            return
        clock = self.clock
        t_yield = clock() + self.slice_s
        try:
            while self.steps < self.target and not self._stop:
                if not self.step():
                    self.failed = True
                    self.target = self.steps
                    self._call_done()
                    self._end()
                    return
                self.steps += 1
                if self.steps >= self.target and self._done:
                    self._call_done()
                if clock() >= t_yield:
                    break
        except BaseException as exc:  # noqa: BLE001 - `run()` raises it, as a task running the steps would
            self._end(exc)
            return
        self._schedule()

    def _end(self, exc: BaseException | None = None) -> None:
        if self._finished is not None and not self._finished.done():
            if exc is None:
                self._finished.set_result(None)
            else:
                self._finished.set_exception(exc)

    def stop(self) -> None:
        self._stop = True
        self._end()
        self._call_done()

    async def run(self) -> None:
        """Step whatever is asked for until `stop()`, or until a step fails (`failed`)."""
        self._loop = asyncio.get_running_loop()
        self._finished = self._loop.create_future()
        if self._stop:
            self._finished.set_result(None)
        self._schedule()
        try:
            await self._finished
        finally:
            self._loop = None
