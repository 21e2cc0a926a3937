"""The client's side of the register map: loading, checks before the wire, encoding, request planning."""
import json

import pytest

from plc_client.checks import check_value, lookup
from plc_client.client import RegisterMap, decode, encode, plan_reads
from twin.core.errors import SignalTypeError
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
        lookup(rmap, "L2.actul")


def test_a_value_outside_the_range_names_the_signal_and_the_range(rmap):
    with pytest.raises(ValueOutOfRangeError, match=r"signal 'L2': 500 mm is out of range: 0 to 441 mm"):
        check_value(rmap, "L2", 500)


def test_outputs_and_wrong_kinds_of_value_are_refused_before_the_wire(rmap):
    with pytest.raises(NotWritableError, match="doGripped"):
        check_value(rmap, "doGripped", True)
    with pytest.raises(SignalValueError, match="needs a number"):
        check_value(rmap, "L2", "fast")
    with pytest.raises(SignalTypeError, match="needs a bool"):  # the twin's own refusal (SignalSpec.check)
        check_value(rmap, "Active", 2)


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


# -- values outside the type's own range (entries without min/max) -------------------------------------------
TYPED = [
    {"name": "sim.advance", "table": "holding_register", "address": 0, "type": "uint16", "min": 0, "max": 65535, "access": "rw"},
    {"name": "jaw_left", "table": "holding_register", "address": 16, "type": "uint16", "scale": 0.01, "unit": "mm",
     "min": 0, "max": 25, "access": "rw"},
    {"name": "goMisses", "table": "holding_register", "address": 17, "count": 2, "type": "int32", "access": "rw"},
    {"name": "count", "table": "holding_register", "address": 19, "count": 2, "type": "uint32", "access": "rw"},
    {"name": "small", "table": "holding_register", "address": 21, "type": "int16", "access": "rw"},
    {"name": "word", "table": "holding_register", "address": 22, "type": "uint16", "access": "rw"},
    {"name": "fine", "table": "holding_register", "address": 23, "count": 2, "type": "int32", "scale": 0.01,
     "unit": "mm", "access": "rw"},
    {"name": "aoFingerReady", "table": "holding_register", "address": 25, "count": 2, "type": "float32",
     "unit": "mm", "access": "rw"},
]


@pytest.fixture
def typed():
    return RegisterMap.from_json(TYPED)


@pytest.mark.parametrize("name, value, message", [
    ("goMisses", 2 ** 31, r"signal 'goMisses': 2147483648 is out of range: -2147483648 to 2147483647$"),
    ("goMisses", -2 ** 31 - 1, r"out of range: -2147483648 to 2147483647"),
    ("count", -1, r"signal 'count': -1 is out of range: 0 to 4294967295$"),
    ("count", 2 ** 32, r"out of range: 0 to 4294967295"),
    ("small", 40000, r"out of range: -32768 to 32767"),
    ("word", 65536, r"out of range: 0 to 65535"),
    ("fine", 3e7, r"signal 'fine': 30000000 mm is out of range: -21474836.48 to 21474836.47 mm"),
    ("aoFingerReady", 1e39, r"signal 'aoFingerReady': 1e\+39 mm is out of range: -3.402823466e\+38 to 3.402823466e\+38 mm"),
    ("aoFingerReady", -1e39, r"out of range"),
])
def test_a_value_outside_the_types_range_is_refused_for_entries_without_min_or_max(typed, name, value, message):
    with pytest.raises(ValueOutOfRangeError, match=message):
        check_value(typed, name, value)


def test_a_fraction_for_a_whole_number_entry_is_refused_not_rounded(typed):
    with pytest.raises(SignalTypeError, match=r"signal 'goMisses': needs a whole number, not 3.5"):
        check_value(typed, "goMisses", 3.5)
    with pytest.raises(SignalValueError, match="whole number"):
        check_value(typed, "sim.advance", 2.5)
    for bad in (float("nan"), float("inf")):  # not a number the signal can hold: the twin's own type refusal
        with pytest.raises(SignalTypeError, match="needs a finite number"):
            check_value(typed, "aoFingerReady", bad)
    # what fits goes through: the type's limits, whole floats, fractions where the scale resolves them
    for name, value in [("goMisses", 3.0), ("goMisses", -2 ** 31), ("count", 2 ** 32 - 1), ("small", -32768),
                        ("word", 65535), ("fine", 12.34), ("aoFingerReady", 3.4e38), ("aoFingerReady", -150.5)]:
        s = typed[name]
        assert decode(s, encode(s, check_value(typed, name, value))) == pytest.approx(value, rel=1e-6)


# -- sim.advance goes last -----------------------------------------------------------------------------------
class _Recorder:
    """Stands in for pymodbus's client: records the requests, answers each one."""

    def __init__(self):
        self.calls = []

    def _answer(self, method, address, values):
        self.calls.append((method, address, list(values)))
        return type("Ok", (), {"isError": lambda self: False})()

    def write_registers(self, address, values, device_id=1):
        return self._answer("write_registers", address, values)

    def write_coils(self, address, values, device_id=1):
        return self._answer("write_coils", address, values)


def test_sim_advance_is_written_last_in_a_request_of_its_own(typed):
    from plc_client.client import TwinClient

    client = TwinClient(typed)
    client._client = _Recorder()
    client.write(jaw_left=5, **{"sim.advance": 20})
    client.write({"sim.advance": 3, "word": 7, "small": -1, "jaw_left": 6})
    assert client._client.calls == [
        ("write_registers", 16, [500]), ("write_registers", 0, [20]),
        ("write_registers", 16, [600]), ("write_registers", 21, [0xFFFF, 7]), ("write_registers", 0, [3])]


# -- plc read: an enumeration prints its index, its text in the unit column -------------------------------------
def test_plc_read_shows_an_enumerations_index_with_its_text(rmap):
    from plc_client.cli import read_row

    assert read_row(rmap["GrippedPart"], "ring") == ("GrippedPart", "1", "(ring)")
    assert read_row(rmap["GrippedPart"], "") == ("GrippedPart", "0", "(none)")
    assert read_row(rmap["L2"], 320.5) == ("L2", "320.5", "mm")
