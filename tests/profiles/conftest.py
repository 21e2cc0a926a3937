"""Fixtures: `twin serve STATION --profile ... --lockstep` subprocesses, and a raw-socket Robotiq client."""
from __future__ import annotations

import struct
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "modbus"))
from modbus_helpers import ROOT, Raw, ServerProcess  # noqa: E402

MAP_UNIT = 247  # the generated map (sim.advance) while a profile is served
RING3F = ROOT / "tests" / "profiles" / "stations" / "ring3f"
SMART_GRIPPER = ROOT / "stations" / "smart_gripper"


def crc16_modbus(data: bytes) -> bytes:
    """The Modbus RTU CRC (polynomial 0xA001 reflected, initial 0xFFFF), low byte first, as on the wire."""
    crc = 0xFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return struct.pack("<H", crc)


def rtu_pdu(frame_hex: str) -> tuple[int, bytes]:
    """A manual's Modbus RTU frame (slave id, PDU, CRC) -> (slave id, PDU), after checking its CRC."""
    frame = bytes.fromhex(frame_hex)
    assert crc16_modbus(frame[:-2]) == frame[-2:], f"CRC of {frame_hex} does not check: a typo in the frame"
    return frame[0], frame[1:-2]


class Robotiq(Raw):
    """A raw Modbus/TCP client for a profile server: the gripper on `unit`, the simulation on the map's unit."""

    def __init__(self, port: int, unit: int):
        super().__init__(port)
        self.unit = unit

    def ask(self, pdu: bytes) -> bytes:
        return self.request(pdu, unit=self.unit)

    def write(self, address: int, words: list[int]) -> bytes:
        pdu = struct.pack(">BHHB", 16, address, len(words), 2 * len(words)) + struct.pack(f">{len(words)}H", *words)
        return self.ask(pdu)

    def status(self, address: int = 0x07D0, count: int = 3) -> bytes:
        resp = self.ask(struct.pack(">BHH", 4, address, count))
        assert resp[:2] == bytes((4, 2 * count)), resp.hex()
        return resp[2:]

    def advance(self, steps: int) -> None:
        """Run `steps` simulation steps (lockstep) and wait until they are done."""
        while steps:
            n = min(steps, 1000)
            assert self.request(struct.pack(">BHH", 6, 0, n), unit=MAP_UNIT) == struct.pack(">BHH", 6, 0, n)
            while self.request(struct.pack(">BHH", 3, 0, 1), unit=MAP_UNIT)[2:] != b"\x00\x00":
                pass
            steps -= n

    def until(self, check, limit: int = 2000, address: int = 0x07D0, count: int = 3) -> tuple[int, bytes]:
        """Step one at a time until `check(status bytes)`; (steps taken, status)."""
        for n in range(1, limit + 1):
            self.advance(1)
            s = self.status(address, count)
            if check(s):
                return n, s
        raise AssertionError(f"not reached within {limit} steps; status {s.hex()}")

    def reset(self, address: int = 0x03E8) -> None:
        self.write(address, [0, 0, 0])
        self.advance(1)


@pytest.fixture(scope="module")
def server_2f():
    with ServerProcess(SMART_GRIPPER, "--lockstep", "--profile", "robotiq-2f") as s:
        yield s


@pytest.fixture(scope="module")
def server_3f():
    with ServerProcess(RING3F, "--lockstep", "--profile", "robotiq-3f") as s:
        yield s
