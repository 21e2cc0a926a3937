"""A client that sends what is not OPC UA costs one log line, no traceback, and the server goes on serving."""
from __future__ import annotations

import asyncio
import socket
import struct
import time
from urllib.parse import urlsplit

from asyncua import Client

from opcua_helpers import NAMESPACE, OpcUaServerProcess, node
from tests.conftest import ROOT

BENCH = ROOT / "tests" / "plc" / "stations" / "ring_bench"


def frames() -> list[bytes]:
    """OPC UA TCP headers (message type, chunk type F, size) over bodies that are none of those messages."""
    out = []
    for kind in (b"HEL", b"OPN", b"MSG", b"CLO", b"ACK", b"ERR", b"XYZ"):
        for body in (b"", b"\x01", bytes(range(7, 70))):
            out.append(kind + b"F" + struct.pack("<I", 8 + len(body)) + body)
    return out + [b"GET / HTTP/1.1\r\nHost: twin\r\n\r\n"]


def test_each_garbage_client_costs_one_log_line_and_no_traceback():
    with OpcUaServerProcess(BENCH, "--lockstep") as server:
        url = urlsplit(server.url)
        server.wait_for(r"OPC UA listening on", timeout=30)  # the start-up lines come through the log's writer
        before = len(server.lines)
        for frame in frames():
            with socket.create_connection((url.hostname, url.port), timeout=5) as c:
                c.sendall(frame)
                c.settimeout(0.3)
                try:
                    while c.recv(4096):  # the server answers (an ERR) or closes
                        pass
                except (socket.timeout, ConnectionResetError):
                    pass
        # the last lines come through the log's writer: wait until none has come for 1 s (a loaded machine may take
        # longer than any fixed pause), at most 10 s
        count, quiet_since, deadline = len(server.lines), time.monotonic(), time.monotonic() + 10.0
        while time.monotonic() - quiet_since < 1.0 and time.monotonic() < deadline:
            time.sleep(0.05)
            if len(server.lines) != count:
                count, quiet_since = len(server.lines), time.monotonic()
        said = server.lines[before:]

        async def still_serving():
            async with Client(server.url, timeout=30) as c:
                ns = await c.get_namespace_index(NAMESPACE + "ring_bench")
                return await node(c, ns, "Active").read_value()

        assert asyncio.run(asyncio.wait_for(still_serving(), 60)) is True
        log = list(server.lines)
    assert not any("Traceback" in line or line.startswith(" ") for line in log), "\n".join(log)
    assert len(frames()) // 2 <= len(said) <= len(frames()), said  # at most one line per client, most named
    assert all(line.startswith("twin serve: warning: OPC UA: ") for line in said), said
