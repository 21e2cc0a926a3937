"""`twin serve smart_gripper --profile robotiq-2f`, from the wire: the 2F-85 manual's Modbus RTU example.

The manual's frames are RTU frames (slave id 9, PDU, CRC). Each frame's CRC is checked here (so a typo
in a copied frame cannot pass) and its PDU is sent over Modbus/TCP with unit id 9; the answer's PDU must
be the manual's answer PDU byte for byte. Status frames depend on where the jaws are: their status,
fault and echo bytes are compared byte for byte, the position with the part's geometry.

The smart gripper's jaws: position 0 = open (25 mm per jaw), 255 = closed (0 mm); the 20 mm cube
between them stops each jaw 10 mm from the centre line: position (25 - 10) / 25 * 255 = 153.
"""
from __future__ import annotations

import struct

import pytest
from conftest import Robotiq, rtu_pdu

CUBE_POSITION = (25 - 10) / 25 * 255  # 153: where the cube stops the jaws (station geometry)

# The 2F-85 & 2F-140 instruction manual, section 4.7 "Modbus RTU example" (request, response).
CLEAR_ACT = ("09 10 03 E8 00 03 06 00 00 00 00 00 00 73 30", "09 10 03 E8 00 03 01 30")
SET_ACT = ("09 10 03 E8 00 03 06 01 00 00 00 00 00 72 E1", "09 10 03 E8 00 03 01 30")
READ_1 = "09 04 07 D0 00 01 30 0F"
ACTIVATING = "09 04 02 11 00 54 A1"
ACTIVATED = "09 04 02 31 00 4D 61"
CLOSE = ("09 10 03 E8 00 03 06 09 00 00 FF FF FF 42 29", "09 10 03 E8 00 03 01 30")
READ_3 = "09 04 07 D0 00 03 B1 CE"
GRIPPED = "09 04 06 B9 00 00 FF BD 00 5C 9A"  # object detected while closing, position 0xBD (the manual's part)
OPEN = ("09 10 03 E8 00 03 06 09 00 00 00 FF FF 72 19", "09 10 03 E8 00 03 01 30")
OPENING = "09 04 06 39 00 00 00 BB 10 71 06"  # not completed: moving, echo 0, position 0xBB, current 0x10
OPENED = "09 04 06 F9 00 00 00 0D 00 17 AA"  # at the requested position (0), position 0x0D (its software limit)
# The same status read with function 3 (holding registers at 0x07D0), as the 2-Finger manuals of 2013-2016 do.
READ_1_FC3 = "09 03 07 D0 00 01 85 CF"
ACTIVATING_FC3 = "09 03 02 11 00 55 D5"
ACTIVATED_FC3 = "09 03 02 31 00 4C 15"
READ_3_FC3 = "09 03 07 D0 00 03 04 0E"
CLOSING_FC3 = "09 03 06 39 00 00 FF 0E 0A F7 8B"  # not completed: moving, echo FF


@pytest.fixture
def g(server_2f):
    with Robotiq(server_2f.port, unit=9) as c:
        c.reset()
        yield c


def test_manual_rtu_example_answered_byte_for_byte(g):
    for request, response in (CLEAR_ACT, SET_ACT):
        slave, pdu = rtu_pdu(request)
        assert slave == 9
        assert g.ask(pdu) == rtu_pdu(response)[1]
    _, read1 = rtu_pdu(READ_1)
    _, read1_fc3 = rtu_pdu(READ_1_FC3)
    g.advance(1)
    assert g.ask(read1) == rtu_pdu(ACTIVATING)[1]  # 11 00: gACT 1, gSTA 1 "activation in progress"
    assert g.ask(read1_fc3) == rtu_pdu(ACTIVATING_FC3)[1]
    steps, _ = g.until(lambda s: s[0] == 0x31, count=1)
    assert g.ask(read1) == rtu_pdu(ACTIVATED)[1]  # 31 00: activation completed
    assert g.ask(read1_fc3) == rtu_pdu(ACTIVATED_FC3)[1]
    assert 0.5 <= steps * 0.012 <= 5.0  # it takes a realistic time, not one step

    _, close = rtu_pdu(CLOSE[0])
    assert g.ask(close) == rtu_pdu(CLOSE[1])[1]
    g.advance(3)
    moving = g.ask(rtu_pdu(READ_3_FC3)[1])
    assert moving[:6] == rtu_pdu(CLOSING_FC3)[1][:6]  # 03 06 39 00 00 FF: go-to, moving, no fault, echo 255
    assert 0 < moving[6] < CUBE_POSITION  # on its way
    _, read3 = rtu_pdu(READ_3)
    _, gripped = g.until(lambda s: s[0] >> 6 != 0)
    assert g.ask(read3)[:6] == rtu_pdu(GRIPPED)[1][:6]  # 04 06 B9 00 00 FF: stopped by the part while closing
    assert abs(gripped[4] - CUBE_POSITION) <= 3  # gPO: where the cube's faces are

    _, open_ = rtu_pdu(OPEN[0])
    assert g.ask(open_) == rtu_pdu(OPEN[1])[1]
    g.advance(3)
    opening = g.ask(read3)
    assert opening[:6] == rtu_pdu(OPENING)[1][:6]  # 04 06 39 00 00 00: moving, no fault, echo 0
    assert 0 < opening[6] < gripped[4]
    g.until(lambda s: s[0] >> 6 == 3)
    opened = g.ask(read3)
    assert opened[:6] == rtu_pdu(OPENED)[1][:6]  # 04 06 F9 00 00 00: at the requested position, echo 0
    assert opened[6] <= 2  # fully open (the real 2F-85 reads a few counts there: its mechanical stop)


