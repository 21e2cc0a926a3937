"""A `twin serve STATION --opcua 0` subprocess, and asyncua client helpers."""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from asyncua import Client, ua

ROOT = Path(__file__).resolve().parents[2]

RING_RIG = ROOT / "stations" / "ring_rig"
NAMESPACE = "urn:gripper-twin:station:"
FOLDERS = ("Gripper", "Fingers", "Robot", "Targets", "Controller", "Sim")


class OpcUaServerProcess:
    """`twin serve STATION --port 0 --opcua 0 ARGS...`; `url` is the OPC UA endpoint, `port` Modbus's (None with
    --no-modbus). Its stderr is collected line by line in `lines`."""

    drain = True  # read the server's log to the end (ServerProcess's reader stops at "listening on" otherwise)

    def __init__(self, station, *args: str, cert_dir=None):
        extra = ["--opcua-cert-dir", str(cert_dir)] if cert_dir is not None else []
        self.cmd = [sys.executable, "-m", "twin", "serve", str(station), "--port", "0", "--opcua", "0", *extra, *args]
        env = {**os.environ, "PYTHONUNBUFFERED": "1"}
        if cert_dir is None:
            env["XDG_DATA_HOME"] = str(ROOT / ".pytest_cache" / "opcua-certs")
        self.proc = subprocess.Popen(self.cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                     cwd=ROOT, env=env)
        self.lines: list[str] = []
        self._seen = threading.Condition()
        threading.Thread(target=self._drain, daemon=True).start()
        self.url = self.wait_for(r"OPC UA listening on (\S+)", timeout=90).group(1)
        m = re.search(r"listening on ([\d.]+):(\d+)$", "\n".join(self.lines), re.M)
        self.host, self.port = (m.group(1), int(m.group(2))) if m else ("127.0.0.1", None)

    def _drain(self) -> None:
        for line in self.proc.stderr:
            with self._seen:
                self.lines.append(line.rstrip("\n"))
                self._seen.notify_all()
        with self._seen:
            self._seen.notify_all()

    def wait_for(self, pattern: str, timeout: float = 5.0) -> re.Match:
        rx, end = re.compile(pattern), time.monotonic() + timeout
        with self._seen:
            while True:
                for line in self.lines:
                    if m := rx.search(line):
                        return m
                left = end - time.monotonic()
                if left <= 0 or self.proc.poll() is not None:
                    raise AssertionError(f"no line matching {pattern!r} from `twin serve`; got:\n" + "\n".join(self.lines))
                self._seen.wait(min(left, 0.1))

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 10.0) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode

    def __enter__(self) -> "OpcUaServerProcess":
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


async def namespace(client: Client, station: str = "ring_rig") -> int:
    return await client.get_namespace_index(NAMESPACE + station)


def node(client: Client, ns: int, name: str):
    return client.get_node(ua.NodeId(name, ns))


async def advance(client: Client, ns: int, steps: int) -> int:
    """Sim.Advance(steps): returns sim.step once the steps are done."""
    sim = node(client, ns, "Sim")
    return await sim.call_method(ua.NodeId("Sim.Advance", ns), ua.Variant(steps, ua.VariantType.UInt32))


async def write_status(n, value, vtype=None) -> str:
    """Write one value; the name of the status code the server answered ('Good' when accepted)."""
    dv = ua.DataValue(ua.Variant(value, vtype) if vtype is not None else ua.Variant(value))
    result = await n.session.write(ua.WriteParameters(NodesToWrite=[
        ua.WriteValue(NodeId=n.nodeid, AttributeId=ua.AttributeIds.Value, Value=dv)]))
    return result[0].name
