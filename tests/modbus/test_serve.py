"""`twin serve` as a subprocess, driven by pymodbus's client: gripping by registers alone, lockstep and
real time, determinism, and the exported map against what the server serves."""
from __future__ import annotations

import json
import math
import signal
import struct
import subprocess
import sys
import time

import pytest
from pymodbus.client import ModbusTcpClient

from modbus_helpers import RING_BENCH, ROOT, SMART_GRIPPER as LIGHT_STATION, ServerProcess

UNIT = 1


@pytest.fixture(scope="module")
def ring_map() -> list[dict]:
    out = subprocess.run([sys.executable, "-m", "twin", "map", str(RING_BENCH), "--format", "json"],
                         capture_output=True, text=True, cwd=ROOT, timeout=60, check=True)
    return json.loads(out.stdout)


def addr(rmap: list[dict], name: str) -> int:
    return next(e["address"] for e in rmap if e["name"] == name)


def connect(server: ServerProcess) -> ModbusTcpClient:
    c = ModbusTcpClient("127.0.0.1", port=server.port, timeout=3, retries=0)
    assert c.connect()
    return c


def ok(response):
    assert not response.isError(), response
    return response


def advance(c: ModbusTcpClient, n: int, rmap: list[dict]) -> None:
    a = addr(rmap, "sim.advance")
    ok(c.write_register(a, n, device_id=UNIT))
    for _ in range(20000):
        if ok(c.read_holding_registers(a, count=1, device_id=UNIT)).registers == [0]:
            return
    raise AssertionError("sim.advance never came back to 0")


def set_fingers(c: ModbusTcpClient, rmap: list[dict], mm: float) -> None:
    counts = round(mm / 0.01)
    ok(c.write_registers(addr(rmap, "L2"), [counts] * 3, device_id=UNIT))  # L2, L3, L4 are contiguous


def gripped(c: ModbusTcpClient, rmap: list[dict]) -> tuple[bool, int]:
    bit = ok(c.read_discrete_inputs(addr(rmap, "doGripped"), count=1, device_id=UNIT)).bits[0]
    part = ok(c.read_input_registers(addr(rmap, "GrippedPart"), count=1, device_id=UNIT)).registers[0]
    return bit, part


def dump(c: ModbusTcpClient, rmap: list[dict]) -> tuple:
    """Every output the server publishes, raw."""
    di = [e for e in rmap if e["table"] == "discrete_input"]
    ir = [e for e in rmap if e["table"] == "input_register"]
    bits = ok(c.read_discrete_inputs(16, count=max(e["address"] for e in di) - 15, device_id=UNIT)).bits
    words = ok(c.read_input_registers(0, count=9, device_id=UNIT)).registers
    words += ok(c.read_input_registers(16, count=max(e["address"] + e["count"] for e in ir) - 16, device_id=UNIT)).registers
    return tuple(bits), tuple(words)


def grip_script(server: ServerProcess, rmap: list[dict]) -> list[tuple]:
    """The thesis's outside grip by register writes alone: fingers to 330 mm, then close 1 mm every
    204 ms (17 steps) until doGripped; then open to 340 mm. Returns what it saw after every move."""
    seen = []
    with connect(server) as c:
        set_fingers(c, rmap, 330.0)
        advance(c, 100, rmap)
        seen.append(dump(c, rmap))
        mm = 330.0
        while not gripped(c, rmap)[0] and mm > 300:
            mm -= 1.0
            set_fingers(c, rmap, mm)
            advance(c, 17, rmap)
            seen.append(dump(c, rmap))
        assert gripped(c, rmap) == (True, 1), f"no grip down to {mm} mm"  # 1 = "ring"
        set_fingers(c, rmap, 340.0)
        advance(c, 100, rmap)
        seen.append(dump(c, rmap))
        assert gripped(c, rmap) == (False, 0)
    return seen


def test_grip_the_ring_by_register_writes_alone_in_lockstep_bit_identical_run_after_run(ring_map):
    runs = []
    for sig in (signal.SIGTERM, signal.SIGINT):
        with ServerProcess(RING_BENCH, "--lockstep") as server:
            runs.append(grip_script(server, ring_map))
            server.wait_for(r"client 127\.0\.0\.1:\d+ connected \(1 connected\)")
            server.wait_for(r"client 127\.0\.0\.1:\d+ disconnected \(closed by the client; 0 connected\)")
            assert server.stop(sig) == 0
            server.wait_for(r"stopped after \d+ steps")
    assert runs[0] == runs[1]
    assert len(runs[0]) > 3


