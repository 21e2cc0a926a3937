"""The whole cell across real sockets: `twin serve stations/ring_rig_plc` (physics and the RAPID robot
controller) in a subprocess, the gripper PLC scanning over Modbus/TCP, and the demo as the operator.

Finger setpoints travel RAPID -> twin -> Modbus/TCP -> PLC -> twin: the robot asks, the PLC drives L2..L4.
"""
from __future__ import annotations

import re
import subprocess
import sys

import pytest

from stations.ring_rig_plc.demo import CellDemo
from tests.conftest import ROOT
from tests.view.demo_report import check_demo_report

CELL = ROOT / "stations" / "ring_rig_plc"


def run_cell(**kw):
    lines: list[str] = []
    summary = CellDemo(CELL, out=lines.append, **kw).run()
    return summary, lines


def narration(lines: list[str]) -> list[str]:
    """The stamped lines in simulated-time order, without what depends on the machine (wall time, port, pid).
    (The robot's lines carry the time the server stamped; they reach the demo through the server's log,
    written by a thread, so one may be printed a scan later than a PLC line of a later step.)"""
    stamped = [re.sub(r"[\d.]+ s wall", "W s wall", line) for line in lines if line.startswith("[t=")]
    return sorted(stamped, key=lambda line: (float(line[3:line.index(" s]")]), line))


@pytest.fixture(scope="module")
def one_cycle():
    return run_cell(cycles=1)


def test_the_full_cycle_moves_the_ring_across_and_back_with_every_grip_confirmed_by_force(one_cycle):
    s, lines = one_cycle
    assert s.cycles_done == 1 and s.grips == 2 and s.misses == 0 and not s.stopped
    assert s.ring_error_mm is not None and s.ring_error_mm < 2.0  # back on the right pallet, where it started
    text = "\n".join(lines)
    # each grip was the PLC's: confirmed once every finger force passed the threshold, then reported
    # to the robot, which only then went on
    confirmed = [line for line in lines if "grip confirmed" in line]
    assert [("outside" in c, "inside" in c) for c in confirmed] == [(True, False), (False, True)]
    for c in confirmed:
        forces = [float(f) for f in re.search(r"forces ([\d / ]+) N", c).group(1).split(" / ")]
        assert len(forces) == 3 and min(forces) >= 200.0
    assert text.index("grip confirmed from outside") < text.index("robot: Gripped the ring, attempt 1")
    # the fingers went where the robot asked (aoFingerReady): 330 mm around the ring, 150 mm into its bore
    assert re.search(r"fingers ready at 3[23]\d\.\d / 3[23]\d\.\d / 3[23]\d\.\d mm", text)
    assert re.search(r"fingers ready at 1[45]\d\.\d / 1[45]\d\.\d / 1[45]\d\.\d mm", text)
    # outside the ring's 320 mm radius, inside its 240 mm bore (fingers' outer faces at setpoint + 40)
    assert re.search(r"grip confirmed from outside: fingers at 3(19|20)\.\d", text)
    assert re.search(r"grip confirmed from inside: fingers at (199|200)\.\d", text)
    assert "summary:" in text and "2 confirmed by force, 0 missed" in text
    # the inside grip opens into the bore, the outside one closes on the ring
    assert "grip from inside: opening into the bore" in text and "grip from outside: closing on the ring" in text
    assert "grip from inside: closing" not in text
    assert s.exit_status == 0 and "injected fault" not in text


def test_the_cycle_in_lockstep_is_the_same_on_every_run(one_cycle):
    s1, lines1 = one_cycle
    s2, lines2 = run_cell(cycles=1)
    # the robot's last line comes through the server's log thread: the demo waits for it, on every run
    assert "robot: Cycle done: 1" in "\n".join(narration(lines1)) and "robot: Cycle done: 1" in "\n".join(narration(lines2))
    assert narration(lines1) == narration(lines2)
    assert (s1.ring_end, s1.cycle_sim, s1.sim_time) == (s2.ring_end, s2.cycle_sim, s2.sim_time)


def test_a_missed_grip_raises_the_fault_and_the_robot_does_not_carry_on():
    s, lines = run_cell(cycles=1, remove_ring_at=1)  # the ring is taken away before the first pick
    text = "\n".join(lines)
    assert s.misses == 2 and s.grips == 0  # the first attempt and the retry
    assert text.count("MISSED GRIP from outside: end of travel at 29") == 2  # fingers at end of travel
    assert "robot: Missed grip, attempt 1" in text and "robot: Missed grip, attempt 2" in text
    assert s.stopped and s.cycles_done == 0 and "robot: Cycle stopped: no ring to pick" in text
    # it never went on to place a ring it does not hold: no release was ever asked for
    assert "release" not in text
    assert s.ring_end is None and not s.ok
    # the verdict on the injected fault is explicit, and it is a success: detected, and the robot stopped
    assert lines[-1] == ("  injected fault  ring taken away at the start of cycle 1: the missed grip was detected "
                         "(2 misses), the robot stopped the cycle")
    assert "  cycle time      no cycle completed" in lines
    assert s.fault_detected and s.exit_status == 0


def test_the_demo_command_prints_its_steps_and_a_summary(tmp_path):
    out = subprocess.run([sys.executable, "-m", "plc_client", "demo", "--cycles", "1", "--report", str(tmp_path / "report")],
                         cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = out.stdout.splitlines()
    assert any("robot: Cycle 1" in line for line in lines)
    summary = "\n".join(lines[lines.index("summary:"):])
    assert re.search(r"cycles\s+1 of 1 completed", summary)
    assert re.search(r"grips\s+2 confirmed by force, 0 missed", summary)
    assert re.search(r"cycle time\s+\d+\.\d+ s simulated, \d+\.\d+ s wall", summary)
    m = re.search(r"ring\s+(\d+\.\d) mm from its start", summary)
    assert m and float(m.group(1)) < 2.0
    check_demo_report(out.stdout, tmp_path / "report")  # the report the demo ends with (tests/view)


def test_the_gripper_plc_in_structured_text_runs_the_same_cycle(one_cycle):
    """`plc demo` (--plc st, the default): gripper.st over Modbus against `twin serve --layout plc`, its located
    variables bound through the map's device ranges. The same cycle as the Python PLC's, line for line."""
    s, lines = run_cell(cycles=1, plc="st")
    assert s.cycles_done == 1 and s.grips == 2 and s.misses == 0 and not s.stopped
    assert s.ring_error_mm is not None and s.ring_error_mm < 2.0
    assert any("the gripper PLC is gripper.st + io.st (Structured Text" in line for line in lines)
    assert narration(lines) == narration(one_cycle[1])
    assert (s.ring_end, s.cycle_sim) == (one_cycle[0].ring_end, one_cycle[0].cycle_sim)
