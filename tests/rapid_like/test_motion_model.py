"""The robot moves as its controller would: zones that blend, speed and acceleration limits, offline timing.

Every check is against geometry, the arm's published limits or the RAPID manual, measured on the TCP of the
physics arm stepped by the cell (not read from the planner): the z50 square's corners are cut inside the zone
without the TCP stopping; fine points are passed within 0.5 mm at rest; a MoveAbsJ lasts at least what its
slowest axis needs at its URDF speed limit and within 20 % of a trapezoid at the axis's limits; VelSet halves
the TCP's speed and AccSet its acceleration; an offline run with the station times every event as the cell.
"""
from __future__ import annotations

import io
import json
import math
import tomllib
import xml.etree.ElementTree as ET
from contextlib import redirect_stderr, redirect_stdout

import numpy as np
import pytest

from rapid_like.cli import main as rapid
from tests.station_copies import STATIONS, edited_station
from twin_app.cell import open_cell

RIG = STATIONS / "ring_rig"
TOOL = "PERS tooldata tG := [TRUE,[[0,0,350],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];"
P0 = "CONST robtarget p0 := [[1500,-300,900],[0,1,0,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];"
CORNERS = [(1.9, -0.3, 0.9), (1.9, 0.3, 0.9), (1.5, 0.3, 0.9), (1.5, -0.3, 0.9)]  # m, the square's corners


def square(zone: str, speed: str = "v500", before: str = "") -> str:
    """Start at p0 (fine), then the square's four sides with `zone` at the first three corners."""
    return f"""MODULE Square
  {TOOL}
  {P0}
  PROC main()
    MoveJ p0, v1000, fine, tG;
    {before}
    MoveL Offs(p0,400,0,0), {speed}, {zone}, tG;
    MoveL Offs(p0,400,600,0), {speed}, {zone}, tG;
    MoveL Offs(p0,0,600,0), {speed}, {zone}, tG;
    MoveL p0, {speed}, fine, tG;
  ENDPROC
ENDMODULE
"""


def station_with(tmp_path, program: str):
    folder = edited_station(RIG, tmp_path / "rig", 'program = "ring_rig.mod"', 'program = "test.mod"')
    (folder / "test.mod").write_text(program)
    return folder


def run_in_cell(tmp_path, program: str, limit_s: float = 20.0):
    """Run `program` in the rig's physics cell: its events, and the TCP (time, position) after every step."""
    events, path = [], []
    with open_cell(station_with(tmp_path, program), on_event=events.append, entry="main") as cell:
        end = cell.step_count + round(limit_s / cell.dt)
        while cell.controller.state != "completed":
            assert cell.step_count < end and cell.controller.state != "error", events[-1:]
            cell.step()
            path.append((cell.time, cell.twin.tcp_pose().position.copy()))
    return events, np.array([t for t, _ in path]), np.array([p for _, p in path])


def speeds(t: np.ndarray, p: np.ndarray) -> np.ndarray:
    """TCP speed between consecutive samples (m/s), at the later sample."""
    return np.concatenate([[0.0], np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)])


def from_line(p: np.ndarray, a, b) -> float:
    a, b = np.array(a), np.array(b)
    u = b - a
    s = float(np.clip((p - a) @ u / (u @ u), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + s * u)))


