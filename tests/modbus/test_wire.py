"""Modbus Application Protocol behaviour of a real `twin serve`, checked on the wire with raw sockets.

Every case here is one a bare pymodbus 3.16 server gets wrong or that the issue spells out.
Addresses are the ring bench's (see `twin map tests/plc/stations/ring_bench`): holding registers
`sim.advance` at 0, `L2`..`L5` at 16..19 (0.01 mm, 0..44100 counts); input registers `sim.step` at 0,
`GrippedPart` at 16, `L2.actual` at 17; coils `Active` at 16 and `ring.present` at 17; discrete input
`doGripped` at 16.
"""
from __future__ import annotations

import asyncio
import struct
import time

import pytest
from pymodbus.client import AsyncModbusTcpClient

from modbus_helpers import Raw, pdu

L2, L3, ADVANCE = 16, 17, 0


def exception(fc: int, code: int) -> bytes:
    return bytes([fc | 0x80, code])


def read_hr(raw: Raw, address: int, count: int = 1) -> list[int]:
    resp = raw.request(pdu(3, address, count))
    assert resp[:2] == bytes([3, 2 * count]), resp
    return list(struct.unpack(f">{count}H", resp[2:]))


def advance(raw: Raw, n: int) -> None:
    assert raw.request(pdu(6, ADVANCE, n)) == pdu(6, ADVANCE, n)
    for _ in range(10000):
        if read_hr(raw, ADVANCE) == [0]:
            return
    raise AssertionError("sim.advance did not come back to 0")


# -- exception responses: function code | 0x80, the right code ---------------------------------------------
@pytest.mark.parametrize("fc", [7, 8, 17, 21, 43, 0x41])  # 20 (read file record) serves the map
def test_an_unknown_function_is_answered_with_its_own_code_and_the_high_bit_and_exception_01(raw, fc):
    assert raw.request(bytes([fc]) + b"\x00\x00\x00\x01") == exception(fc, 0x01)


@pytest.mark.parametrize("fc,count", [(3, 126), (4, 126), (3, 0), (4, 0), (1, 2001), (2, 2001), (1, 0), (2, 0),
                                      (3, 0xFFFF)])
def test_a_read_of_zero_or_more_than_the_limit_gets_illegal_data_value(raw, fc, count):
    assert raw.request(pdu(fc, 16, count)) == exception(fc, 0x03)


@pytest.mark.parametrize("fc,address,count", [
    (3, 20, 1),      # one past the last holding register
    (3, 19, 2),      # crosses the end of the map
    (3, 1, 1),       # a gap in the reserved block
    (3, 0, 17),      # from sim.advance through the gap into L2
    (4, 9, 1), (4, 60000, 10), (1, 0, 1), (1, 18, 1), (2, 3, 1), (2, 16, 100),
])
def test_an_address_outside_the_map_or_in_a_gap_gets_illegal_data_address(raw, fc, address, count):
    assert raw.request(pdu(fc, address, count)) == exception(fc, 0x02)


def test_writes_outside_the_map_get_illegal_data_address(raw):
    assert raw.request(pdu(6, 20, 100)) == exception(6, 0x02)
    assert raw.request(pdu(5, 18, 0xFF00)) == exception(5, 0x02)
    assert raw.request(bytes([16]) + struct.pack(">HHBHH", 19, 2, 4, 1, 2)) == exception(16, 0x02)
    assert raw.request(bytes([15]) + struct.pack(">HHB", 17, 2, 1) + b"\x03") == exception(15, 0x02)


def test_a_value_outside_the_range_gets_illegal_data_value_and_changes_nothing(raw):
    before = read_hr(raw, L2, 4)
    assert raw.request(pdu(6, L2, 44101)) == exception(6, 0x03)
    # all or nothing: L2 valid, L3 out of range -> neither is written
    assert raw.request(bytes([16]) + struct.pack(">HHBHH", L2, 2, 4, 30000, 50000)) == exception(16, 0x03)
    advance(raw, 2)
    assert read_hr(raw, L2, 4) == before


