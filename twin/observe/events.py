"""The server's machine interface: `twin serve --events FILE|-` writes one JSON object per line.

The log (stderr) is for people and may be reworded; the event stream is for programs (a test harness,
the demo, a supervisor) and keeps its schema (docs/events.md). Every event has `event` (its kind),
`step` and `t` (the simulated step count and seconds when it happened), then its own fields:

    ready            front_ends: [{name, host, port, ...}]   every front end started, the cell runs
    client_connected front_end, peer, connected[, tls_subject, role]
    client_gone      front_end, peer, reason, connected
    client_refused   front_end, peer, reason
    comm_lost        silent_s, timeout_s, last_source, safe_state
    comm_restored    source, silent_s
    controller       type (print, errlog, DO, AO, GO, move, end, error, ...) and the controller's fields
    fault            message                                 the simulation stopped on an error
    stopped          steps, requests[, late_steps]           the last line

Written in order, from whichever thread has something to say (one lock). To a regular file every line is
written at once, so a reader that has seen the server answer a request after step N finds every event
up to step N in the file. To a pipe or a terminal (`-`), lines go through a bounded queue and a writer
thread: a reader that does not read never holds up the simulation; what does not fit is dropped and
counted (an `events_dropped` event says how many, once the reader reads again).
"""
from __future__ import annotations

import json
import math
import os
import queue
import stat
import sys
import threading
from collections.abc import Callable

QUEUE_LINES = 10000

READY, CLIENT_CONNECTED, CLIENT_GONE, CLIENT_REFUSED = "ready", "client_connected", "client_gone", "client_refused"
COMM_LOST, COMM_RESTORED, CONTROLLER, FAULT, STOPPED = "comm_lost", "comm_restored", "controller", "fault", "stopped"
EVENTS_DROPPED = "events_dropped"
KINDS = (READY, CLIENT_CONNECTED, CLIENT_GONE, CLIENT_REFUSED, COMM_LOST, COMM_RESTORED, CONTROLLER, FAULT, STOPPED,
         EVENTS_DROPPED)


def _plain(value):
    """JSON has no NaN or infinity: such a number is written as null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


class Events:
    """Where events go: nowhere (`Events()`), or a file / stdout (`Events.open(target)`)."""

    def __init__(self, write: Callable[[str], None] | None = None, clock: Callable[[], tuple[int, float]] | None = None):
        self._write = write
        self.clock = clock or (lambda: (0, 0.0))  # (step, simulated s); the cell sets its twin's
        self._lock = threading.Lock()
        self._close: Callable[[], None] = lambda: None
        self.count = 0

    @property
    def enabled(self) -> bool:
        return self._write is not None

    @classmethod
    def open(cls, target: str | None) -> "Events":
        """`-`: standard output; a path: that file (created or truncated); None: no events."""
        if target is None:
            return cls()
        if target == "-":
            # the events own standard output: anything else printed there (a library's banner, a child
            # process's) goes to stderr instead, so every line of stdout is an event
            sys.stdout.flush()
            fd, own = os.dup(1), True
            os.dup2(2, 1)
        else:
            fd, own = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644), True
        events = cls()
        if stat.S_ISREG(os.fstat(fd).st_mode):
            events._write = lambda text: _write_all(fd, text)
            events._close = (lambda: os.close(fd)) if own else (lambda: None)
        else:
            writer = _QueueWriter(fd)
            events._write = writer.put
            events._close = lambda: (writer.close(), os.close(fd) if own else None)
        return events

    def emit(self, kind: str, *, t: float | None = None, **fields) -> None:
        """Write one event (`t`: the simulated time it happened, when it is not now, e.g. a controller's)."""
        if self._write is None:
            return
        step, now = self.clock()
        record = {"event": kind, "step": step, "t": round(now if t is None else t, 6), **_plain(fields)}
        line = json.dumps(record, separators=(",", ":"), ensure_ascii=False) + "\n"
        with self._lock:
            self.count += 1
            try:
                self._write(line)
            except OSError:  # the reader is gone: the simulation goes on
                self._write = None

    def close(self) -> None:
        with self._lock:
            self._write = None
            self._close()
            self._close = lambda: None


def _write_all(fd: int, text: str) -> None:
    data = text.encode("utf-8")
    while data:
        data = data[os.write(fd, data):]


class _QueueWriter:
    """A pipe's writer thread: never blocks the caller; drops (and later reports) what does not fit."""

    def __init__(self, fd: int, capacity: int = QUEUE_LINES):
        self.fd, self.queue, self.dropped = fd, queue.Queue(capacity), 0
        self._thread = threading.Thread(target=self._drain, name="twin-serve-events", daemon=True)
        self._thread.start()

    def put(self, line: str) -> None:
        try:
            self.queue.put_nowait(line)
        except queue.Full:
            self.dropped += 1

    def _drain(self) -> None:
        while (line := self.queue.get()) is not None:
            try:
                if self.dropped:
                    lost, self.dropped = self.dropped, 0
                    _write_all(self.fd, json.dumps({"event": EVENTS_DROPPED, "count": lost}) + "\n")
                _write_all(self.fd, line)
            except OSError:
                return

    def close(self, timeout: float = 2.0) -> None:
        try:
            self.queue.put(None, timeout=timeout)
        except queue.Full:
            return
        self._thread.join(timeout)
