"""The client's side of the register map: loading, checks before the wire, encoding, request planning."""
import json

import pytest

from plc_client.client import RegisterMap, decode, encode, plan_reads
from plc_client.errors import MapError, NotWritableError, SignalValueError, UnknownSignalError, ValueOutOfRangeError

MAP = {"signals": [
    {"name": "L2", "table": "holding_register", "address": 0, "count": 2, "type": "uint32", "scale": 0.01,
     "unit": "mm", "min": 0, "max": 441, "access": "rw"},
    {"name": "L3", "table": "holding_register", "address": 2, "count": 2, "type": "uint32", "scale": 0.01,
     "unit": "mm", "min": 0, "max": 441, "access": "rw"},
    {"name": "L2.actual", "table": "input_register", "address": 0, "count": 2, "type": "int32", "scale": 0.01, "unit": "mm"},
    {"name": "L2.force", "table": "input_register", "address": 2, "count": 2, "type": "float32", "unit": "N"},
    {"name": "GrippedPart", "table": "input_register", "address": 10, "type": "uint16", "choices": ["", "ring"]},
    {"name": "Active", "table": "coil", "address": 0, "access": "rw"},
    {"name": "doGripped", "table": "discrete_input", "address": 0},
]}


@pytest.fixture
def rmap(tmp_path):
    path = tmp_path / "map.json"
    path.write_text(json.dumps(MAP))
    return RegisterMap.from_json(path)


def test_a_misspelt_name_gets_a_suggestion(rmap):
    with pytest.raises(UnknownSignalError, match=r"unknown signal 'L2.actul'; did you mean 'L2.actual'\?"):
        rmap["L2.actul"]


def test_a_value_outside_the_range_names_the_signal_and_the_range(rmap):
    with pytest.raises(ValueOutOfRangeError, match=r"signal 'L2': 500 mm is out of range: 0 to 441 mm"):
        rmap.check_value("L2", 500)


def test_outputs_and_wrong_kinds_of_value_are_refused_before_the_wire(rmap):
    with pytest.raises(NotWritableError, match="doGripped"):
        rmap.check_value("doGripped", True)
    with pytest.raises(SignalValueError, match="needs a number"):
        rmap.check_value("L2", "fast")
    with pytest.raises(SignalValueError, match="true or false"):
        rmap.check_value("Active", 2)


@pytest.mark.parametrize("name, value", [("L2", 320.5), ("L2.actual", -12.34), ("L2.force", 1499.5), ("GrippedPart", "ring"),
                                          ("Active", True)])
def test_values_survive_the_round_trip_through_registers(rmap, name, value):
    s = rmap[name]
    raw = s.choices.index(value) if s.choices else value
    assert decode(s, encode(s, raw)) == value


def test_multi_register_values_are_big_endian_high_word_first(rmap):
    assert encode(rmap["L2"], 700.0) == [0x0001, 0x1170]  # 70000 counts of 0.01 mm


def test_contiguous_addresses_of_one_table_are_read_in_one_request(rmap):
    runs = plan_reads(rmap[n] for n in ("L3", "L2", "L2.actual", "L2.force", "GrippedPart", "doGripped"))
    assert [(r.table, r.start, r.end) for r in runs] == [
        ("discrete_input", 0, 1), ("holding_register", 0, 4), ("input_register", 0, 4), ("input_register", 10, 11)]


def test_a_gap_of_mapped_addresses_is_read_through_but_an_unmapped_one_is_not(rmap):
    wanted = [rmap["L2.actual"], rmap["GrippedPart"], rmap["L2"]]
    filler = {"input_register": set(range(0, 11)), "holding_register": {0, 1}}
    assert [(r.start, r.end) for r in plan_reads(wanted, filler)] == [(0, 2), (0, 11)]
    assert [(r.start, r.end) for r in plan_reads(wanted, rmap.mapped)] == [(0, 2), (0, 2), (10, 11)]


def test_a_map_that_is_not_the_twin_map_output_is_a_clear_error(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(MapError, match="bad.json: not JSON"):
        RegisterMap.from_json(bad)
    with pytest.raises(MapError, match="cannot read"):
        RegisterMap.from_json(tmp_path / "missing.json")
