"""The client, the `plc` command and the grip sequence against a real `twin serve` on loopback."""
import json
import os
import subprocess
import sys
import time

import pytest

from plc_client import ClientIO, Phase, RegisterMap, ScanCycle, TwinClient
from plc_client.errors import ConnectionFailedError, MapError, UnknownSignalError, ValueOutOfRangeError
from plc_client.testing import free_port, twin_server
from tests.plc.conftest import BENCH, RING_FORCES, STATIONS, ring_sequence

EMPTY = BENCH.with_name("ring_bench_empty")  # the ring lies 2.4 m away: every grip misses


@pytest.fixture(scope="module")
def server():
    with twin_server(BENCH, lockstep=True) as s:
        yield s


@pytest.fixture
def client(server):
    with server.client() as c:
        yield c


def plc(server, *args, timeout=20):
    return subprocess.run([sys.executable, "-m", "plc_client", *server.plc_args(), *args], capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, "COLUMNS": "200"})


# -- the client --------------------------------------------------------------------------------------------
def test_a_batch_read_takes_one_request_per_run_of_addresses(client):
    before = client.requests
    values = client.read("L2.actual", "L3.actual", "L4.actual", *RING_FORCES)
    assert client.requests - before == 1  # input registers 17..26, L5.actual between them read through
    assert values["L2.actual"] == pytest.approx(330.0, abs=0.05)  # mm


def test_a_write_takes_effect_at_the_next_steps_in_lockstep(client):
    client.write(L2=325.0, L3=325.0)
    assert client.read("L2", "L3") == {"L2": 325.0, "L3": 325.0}  # an input reads back what was written
    assert client.get("L2.actual") == pytest.approx(330.0, abs=0.05)  # outputs: the last completed step
    client.advance(1)
    assert client.get("L2.actual") < 330.0  # the fingers started to move in the step that followed
    client.advance(100)
    assert client.get("L2.actual") == pytest.approx(325.0, abs=0.1)
    client.write(L2=330.0, L3=330.0)
    client.advance(100)


def test_the_client_refuses_bad_names_and_values_before_the_wire(client):
    before = client.requests
    with pytest.raises(UnknownSignalError, match="did you mean 'L2.force'"):
        client.read("L2.forc")
    with pytest.raises(ValueOutOfRangeError, match="0 to 441 mm"):
        client.write(L2=500.0)
    assert client.requests == before


def test_no_server_is_a_connection_error():
    with pytest.raises(ConnectionFailedError, match=r"127.0.0.1:\d+"):
        TwinClient.connect("127.0.0.1", free_port(), map=[{"name": "x", "table": "coil", "address": 0}], timeout=0.5)


# -- the plc command -----------------------------------------------------------------------------------------
def test_plc_read_prints_name_value_unit(server):
    r = plc(server, "read", "L4", "L2.force", "doGripped", "GrippedPart")
    assert r.returncode == 0, r.stderr
    rows = [line.split() for line in r.stdout.splitlines()]
    assert rows[0] == ["L4", "330", "mm"] and rows[1][0] == "L2.force" and rows[1][2] == "N"
    assert rows[2] == ["doGripped", "0"] and rows[3] == ["GrippedPart", "0", "(none)"]  # index, then its text


def test_plc_write_sets_signals_in_engineering_units(server, client):
    r = plc(server, "write", "L4=327.5", "Active=1")
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["L4", "327.5", "mm", "Active", "1"]
    client.advance(1)
    assert client.read("L4", "Active") == {"L4": 327.5, "Active": True}
    client.write(L4=330.0)
    client.advance(1)


def test_plc_watch_prints_one_line_per_sample_when_not_a_terminal(server):
    r = plc(server, "watch", "L2.actual", "sim.step", "--interval", "0.05", "--count", "3")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].split() == ["t_s", "L2.actual[mm]", "sim.step[steps]"] and len(lines) == 4
    assert all(len(line.split()) == 3 for line in lines[1:])


