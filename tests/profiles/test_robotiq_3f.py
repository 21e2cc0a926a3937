"""`twin serve ring3f --profile robotiq-3f`, from the wire: the 3-Finger manual's Modbus TCP example.

Over Modbus/TCP the manual's frames are whole ADUs (transaction id, protocol id, length, unit id 2, PDU),
so they are sent and compared byte for byte as they stand: the 2018 edition's layout (robot output and
status at 0x0000) and the 2014 edition's (0x03E8 and 0x07D0). Status frames depend on where the fingers
are: status, object and echo bytes are compared with the manual, positions with the station's geometry.

The ring bench's fingers: position 0 = open (441 mm), 255 = closed (0 mm), linear; the ring's outside
(radius 320 mm) stops them at (441 - 320) / 441 * 255 = 70.
"""
from __future__ import annotations

import struct

import pytest
from conftest import MAP_UNIT, Robotiq
from pymodbus.client import ModbusTcpClient

RING_POSITION = (441 - 320) / 441 * 255  # 70


def counts(radius_m: float) -> float:
    return (0.441 - radius_m) / 0.441 * 255


@pytest.fixture
def g(server_3f):
    with Robotiq(server_3f.port, unit=2) as c:
        c.reset(0x0000)
        c.write(0x0000, [0, 0, 0, 0, 0, 0, 0, 0])
        c.advance(1)
        yield c


def adu(g: Robotiq, hex_frame: str) -> bytes:
    g.send(bytes.fromhex(hex_frame))
    tid, pid, length, unit = struct.unpack(">HHHB", g.recv_exact(7))
    return struct.pack(">HHHB", tid, pid, length, unit) + g.recv_exact(length - 1)


def h(text: str) -> bytes:
    return bytes.fromhex(text)


def test_manual_tcp_example_2018_at_address_0(g):
    # Step 1: activation request (rACT = 1)
    assert adu(g, "33 9A 00 00 00 0D 02 10 00 00 00 03 06 01 00 00 00 00 00") == h("33 9A 00 00 00 06 02 10 00 00 00 03")
    # Step 2: read the status until the activation is completed. (The manual's request bytes say function 03
    # where its text and its responses say 04, "Read Input Registers": the request is sent as 04.)
    g.advance(1)
    assert adu(g, "45 33 00 00 00 06 02 04 00 00 00 01") == h("45 33 00 00 00 05 02 04 02 11 00")
    steps, _ = g.until(lambda s: s[0] == 0x31, address=0, count=1)
    assert adu(g, "45 33 00 00 00 06 02 04 00 00 00 01") == h("45 33 00 00 00 05 02 04 02 31 00")
    assert 0.5 <= steps * 0.012 <= 5.0
    # Step 4: close at full speed and force (basic mode, simple control)
    assert adu(g, "71 EE 00 00 00 0D 02 10 00 00 00 03 06 09 00 00 FF FF FF") == h("71 EE 00 00 00 06 02 10 00 00 00 03")
    g.advance(3)
    moving = adu(g, "77 6B 00 00 00 06 02 04 00 00 00 08")
    manual = h("77 6B 00 00 00 13 02 04 10 39 C0 00 FF 08 0F 00 08 10 00 08 0F 00 89 00 00")  # not completed
    assert moving[:13] == manual[:13]  # header, 39 C0 00 FF: go-to, moving, scissor at its request, echo 255
    assert moving[15] == manual[15] and moving[18] == manual[18] and moving[21] == manual[21]  # B, C, S echo 0
    # ... until the grip is completed: every finger stopped on the ring while closing
    _, s = g.until(lambda s: s[0] >> 6 != 0, address=0, count=8)
    assert s[0] == 0xB9  # gSTA 2: all fingers stopped before the requested position
    assert s[1] == 0xEA  # gDTA = gDTB = gDTC = 2 (contact while closing), gDTS = 3
    for pos in (s[4], s[7], s[10]):
        assert abs(pos - RING_POSITION) <= 2  # 1.7 mm per count
    # Step 7: open (position 0)
    assert adu(g, "34 AB 00 00 00 0D 02 10 00 00 00 03 06 09 00 00 00 FF FF") == h("34 AB 00 00 00 06 02 10 00 00 00 03")
    _, s = g.until(lambda s: s[0] >> 6 == 3, address=0, count=8)
    manual_opened = h("F9 FF 00 00 07 00 00 06 00 00 06 00 00 89 00 00")  # the manual's "opening completed"
    assert s[:4] == manual_opened[:4]  # F9 FF 00 00: every finger at its request, no fault, echo 0
    assert (s[6], s[9], s[12]) == (0, 0, 0)
    assert s[4] == s[7] == s[10] == 0  # fully open (the real gripper's software limit reads 6 or 7)