def test_fc23_reads_the_status_and_writes_position_speed_force(g):
    """The manual's FC 23 example: read 0x07D0-0x07D1, write 0x03E9-0x03EA (position 0xE6, speed 0x3C, force 0xC8)."""
    g.write(0x03E8, [0x0100, 0, 0])
    g.until(lambda s: s[0] == 0x31, count=1)
    g.write(0x03E8, [0x0900])
    _, pdu = rtu_pdu("09 17 07 D0 00 02 03 E9 00 02 04 00 E6 3C C8 2D 0C")
    resp = g.ask(pdu)
    assert resp[:2] == b"\x17\x04" and len(resp) == 6  # the status before the write takes effect (next step)
    assert g.ask(struct.pack(">BHH", 3, 0x03E9, 2)) == bytes.fromhex("03 04 00 E6 3C C8")  # read back at once
    g.advance(1)
    status = g.status(count=3)
    assert status[2:4] == b"\x00\xe6"  # no fault, position request echo 0xE6
    assert status[0] & 0x08  # gGTO


def test_faults_activation_must_come_first(g):
    g.write(0x03E8, [0x0800, 0x00FF, 0xFFFF])  # go-to without rACT
    g.advance(1)
    s = g.status()
    assert s[0] == 0x00 and s[2] == 0x07  # "the activation bit must be set prior to action"
    g.write(0x03E8, [0x0900, 0x00FF, 0xFFFF])  # activate and go at once: the action waits for the activation
    g.advance(1)
    s = g.status()
    assert s[0] == 0x11 and s[2] == 0x05  # "action delayed, activation must be completed prior to action"
    _, s = g.until(lambda s: s[0] & 0x30 == 0x30)
    assert s[2] == 0x00 and s[0] & 0x08  # activated: the fault clears and the go-to runs
    _, s = g.until(lambda s: s[0] >> 6 == 2)
    assert abs(s[4] - CUBE_POSITION) <= 3
    g.write(0x03E8, [0x0000])  # reset clears it all
    g.advance(1)
    assert g.status()[:3] == b"\x00\x00\x00"


def _travel_steps(g, position: int, speed: int, mark: int) -> int:
    """Steps from the request until the jaw passes position `mark` (the travel, without the settling at its end)."""
    start = g.status()[4]
    g.write(0x03E8, [0x0900, position, (speed << 8) | 0xFF])
    steps, _ = g.until(lambda s: (s[4] - mark) * (position - start) >= 0)
    _, s = g.until(lambda s: s[0] >> 6 == 3)
    assert s[3] == position and abs(s[4] - position) <= 1
    return steps


def test_speed_request_sets_the_travel_time(g):
    """Open (0) towards position 100 (jaw from 25 to 15.2 mm, clear of the cube) at speed 255 and at speed 0, timed
    to position 80: the 2F-85 moves at 150 and 20 mm/s (spec sheet); this jaw's full speed is its URDF's 50 mm/s."""
    g.write(0x03E8, [0x0100, 0, 0])
    g.until(lambda s: s[0] == 0x31, count=1)
    distance = 0.025 * 80 / 255
    fast = _travel_steps(g, 100, 255, 80)
    _travel_steps(g, 0, 255, 0)
    slow = _travel_steps(g, 100, 0, 80)
    assert abs(fast * 0.012 - distance / 0.05) <= 0.03  # s: at the joint's velocity limit
    assert 150 / 20 * 0.85 <= slow / fast <= 150 / 20 * 1.15


def test_force_request_sets_the_grip_force(g):
    """Grip the cube at force 255 and at force 0: the current (drive force, 255 = the jaw's 5 N effort) follows
    the 2F-85's 235 N and 20 N (spec sheet) as a ratio."""
    g.write(0x03E8, [0x0100, 0, 0])
    g.until(lambda s: s[0] == 0x31, count=1)
    currents = {}
    for force in (255, 0):
        g.write(0x03E8, [0x0900, 0x00FF, 0xFF00 | force])
        g.until(lambda s: s[0] >> 6 == 2)
        g.advance(10)
        currents[force] = g.status()[5]
        g.write(0x03E8, [0x0900, 0x0000, 0xFFFF])
        g.until(lambda s: s[0] >> 6 == 3)
    assert currents[255] >= 240
    assert abs(currents[0] / currents[255] - 20 / 235) <= 0.03