def test_a_square_with_z50_cuts_each_corner_inside_the_zone_without_stopping(tmp_path):
    events, t, p = run_in_cell(tmp_path, square("z50"))
    first = next(e["t"] for e in events if e["type"] == "move" and e["instr"] == "MoveL")
    t, p = t[t >= first], p[t >= first]  # from p0 on (reached by the MoveJ, a fine point)
    v = speeds(t, p)
    v[0] = v[1]
    start = p[0]
    lines = [(CORNERS[3], CORNERS[0]), (CORNERS[0], CORNERS[1]), (CORNERS[1], CORNERS[2]), (CORNERS[2], CORNERS[3])]
    assert np.linalg.norm(start - CORNERS[3]) < 0.0005
    radius = 0.050
    for corner in CORNERS[:3]:
        d = np.linalg.norm(p - corner, axis=1)
        near = d < radius + 0.01
        # the TCP does not stop in the corner: over 40 % of the programmed 500 mm/s all through it
        assert v[near].min() > 0.2, f"the TCP slows to {v[near].min():.3f} m/s at {corner}"
        # it leaves the programmed lines only inside the zone (1 mm: the arm's tracking of the plan)
        off = [i for i in range(len(p)) if min(from_line(p[i], *ln) for ln in lines) > 0.001]
        assert off, "the path never leaves the programmed lines: the corners are not cut"
        for i in off:
            assert min(np.linalg.norm(p[i] - c) for c in CORNERS[:3]) <= radius + 0.001
        # and cuts the corner by a plausible amount: never through the point, never beyond the chord between
        # where the zone meets the two sides (at 50 mm from the corner: r / sqrt(2) from it)
        assert 0.002 < d.min() < radius / math.sqrt(2)
    assert np.linalg.norm(p[-1] - CORNERS[3]) < 0.0005  # the last point is fine: it ends there


def test_the_same_square_with_fine_stops_within_half_a_millimetre_of_each_corner(tmp_path):
    _, t, p = run_in_cell(tmp_path, square("fine"))
    v = speeds(t, p)
    for corner in CORNERS:
        near = np.linalg.norm(p - corner, axis=1) < 0.0005
        # at rest there (the closest sample may be the one that arrives, a few um before it settles)
        assert near.any() and v[near].min() < 0.01


def test_zones_shorten_the_cycle(tmp_path):
    fine = run_in_cell(tmp_path / "a", square("fine"))[1]
    zoned = run_in_cell(tmp_path / "b", square("z50"))[1]
    assert zoned[-1] < fine[-1] - 0.3  # three stops fewer (each ramp down and up again is ~0.3 s at v500)


def urdf_limits():
    """(velocity rad/s) of the arm's six joints, read from the URDF file itself."""
    root = ET.parse(STATIONS / "robots" / "arm6700.urdf").getroot()
    return np.array([float(j.find("limit").get("velocity")) for j in root.iter("joint") if j.get("type") == "revolute"])


def test_a_moveabsj_and_a_movej_last_as_long_as_their_slowest_axis_needs_at_its_limits(tmp_path):
    station = tomllib.loads((RIG / "station.toml").read_text())["robot"]
    start, goal = np.array(station["home_deg"]), np.array([60.0, 10.0, 20.0, 45.0, 40.0, -150.0])
    vmax, amax = urdf_limits(), np.radians(station["accel_deg"])
    program = f"""MODULE Abs
  {TOOL}
  PERS jointtarget jEnd := [[0,0,0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    MoveAbsJ [[{', '.join(f'{a:g}' for a in goal)}],[9E9,9E9,9E9,9E9,9E9,9E9]], vmax, fine, tG;
    MoveJ [[1400,-1000,700],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], vmax, fine, tG;
    jEnd := CJointT();
  ENDPROC
ENDMODULE
"""
    events = []
    with open_cell(station_with(tmp_path, program), on_event=events.append, entry="main") as cell:
        while cell.controller.state != "completed":
            cell.step()
        end = np.array([float(v) for v in cell.controller.interp.globals["jend"].value.fields["robax"].values()])
    times = [e["t"] for e in events if e["type"] in ("move", "end")]
    for travel_deg, duration in ((goal - start, times[1] - times[0]), (end - goal, times[2] - times[1])):
        travel = np.radians(np.abs(travel_deg))
        assert duration >= max(travel / vmax)
        # a trapezoid (a triangle when too short for top speed) at each axis's speed and acceleration limits: the
        # slowest axis's time bounds the move
        limit_based = max(np.where(travel >= vmax ** 2 / amax, travel / vmax + vmax / amax, 2 * np.sqrt(travel / amax)))
        assert duration == pytest.approx(limit_based, rel=0.2)


