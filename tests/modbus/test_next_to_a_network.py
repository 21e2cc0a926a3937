"""`twin serve` next to a real network: a log pipe nobody reads, connection limits, idle connections,
read-only, allow-lists (two loopback addresses), gaps read as zeros. Real subprocesses, real sockets."""
from __future__ import annotations

import socket
import struct
import time

import pytest

from modbus_helpers import RING_BENCH, Raw, ServerProcess, pdu

ADDR = {"L2": 16, "L3": 17, "sim.step": 0, "L2.actual": 17, "Active": 16, "ring.present": 17}


def steps(raw: Raw) -> int:
    words = struct.unpack(">2H", raw.request(pdu(4, 0, 2))[2:])
    return words[0] << 16 | words[1]


def test_a_log_pipe_nobody_reads_neither_stops_the_answers_nor_the_simulation():
    """2000 connect/close cycles log 4000 lines (some 300 kB, far more than a pipe holds) into a stderr
    nobody reads: every cycle is still accepted and the simulation keeps stepping."""
    with ServerProcess(RING_BENCH, drain=False) as server:
        with Raw(server.port) as probe:
            s0 = steps(probe)
        for i in range(2000):
            with socket.create_connection(("127.0.0.1", server.port), timeout=5):
                pass
        with Raw(server.port, timeout=5) as probe:
            assert probe.request(pdu(3, ADDR["L2"], 1))[:2] == b"\x03\x02"
            s1 = steps(probe)
            time.sleep(0.3)
            s2 = steps(probe)
        assert server.proc.poll() is None
    assert s1 > s0 and s2 > s1, (s0, s1, s2)


@pytest.fixture(scope="module")
def limited():
    with ServerProcess(RING_BENCH, "--max-connections", "2", "--idle-timeout", "0.6") as s:
        yield s


def test_one_connection_beyond_the_limit_is_refused_and_logged_the_others_keep_being_served(limited):
    with Raw(limited.port) as a, Raw(limited.port) as b:
        assert a.request(pdu(3, ADDR["L2"], 1))[:2] == b"\x03\x02"
        assert b.request(pdu(3, ADDR["L2"], 1))[:2] == b"\x03\x02"
        start = len(limited.lines)
        with Raw(limited.port) as c:
            assert c.closed_by_peer(3.0)
        limited.wait_for(r"refused: 2 connections already, the limit \(--max-connections\)", start=start)
        assert a.request(pdu(3, ADDR["L2"], 1))[:2] == b"\x03\x02"
    time.sleep(0.2)  # both closed: a new one is served again
    with Raw(limited.port) as d:
        assert d.request(pdu(3, ADDR["L2"], 1))[:2] == b"\x03\x02"


def test_an_idle_connection_is_closed_after_the_idle_timeout_a_busy_one_is_not(limited):
    with Raw(limited.port) as idle, Raw(limited.port) as busy:
        t0 = time.monotonic()
        idle.request(pdu(3, ADDR["L2"], 1))
        while time.monotonic() - t0 < 1.5:
            assert busy.request(pdu(3, ADDR["L2"], 1))[:2] == b"\x03\x02"
            time.sleep(0.1)
        assert idle.closed_by_peer(0.5)
        assert busy.request(pdu(3, ADDR["L2"], 1))[:2] == b"\x03\x02"
    limited.wait_for(r"disconnected \(idle for 0.6 s \(--idle-timeout\)")


def test_read_only_refuses_every_write_function_with_exception_01_and_changes_nothing():
    with ServerProcess(RING_BENCH, "--lockstep", "--read-only") as server, Raw(server.port) as raw:
        before = {fc: raw.request(pdu(fc, 0, 32)) for fc in (1, 3)}
        writes = [pdu(5, ADDR["Active"], 0x0000), pdu(6, ADDR["L2"], 1000),
                  pdu(15, ADDR["Active"], 2, fmt="HH", tail=bytes([1, 0])),
                  pdu(16, ADDR["L2"], 2, fmt="HH", tail=struct.pack(">BHH", 4, 1000, 1000)),
                  pdu(22, ADDR["L2"], 0x00F2, 0x0025), pdu(6, 0, 5),  # sim.advance is a write too
                  pdu(23, ADDR["L2"], 1, ADDR["L2"], 1, fmt="HHHH", tail=struct.pack(">BH", 2, 1000))]
        for frame in writes:
            assert raw.request(frame) == bytes([frame[0] | 0x80, 0x01]), frame.hex()
        assert {fc: raw.request(pdu(fc, 0, 32)) for fc in (1, 3)} == before
        assert raw.request(pdu(2, 0, 3))[:2] == b"\x02\x01"  # reads are served


def test_allow_closes_connections_from_other_addresses_and_logs_them():
    """Two loopback addresses: 127.0.0.2 is allowed, 127.0.0.1 is not."""
    with ServerProcess(RING_BENCH, "--host", "0.0.0.0", "--allow", "127.0.0.2/32,10.0.0.0/8") as server:
        with socket.create_connection(("127.0.0.1", server.port), timeout=3, source_address=("127.0.0.2", 0)) as ok:
            raw = Raw.__new__(Raw)
            raw.sock, raw.tid = ok, 0
            assert raw.request(pdu(3, ADDR["L2"], 1))[:2] == b"\x03\x02"
        start = len(server.lines)
        with socket.create_connection(("127.0.0.1", server.port), timeout=3, source_address=("127.0.0.1", 0)) as bad:
            raw = Raw.__new__(Raw)
            raw.sock, raw.tid = bad, 0
            with pytest.raises((ConnectionError, OSError)):
                raw.request(pdu(3, ADDR["L2"], 1))
        server.wait_for(r"client 127\.0\.0\.1:\d+ refused: not in the allowed networks", start=start)


def test_a_bad_allow_list_is_an_error_naming_the_entry(tmp_path):
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-m", "twin", "serve", str(RING_BENCH), "--allow", "127.0.0.1,nonsense"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "'nonsense' is not an address or a network" in r.stderr


def test_gaps_zero_answers_block_reads_across_reserved_gaps_with_zeros_and_still_refuses_writes_there():
    with ServerProcess(RING_BENCH, "--lockstep", "--gaps", "zero") as server, Raw(server.port) as raw:
        block = raw.request(pdu(4, 0, 21))  # sim.step .. L2.actual, across the gaps at 9 and 14-15
        assert block[:2] == bytes([4, 42])
        words = struct.unpack(">21H", block[2:])
        assert words[9] == 0 and words[14] == 0 and words[15] == 0
        for a in (0, 6, 10, 16, 17):  # the mapped ones read as they do one by one
            assert raw.request(pdu(4, a, 1))[2:] == struct.pack(">H", words[a])
        bits = raw.request(pdu(2, 0, 20))  # fault, sim.lockstep, sim.late, gap 3..15, doGripped ...
        assert bits[:2] == bytes([2, 3]) and bits[2] & 0b10  # sim.lockstep
        assert bits[2] & 0xF8 == 0 and bits[3] == 0  # the gap 3..15 reads 0
        assert raw.request(pdu(6, 9, 1)) == b"\x86\x02"  # a write into a gap: still exception 02
        assert raw.request(pdu(3, 0, 20))[:2] == bytes([3, 40])
        assert raw.request(pdu(4, 100, 1)) == b"\x84\x02"  # beyond the table: still 02
    with ServerProcess(RING_BENCH, "--lockstep") as server, Raw(server.port) as raw:
        assert raw.request(pdu(4, 0, 21)) == b"\x84\x02"  # without --gaps zero: exception 02
