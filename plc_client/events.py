"""Reading a twin server's machine interface: the JSON lines of `twin serve --events FILE` (docs/events.md).

A client needs nothing of the twin to read them: one JSON object per line, `event` its kind."""
from __future__ import annotations

import json
import subprocess
import time
from pathlib import Path


class EventLog:
    """The JSON lines a `twin serve --events FILE` writes (docs/events.md), read as they come.

    The server writes each event to the file as it happens, so once a client has seen the answer to a
    request, every event of the steps before it is in the file: `new()` then returns them all."""

    def __init__(self, path: str | Path, process: subprocess.Popen | None = None):
        self.path, self.process = Path(path), process
        self.seen: list[dict] = []  # every event read so far, in order
        self._offset, self._rest = 0, b""

    def new(self) -> list[dict]:
        """The events written since the last call (complete lines only)."""
        try:
            with open(self.path, "rb") as f:
                f.seek(self._offset)
                data = f.read()
        except FileNotFoundError:
            return []
        self._offset += len(data)
        data, self._rest = self._rest + data, b""
        lines = data.split(b"\n")
        self._rest = lines.pop()  # a line not yet complete (b"" after a newline)
        found = [json.loads(line) for line in lines if line.strip()]
        self.seen += found
        return found

    def wait(self, kind: str, timeout: float = 10.0, where=lambda event: True) -> dict | None:
        """The first event of `kind` (seen or to come) for which `where(event)` holds; None when the server
        exits or `timeout` s pass first."""
        end, start = time.monotonic() + timeout, 0
        while True:
            self.new()
            for event in self.seen[start:]:
                if event["event"] == kind and where(event):
                    return event
            start = len(self.seen)
            if time.monotonic() > end:
                return None
            if self.process is not None and self.process.poll() is not None:
                self.new()
                return next((e for e in self.seen[start:] if e["event"] == kind and where(e)), None)
            time.sleep(0.02)

    def endpoint(self, name: str = "modbus", protocol: str | None = None) -> dict:
        """A front end's address from the `ready` event (KeyError when it does not serve it)."""
        ready = next((e for e in self.seen if e["event"] == "ready"), None)
        if ready is None:
            raise KeyError("the server is not ready")
        for front in ready["front_ends"]:
            if front["name"] == name and (protocol is None or front.get("protocol") == protocol):
                return front
        raise KeyError(f"the server has no {name}{f' ({protocol})' if protocol else ''} front end")