def line_program(before: str, speed: str = "v500") -> str:
    return f"""MODULE Line
  {TOOL}
  {P0}
  PROC main()
    MoveJ p0, v1000, fine, tG;
    {before}
    MoveL Offs(p0,0,600,0), {speed}, fine, tG;
  ENDPROC
ENDMODULE
"""


def line_run(tmp_path, before: str, speed: str = "v500"):
    events, t, p = run_in_cell(tmp_path, line_program(before, speed))
    start = next(e["t"] for e in events if e["type"] == "move" and e["instr"] == "MoveL")
    keep = t > start + 1e-9
    t, p = t[keep], p[keep]
    v = speeds(t, p)[1:]
    a = np.abs(np.diff(v) / np.diff(t)[1:])
    return events[-1]["t"] - start, v.max(), a.max()


def test_velset_50_halves_the_tcp_speed_and_accset_50_halves_the_acceleration(tmp_path):
    duration, vmax, amax = line_run(tmp_path / "plain", "")
    assert vmax == pytest.approx(0.5, rel=0.03)
    v_duration, v_vmax, _ = line_run(tmp_path / "velset", "VelSet 50, 5000;")
    assert v_vmax == pytest.approx(0.25, rel=0.03)  # the manual: 50 % of the programmed speed
    assert v_duration > 1.6 * duration
    # fast enough for the arm to reach its acceleration limit (at v500 the rise ends before it does)
    f_duration, f_vmax, f_amax = line_run(tmp_path / "fast", "", "v1000")
    a_duration, a_vmax, a_amax = line_run(tmp_path / "accset", "AccSet 50, 50;", "v1000")
    assert a_vmax == pytest.approx(f_vmax, rel=0.03)  # the same speed, reached more slowly
    assert a_amax == pytest.approx(0.5 * f_amax, rel=0.1)  # the manual: 50 % of the normal acceleration
    assert a_duration > f_duration + 0.1
    _, m_vmax, _ = line_run(tmp_path / "max", "VelSet 100, 200;")
    assert m_vmax == pytest.approx(0.2, rel=0.03)  # Max: the TCP at most 200 mm/s


def test_an_offline_run_with_the_station_times_every_event_as_the_cell(tmp_path):
    program = square("z50", before="SetDO fullAutoRun, 1;").replace(
        "    MoveL p0, v500, fine, tG;", "    SetDO fullAutoRun, 0;\n    MoveL p0, v500, fine, tG;\n    WaitTime 0.3;\n"
                                        "    MoveJ Offs(p0,0,0,-300), v1000, z10, tG;\n    MoveL p0, v200, fine, tG;")
    cell_events, _, _ = run_in_cell(tmp_path / "cell", program)
    station = station_with(tmp_path / "offline", program)
    out = io.StringIO()
    with redirect_stdout(out):
        assert rapid(["run", str(station / "test.mod"), "--station", str(station), "--entry", "main", "--trace"]) == 0
    offline = [json.loads(line) for line in out.getvalue().splitlines()]
    assert [(e["type"], e.get("instr"), e.get("signal")) for e in offline] == \
           [(e["type"], e.get("instr"), e.get("signal")) for e in cell_events]
    assert [e["t"] for e in offline] == [e["t"] for e in cell_events]
    assert offline[-1]["t"] > 5.0  # the motions took their time


def test_check_with_the_station_knows_its_io_and_a_run_with_it_starts_at_its_home_pose(tmp_path):
    out = io.StringIO()
    with redirect_stdout(out):
        assert rapid(["check", "--station", str(RIG)]) == 0
    assert out.getvalue() == ""  # every signal of the shipped program is in the station's I/O configuration
    program = f"""MODULE Where
  {TOOL}
  PROC main()
    VAR robtarget here;
    here := CRobT(\\Tool:=tG);
    TPWrite "at " \\Pos:=here.trans;
  ENDPROC
ENDMODULE
"""
    station = station_with(tmp_path, program)
    out = io.StringIO()
    with redirect_stdout(out):
        assert rapid(["run", str(station / "test.mod"), "--station", str(station), "--entry", "main"]) == 0
    grip_right = tomllib.loads((RIG / "station.toml").read_text())["robot"]["targets"]["grip_right"]["xyz"]
    at = [float(v) for v in out.getvalue().strip().removeprefix("at [").removesuffix("]").split(",")]
    assert at == pytest.approx([v * 1000 for v in grip_right], abs=0.1)  # home_deg is given to 0.001 degrees