def test_plc_map_lists_the_names_with_table_address_unit_and_range(server):
    r = plc(server, "map")
    assert r.returncode == 0, r.stderr
    rows = {line.split()[0]: line.split() for line in r.stdout.splitlines()[2:]}
    assert rows["L2"] == ["L2", "holding_register", "16", "uint16", "mm", "0..441", "rw"]
    assert rows["L2.force"][1:] == ["input_register", "29-30", "uint32", "N", "0..", "r"]


def test_plc_run_scans_user_logic_against_the_server_in_lockstep(server, client, tmp_path):
    (tmp_path / "logic.py").write_text(
        "from plc_client import plc_logic\n\n\n"
        "@plc_logic(inputs=['L4.actual'])\n"
        "def to_328(inputs, state):\n"
        "    return {'L4': 328.0, 'Active': inputs['L4.actual'] > 328.5}\n")
    step = client.get("sim.step")
    r = plc(server, "run", f"{tmp_path / 'logic.py'}:to_328", "--scans", "120")  # 1.2 s of PLC time
    assert r.returncode == 0, r.stderr
    assert "lockstep" in r.stderr and "Active=0" in r.stdout  # the bool outputs' changes are logged
    assert client.get("sim.step") - step == 100  # 120 scans of 10 ms = 100 steps of 12 ms
    assert client.get("L4.actual") == pytest.approx(328.0, abs=0.1)
    client.write(L4=330.0, Active=True)
    client.advance(100)


def test_plc_unknown_name_is_exit_2_with_a_suggestion(server):
    r = plc(server, "read", "L2.actul")
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.strip() == "plc: error: unknown signal 'L2.actul'; did you mean 'L2.actual'?"


def test_plc_out_of_range_is_exit_2_naming_the_range(server, client):
    r = plc(server, "write", "L3=300", "L2=450")
    assert r.returncode == 2
    assert r.stderr.strip() == "plc: error: signal 'L2': 450 mm is out of range: 0 to 441 mm"
    client.advance(1)
    assert client.get("L3") == 330.0  # all or nothing: L3 was not written either


def test_plc_writing_an_output_is_exit_2(server):
    r = plc(server, "write", "doGripped=1")
    assert r.returncode == 2 and "output" in r.stderr and "Traceback" not in r.stderr


def test_plc_without_a_server_is_exit_1(server):
    r = subprocess.run([sys.executable, "-m", "plc_client", "--port", str(free_port()), "--map", str(server.map_file),
                        "--timeout", "0.5", "read", "L2"], capture_output=True, text=True, timeout=20)
    assert r.returncode == 1 and r.stderr.startswith("plc: error: cannot reach a twin server at 127.0.0.1:")
    assert len(r.stderr.strip().splitlines()) == 1


# -- the grip sequence over the network -------------------------------------------------------------------------
def grip_over_the_network(station):
    """The robot's side played here: grip request, then the PLC scans (lockstep) until gripped or fault."""
    seq = ring_sequence()
    with twin_server(station, lockstep=True) as srv, srv.client() as c:
        io = ClientIO(c, local=seq.handshake_signals())
        plc_ = ScanCycle(io, seq)
        io.set("grip_request", True)
        image = plc_.run_until(lambda i, s: s.phase in (Phase.HELD, Phase.FAULT_MISSED), timeout=10.0)
        plc_.run(seconds=0.2)
        return plc_, dict(image), c.read("doGripped", "GrippedPart", "L2.actual", "L3.actual", "L4.actual", "sim.step")