def test_grip_the_ring_in_real_time_and_the_clock_keeps_pace(ring_map):
    with ServerProcess(RING_BENCH) as server, connect(server) as c:
        a_step = addr(ring_map, "sim.step")

        def sim_step() -> int:
            hi, lo = ok(c.read_input_registers(a_step, count=2, device_id=UNIT)).registers
            return hi << 16 | lo

        s0, t0 = sim_step(), time.monotonic()
        set_fingers(c, ring_map, 319.0)
        deadline = time.monotonic() + 10
        while not gripped(c, ring_map)[0]:
            assert time.monotonic() < deadline, "no grip within 10 s"
            time.sleep(0.02)
        assert gripped(c, ring_map) == (True, 1)
        time.sleep(0.5)
        steps, wall = sim_step() - s0, time.monotonic() - t0
        assert steps * 0.012 == pytest.approx(wall, abs=0.1)
        # in real time, sim.advance reads 0 and refuses anything else (exception 03)
        r = c.write_register(addr(ring_map, "sim.advance"), 5, device_id=UNIT)
        assert r.isError() and r.exception_code == 3
        mode = ok(c.read_input_registers(addr(ring_map, "sim.mode"), count=2, device_id=UNIT)).registers
        assert mode == [1, 100]  # real time, 100 %
        assert ok(c.read_discrete_inputs(0, count=2, device_id=UNIT)).bits[:2] == [False, False]  # fault, lockstep


def test_speed_runs_the_simulation_x_times_real_time(ring_map):
    # A light station, so the machine can afford 4x real time; sim.time_ms sits in the reserved block, at the
    # same address on every station's map.
    with ServerProcess(LIGHT_STATION, "--speed", "4") as server, connect(server) as c:
        a = addr(ring_map, "sim.time_ms")

        def ms() -> int:
            hi, lo = ok(c.read_input_registers(a, count=2, device_id=UNIT)).registers
            return hi << 16 | lo

        m0, t0 = ms(), time.monotonic()
        time.sleep(1.0)
        m1, t1 = ms(), time.monotonic()
        assert (m1 - m0) / 1000 / (t1 - t0) == pytest.approx(4.0, rel=0.1)


def _expected(entry: dict, value) -> float:
    """A twin value (SI) in the map's engineering units, as counts."""
    if entry["type"] == "bool":
        return 1 if value else 0
    if isinstance(value, str):
        return entry["choices"].index(value)
    factor = {"mm": 1000.0, "deg": 180.0 / math.pi}.get(entry["unit"], 1.0)
    return value * factor / entry["scale"]


def _decode(entry: dict, words: list[int]):
    raw = struct.pack(f">{len(words)}H", *words)
    return struct.unpack({"uint16": ">H", "int16": ">h", "uint32": ">I", "int32": ">i", "float32": ">f"}[entry["type"]], raw)[0]


def map_crc_of(entries: list[dict]) -> int:
    """The CRC-32 of a JSON map, computed here from the documented canonical form (not with the server's
    code): `name,table,address,count,type,scale` per entry but sim.map_crc, by table then address."""
    import zlib

    order = ["coil", "discrete_input", "holding_register", "input_register"]
    rows = sorted((e for e in entries if e["name"] != "sim.map_crc"), key=lambda e: (order.index(e["table"]), e["address"]))
    text = "\n".join(f"{e['name']},{e['table']},{e['address']},{e['count']},{e['type']},{float(e['scale']):.10g}" for e in rows)
    return zlib.crc32(text.encode())