def test_manual_tcp_example_2014_at_03e8_and_07d0(g):
    assert adu(g, "33 9A 00 00 00 0D 02 10 03 E8 00 03 06 01 00 00 00 00 00") == h("33 9A 00 00 00 06 02 10 03 E8 00 03")
    g.advance(1)
    assert adu(g, "45 33 00 00 00 06 02 04 07 D0 00 01") == h("45 33 00 00 00 05 02 04 02 11 00")
    g.until(lambda s: s[0] == 0x31, count=1)
    assert adu(g, "45 33 00 00 00 06 02 04 07 D0 00 01") == h("45 33 00 00 00 05 02 04 02 31 00")
    assert adu(g, "71 EE 00 00 00 0D 02 10 03 E8 00 03 06 09 00 00 FF FF FF") == h("71 EE 00 00 00 06 02 10 03 E8 00 03")
    g.advance(3)
    moving = adu(g, "77 6B 00 00 00 06 02 04 07 D0 00 08")
    manual = h("77 6B 00 00 00 13 02 04 10 39 C0 00 FF 08 0F 00 08 10 00 08 0F 00 89 00 00")
    assert moving[:13] == manual[:13]
    g.until(lambda s: s[0] >> 6 == 2, count=8)
    assert adu(g, "34 AB 00 00 00 0D 02 10 03 E8 00 03 06 09 00 00 00 FF FF") == h("34 AB 00 00 00 06 02 10 03 E8 00 03")
    g.until(lambda s: s[0] == 0xF9 and s[1] == 0xFF, count=8)


def test_individual_control_reports_each_finger(g):
    """rICF: each finger its own position and speed, in free air; B slow. Midway A and C are at their request (3)
    while B still moves (0); in the end each stands at its own request, echoed per finger."""
    g.write(0x0000, [0x0100, 0, 0, 0, 0, 0, 0, 0])
    g.until(lambda s: s[0] == 0x31, address=0, count=1)
    req = {"A": (20, 255), "B": (60, 0), "C": (40, 255)}
    out = bytes([0x09, 0x04, 0x00, req["A"][0], req["A"][1], 0xFF, req["B"][0], req["B"][1], 0xFF,
                 req["C"][0], req["C"][1], 0xFF, 0, 0, 0, 0])
    g.write(0x0000, list(struct.unpack(">8H", out)))
    _, s = g.until(lambda s: s[1] & 0x33 == 0x33, address=0, count=8)  # A and C arrived
    assert s[1] == 0xF3 and s[0] == 0x39  # A 3, B 0 (moving), C 3, scissor 3; gSTA 0: a finger still moves
    assert abs(s[4] - 20) <= 1 and abs(s[10] - 40) <= 1 and s[7] < 55
    _, s = g.until(lambda s: s[0] >> 6 == 3, address=0, count=8)
    assert s[1] == 0xFF
    assert (s[3], s[6], s[9]) == (20, 60, 40)  # position request echoes, per finger
    assert (abs(s[4] - 20), abs(s[7] - 60), abs(s[10] - 40)) <= (1, 1, 1)


def test_driver_style_client_grips_the_ring(server_3f):
    """PLC code as Robotiq's ROS driver writes it (pymodbus, unit id left at its default, write_registers(0, ...),
    read_input_registers(0, 8)) runs unchanged; the generated map's sim.advance steps it."""
    c = ModbusTcpClient("127.0.0.1", port=server_3f.port)
    assert c.connect()
    try:
        def step(n):
            c.write_register(0, n, device_id=MAP_UNIT)
            while c.read_holding_registers(0, count=1, device_id=MAP_UNIT).registers[0]:
                pass

        def status():
            regs = c.read_input_registers(0, count=8).registers
            return b"".join(struct.pack(">H", r) for r in regs)

        c.write_registers(0, [0, 0, 0, 0, 0, 0, 0, 0])
        step(1)
        c.write_registers(0, [0x0100, 0, 0, 0, 0, 0, 0, 0])
        for _ in range(400):
            step(1)
            if status()[0] == 0x31:
                break
        c.write_registers(0, [0x0900, 0x00FF, 0xFF80, 0, 0, 0, 0, 0])  # close, full speed, half force
        for _ in range(600):
            step(1)
            s = status()
            if s[0] >> 6:
                break
        assert s[0] == 0xB9 and s[1] == 0xEA and s[2] == 0
        assert all(abs(p - RING_POSITION) <= 2 for p in (s[4], s[7], s[10]))
        assert all(100 <= cur <= 160 for cur in (s[5], s[8], s[11]))  # half force: about half the current
    finally:
        c.close()


def test_mode_change_and_automatic_release(g):
    g.write(0x0000, [0x0100, 0, 0])
    g.until(lambda s: s[0] == 0x31, address=0, count=1)
    g.write(0x0000, [0x0B00, 0x0040, 0xFFFF])  # pinch mode (rMOD 1) and go to 64 at once
    g.advance(1)
    s = g.status(0, 2)
    assert s[0] == 0x23 and s[2] == 0x06  # gMOD 1, gIMC 2 "mode change in progress"; "action delayed, mode change"
    steps, s = g.until(lambda s: s[0] & 0x30 == 0x30, address=0, count=2)
    assert 0.5 <= steps * 0.012 <= 2.0 and s[2] == 0x00  # completed: the fault clears, the go-to runs
    _, s = g.until(lambda s: s[0] >> 6 == 3, address=0, count=8)
    assert s[0] == 0xFB and all(abs(p - 64) <= 1 for p in (s[4], s[7], s[10]))  # gMOD 1, at 64
    g.write(0x0000, [0x1B00])  # rATR: automatic release
    g.advance(1)
    s = g.status(0, 2)
    assert s[0] & 0x38 == 0 and s[2] == 0x0B  # gIMC 0 (release state), gGTO 0, "automatic release in progress"
    _, s = g.until(lambda s: s[2] == 0x0F, address=0, count=8)  # "completed, reset and activation is required"
    assert s[4] == s[7] == s[10] == 0  # released: open
    g.write(0x0000, [0x0000])  # rACT 0 clears it
    g.advance(1)
    assert g.status(0, 2) == b"\x00\x00\x00\x00"
