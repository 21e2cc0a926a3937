"""`plc check FILE.st --station DIR` (or `--map FILE.json`): the ST checks, then every located variable against
the station's PLC layout, the ranges a Modbus master moves. An error names the file, line and column of the
declaration, the variable and the signal at that address; exit 65."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CELL = ROOT / "stations" / "ring_rig_plc"

BAD = """PROGRAM p
  VAR
    ok_bit AT %IX100.0 : BOOL;
    setpoint AT %QW100 : INT;
    past AT %IX103.2 : BOOL;
    wide AT %ID100 : DINT;
  END_VAR
  VAR
    x : INT;
  END_VAR
  x := 1;
END_PROGRAM
"""


def plc(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "plc_client", *args], cwd=ROOT, capture_output=True, text=True)


def test_located_variables_the_master_does_not_move_or_cannot_hold_are_errors_at_their_declaration(tmp_path):
    src = tmp_path / "p.st"
    src.write_text(BAD)
    assert plc("check", str(src)).returncode == 0  # the language alone has nothing against them
    out = plc("check", str(src), "--station", str(CELL))
    assert out.returncode == 65
    lines = out.stderr.strip().splitlines()
    # the twin's map: L2 (holding register 0, 0 .. 441 mm in counts of 0.01) is 0 .. 44100 counts; the PLC layout
    # has 26 discrete inputs (%IX100.0 .. %IX103.1)
    assert re.match(rf"^{re.escape(str(src))}:4:5: error: setpoint: %QW100 is L2 .*44100.*UINT", lines[0]), lines
    assert re.match(rf"^{re.escape(str(src))}:5:5: error: past: %IX103\.2: no signal there", lines[1]), lines
    assert re.match(rf"^{re.escape(str(src))}:6:5: error: wide: %ID100: .*16-bit registers", lines[2]), lines
    assert len(lines) == 3


def test_the_shipped_gripper_plc_and_its_declarations_check_against_the_station(tmp_path):
    out = plc("check", str(CELL / "gripper.st"), str(CELL / "io.st"), "--station", str(CELL))
    assert out.returncode == 0, out.stderr
    json_map = tmp_path / "map.json"
    json_map.write_text(subprocess.run([sys.executable, "-m", "twin", "map", str(CELL), "--layout", "plc", "--format",
                                        "json"], cwd=ROOT, capture_output=True, text=True, check=True).stdout)
    out = plc("check", str(CELL / "gripper.st"), str(CELL / "io.st"), "--map", str(json_map))
    assert out.returncode == 0, out.stderr
    # the default layout's map is another: the same declarations do not fit it
    json_map.write_text(subprocess.run([sys.executable, "-m", "twin", "map", str(CELL), "--format", "json"], cwd=ROOT,
                                       capture_output=True, text=True, check=True).stdout)
    out = plc("check", str(CELL / "gripper.st"), str(CELL / "io.st"), "--map", str(json_map))
    assert out.returncode == 2 and "not laid out for a Modbus master PLC" in out.stderr and "--layout plc" in out.stderr


def gripped(event: dict) -> bool:
    """The robot program's TPWrite after its first pick is gripped (ring_rig_plc.mod), on the events stream."""
    return event.get("type") == "print" and event.get("text", "").startswith("Gripped the ring, attempt 1")


def test_the_st_gripper_plc_grips_the_ring_over_modbus_in_lockstep():
    """`plc run gripper.st io.st --port P` against `twin serve --layout plc --lockstep`: the robot's first pick
    from outside is gripped by force, as with the Python PLC (the robot says so in the server's log)."""
    sys.path.insert(0, str(ROOT / "tests" / "modbus"))
    from modbus_helpers import ServerProcess

    with ServerProcess(CELL, "--lockstep", "--layout", "plc") as server:
        assert plc("--port", str(server.port), "write", "fullAutoRun=1").returncode == 0  # the operator's switch
        out = plc("run", str(CELL / "gripper.st"), str(CELL / "io.st"), "--port", str(server.port), "--for", "3")
        assert out.returncode == 0, out.stderr
        assert server.events.wait("controller", timeout=10, where=gripped) is not None  # the robot's own words
    changes = [line for line in out.stdout.splitlines() if line.startswith("t=")]
    assert any("diGripOk=1" in line for line in changes), changes
    assert not any("diGripFault=1" in line for line in changes), changes


WIDE = """PROGRAM wide
  VAR_EXTERNAL
    L5 : UINT;
  END_VAR
  L5 := 5000;  (* 50 mm: the fine axis travels 0 .. 10 mm *)
END_PROGRAM
"""