def test_every_entry_of_the_exported_json_map_reads_back_at_its_address_with_its_type(ring_map, lockstep_server):
    """The server's values, read entry by entry where the JSON says, against the same station stepped in
    this process with the same writes (the twin is deterministic, so they agree to the count)."""
    from twin.core import Twin

    writes = {"L2": 0.318, "L3": 0.318, "L4": 0.318, "L5": 0.005}
    steps = 120
    with connect(lockstep_server) as c:
        a0 = ok(c.read_input_registers(0, count=2, device_id=UNIT)).registers
        assert a0 == [0, 0], "this test needs a fresh lockstep server (run it first in the module)"
        for name, v in writes.items():
            ok(c.write_register(addr(ring_map, name), round(v * 1e5), device_id=UNIT))
        advance(c, steps, ring_map)
        got = {}
        for e in ring_map:
            table, a, n = e["table"], e["address"], e["count"]
            if table == "coil":
                got[e["name"]] = int(ok(c.read_coils(a, count=1, device_id=UNIT)).bits[0])
            elif table == "discrete_input":
                got[e["name"]] = int(ok(c.read_discrete_inputs(a, count=1, device_id=UNIT)).bits[0])
            elif table == "holding_register":
                got[e["name"]] = _decode(e, ok(c.read_holding_registers(a, count=n, device_id=UNIT)).registers)
            else:
                got[e["name"]] = _decode(e, ok(c.read_input_registers(a, count=n, device_id=UNIT)).registers)

    with Twin.from_station(RING_BENCH) as twin:
        for name, v in writes.items():
            twin.write(name, v)
        twin.step(steps)
        sim = {"sim.advance": 0, "sim.step": steps, "sim.time_ms": steps * 12, "sim.late_steps": 0,
               "sim.dt_us": 12000, "sim.mode": 0, "sim.speed_pct": 0, "fault": 0, "sim.lockstep": 1, "sim.late": 0,
               "sim.map_crc": map_crc_of(ring_map), "comm.lost": 0, "comm.watchdog_ms": 0}
        for e in ring_map:
            if e["name"] in sim:
                assert got[e["name"]] == sim[e["name"]], e["name"]
                continue
            want = _expected(e, twin.read(e["name"]))
            lo, hi = {"uint16": (0, 65535), "int16": (-32768, 32767)}.get(e["type"], (-2**31, 2**32))
            want = min(max(want, lo), hi)
            assert got[e["name"]] == pytest.approx(want, abs=0.5 + 1e-9), e["name"]
        assert twin.read("doGripped") and got["doGripped"] == 1 and got["GrippedPart"] == 1


