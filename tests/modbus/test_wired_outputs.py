"""A wired controller output reads what it drives: aoAxis1 (scale 0.001) drives L2, so with L2 at 350 mm
(written by a PLC, not by the robot) aoAxis1 reads 350.0 on the signal table and on Modbus."""
from __future__ import annotations

import struct

import pytest

from tests.conftest import STATIONS
from twin_app.cell import open_cell
from twin.frontends.modbus.bridge import TwinBridge


def test_ao_axis1_mirrors_l2_whoever_wrote_it():
    with open_cell(STATIONS / "ring_rig") as twin:
        rmap = twin.register_map
        bridge = TwinBridge(twin.exchange, rmap)
        e = rmap["aoAxis1"]
        assert e.table == "input_register"
        for mm in (350.0, 281.5):
            twin.write("L2", mm / 1000)  # as the PLC's Modbus write does (the bridge's queue, applied at a step)
            twin.step()
            assert twin.read("aoAxis1") == pytest.approx(mm)
            words = list(struct.unpack(f">{e.count}H", bridge.images.input_registers[2 * e.address:2 * e.end]))
            assert e.decode(words) == pytest.approx(mm, abs=1e-3)