def test_a_coil_value_other_than_on_or_off_gets_illegal_data_value(raw):
    assert raw.request(pdu(5, 16, 0x1234)) == exception(5, 0x03)


def test_writing_a_read_only_table_is_an_unknown_function_for_no_such_write_exists(raw):
    # there is no "write input register": function 0x44 does not exist
    assert raw.request(pdu(0x44, 16, 1)) == exception(0x44, 0x01)


@pytest.mark.parametrize("request_pdu", [
    bytes([3, 0, 16]),                                          # too short
    bytes([3, 0, 16, 0, 1, 0]),                                 # too long
    bytes([16]) + struct.pack(">HHB", L2, 2, 3) + b"\x00\x01\x00",  # byte count does not match the quantity
    bytes([16]) + struct.pack(">HHB", L2, 2, 4) + b"\x00\x01",  # fewer bytes than the byte count
    bytes([15]) + struct.pack(">HHB", 16, 1, 2) + b"\x01\x00",  # byte count 2 for one coil
    bytes([16]) + struct.pack(">HHB", L2, 124, 2) + b"\x00" * 2,  # more than 123 registers
    bytes([16]) + struct.pack(">HHB", L2, 0, 0),                # zero registers
])
def test_a_malformed_request_gets_illegal_data_value_and_the_connection_goes_on(raw, request_pdu):
    assert raw.request(request_pdu) == exception(request_pdu[0], 0x03)
    assert read_hr(raw, L2)  # the same connection still works


def test_exception_responses_keep_the_transaction_and_unit_ids(raw):
    raw.send(raw.frame(pdu(3, 500, 1), tid=0xBEEF, unit=255))
    assert raw.response() == (0xBEEF, 255, exception(3, 0x02))


def test_the_configured_unit_0_and_255_are_answered_and_others_get_gateway_exception_0b(raw):
    for unit in (1, 0, 255):
        assert raw.request(pdu(3, L2, 1), unit=unit)[:2] == b"\x03\x02"
    assert raw.request(pdu(3, L2, 1), unit=7) == exception(3, 0x0B)


# -- reads and writes of every function ---------------------------------------------------------------------
def test_all_supported_functions_on_the_wire(raw):
    assert raw.request(pdu(1, 16, 1)) == bytes([1, 1, 1])  # Active is on
    assert raw.request(pdu(5, 16, 0xFF00)) == pdu(5, 16, 0xFF00)
    assert raw.request(bytes([15]) + struct.pack(">HHB", 16, 1, 1) + b"\x01") == pdu(15, 16, 1)
    assert raw.request(pdu(2, 0, 3))[:2] == bytes([2, 1])
    assert raw.request(pdu(4, 0, 9))[:2] == bytes([4, 18])
    assert raw.request(pdu(6, L3, 33000)) == pdu(6, L3, 33000)
    assert raw.request(bytes([16]) + struct.pack(">HHBHH", L2, 2, 4, 33000, 33000)) == pdu(16, L2, 2)
    # 23: write L4, read L2..L5 in one request
    resp = raw.request(bytes([23]) + struct.pack(">HHHHBH", L2, 4, 18, 1, 2, 33000))
    assert resp[:2] == bytes([23, 8])


def read_ir(raw: Raw, address: int, count: int = 1) -> list[int]:
    resp = raw.request(pdu(4, address, count))
    assert resp[:2] == bytes([4, 2 * count]), resp
    return list(struct.unpack(f">{count}H", resp[2:]))


def outputs(raw: Raw) -> tuple[bytes, bytes]:
    """Every discrete input and input register of the ring bench, raw."""
    bits = raw.request(pdu(2, 0, 3)) + raw.request(pdu(2, 16, 12))
    return bits, raw.request(pdu(4, 0, 9)) + raw.request(pdu(4, 16, 17))