def test_a_grip_and_release_across_the_network_frees_the_ring():
    seq = ring_sequence()
    with twin_server(BENCH, lockstep=True) as srv, srv.client() as c:
        io = srv.io(c, local=seq.handshake_signals())
        plc_ = ScanCycle(io, seq)
        io.set("grip_request", True)
        plc_.run_until(lambda i, s: s.phase is Phase.HELD, timeout=10.0)
        assert c.get("doGripped") and io.get("gripped")
        io.set("grip_request", False)
        io.set("release_request", True)
        image = plc_.run_until(lambda i, s: s.phase in (Phase.IDLE, Phase.FAULT_STUCK), timeout=10.0)
        assert plc_.state.phase is Phase.IDLE and not io.get("gripped") and not c.get("doGripped")
        assert not any(image[n] for n in ("L2.contact", "L3.contact", "L5.contact"))
        assert image["L2.actual"] >= 329.5  # back where the next outside grip starts


def test_a_grip_across_the_network_in_lockstep_is_the_same_on_every_run():
    first, image, twin = grip_over_the_network(BENCH)
    assert first.state.phase is Phase.HELD and twin["doGripped"] and twin["GrippedPart"] == "ring"
    assert all(image[f] >= 200.0 for f in RING_FORCES)
    again, image2, twin2 = grip_over_the_network(BENCH)
    assert (again.scans, image2, twin2) == (first.scans, image, twin)


def test_a_missed_grip_across_the_network_raises_the_fault_at_end_of_travel():
    plc_, image, twin = grip_over_the_network(EMPTY)
    assert plc_.state.phase is Phase.FAULT_MISSED and plc_.io.local["grip_fault"] and not plc_.io.local["gripped"]
    assert not twin["doGripped"]
    assert [twin[f"{a}.actual"] for a in ("L2", "L3", "L4")] == pytest.approx([290.0] * 3, abs=0.5)


# -- sim.advance last, so a lockstep write-and-step is the same on every run -------------------------------------
def test_plc_write_sends_sim_advance_after_the_other_writes(server, client):
    step = client.get("sim.step")
    r = plc(server, "write", "L4=325", "sim.advance=1")
    assert r.returncode == 0, r.stderr
    for _ in range(2000):
        if client.get("sim.advance") == 0:
            break
    assert client.get("sim.step") == step + 1
    assert client.get("L4.actual") < 330.0  # the one step ran with L4 already at 325
    client.write(L4=330.0, **{"sim.advance": 100})
    client.advance(1)


def write_map(tmp_path, entries):
    path = tmp_path / "map.json"
    path.write_text(json.dumps(entries))
    return path


@pytest.mark.parametrize("assignment, message", [
    ("goMisses=3.5", "plc: error: signal 'goMisses': needs a whole number, not 3.5"),
    ("goMisses=3000000000", "plc: error: signal 'goMisses': 3000000000 is out of range: -2147483648 to 2147483647"),
    ("aoFingerReady=1e39", "plc: error: signal 'aoFingerReady': 1e+39 mm is out of range: "
                           "-3.402823466e+38 to 3.402823466e+38 mm"),
    ("aoFingerReady=inf", "plc: error: signal 'aoFingerReady': needs a finite number, not inf"),
])
def test_plc_write_refuses_values_outside_the_type_before_anything_is_sent(tmp_path, assignment, message):
    path = write_map(tmp_path, [
        {"name": "goMisses", "table": "holding_register", "address": 16, "count": 2, "type": "int32", "access": "rw"},
        {"name": "aoFingerReady", "table": "holding_register", "address": 18, "count": 2, "type": "float32",
         "unit": "mm", "access": "rw"}])
    # no server at that port: a request would be exit 1, "cannot reach"
    r = subprocess.run([sys.executable, "-m", "plc_client", "--map", str(path), "--port", str(free_port()),
                        "write", assignment], capture_output=True, text=True, timeout=20)
    assert (r.returncode, r.stdout, r.stderr.strip()) == (2, "", message)


