"""One register map type and one map error on both sides of the wire: the PLC client loads the server's own
`twin.frontends.modbus.register_map.RegisterMap`, from a station or from `twin map --format json` output, and a map it
cannot load is one `MapError` naming the file and the entry."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

import plc_client
from plc_client.checks import check_value
from plc_client.client import decode, encode, plan_reads
from plc_client.errors import PlcClientError, UnknownSignalError
from twin.core.errors import TwinError
from twin.frontends.modbus import register_map
from twin.frontends.modbus.register_map import MapError, RegisterMap, build_map

ROOT = Path(__file__).resolve().parents[2]
STATIONS = [ROOT / "stations" / n for n in ("ring_rig_plc", "ring_rig", "smart_gripper", "four_finger")]


def test_the_client_and_the_server_share_one_map_type_and_one_map_error():
    assert plc_client.RegisterMap is register_map.RegisterMap
    assert plc_client.MapError is plc_client.errors.MapError is register_map.MapError
    # one `except TwinError` catches a map problem and the client's own errors alike
    assert issubclass(MapError, TwinError) and issubclass(PlcClientError, TwinError)
    assert issubclass(MapError, ValueError)  # as before, for code that caught the server side's ValueError


@pytest.mark.parametrize("station", STATIONS, ids=lambda p: p.name)
def test_a_station_and_its_json_export_load_as_the_same_map(station, tmp_path):
    served = build_map(station)
    path = tmp_path / "map.json"
    path.write_text(served.to_json())
    from_file = RegisterMap.from_json(path)
    from_station = RegisterMap.from_station(station)
    assert from_station == served and from_station.source == f"station {served.station!r}"
    assert from_file.source == str(path)
    assert from_file.as_list() == served.as_list() and from_file.crc == served.crc
    for name in ("L2", "L2.actual", "sim.step", "doGripped"):
        if name in served:
            assert (from_file[name].table, from_file[name].address) == (served[name].table, served[name].address)
    # the addresses a read may cover, per table, as the entries span them
    for table in register_map.TABLES:
        spans = {a for e in served.table(table) for a in range(e.address, e.address + e.count)}
        assert from_file.mapped[table] == spans == served.mapped[table]


def test_the_client_encodes_engineering_units_from_either_map(tmp_path):
    """A station's map carries the SI factor (the server's side); the json export does not. The client writes
    mm and deg through both alike: 320 mm at 0.01 mm per count is 32000 counts (the map's documented scale)."""
    station = ROOT / "stations" / "ring_rig_plc"
    served = RegisterMap.from_station(station)
    exported = RegisterMap.from_json(served.to_json())
    assert served["L2"].factor == 1000.0 and exported["L2"].factor == 1.0
    for rmap in (served, exported):
        assert encode(rmap["L2"], check_value(rmap, "L2", 320.0)) == [32000]
        assert decode(rmap["L2.actual"], [32050]) == 320.5
    # and the server's side still encodes the twin's SI value to the same counts
    assert served["L2"].encode(0.320) == [32000]


def test_a_client_given_a_station_map_writes_mm_over_the_wire():
    """From the server's own map type (with its SI factors) straight into TwinClient: the setpoint read
    back over Modbus is the one written, in mm, and the finger goes there (not 1000 times further)."""
    from plc_client.testing import twin_server

    station = ROOT / "tests" / "plc" / "stations" / "ring_bench"
    rmap = RegisterMap.from_station(station)
    with twin_server(station) as server, plc_client.TwinClient.connect(server.host, server.port, map=rmap) as client:
        client.write(L2=400.25)
        assert client.get("L2") == 400.25
        client.advance(500)  # the finger opens from 330 mm to 400.25 mm (away from the ring)
        assert client.get("L2.actual") == pytest.approx(400.25, abs=0.5)
        with pytest.raises(UnknownSignalError, match="did you mean 'L2.actual'"):
            client.read("L2.actul")


ENTRY = {"name": "L2", "table": "holding_register", "address": 16, "type": "uint16", "scale": 0.01, "unit": "mm",
         "min": 0, "max": 441, "access": "rw"}


@pytest.mark.parametrize("change, message", [
    ({"table": "register"}, r"entry 1 \('L2'\): unknown table 'register'"),
    ({"type": "float64"}, r"entry 1 \('L2'\): unknown type 'float64'"),
    ({"type": "bool"}, r"entry 1 \('L2'\): a holding_register holds words, not bool"),
    ({"count": 2}, r"entry 1 \('L2'\): a uint16 takes 1 register, not count 2"),
    ({"address": 70000}, r"entry 1 \('L2'\): address 70000 is outside 0..65535"),
    ({"address": "sixteen"}, r"entry 1 \('L2'\): invalid literal"),
    ({"table": "input_register", "access": "rw"}, r"entry 1 \('L2'\): access 'rw'"),
    ({"min": 500}, r"entry 1 \('L2'\): min 500 is above max 441"),
    ({"name": "sim.step"}, r"entry 1 \('sim.step'\): the name appears twice \(entry 0 too\)"),
    ({"table": "input_register", "access": "r", "address": 1},  # sim.step is a uint32 at 0..1
     r"entry 1 \('L2'\) at input_register 1 overlaps entry 0 \('sim.step', addresses 0..1\)"),
])
def test_a_bad_entry_in_a_map_file_names_the_file_and_the_entry(tmp_path, change, message):
    path = tmp_path / "ring.json"
    first = {"name": "sim.step", "table": "input_register", "address": 0, "count": 2, "type": "uint32"}
    path.write_text(json.dumps([first, dict(ENTRY, **change)]))
    with pytest.raises(MapError, match=rf"^{str(path).replace('.', '[.]')}: {message}"):
        RegisterMap.from_json(path)


def test_a_map_file_without_entries_or_with_a_bare_entry_is_refused(tmp_path):
    with pytest.raises(MapError, match="expected a list of entries"):
        RegisterMap.from_json('{"station": "x"}')
    with pytest.raises(MapError, match=r"register map: entry 0 needs at least name, table and address"):
        RegisterMap.from_json([{"name": "L2"}])
    loaded = RegisterMap.from_json({"station": "ring_rig", "made_by": "hand", "signals": [ENTRY]})
    assert (loaded.station, dict(loaded.meta), loaded.source) == ("ring_rig", {"station": "ring_rig", "made_by": "hand"}, "")


def test_plc_prints_a_bad_map_file_as_one_line_naming_it(tmp_path):
    path = tmp_path / "ring.json"
    path.write_text(json.dumps([ENTRY, dict(ENTRY, name="L3", address=17, type="int64")]))
    r = subprocess.run([sys.executable, "-m", "plc_client", "--map", str(path), "map"], capture_output=True, text=True,
                       cwd=ROOT, timeout=60)
    assert (r.returncode, r.stdout) == (2, "")
    assert r.stderr == f"plc: error: {path}: entry 1 ('L3'): unknown type 'int64' (one of bool, uint16, int16, uint32, int32, float32)\n"


def test_plc_with_a_station_that_cannot_be_read_is_one_line_naming_its_file(tmp_path):
    (tmp_path / "station.toml").write_text('[station]\nname = "broken"\n\n[gripper]\nurdf = "missing.urdf"\n')
    r = subprocess.run([sys.executable, "-m", "plc_client", "--station", str(tmp_path), "map"], capture_output=True,
                       text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.startswith("plc: error: ") and "station.toml" in r.stderr and len(r.stderr.splitlines()) == 1
    with pytest.raises(MapError, match="station.toml"):
        RegisterMap.from_station(tmp_path)


def test_reads_are_split_at_the_protocols_limit_of_125_registers():
    """Modbus application protocol 6.3/6.4: at most 125 registers per read (2000 bits)."""
    words = [{"name": f"w{i}", "table": "input_register", "address": i} for i in range(300)]
    bits = [{"name": f"b{i}", "table": "discrete_input", "address": i} for i in range(2100)]
    rmap = RegisterMap.from_json(words + bits)
    runs = plan_reads(rmap, rmap.mapped)
    assert [(r.table, r.start, r.end) for r in runs] == [
        ("discrete_input", 0, 2000), ("discrete_input", 2000, 2100),
        ("input_register", 0, 125), ("input_register", 125, 250), ("input_register", 250, 300)]


def test_the_serve_parser_takes_the_protocol_numbers_without_importing_the_server():
    code = ("import sys, twin_app.cli_modbus as c, twin.frontends.modbus.protocol as p; "
            "print(c.TLS_PORT, c.MAX_CONNECTIONS, 'twin.frontends.modbus.server' in sys.modules, 'asyncio' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=60, check=True)
    assert out.stdout.split() == ["802", "64", "False", "False"]