def test_a_write_reads_back_at_once_and_takes_effect_at_the_next_step(raw):
    old = read_hr(raw, L2)[0]
    new = 32900 if old != 32900 else 32800
    before, actual = outputs(raw), read_ir(raw, 17, 3)  # L2..L4.actual
    assert raw.request(pdu(6, L2, new)) == pdu(6, L2, new)
    assert read_hr(raw, L2) == [new]  # an input reads back what was written, before any step
    assert raw.request(pdu(5, 17, 0x0000)) == pdu(5, 17, 0x0000)  # ring.present off
    assert raw.request(pdu(1, 16, 2)) == bytes([1, 1, 0b01])  # Active on, ring.present off at once
    assert raw.request(bytes([16]) + struct.pack(">HHBHH", L3, 2, 4, 32950, 32960)) == pdu(16, L3, 2)
    assert read_hr(raw, L2, 3) == [new, 32950, 32960]
    assert outputs(raw) == before  # outputs: still the last completed step
    advance(raw, 1)
    moved = read_ir(raw, 17, 3)
    assert all(m != a for m, a in zip(moved, actual)), (actual, moved)  # the step applied the writes
    assert read_hr(raw, L2, 3) == [new, 32950, 32960]  # and its publish kept them
    assert raw.request(pdu(1, 16, 2)) == bytes([1, 1, 0b01])
    raw.request(bytes([16]) + struct.pack(">HHBHHH", L2, 3, 6, 33000, 33000, 33000))
    raw.request(pdu(5, 17, 0xFF00))
    advance(raw, 1)


def test_function_23_writes_first_then_reads_and_the_read_sees_the_write(raw):
    resp = raw.request(bytes([23]) + struct.pack(">HHHHBH", L2, 4, 18, 1, 2, 32990))
    assert resp[:2] == bytes([23, 8]) and struct.unpack(">4H", resp[2:])[2] == 32990
    assert read_hr(raw, 18) == [32990]
    raw.request(pdu(6, 18, 33000))
    advance(raw, 1)


def test_sim_advance_counts_down_to_zero_and_sim_step_and_time_follow(raw):
    def step_and_ms():
        resp = raw.request(pdu(4, 0, 4))
        return struct.unpack(">II", resp[2:])

    s0, ms0 = step_and_ms()
    advance(raw, 25)
    s1, ms1 = step_and_ms()
    assert (s1 - s0, ms1 - ms0) == (25, 300)
    assert raw.request(pdu(6, ADVANCE, 0)) == pdu(6, ADVANCE, 0)  # 0 is a no-op


# -- framing ------------------------------------------------------------------------------------------------
def test_pipelined_requests_are_all_answered_in_order(raw):
    frames = [raw.frame(pdu(3, L2, 1), tid=100 + i) for i in range(5)]
    frames.insert(2, raw.frame(pdu(3, 999, 1), tid=150))  # an exception in the middle
    raw.send(b"".join(frames))
    tids = [raw.response()[0] for _ in frames]
    assert tids == [100, 101, 150, 102, 103, 104]


def test_a_request_split_across_segments_is_reassembled(raw):
    frame = raw.frame(pdu(3, L2, 2))
    for i in range(len(frame)):
        raw.send(frame[i:i + 1])
        time.sleep(0.005)
    assert raw.response()[2][:2] == b"\x03\x04"


def test_a_stalled_half_frame_is_dropped_after_the_timeout_not_glued_to_the_next_request(lockstep_server):
    with Raw(lockstep_server.port) as stalled, Raw(lockstep_server.port) as other:
        stalled.send(stalled.frame(pdu(3, L2, 1))[:9])
        t0 = time.monotonic()
        assert other.request(pdu(3, L2, 1))[:2] == b"\x03\x02"  # others notice nothing
        assert stalled.closed_by_peer(timeout=3.0)
        assert 0.2 < time.monotonic() - t0 < 2.0  # --frame-timeout 0.3
        assert other.request(pdu(3, L2, 1))[:2] == b"\x03\x02"
    lockstep_server.wait_for(r"disconnected \(half a frame \(9 bytes\)")