def test_with_configuration_monitoring_on_a_target_in_another_configuration_is_an_error_at_its_line(tmp_path):
    # cf1 = 1: axis 1 between 90 and 180 degrees, but the target lies at -11 degrees (atan2(-300, 1500))
    program = f"""MODULE Conf
  {TOOL}
  PROC main()
    ConfJ \\On;
    MoveJ [[1500,-300,900],[0,1,0,0],[1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v1000, fine, tG;
  ENDPROC
ENDMODULE
"""
    station = station_with(tmp_path, program)
    err = io.StringIO()
    with redirect_stdout(io.StringIO()), redirect_stderr(err):
        assert rapid(["run", str(station / "test.mod"), "--station", str(station), "--entry", "main"]) == 70
    assert ":5:5: error:" in err.getvalue() and "configuration" in err.getvalue()
    ok = program.replace("ConfJ \\On;", "ConfJ \\Off;")
    (station / "test.mod").write_text(ok)
    with redirect_stdout(io.StringIO()):
        assert rapid(["run", str(station / "test.mod"), "--station", str(station), "--entry", "main"]) == 0


def test_open_dir_lists_a_directory_and_get_motor_torque_reads_the_physics_arm(tmp_path):
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in ("b.txt", "a.txt"):
        (folder / name).write_text("x")
    p = tmp_path / "dir.mod"
    p.write_text(f"""MODULE Dir
  VAR dir d;
  VAR string name;
  PROC main()
    OpenDir d, "{folder}";
    WHILE ReadDir(d, name) DO
      TPWrite name;
    ENDWHILE
    CloseDir d;
  ENDPROC
ENDMODULE
""")
    out = io.StringIO()
    with redirect_stdout(out):
        assert rapid(["run", str(p)]) == 0
    assert out.getvalue().split() == ["a.txt", "b.txt"]
    # axis 2 carries the arm's weight: the physics motor holds it with a torque, read by the program
    program = f"""MODULE Torque
  PERS num t2 := 0;
  PROC main()
    WaitTime 0.1;
    t2 := GetMotorTorque(2);
  ENDPROC
ENDMODULE
"""
    with open_cell(station_with(tmp_path / "cell", program), entry="main") as cell:
        while cell.controller.state != "completed":
            cell.step()
        t2 = cell.controller.interp.globals["t2"].value
        # a second implementation: the torque that holds the arm (and the gripper on it) still against gravity, by
        # pybullet's inverse dynamics (recursive Newton-Euler) at the present joints with no speed or acceleration
        robot = cell.twin.robot
        c = robot.client
        movable = [j for j in range(c.getNumJoints(robot.body)) if c.getJointInfo(robot.body, j)[2] != c.JOINT_FIXED]
        q = [c.getJointState(robot.body, j)[0] for j in movable]
        gravity = c.calculateInverseDynamics(robot.body, q, [0.0] * len(q), [0.0] * len(q))[movable.index(robot.joints[1])]
        assert abs(gravity) > 1000.0  # (the arm's weight on axis 2: thousands of N m)
        assert t2 == pytest.approx(gravity, rel=0.01)


def offline_trace(tmp_path, program: str) -> list[dict]:
    station = station_with(tmp_path, program)
    out = io.StringIO()
    with redirect_stdout(out):
        assert rapid(["run", str(station / "test.mod"), "--station", str(station), "--entry", "main", "--trace"]) == 0
    return [json.loads(line) for line in out.getvalue().splitlines()]