# -- the register map must be the one the server serves ------------------------------------------------------------
def test_a_client_with_another_stations_map_is_refused_at_connect(server):
    other = RegisterMap.from_station(STATIONS / "smart_gripper")
    with pytest.raises(MapError, match=rf"the server at 127.0.0.1:{server.port} serves another register map "
                                       r"\(another station\?\) than the one given \(station 'smart_gripper'\): "
                                       r"its sim.map_crc is 0x[0-9a-f]{8}, the given map's 0x[0-9a-f]{8}"):
        TwinClient.connect("127.0.0.1", server.port, map=other)
    # a map from before sim.map_crc cannot be checked: it is taken as it is
    old = RegisterMap.from_json([e for e in server.map.as_list() if e["name"] != "sim.map_crc"])
    with TwinClient.connect("127.0.0.1", server.port, map=old) as c:
        assert c.get("L2") == 330.0


def test_plc_with_another_stations_map_is_exit_2(server):
    r = subprocess.run([sys.executable, "-m", "plc_client", "--station", str(STATIONS / "smart_gripper"),
                        "--port", str(server.port), "read", "sim.step"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.startswith(f"plc: error: the server at 127.0.0.1:{server.port} serves another register map")
    assert len(r.stderr.splitlines()) == 1  # and no pybullet banner


def test_plc_with_a_station_that_does_not_exist_is_one_line(tmp_path):
    r = subprocess.run([sys.executable, "-m", "plc_client", "--station", str(tmp_path / "nowhere"), "read", "L2"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert r.stderr.splitlines() == [f"plc: error: {tmp_path / 'nowhere'}: no such station file"]


# -- plc run -------------------------------------------------------------------------------------------------------
def test_plc_run_of_a_logic_for_another_station_names_it_and_every_missing_signal(server):
    r = plc(server, "run", "stations.ring_rig_plc.plc_logic:cell_sequence", "--scans", "1")
    assert r.returncode == 2 and len(r.stderr.splitlines()) == 1, r.stderr
    assert r.stderr.startswith("plc: error: the logic stations.ring_rig_plc.plc_logic:cell_sequence reads doGripRequest, "
                               "doReleaseRequest, doGripInside, doPrepare, aoFingerReady and writes diGripOk, "
                               "diGripFault, diGripDone, which the register map (/tmp/twin-map-")
    assert r.stderr.rstrip().endswith("does not have (is it the logic for this station?)")


def test_plc_run_stops_with_one_line_naming_an_output_the_server_refuses(server, client, tmp_path):
    (tmp_path / "wild.py").write_text(
        "from plc_client import plc_logic\n\n\n"
        "@plc_logic(inputs=['L4.actual'])\n"
        "def wild(inputs, state):\n"
        "    return {'Active': True, 'L4': 500.0 if inputs.scan >= 3 else 330.0}\n")
    r = plc(server, "run", f"{tmp_path / 'wild.py'}:wild", "--scans", "10", "--quiet")
    assert r.returncode == 1, r.stderr
    errors = [line for line in r.stderr.splitlines() if "error" in line]
    assert errors == ["plc: error: the PLC logic's output L4=500 refused at scan 3 (t=0.030 s): signal 'L4': "
                      "500 mm is out of range: 0 to 441 mm; the PLC stopped"]
    assert client.get("L4") == 330.0


def test_plc_run_in_real_time_keeps_the_pace_given_by_speed(server, tmp_path):
    (tmp_path / "idle.py").write_text("from plc_client import plc_logic\n\n\n"
                                      "@plc_logic(inputs=['L4.actual'])\n"
                                      "def idle(inputs, state):\n"
                                      "    return {}\n")
    start = time.monotonic()
    r = plc(server, "run", f"{tmp_path / 'idle.py'}:idle", "--realtime", "--speed", "8", "--seconds", "8")
    took = time.monotonic() - start
    assert r.returncode == 0, r.stderr
    assert "real time x8" in r.stderr
    assert took < 6.0  # 8 s of PLC time at 8x: 1 s of wall clock (plus the start), not 8
    r = plc(server, "run", f"{tmp_path / 'idle.py'}:idle", "--speed", "0", "--scans", "1")
    assert r.returncode == 2 and r.stderr.splitlines() == [
        "plc run: error: argument --speed: must be greater than 0, not 0 (`plc run --help` tells more)"]