@pytest.mark.parametrize("header,why", [
    (struct.pack(">HHHB", 1, 0, 0xFFFF, 1), "frame length field 65535"),
    (struct.pack(">HHHB", 1, 0, 300, 1), "frame length field 300"),
    (struct.pack(">HHHB", 1, 0, 266, 1), "frame length field 266"),
    (struct.pack(">HHHB", 1, 0, 1, 1), "frame length field 1"),
    (struct.pack(">HHHB", 1, 7, 6, 1) + pdu(3, L2, 1), "protocol id 7"),
])
def test_a_frame_that_cannot_be_resynchronised_closes_that_connection_alone(lockstep_server, header, why):
    with Raw(lockstep_server.port) as bad, Raw(lockstep_server.port) as other:
        start = len(lockstep_server.lines)
        bad.send(header)
        assert bad.closed_by_peer()
        assert other.request(pdu(3, L2, 1))[:2] == b"\x03\x02"
        lockstep_server.wait_for(why, start=start)


@pytest.mark.parametrize("bad", [dict(pid=1), dict(length=300)])
def test_requests_before_a_bad_header_in_the_same_segment_are_answered_before_the_connection_closes(
        lockstep_server, bad):
    with Raw(lockstep_server.port) as c:
        c.send(c.frame(pdu(3, L2, 1), tid=1) + c.frame(pdu(4, 0, 2), tid=2) + c.frame(pdu(3, L2, 1), tid=3, **bad))
        assert [c.response()[0] for _ in range(2)] == [1, 2]
        assert c.closed_by_peer()


@pytest.mark.parametrize("request_pdu", [
    bytes([16]) + struct.pack(">HHB", L2, 124, 248) + bytes(248),  # MBAP length 255
    bytes([16]) + struct.pack(">HHB", L2, 127, 254) + bytes(254),  # 261
    bytes([23]) + struct.pack(">HHHHB", L2, 1, L2, 127, 254) + bytes(254),  # 265, the longest we frame
    bytes([15]) + struct.pack(">HHB", 16, 2000, 250) + bytes(250),  # 257
])
def test_a_write_just_over_the_quantity_limit_gets_illegal_data_value_not_a_dropped_connection(raw, request_pdu):
    assert raw.request(request_pdu) == exception(request_pdu[0], 0x03)
    assert read_hr(raw, L2)  # the same connection still works


def test_a_client_that_vanishes_mid_frame_leaves_the_server_and_the_simulation_going(lockstep_server):
    with Raw(lockstep_server.port) as other:
        for _ in range(5):
            gone = Raw(lockstep_server.port)
            gone.send(gone.frame(bytes([16]) + struct.pack(">HHB", L2, 2, 4) + b"\x80")[:12])
            gone.close()
        advance(other, 3)
        assert other.request(pdu(3, L2, 1))[:2] == b"\x03\x02"
    assert lockstep_server.proc.poll() is None


def test_a_flood_of_garbage_does_not_stop_the_server(lockstep_server):
    with Raw(lockstep_server.port) as bad:
        try:
            bad.send(bytes(range(256)) * 40)
        except OSError:
            pass
        assert bad.closed_by_peer()
    with Raw(lockstep_server.port) as ok:
        assert ok.request(pdu(3, L2, 1))[:2] == b"\x03\x02"


# -- two clients at once -------------------------------------------------------------------------------------
def test_two_pymodbus_clients_at_once_each_get_their_own_answers(lockstep_server):
    async def one(register: int, value: int) -> list[int]:
        client = AsyncModbusTcpClient("127.0.0.1", port=lockstep_server.port, timeout=3)
        await client.connect()
        try:
            seen = []
            for _ in range(100):
                r = await client.read_holding_registers(register, count=1, device_id=1)
                assert not r.isError()
                seen.append(r.registers[0])
                r = await client.read_input_registers(9, count=1, device_id=1)  # a gap: exception 02
                assert r.isError() and r.exception_code == 2
            return seen
        finally:
            client.close()

    async def both():
        return await asyncio.gather(one(ADVANCE, 0), one(L2, 0))

    a, b = asyncio.run(both())
    assert set(a) == {0} and len(set(b)) == 1 and len(a) == len(b) == 100
