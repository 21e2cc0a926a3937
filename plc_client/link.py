"""Faults of the PLC's link to the process: lost for a time, latency and jitter. A `ProcessIO` between a
scan cycle and its I/O, so it works in process (`TwinIO`) and over Modbus (`ClientIO`) alike:

    from plc_client.link import LinkFaults

    link = LinkFaults(server.io(client), lost=[(2.0, 3.5)], latency=0.020, jitter=0.010, seed=1)
    plc = ScanCycle(link, logic)

Times are the PLC's (s since its first scan: simulated time in lockstep). While the link is lost the
PLC reads the last image that came through (a real PLC's Modbus requests time out and its inputs hold)
and its writes do not arrive; when the link is back, the outputs it last wanted are written at once (a
PLC writes its output image every cycle). Latency delays both ways: the PLC reads the process as it was
`latency` (+ up to `jitter`, drawn per exchange from a seeded generator) earlier, and its writes arrive as
much later, in the order sent. Lockstep advances are the test's clock, not the link: they always pass.

The PLC can see its link's state as the input `link.ok` (True while the link is up), as a real PLC
sees its communication status. `on_exchange` is called for every read that gets through: in process, feed
the cell's comm-loss watchdog with it (`cell.watchdog.feed`), as the server does for every request.
"""
from __future__ import annotations

import bisect
import random
import time as _time
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from typing import Any

LINK_OK = "link.ok"


class LinkFaults:
    """Wraps a `ProcessIO`: `lost` windows [(start, end), ...] in s, `latency` and `jitter` in s."""

    def __init__(self, io, *, lost: Iterable[tuple[float, float]] = (), latency: float = 0.0, jitter: float = 0.0,
                 seed: int = 0, clock: Callable[[], float] | None = None,
                 on_exchange: Callable[[], None] | None = None):
        self.io = io
        self.on_exchange = on_exchange  # called for every exchange that gets through (e.g. a watchdog's feed)
        self.lockstep = getattr(io, "lockstep", True)
        self.lost = sorted((float(a), float(b)) for a, b in lost)
        for a, b in self.lost:
            if not (0 <= a < b):
                raise ValueError(f"a link loss needs 0 <= start < end, not ({a:g}, {b:g})")
        if latency < 0 or jitter < 0:
            raise ValueError("latency and jitter must not be negative")
        self.latency, self.jitter = float(latency), float(jitter)
        self._random = random.Random(seed)
        self._clock = clock or _time.monotonic
        self._t0: float | None = None
        self._time = 0.0  # lockstep: the sum of the advances
        self._history: deque[tuple[float, dict]] = deque()  # (time, image as read from the process)
        self._delivered: dict[str, Any] = {}  # the last image that reached the PLC
        self._outbox: list[tuple[float, int, dict]] = []  # (delivery time, order, values) in flight
        self._held: dict[str, Any] = {}  # writes made while the link is down: the latest value per name
        self._sent = 0
        self._last_delivery = 0.0
        self.dropped_reads = 0
        self.dropped_writes = 0

    # -- time and state -------------------------------------------------------------------------------
    @property
    def now(self) -> float:
        if self.lockstep:
            return self._time
        if self._t0 is None:
            self._t0 = self._clock()
        return self._clock() - self._t0

    def up(self, t: float | None = None) -> bool:
        """The link is up at PLC time t (default: now)."""
        t = self.now if t is None else t
        return not any(a <= t < b for a, b in self.lost)

    def _delay(self) -> float:
        if not (self.latency or self.jitter):
            return 0.0
        return self.latency + (self._random.uniform(0.0, self.jitter) if self.jitter else 0.0)

    # -- ProcessIO ---------------------------------------------------------------------------------------
    def read_image(self, names: Iterable[str]) -> dict[str, Any]:
        names = list(names)
        now = self.now
        self._flush(now)
        wanted = [n for n in names if n != LINK_OK]
        if self.up(now):
            self._history.append((now, self.io.read_image(wanted)))
            if self.on_exchange is not None:
                self.on_exchange()
            delay = self._delay()
            image = self._history[-1][1]
            if delay:
                # the newest image at least `delay` old (the oldest one while the link is younger than that)
                cut = now - delay + 1e-12
                times = [t for t, _ in self._history]
                k = bisect.bisect_right(times, cut) - 1
                image = self._history[max(k, 0)][1]
                while len(self._history) > 1 and self._history[1][0] <= cut:
                    self._history.popleft()
            self._delivered.update(image)
        else:
            self.dropped_reads += 1
            missing = [n for n in wanted if n not in self._delivered]
            if missing:  # nothing ever came through for these: the PLC's input image starts at the process's
                self._delivered.update(self.io.read_image(missing))
        out = {n: self._delivered[n] for n in wanted}
        if LINK_OK in names:
            out[LINK_OK] = self.up(now)
        return {n: out[n] for n in names}

    def write_image(self, values: Mapping[str, Any]) -> None:
        now = self.now
        values = {k: v for k, v in values.items() if k != LINK_OK}
        if not values:
            return
        if not self.up(now):
            self.dropped_writes += 1
            self._held.update(values)
            return
        self._send(now, values)

    def _send(self, now: float, values: dict) -> None:
        delay = self._delay()
        if not delay:
            self.io.write_image(values)
            return
        at = max(now + delay, self._last_delivery)  # a link delivers in order
        self._last_delivery = at
        self._sent += 1
        bisect.insort(self._outbox, (at, self._sent, dict(values)))

    def _flush(self, now: float) -> None:
        if self._held and self.up(now):
            held, self._held = self._held, {}
            self._send(now, held)
        while self._outbox and self._outbox[0][0] <= now + 1e-12:
            _, _, values = self._outbox.pop(0)
            self.io.write_image(values)

    def advance(self, seconds: float) -> None:
        self._flush(self.now)
        self.io.advance(seconds)
        self._time += seconds
        self._flush(self.now)

    # the LocalSignals conveniences (a test playing the robot sets its handshake bits through the I/O)
    def set(self, name: str, value: Any) -> None:
        local = getattr(self.io, "local", {})
        if name in local:
            self.io.set(name, value)
        else:
            self.write_image({name: value})

    def get(self, name: str) -> Any:
        return self.read_image([name])[name]