def test_a_zone_point_whose_next_motion_comes_too_late_stops_and_is_warned_of_unless_told_not_to(tmp_path):
    body = """MoveJ p0, v1000, fine, tG;
    MoveL Offs(p0,400,0,0), v500, z50, tG;
    WaitTime 1;
    MoveL Offs(p0,400,600,0), v500, z50, tG;
    WaitTime \\InPos, 0;
    MoveL p0, v500, fine, tG;"""
    program = square("fine").replace("""MoveJ p0, v1000, fine, tG;
    
    MoveL Offs(p0,400,0,0), v500, fine, tG;
    MoveL Offs(p0,400,600,0), v500, fine, tG;
    MoveL Offs(p0,0,600,0), v500, fine, tG;
    MoveL p0, v500, fine, tG;""", body)
    assert body in program
    warned = [e for e in offline_trace(tmp_path / "a", program) if e["type"] == "errlog"]
    # the WaitTime 1 kept the next motion from the planner: the robot stopped at the zone point (ABB's 50024);
    # the WaitTime \InPos asked for the stop: no warning for it
    assert len(warned) == 1 and warned[0]["header"] == "Corner path failure" and "line 8:" in warned[0]["reason"]
    quiet = program.replace("MoveJ p0, v1000, fine, tG;", "MoveJ p0, v1000, fine, tG;\n    CornerPathWarning FALSE;")
    assert not [e for e in offline_trace(tmp_path / "b", quiet) if e["type"] == "errlog"]


def test_movel_with_t_takes_that_time_and_a_heavier_payload_accelerates_less(tmp_path):
    def duration(tmp, before: str, move: str) -> float:
        program = line_program(before).replace("MoveL Offs(p0,0,600,0), v500, fine, tG;", move)
        events = offline_trace(tmp, program)
        start = next(e["t"] for e in events if e["type"] == "move" and e["instr"] == "MoveL")
        return events[-1]["t"] - start

    # \T: the motion takes 3 s (the manual: the total time of the movement), to the controller's 12 ms tick
    assert duration(tmp_path / "t", "", "MoveL Offs(p0,0,600,0), v500 \\T:=3, fine, tG;") == pytest.approx(3.0,
                                                                                                          abs=0.013)
    light = duration(tmp_path / "light", "", "MoveL Offs(p0,0,600,0), v2000, fine, tG;")
    heavy = duration(tmp_path / "heavy", "GripLoad [200,[0,0,100],[1,0,0,0],0,0,0];",
                     "MoveL Offs(p0,0,600,0), v2000, fine, tG;")
    assert heavy > light + 0.05  # the rated payload on top of the gripper: about half the acceleration


def test_configuration_monitoring_is_on_at_the_start_as_on_the_controller_unless_the_station_says_otherwise(tmp_path):
    """The manual: ConfJ\\On and ConfL\\On at a program's start. A station without `conf_monitoring` monitors
    from the first motion; the shipped rig, whose arm model's axis zeros are not ABB's, starts with it off."""
    program = f"""MODULE Conf
  {TOOL}
  PROC main()
    MoveJ [[1500,-300,900],[0,1,0,0],[1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v1000, fine, tG;
  ENDPROC
ENDMODULE
"""
    monitored = station_with(tmp_path / "a", program)
    toml = monitored / "station.toml"
    toml.write_text(toml.read_text().replace("conf_monitoring = false", ""))
    err = io.StringIO()
    with redirect_stdout(io.StringIO()), redirect_stderr(err):
        assert rapid(["run", str(monitored / "test.mod"), "--station", str(monitored), "--entry", "main"]) == 70
    assert ":4:5: error:" in err.getvalue() and "configuration monitoring is on" in err.getvalue()
    shipped = station_with(tmp_path / "b", program)
    with redirect_stdout(io.StringIO()):
        assert rapid(["run", str(shipped / "test.mod"), "--station", str(shipped), "--entry", "main"]) == 0
    toml = shipped / "station.toml"
    toml.write_text(toml.read_text().replace("conf_monitoring = false", "conf_monitoring = 0"))
    err = io.StringIO()
    with redirect_stdout(io.StringIO()), redirect_stderr(err):
        assert rapid(["run", str(shipped / "test.mod"), "--station", str(shipped), "--entry", "main"]) != 0
    assert "conf_monitoring" in err.getvalue()
