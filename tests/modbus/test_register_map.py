"""The register map as a pure function of a signal table (no physics, no sockets)."""
from __future__ import annotations

import csv
import io
import json
import math

import pytest

from twin.core.signals import BOOL, ENUM, FLOAT, INPUT, INT, OUTPUT, SignalSpec
from twin.frontends.modbus.register_map import (ADVANCE, COIL, DISCRETE_INPUT, FAULT, HOLDING_REGISTER, INPUT_REGISTER,
                                      RESERVED, STEP, TIME_MS, MapError, build_register_map)

SIGNALS = (
    SignalSpec("Active", INPUT, BOOL),
    SignalSpec("L2", INPUT, FLOAT, "m", 0.0, 0.441),
    SignalSpec("wrist", INPUT, FLOAT, "rad", -math.pi, math.pi),
    SignalSpec("doGripped", OUTPUT, BOOL),
    SignalSpec("GrippedPart", OUTPUT, ENUM, choices=("", "ring", "puck")),
    SignalSpec("L2.actual", OUTPUT, FLOAT, "m", 0.0, 0.441),
    SignalSpec("L2.in_position", OUTPUT, BOOL),
    SignalSpec("L2.contact", OUTPUT, BOOL),
    SignalSpec("L2.force", OUTPUT, FLOAT, "N", 0.0, None),
    SignalSpec("robot.j1", OUTPUT, FLOAT, "rad"),
    SignalSpec("long_stroke", INPUT, FLOAT, "m", 0.0, 2.0),
    SignalSpec("cycles", OUTPUT, INT, "", 0, None),
    SignalSpec("gain", INPUT, FLOAT, "", 0.0, 10.0),
)


@pytest.fixture(scope="module")
def rmap():
    return build_register_map(SIGNALS, "test")


def test_signals_go_to_their_table_from_the_reserved_block_on_in_declaration_order(rmap):
    assert [(e.name, e.address) for e in rmap.table(COIL)] == [("Active", RESERVED)]
    di = [(e.name, e.address) for e in rmap.table(DISCRETE_INPUT) if e.address >= RESERVED]
    assert di == [("doGripped", 16), ("L2.in_position", 17), ("L2.contact", 18)]
    hr = [(e.name, e.address, e.count) for e in rmap.table(HOLDING_REGISTER) if e.address >= RESERVED]
    assert hr == [("L2", 16, 1), ("wrist", 17, 1), ("long_stroke", 18, 2), ("gain", 20, 2)]
    ir = [(e.name, e.address, e.count) for e in rmap.table(INPUT_REGISTER) if e.address >= RESERVED]
    assert ir == [("GrippedPart", 16, 1), ("L2.actual", 17, 1), ("L2.force", 18, 2), ("robot.j1", 20, 2),
                  ("cycles", 22, 2)]


def test_the_simulator_entries_sit_at_fixed_addresses_in_the_reserved_block(rmap):
    assert (rmap[ADVANCE].table, rmap[ADVANCE].address, rmap[ADVANCE].access) == (HOLDING_REGISTER, 0, "rw")
    assert (rmap[FAULT].table, rmap[FAULT].address) == (DISCRETE_INPUT, 0)
    assert (rmap[STEP].address, rmap[STEP].type, rmap[TIME_MS].address) == (0, "uint32", 2)
    assert all(e.address < RESERVED for e in rmap if e.signal is None)


def test_adding_a_signal_at_the_end_moves_no_other_entry(rmap):
    bigger = build_register_map(SIGNALS + (SignalSpec("L6", INPUT, FLOAT, "m", 0, 0.1),
                                           SignalSpec("L6.contact", OUTPUT, BOOL)))
    for e in rmap:
        assert bigger[e.name] == e
    assert bigger["L6"].address == rmap.size(HOLDING_REGISTER)


def test_the_map_is_the_same_from_run_to_run(rmap):
    assert build_register_map(SIGNALS, "test").to_json() == rmap.to_json()


def test_types_are_the_smallest_that_hold_the_range_in_engineering_units(rmap):
    l2 = rmap["L2"]
    assert (l2.type, l2.unit, l2.scale, l2.min, l2.max) == ("uint16", "mm", 0.01, 0.0, 441.0)
    wrist = rmap["wrist"]
    assert (wrist.type, wrist.unit, wrist.scale, wrist.min, wrist.max) == ("int16", "deg", 0.01, -180.0, 180.0)
    assert (rmap["long_stroke"].type, rmap["long_stroke"].max) == ("uint32", 2000.0)  # 200000 counts
    assert (rmap["L2.force"].type, rmap["L2.force"].unit) == ("uint32", "N")  # no upper bound
    assert rmap["robot.j1"].type == "int32"  # no range at all
    assert rmap["gain"].type == "float32"  # a unit without a scaling rule
    gp = rmap["GrippedPart"]
    assert (gp.type, gp.min, gp.max, gp.choices) == ("uint16", 0, 2, ("", "ring", "puck"))


