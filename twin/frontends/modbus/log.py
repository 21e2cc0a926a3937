"""The server's log: the standard `logging` module behind a handler that never blocks the event loop.

Every line reads `twin serve: MESSAGE` on stderr (warnings and errors: `twin serve: warning: ...`), so it
reads apart from a client's output. Records go into a bounded queue; one background thread writes them
to the sink. When the sink does not take them (stderr on a pipe nobody reads), the writer thread blocks,
the queue fills, and further records are dropped and counted: the serving thread never waits. Once the
sink drains, the writer says how many lines were lost (`N log lines dropped: the log sink was full`).

`log(text)` is the old call (INFO on the `twin.serve` logger). Start-up and shutdown lines (`loading`,
`listening on`, `stopped`) go to `lifecycle`, which `--log-level` does not silence. The log is for people: a
program reads `twin serve --events` (`twin.observe.events`, docs/events.md), never these lines. Imports nothing heavy, so `twin serve` can log before it loads a station.
"""
from __future__ import annotations

import logging
import os
import queue
import sys
import threading
import time

logger = logging.getLogger("twin.serve")
lifecycle = logging.getLogger("twin.serve.lifecycle")  # start-up and shutdown: shown at every --log-level
LEVELS = ("debug", "info", "warning", "error")
QUEUE_LINES = 10000  # records held while the sink is slow; beyond that they are dropped and counted


class _Format(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        text = record.getMessage()
        if record.levelno >= logging.WARNING and not text.startswith(("error:", "warning:")):
            text = f"{record.levelname.lower()}: {text}"
        if record.exc_info:
            text += "\n" + self.formatException(record.exc_info)
        return f"twin serve: {text}"


class DroppingQueueHandler(logging.Handler):
    """Hands formatted lines to a writer thread through a bounded queue; drops (and counts) when full."""

    def __init__(self, write=None, capacity: int = QUEUE_LINES):
        super().__init__()
        self.setFormatter(_Format())
        self._write = write or _write_stderr
        self.queue: queue.Queue = queue.Queue(capacity)
        self.dropped = 0  # total, for tests and the final line
        self._unreported = 0
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._drain, name="twin-serve-log", daemon=True)
        self._thread.start()

    def emit(self, record: logging.LogRecord) -> None:
        try:
            line = self.format(record) + "\n"
        except Exception:  # a bad format argument must not reach the caller
            line = f"twin serve: (unprintable log record {record.msg!r})\n"
        try:
            self.queue.put_nowait(line)
        except queue.Full:
            with self._lock:
                self.dropped += 1
                self._unreported += 1

    def _drain(self) -> None:
        while True:
            line = self.queue.get()
            if line is None:
                return
            with self._lock:
                lost, self._unreported = self._unreported, 0
            try:
                if lost:
                    self._write(f"twin serve: warning: {lost} log lines dropped: the log sink was full\n")
                self._write(line)
            except Exception:  # the sink is gone (closed pipe): nothing more to say
                pass

    def flush(self, timeout: float = 1.0) -> None:
        """Wait (at most `timeout` s) until the queue is written: at shutdown, never forever."""
        deadline = time.monotonic() + timeout
        while not self.queue.empty() and time.monotonic() < deadline:
            time.sleep(0.01)


def _write_stderr(text: str) -> None:
    data = text.encode("utf-8", "replace")
    fd = sys.stderr.fileno() if sys.stderr is not None else 2
    while data:
        n = os.write(fd, data)
        data = data[n:]


_handler: DroppingQueueHandler | None = None


def setup(level: str = "info") -> DroppingQueueHandler:
    """Route the server's loggers (and asyncio's) through the non-blocking handler at `level`."""
    global _handler
    if _handler is None:
        _handler = DroppingQueueHandler()
        for name in ("twin.serve", "asyncio"):
            lg = logging.getLogger(name)
            lg.addHandler(_handler)
            lg.propagate = False
        lifecycle.setLevel(logging.INFO)
    logger.setLevel(getattr(logging, level.upper()))
    logging.getLogger("asyncio").setLevel(max(logging.WARNING, logger.level))
    return _handler


def flush(timeout: float = 1.0) -> None:
    if _handler is not None:
        _handler.flush(timeout)


def log(text: str, level: int = logging.INFO) -> None:
    if _handler is None:
        setup()
    logger.log(level, text)


def announce(text: str) -> None:
    """A start-up or shutdown line: shown whatever --log-level says."""
    if _handler is None:
        setup()
    lifecycle.info(text)
