"""The pytest fixtures of plc_client.testing, used the way docs/commissioning-checks.md shows."""

import pytest

from plc_client import ScanCycle, plc_logic
from tests.plc.conftest import BENCH

pytest_plugins = ["plc_client.testing"]


@pytest.fixture
def plc_station():
    return BENCH


def test_a_check_in_a_few_lines(twin_client):
    twin_client.write(L2=320.5)
    twin_client.advance(round(1.0 / 0.012))  # 1 s of simulated time
    assert twin_client.get("L2.actual") == pytest.approx(320.5, abs=0.5)  # touching the ring: no force yet


@plc_logic(inputs=["L2.force", "L2.actual"])
def press(inputs, state):  # close L2 until it presses with 200 N, then hold
    if inputs["L2.force"] >= 200.0:
        state.done = True
    return {} if getattr(state, "done", False) else {"L2": max(inputs["L2.actual"] - 1.0, 0.0)}


def test_user_logic_on_the_scan_cycle_against_the_server(plc_server, twin_client):
    y0 = twin_client.get("ring.y")
    plc = ScanCycle(plc_server.io(twin_client), press, cycle=0.010)
    plc.run_until(lambda inputs, state: getattr(state, "done", False), timeout=10.0)  # L2 pressed with 200 N ...
    twin_client.advance(round(0.5 / 0.012))
    # ... alone, on a 66 kg ring whose pallet holds it with 0.2 x 647 N = 130 N of friction: it pushed the ring
    assert abs(twin_client.get("ring.y") - y0) > 0.5


@pytest.mark.parametrize("plc_station", [BENCH.with_name("ring_bench_empty")])  # the ring lies far away
def test_the_documented_missed_grip_check(plc_server, twin_client):
    from plc_client import Phase
    from stations.ring_rig_plc import plc_logic as ring_rig

    seq = ring_rig.sequence()
    io = plc_server.io(twin_client, local=seq.handshake_signals())
    plc = ScanCycle(io, seq)
    io.set("grip_request", True)  # the robot asks for an outside grip
    plc.run_until(lambda i, s: s.phase in (Phase.HELD, Phase.FAULT_MISSED), timeout=10.0)
    assert io.get("grip_fault") and not io.get("gripped")
    assert twin_client.get("L2.actual") == pytest.approx(290.0, abs=0.5)  # stopped at the end of travel


@pytest.mark.parametrize("plc_station", [BENCH.parents[3] / "stations" / "ring_rig_plc"])
def test_the_documented_full_cycle_check(plc_server, twin_client):
    from plc_client import Combined
    from stations.ring_rig_plc import plc_logic as ring_rig
    from stations.ring_rig_plc.demo import operator

    plc = ScanCycle(plc_server.io(twin_client), Combined(ring_rig.cell_sequence(), operator(cycles=1)))
    plc.run_until(lambda inputs, state: twin_client.get("goCyclesDone") == 1, timeout=60.0)
    assert twin_client.read("ring.x", "ring.y") == pytest.approx({"ring.x": 1600.0, "ring.y": -800.0}, abs=2.0)


@pytest.mark.parametrize("plc_station", [BENCH])
def test_a_part_taken_away_by_its_coil_makes_the_grip_miss(plc_server, twin_client):
    from plc_client import Phase
    from stations.ring_rig_plc import plc_logic as ring_rig

    seq = ring_rig.sequence()
    io = plc_server.io(twin_client, local=seq.handshake_signals())
    twin_client.write({"ring.present": False})  # the part is not there
    plc = ScanCycle(io, seq)
    io.set("grip_request", True)
    plc.run_until(lambda i, s: s.phase in (Phase.HELD, Phase.FAULT_MISSED), timeout=10.0)
    assert plc.state.phase is Phase.FAULT_MISSED and io.get("grip_fault")
    twin_client.write({"ring.present": True})  # and back where the station put it
    twin_client.advance(2)
    assert twin_client.read("ring.x", "ring.y", "ring.z") == pytest.approx(
        {"ring.x": 1600.0, "ring.y": -800.0, "ring.z": 180.0}, abs=0.5)


PRESS_ST = """PROGRAM press
  VAR_EXTERNAL
    L2 : UINT;
    L2_actual : UINT;
    L2_force_HI : INT;
    L2_force_LO : UINT;
  END_VAR
  VAR
    force : DINT;
    done : BOOL;
  END_VAR
  force := INT_TO_DINT(L2_force_HI) * 65536 + UINT_TO_DINT(L2_force_LO);  (* counts of 0.01 N *)
  IF force >= 20000 THEN
    done := TRUE;
  END_IF;
  IF NOT done THEN
    L2 := L2_actual - 100;  (* 1 mm inside where it is *)
  END_IF;
END_PROGRAM
"""


def test_an_st_plc_in_lockstep_against_the_station(st_plc, tmp_path):
    """The same check as the Python logic above, written in ST with the station's generated declarations."""
    src = tmp_path / "press.st"
    src.write_text(PRESS_ST)
    run = st_plc(src, program="press")
    run.cycle.run_until(lambda inputs, plc: run.get("done"), timeout=10.0)
    assert run.client.get("L2.force") >= 200.0  # the twin's measured force
    assert run.get("force") >= 20000  # and the PLC's, assembled from its two located words