def test_values_encode_as_scaled_counts_and_32_bit_values_high_word_first(rmap):
    assert rmap["L2"].encode(0.32) == [32000]
    assert rmap["wrist"].encode(-math.pi / 2) == [(-9000) & 0xFFFF]
    assert rmap["long_stroke"].encode(1.5) == [0x0002, 0x49F0]  # 150000 = 0x000249F0
    assert rmap["robot.j1"].encode(-math.radians(1000)) == [0xFFFE, 0x7960]  # -100000
    assert rmap["GrippedPart"].encode("puck") == [2] and rmap["GrippedPart"].encode("") == [0]
    assert rmap["gain"].encode(2.5) == [0x4020, 0x0000]
    assert rmap["L2.force"].decode([0x0001, 0x86A0]) == pytest.approx(1000.0)


def test_outputs_saturate_at_their_declared_range_and_type_limits(rmap):
    assert rmap["L2.actual"].encode(-0.00002) == [0]
    assert rmap["L2.actual"].encode(1.0) == [44100]  # a finger pressed past its 441 mm limit reads 441 mm
    assert rmap["L2.force"].encode(1e9) == [0xFFFF, 0xFFFF]  # no upper bound: the type's limit


def test_a_written_count_on_the_range_edge_maps_inside_the_si_range(rmap):
    l2 = rmap["L2"]
    assert l2.count_range == (0, 44100)
    assert 0.0 <= l2.si_of_words([44100]) <= 0.441
    assert l2.si_of_words([44101]) is None
    assert rmap["wrist"].si_of_words([(-18001) & 0xFFFF]) is None
    assert rmap["wrist"].si_of_words([(-18000) & 0xFFFF]) == pytest.approx(-math.pi)
    assert rmap["gain"].si_of_words([0x7FC0, 0]) is None  # NaN
    assert rmap["Active"].si_of_words([1]) is True


def test_json_lists_every_entry_with_the_documented_keys(rmap):
    data = json.loads(rmap.to_json())
    assert isinstance(data, list) and len(data) == len(rmap)
    keys = {"name", "table", "address", "count", "type", "scale", "unit", "min", "max", "access", "description"}
    for d in data:
        assert keys <= d.keys()
        assert d["table"] in ("coil", "discrete_input", "holding_register", "input_register")
        assert d["type"] in ("bool", "uint16", "int16", "uint32", "int32", "float32")
        assert d["access"] in ("r", "rw")


def test_csv_and_markdown_carry_the_same_entries(rmap):
    rows = list(csv.DictReader(io.StringIO(rmap.to_csv())))
    assert [r["name"] for r in rows] == [e.name for e in rmap]
    md = rmap.to_markdown()
    assert "high word first" in md
    for e in rmap:
        assert f"`{e.name}`" in md
    assert "| 16 | 40017 | `L2` | uint16 | mm | 0.01 | 0 .. 441 | rw |" in md


def test_a_name_declared_twice_is_refused():
    with pytest.raises(MapError, match="twice"):
        build_register_map([SignalSpec("x", INPUT, BOOL), SignalSpec("x", OUTPUT, BOOL)])
    with pytest.raises(MapError, match="sim.step"):
        build_register_map([SignalSpec("sim.step", OUTPUT, INT)])


# -- sim.map_crc: the map's own CRC, so a client can tell it holds the map the server serves -----------------
def test_the_map_crc_sits_in_the_reserved_block_of_the_input_registers(rmap):
    from twin.frontends.modbus.register_map import MAP_CRC

    e = rmap[MAP_CRC]
    assert (e.table, e.address, e.count, e.type, e.access) == (INPUT_REGISTER, 10, 2, "uint32", "r")
    assert e.end <= RESERVED and e.signal is None


def test_the_map_crc_covers_name_table_address_count_type_and_scale_of_every_other_entry(rmap):
    import dataclasses
    import zlib

    from twin.frontends.modbus.register_map import MAP_CRC, RegisterMap, map_crc

    order = [COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER]
    rows = sorted((e for e in rmap if e.name != MAP_CRC), key=lambda e: (order.index(e.table), e.address))
    canonical = "\n".join(f"{e.name},{e.table},{e.address},{e.count},{e.type},{e.scale:.10g}" for e in rows)
    assert rmap.crc == map_crc(rmap) == zlib.crc32(canonical.encode())
    assert build_register_map(SIGNALS, "another name").crc == rmap.crc  # same layout: same CRC

    def changed(which, **kw):
        return RegisterMap(tuple(dataclasses.replace(e, **kw) if e.name == which else e for e in rmap)).crc

    assert changed("L2", description="else", unit="m", min=1.0) == rmap.crc  # not part of the layout
    for kw in ({"address": 30}, {"type": "int32"}, {"scale": 0.1}, {"count": 2}, {"name": "L9"},
               {"table": INPUT_REGISTER}):
        assert changed("L2", **kw) != rmap.crc, kw
    assert changed(MAP_CRC, address=12) == rmap.crc  # itself excluded
    assert build_register_map(SIGNALS + (SignalSpec("L6", INPUT, FLOAT, "m", 0, 0.1),)).crc != rmap.crc


def test_the_json_map_carries_the_crc_entry_and_gives_the_same_crc_on_the_client_side(rmap):
    from plc_client.client import RegisterMap as ClientMap

    assert ClientMap.from_json(rmap.to_json()).crc == rmap.crc