def test_twin_map_prints_csv_and_markdown_for_any_station():
    from modbus_helpers import SMART_GRIPPER

    md = subprocess.run([sys.executable, "-m", "twin", "map", str(SMART_GRIPPER), "--format", "md"],
                        capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert md.returncode == 0, md.stderr
    assert "| 16 | 40017 | `jaw_left` | uint16 | mm | 0.01 | 0 .. 25 | rw |" in md.stdout
    assert "high word first" in md.stdout
    out = subprocess.run([sys.executable, "-m", "twin", "map", str(SMART_GRIPPER), "--format", "csv"],
                         capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert out.returncode == 0 and out.stdout.startswith("name,table,address,count,type,scale,unit,min,max,access")


def test_a_wrong_station_or_a_busy_port_is_one_line_on_stderr_and_exit_2(lockstep_server, tmp_path):
    r = subprocess.run([sys.executable, "-m", "twin", "serve", str(tmp_path / "nowhere")], capture_output=True,
                       text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    r = subprocess.run([sys.executable, "-m", "twin", "serve", str(RING_BENCH), "--port", str(lockstep_server.port)],
                       capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 2 and "cannot listen on" in r.stderr and "Traceback" not in r.stderr


def test_the_smart_gripper_grips_its_cube_in_real_time_by_one_register_write():
    from modbus_helpers import SMART_GRIPPER

    from twin.frontends.modbus.register_map import build_map

    rmap = build_map(SMART_GRIPPER)
    with ServerProcess(SMART_GRIPPER) as server, connect(server) as c:
        ok(c.write_register(rmap["jaw_left"].address, 0, device_id=UNIT))  # close: 0.00 mm
        deadline = time.monotonic() + 10
        while not ok(c.read_discrete_inputs(rmap["doGripped"].address, count=1, device_id=UNIT)).bits[0]:
            assert time.monotonic() < deadline, "the cube was not gripped within 10 s"
            time.sleep(0.02)
        assert ok(c.read_input_registers(rmap["GrippedPart"].address, count=1, device_id=UNIT)).registers == [1]
        jaw = ok(c.read_input_registers(rmap["jaw_left.actual"].address, count=1, device_id=UNIT)).registers[0]
        assert 850 < jaw <= 1100  # 9.3 to 11 mm (still settling): the 20 mm cube between two jaws
        assert ok(c.read_coils(rmap["Active"].address, count=1, device_id=UNIT)).bits[0]


def test_the_ring_rig_serves_its_robot_axes_in_hundredths_of_a_degree():
    from twin.frontends.modbus.register_map import build_map

    ring_rig = ROOT / "stations" / "ring_rig"
    rmap = build_map(ring_rig)
    with ServerProcess(ring_rig, "--lockstep") as server, connect(server) as c:
        advance(c, 10, [{"name": "sim.advance", "address": rmap["sim.advance"].address}])
        e = rmap["robot.j1"]
        words = ok(c.read_input_registers(e.address, count=12, device_id=UNIT)).registers
        axes = [rmap[f"robot.j{i}"].decode(words[2 * i - 2:2 * i]) for i in range(1, 7)]
        assert axes == pytest.approx([-26.565, 42.642, 26.034, 0.0, 21.323, -206.565], abs=0.05)  # home_deg: at grip_right
        assert not ok(c.read_discrete_inputs(rmap["robot.busy"].address, count=1, device_id=UNIT)).bits[0]
        assert rmap["L2.actual"].decode(ok(c.read_input_registers(rmap["L2.actual"].address, count=1,
                                                                  device_id=UNIT)).registers) == pytest.approx(350, abs=1)


def test_a_port_out_of_range_is_a_usage_error_not_a_traceback():
    r = subprocess.run([sys.executable, "-m", "twin", "serve", str(RING_BENCH), "--port", "70000"],
                       capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "a TCP port is 0..65535, not 70000" in r.stderr.splitlines()[-1]


def start_and_signal(*signals: int) -> tuple[int, str]:
    """Start `twin serve` on the ring rig, send `signals` as soon as it says it is loading the station
    (which takes ~0.3 s, pybullet, before the event loop takes the signals over); (exit code, stderr)."""
    cmd = [sys.executable, "-m", "twin", "serve", str(ROOT / "stations" / "ring_rig"), "--port", "0"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    try:
        first = proc.stderr.readline()
        assert "loading station" in first, first
        for sig in signals:
            proc.send_signal(sig)
        err = first + proc.stderr.read()
        proc.wait(30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return proc.returncode, err


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_while_the_station_is_still_loading_stops_cleanly(sig):
    code, err = start_and_signal(sig)
    assert code == 0 and "Traceback" not in err, err
    assert f"stopped by {sig.name} while starting" in err and "listening" not in err, err


def test_a_second_signal_while_loading_cuts_the_loading_short():
    code, err = start_and_signal(signal.SIGTERM, signal.SIGINT)  # pending together: the lowest number first
    assert code == 0 and "stopped by SIGINT while starting" in err and "listening" not in err, err


def test_the_ring_rig_grips_its_ring_by_register_writes_alone():
    from twin.frontends.modbus.register_map import build_map

    ring_rig = ROOT / "stations" / "ring_rig"
    rmap = build_map(ring_rig)  # the cell starts with the open gripper around the ring on the right pallet
    with ServerProcess(ring_rig, "--lockstep") as server, connect(server) as c:
        fingers = rmap["L2"]
        assert [rmap["L3"].address, rmap["L4"].address] == [fingers.address + 1, fingers.address + 2]
        ok(c.write_registers(fingers.address, [30000, 30000, 30000], device_id=UNIT))  # 300 mm, 0.01 mm counts
        advance(c, 200, [{"name": "sim.advance", "address": rmap["sim.advance"].address}])
        assert ok(c.read_discrete_inputs(rmap["doGripped"].address, count=1, device_id=UNIT)).bits[0]
        assert ok(c.read_input_registers(rmap["GrippedPart"].address, count=1, device_id=UNIT)).registers == [1]
        words = ok(c.read_input_registers(rmap["L2.actual"].address, count=1, device_id=UNIT)).registers
        assert rmap["L2.actual"].decode(words) == pytest.approx(320.0, abs=1.0)  # on the ring's 320 mm radius
