"""`plc demo` without running a cell: its arguments, its narration and its verdicts (fast, no server)."""
from __future__ import annotations

import subprocess
import sys
from types import SimpleNamespace

import pytest

from stations.ring_rig_plc.demo import CellDemo, Summary, injected_fault_text
from plc_client.grip_sequence import Fault, Phase
from tests.conftest import ROOT


def demo(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "plc_client", "demo", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=timeout)


@pytest.mark.parametrize("args, message", [
    (["--cycles", "0"], "plc demo: error: argument --cycles: must be at least 1, not 0"),
    (["--realtime", "--speed", "0"], "plc demo: error: argument --speed: must be greater than 0, not 0"),
    (["--scan", "0"], "plc demo: error: argument --scan: must be greater than 0, not 0"),
    (["--remove-ring", "0"], "plc demo: error: argument --remove-ring: must be at least 1, not 0"),
    (["--cycles", "2", "--remove-ring", "3"],
     "plc: error: --remove-ring 3 is after the last cycle (--cycles 2): the ring would never be taken away"),
    (["--station", "/nonexistent"], "plc: error: /nonexistent: no such station file"),
    (["--station", "stations/smart_gripper"],
     f"plc: error: {ROOT / 'stations' / 'smart_gripper' / 'station.toml'}: station 'smart_gripper' has no plc demo: "
     "its station file names none under [plugins] plc_demo (shipped stations with one: ring_rig_plc)"),
])
def test_bad_demo_arguments_are_one_line_and_exit_2(args, message):
    r = demo(*args)
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.splitlines()) == 1 and r.stderr.startswith(message), r.stderr


def test_the_demo_help_says_what_the_exit_status_means():
    r = demo("--help")
    assert r.returncode == 0
    text = " ".join(r.stdout.split())
    assert "exit status: 0 every cycle was done and the ring is back within 5 mm of where it started; " \
           "with --remove-ring: the injected miss was detected and the robot stopped the cycle; " \
           "with --faults: as without, or the PLC reported a fault and the robot stopped the cycle 1 otherwise" in text


def test_importing_the_demo_does_not_import_the_pytest_plugin():
    code = "import sys, stations.ring_rig_plc.demo, plc_client.cli; print('plc_client.testing' in sys.modules)"
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.stdout.strip() == "False", r.stderr


def narrated(phase, mode, before=Phase.IDLE, **state):
    lines = []
    d = CellDemo(out=lines.append)
    st = SimpleNamespace(phase=phase, mode=mode, goal=None, forces_at_grip={}, **state)
    image = {"L2.actual": 200.0, "L3.actual": 200.0, "L4.actual": 200.0, "doGripInside": mode == "inside"}
    d._narrate_grip(before, st, image, Summary(1))
    return lines


def test_an_inside_grip_is_narrated_as_opening_into_the_bore():
    assert narrated(Phase.GRIPPING, "inside") == [
        "[t=   0.000 s] plc: grip from inside: opening into the bore at 20 mm/s until every finger reaches 200 N"]
    assert narrated(Phase.GRIPPING, "outside") == [
        "[t=   0.000 s] plc: grip from outside: closing on the ring at 20 mm/s until every finger reaches 200 N"]
    assert narrated(Phase.RELEASING, "inside") == ["[t=   0.000 s] plc: release: closing out of the bore until the ring is free"]
    assert narrated(Phase.RELEASING, "outside") == ["[t=   0.000 s] plc: release: opening until the ring is free"]


def test_a_refused_prepare_request_is_narrated():
    lines = []
    CellDemo(out=lines.append)._narrate_refusal(SimpleNamespace(refused=500.0, fault=Fault.BAD_REQUEST))
    assert lines == ["[t=   0.000 s] plc: REFUSED the finger preparation to 500 mm, outside the axes' travel "
                     "0..441 mm: nothing moves; fault to the robot"]


@pytest.mark.parametrize("removed, misses, stopped, text, status", [
    (True, 2, True, "ring taken away at the start of cycle 2: the missed grip was detected (2 misses), "
                    "the robot stopped the cycle", 0),
    (True, 1, False, "ring taken away at the start of cycle 2: the missed grip was detected (1 miss), "
                     "but the robot did NOT stop the cycle", 1),
    (True, 0, False, "ring taken away at the start of cycle 2: the missed grip was NOT detected, "
                     "and the robot did not stop the cycle", 1),
    (True, 0, True, "ring taken away at the start of cycle 2: the missed grip was NOT detected, "
                    "though the robot stopped the cycle", 1),
    (False, 0, True, "ring to be taken away at the start of cycle 2: NOT injected, cycle 2 never started", 1),
])
def test_the_injected_fault_always_gets_an_explicit_verdict(removed, misses, stopped, text, status):
    s = Summary(3, misses=misses, stopped=stopped, remove_ring_at=2, ring_removed=removed,
                misses_after_removal=misses)
    assert injected_fault_text(s) == text and s.exit_status == status


def test_a_summary_without_a_completed_cycle_says_so():
    lines = []
    d = CellDemo(out=lines.append, remove_ring_at=1)
    s = Summary(1, misses=2, stopped=True, remove_ring_at=1, ring_removed=True, misses_after_removal=2,
                sim_time=10.0, wall_time=2.0)
    d._print_summary(s, (1.6, -0.8, 0.18), SimpleNamespace(scans=1000))
    assert "  cycle time      no cycle completed" in lines
    assert lines[-1] == ("  injected fault  ring taken away at the start of cycle 1: the missed grip was detected "
                         "(2 misses), the robot stopped the cycle")
