"""Helpers: a real `twin serve` subprocess on a free loopback port, and raw-socket Modbus helpers."""
from __future__ import annotations

import contextlib
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from plc_client.events import EventLog

ROOT = Path(__file__).resolve().parents[2]
RING_BENCH = ROOT / "tests" / "plc" / "stations" / "ring_bench"  # the ring rig's gripper, no robot
SMART_GRIPPER = ROOT / "stations" / "smart_gripper"


class ServerProcess:
    """`twin serve STATION --port 0 ... --events FILE` as a subprocess: where it listens comes from its `ready`
    event (docs/events.md), what happens next from `events`; its stderr (the log) is collected in `lines`."""

    def __init__(self, station: Path, *args: str, drain: bool = True, port: str = "0"):
        """`drain=False`: stderr is read until the server is ready, then nobody reads the pipe."""
        self._start([sys.executable, "-m", "twin", "serve", str(station), "--port", port, *args], drain=drain)
        self.tls_port = None
        if "--tls-cert" in self.cmd:
            self.tls_port = self.endpoint("modbus", "modbus/tcp+tls")["port"]
        self.host, self.port = "127.0.0.1", self.tls_port
        if "--tls-only" not in self.cmd:
            front = self.endpoint("modbus", "modbus/tcp")
            self.host, self.port = front["host"], front["port"]

    def _start(self, cmd: list[str], drain: bool = True, env: dict[str, str] | None = None,
               timeout: float = 30.0) -> None:
        """Start `cmd` (a `twin serve` command line) with `--events FILE`, collect its stderr in `lines` from a
        thread, and wait for its `ready` event (AssertionError, with the log, if it does not come)."""
        self._dir = tempfile.TemporaryDirectory(prefix="twin-serve-")
        cmd = [*cmd, "--events", str(Path(self._dir.name) / "events.jsonl")]
        self.cmd, self.drain = cmd, drain
        self.proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                     cwd=ROOT, env={**os.environ, "PYTHONUNBUFFERED": "1", **(env or {})})
        self.events = EventLog(Path(self._dir.name) / "events.jsonl", self.proc)
        self.lines: list[str] = []
        self._seen = threading.Condition()
        self._ready = threading.Event()
        threading.Thread(target=self._drain, daemon=True).start()
        self.ready = self.events.wait("ready", timeout)
        self._ready.set()
        if self.ready is None:
            self.stop()
            raise AssertionError("`twin serve` did not get ready; its log:\n" + "\n".join(self.lines))

    def endpoint(self, name: str, protocol: str | None = None) -> dict:
        """A front end's address from the `ready` event."""
        return self.events.endpoint(name, protocol)

    def _drain(self) -> None:
        for line in self.proc.stderr:
            with self._seen:
                self.lines.append(line.rstrip("\n"))
                self._seen.notify_all()
            if not self.drain and self._ready.is_set():
                return  # from now on nobody reads the pipe
        with self._seen:
            self._seen.notify_all()

    def wait_for(self, pattern: str, timeout: float = 5.0, start: int = 0) -> re.Match:
        rx = re.compile(pattern)
        end = time.monotonic() + timeout
        with self._seen:
            while True:
                for line in self.lines[start:]:
                    if m := rx.search(line):
                        return m
                left = end - time.monotonic()
                if left <= 0 or (self.proc.poll() is not None and not self._more()):
                    raise AssertionError(f"no line matching {pattern!r} from `twin serve`; got:\n" + "\n".join(self.lines))
                self._seen.wait(min(left, 0.1))

    def _more(self) -> bool:
        return False

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 10.0) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.events.new()  # the last ones (`stopped`)
        return self.proc.returncode

    def __enter__(self) -> "ServerProcess":
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


# -- raw Modbus/TCP ---------------------------------------------------------------------------------------
class Raw:
    """A raw socket speaking MBAP by hand, for frames pymodbus's client will not send."""

    def __init__(self, port: int, timeout: float = 3.0):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.tid = 0

    def frame(self, pdu: bytes, unit: int = 1, tid: int | None = None, pid: int = 0, length: int | None = None) -> bytes:
        if tid is None:
            self.tid = (self.tid + 1) & 0xFFFF
            tid = self.tid
        return struct.pack(">HHHB", tid, pid, len(pdu) + 1 if length is None else length, unit) + pdu

    def send(self, data: bytes) -> None:
        self.sock.sendall(data)

    def recv_exact(self, n: int) -> bytes:
        out = b""
        while len(out) < n:
            chunk = self.sock.recv(n - len(out))
            if not chunk:
                raise ConnectionError(f"closed after {len(out)} of {n} bytes")
            out += chunk
        return out

    def response(self) -> tuple[int, int, bytes]:
        """(transaction id, unit, PDU) of the next response."""
        tid, pid, length, unit = struct.unpack(">HHHB", self.recv_exact(7))
        assert pid == 0
        return tid, unit, self.recv_exact(length - 1)

    def request(self, pdu: bytes, unit: int = 1) -> bytes:
        self.send(self.frame(pdu, unit))
        tid, u, resp = self.response()
        assert (tid, u) == (self.tid, unit)
        return resp

    def closed_by_peer(self, timeout: float = 3.0) -> bool:
        self.sock.settimeout(timeout)
        try:
            return self.sock.recv(1) == b""
        except ConnectionResetError:
            return True
        except socket.timeout:
            return False

    def close(self) -> None:
        with contextlib.suppress(OSError):
            self.sock.close()

    def __enter__(self) -> "Raw":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def pdu(fc: int, *fields: int, fmt: str | None = None, tail: bytes = b"") -> bytes:
    return bytes([fc]) + struct.pack(">" + (fmt or "H" * len(fields)), *fields) + tail