def test_an_st_plc_whose_write_the_twin_refuses_stops_naming_the_signal_the_value_and_why(tmp_path):
    sys.path.insert(0, str(ROOT / "tests" / "modbus"))
    from modbus_helpers import ServerProcess

    bench = ROOT / "tests" / "plc" / "stations" / "ring_bench"
    (tmp_path / "wide.st").write_text(WIDE)
    (tmp_path / "io.st").write_text(subprocess.run([sys.executable, "-m", "twin", "map", str(bench), "--format", "st",
                                                    "--program", "wide"], cwd=ROOT, capture_output=True, text=True,
                                                   check=True).stdout)
    with ServerProcess(bench, "--lockstep", "--layout", "plc") as server:
        out = plc("run", str(tmp_path / "wide.st"), str(tmp_path / "io.st"), "--port", str(server.port), "--for", "1")
    assert out.returncode == 1
    assert re.search(r"L5=50 refused at scan 0 .*'L5': 50 mm is out of range: 0 to 10 mm; the PLC stopped", out.stderr)


def test_the_st_gripper_plc_behind_an_openplc_like_master_grips_in_real_time():
    """The chain a real soft-PLC uses, rebuilt here from its documented behaviour (measured-facts: OpenPLC v3):
    the generated slave device's ranges (mbconfig.cfg), polled every 10 ms with one request per table (read
    discrete inputs, write coils, read input registers, write holding registers; zeros written before the
    first scan), its words at %IX100.0 / %QX100.0 / %IW100 / %QW100 counted from each range's start, and
    gripper.st scanning on that image against `twin serve --realtime --layout plc`."""
    import time

    from pymodbus.client import ModbusTcpClient

    from structured_text.runtime import load

    sys.path.insert(0, str(ROOT / "tests" / "modbus"))
    from modbus_helpers import ServerProcess

    cfg = {k: int(v) for k, v in re.findall(r'^device0\.(\w+) = "(\d+)"$', (CELL / "mbconfig.cfg").read_text(), re.M)}
    bit = lambda area, n: f"%{area}X{100 + n // 8}.{n % 8}"  # noqa: E731
    st = load([CELL / "gripper.st", CELL / "io.st"])
    from twin.frontends.modbus.register_map import build_map

    fault_coil = build_map(CELL, "plc")["diGripFault"].address - cfg["Coils_Start"]
    with ServerProcess(CELL, "--realtime", "--layout", "plc") as server:
        assert plc("--port", str(server.port), "write", "fullAutoRun=1").returncode == 0
        master = ModbusTcpClient("127.0.0.1", port=server.port, timeout=3, retries=0)
        assert master.connect()
        try:
            # polled until the robot says it gripped (about 3 s of the cell's time): on a busy machine the real-time
            # twin falls behind the wall clock, so a fixed window of wall time would not prove anything more
            t0, polls, faults, grip = time.monotonic(), 0, 0, None
            while grip is None and time.monotonic() - t0 < 15.0:
                tick = time.monotonic()
                di = master.read_discrete_inputs(cfg["Discrete_Inputs_Start"], count=cfg["Discrete_Inputs_Size"]).bits
                for n in range(cfg["Discrete_Inputs_Size"]):
                    st.write_located(bit("I", n), di[n])
                coils = [bool(st.read_located(bit("Q", n))) for n in range(cfg["Coils_Size"])]
                assert not master.write_coils(cfg["Coils_Start"], coils).isError()
                ir = master.read_input_registers(cfg["Input_Registers_Start"], count=cfg["Input_Registers_Size"]).registers
                for n, word in enumerate(ir):
                    st.write_located(f"%IW{100 + n}", word)
                words = [int(st.read_located(f"%QW{100 + n}")) for n in range(cfg["Holding_Registers_Size"])]
                assert not master.write_registers(cfg["Holding_Registers_Start"], words).isError()
                st.scan(tick - t0)  # the PLC's own clock; the image above is the one its next poll sends
                polls += 1
                faults += bool(st.read_located(bit("Q", fault_coil)))
                if polls % 10 == 0:
                    grip = next((e for e in server.events.new() if e["event"] == "controller" and gripped(e)), None)
                time.sleep(max(0.0, 0.010 - (time.monotonic() - tick)))
        finally:
            master.close()
    assert grip is not None, "the robot never gripped the ring"
    assert polls > 100 and faults == 0
