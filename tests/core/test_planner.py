"""The motion planner on an arm nobody tuned: the shipped arm's URDF with every axis at a different speed limit,
acceleration limits from the station, zones blended through the twin's API (no RAPID). Checked against the
URDF's limits and the corner's geometry, measured on the physics arm."""
import math

import numpy as np
import pytest

from tests.core.test_foreign_models import ARM, robot_station
from twin.core import Twin
from twin.core.geometry import Pose
from twin.core.motion import Speed
from twin.core.planner import FINE, Zone

SPEEDS = [0.9, 1.3, 1.1, 2.0, 2.4, 3.0]  # rad/s, our arm's (the shipped one's are 1.92 to 4.1)
ACCEL_DEG = [150.0, 220.0, 180.0, 400.0, 300.0, 500.0]


@pytest.fixture
def twin(tmp_path):
    text = ARM.read_text()
    for i, v in enumerate(SPEEDS, start=1):
        start = text.index(f'<joint name="joint_{i}"')
        limit = text.index("velocity=", start)
        end = text.index('"', limit + len('velocity="'))
        text = text[:limit] + f'velocity="{v}' + text[end:]
    arm = tmp_path / "slow_arm.urdf"
    arm.write_text(text)
    with Twin.from_station(robot_station(tmp_path, arm, f"accel_deg = {ACCEL_DEG}")) as t:
        yield t


def down(x, y, z):
    return Pose.from_xyz_rpy((x, y, z), (math.pi, 0.0, 0.0))


def run(twin):
    t, p = [], []
    while twin.robot_busy:
        twin.step()
        t.append(twin.time)
        p.append(twin.tcp_pose().position.copy())
    return np.array(t), np.array(p)


def test_a_moveabsj_takes_what_its_slowest_axis_needs_at_this_arms_limits(twin):
    start = twin.robot_q
    goal = start + np.radians([70.0, 10.0, -15.0, 90.0, 20.0, 100.0])
    t0 = twin.time
    twin.move("MoveAbsJ", goal, Speed(v_tcp=10.0, v_ori=10.0))
    run(twin)
    duration = twin.time - t0
    travel, v, a = np.abs(goal - start), np.array(SPEEDS), np.radians(ACCEL_DEG)
    assert duration >= max(travel / v)
    trapezoid = np.where(travel >= v ** 2 / a, travel / v + v / a, 2 * np.sqrt(travel / a))
    assert duration == pytest.approx(max(trapezoid), rel=0.2)
    assert np.allclose(twin.robot_q, goal, atol=1e-3)


def test_zones_blend_on_this_arm_within_the_zone_and_without_stopping(twin):
    twin.run_motion("MoveJ", down(1.5, -0.3, 0.7), 1.0)
    corners = [(1.8, -0.3, 0.7), (1.8, 0.2, 0.7), (1.5, 0.2, 0.7)]
    z = Zone(False, 0.03, 0.045, 0.045, math.radians(4.5))  # z30
    for i, c in enumerate(corners):
        twin.move("MoveL", down(*c), Speed(v_tcp=0.4), zone=z if i < 2 else FINE)
    t, p = run(twin)
    v = np.concatenate([[0.0], np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)])
    for c in corners[:2]:
        d = np.linalg.norm(p - c, axis=1)
        assert v[d < 0.035].min() > 0.1  # through the corner at speed
        assert 0.002 < d.min() < 0.03 / math.sqrt(2)  # cut, inside the chord of the zone
    assert np.linalg.norm(p[-1] - corners[2]) < 0.0005


def test_blended_motions_replay_bit_for_bit(tmp_path):
    runs = []
    for k in range(2):
        (tmp_path / str(k)).mkdir()
        with Twin.from_station(robot_station(tmp_path / str(k), ARM)) as twin:
            z = Zone(False, 0.05, 0.075, 0.075, math.radians(7.5))
            twin.move("MoveJ", down(1.5, -0.3, 0.7), Speed(v_tcp=1.0), zone=z)
            twin.move("MoveL", down(1.8, -0.3, 0.7), Speed(v_tcp=0.5), zone=z)
            twin.move("MoveL", down(1.8, 0.2, 0.7), Speed(v_tcp=0.5), zone=FINE)
            run(twin)
            runs.append(np.concatenate([twin.robot.q, twin.robot.qd, [twin.time]]))
    assert np.array_equal(runs[0], runs[1])


def test_the_arm_in_numpy_is_the_arm_pybullet_computes_with_a_prismatic_axis_and_a_tilted_base(tmp_path):
    """fk_many (the planner's product of exponentials) against pybullet's own forward kinematics, on an arm whose
    first axis is a lift (prismatic, tilted off z) and whose base and tool are turned."""
    from twin.core.kinematics import ArmKinematics
    from twin.core.geometry import quat_matrix

    text = ARM.read_text().replace('<joint name="joint_1" type="revolute">', '<joint name="joint_1" type="prismatic">')
    text = text.replace('<origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 0 1"/>',
                        '<origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0.6 0 0.8"/>', 1)
    lift = tmp_path / "lift_arm.urdf"
    lift.write_text(text)
    odd = tmp_path / "odd_axis_arm.urdf"  # an axis not of unit length: pybullet's reading of it is the arm
    odd.write_text(text.replace('<axis xyz="0.6 0 0.8"/>', '<axis xyz="0.3 0 1"/>'))
    for urdf in (ARM, lift, odd):
        kin = ArmKinematics(urdf, (0.2, -0.1, 0.4), Pose.from_xyz_rpy((0, 0, 0), (0.1, -0.2, 0.7)).orientation,
                            tool=Pose.from_xyz_rpy((0.01, 0.02, 0.3), (0.3, 0.0, -0.5)))
        try:
            qs = np.random.default_rng(7).uniform(kin.lower, kin.upper, (40, 6))
            positions, rotations = kin.fk_many(qs)
            for q, p, r in zip(qs, positions, rotations):
                pose = kin.fk(q)
                assert np.allclose(p, pose.position, atol=1e-6)
                assert np.allclose(r, quat_matrix(pose.orientation), atol=1e-6)
        finally:
            kin.close()


def test_a_paths_samples_solved_at_once_are_the_path_solved_one_by_one(twin, monkeypatch):
    """The batch IK along a MoveL and a MoveC against the sample-by-sample solve (pybullet's IK seeded from the
    previous sample), and every knot's TCP on the programmed line / circle."""
    from twin.core import motion

    kin = twin.kinematics
    q0 = twin.robot_q
    start = kin.fk(q0)
    line_end = down(1.7, 0.4, 0.5)
    via, arc_end = down(1.6, -0.3, 0.9), down(1.2, 0.3, 0.9)
    plans = {}
    for batch in (True, False):
        monkeypatch.setattr(motion, "BATCH_IK", batch)
        plans[batch] = (motion.movel(kin, q0, line_end, Speed(v_tcp=0.5)),
                        motion.movec(kin, q0, via, arc_end, Speed(v_tcp=0.5)))
    for fast, slow in zip(plans[True], plans[False]):
        assert np.array_equal(fast._s, slow._s)
        assert np.abs(fast._knots - slow._knots).max() < 2e-3  # rad: both within the IK's 0.1 mm
        assert fast.duration == pytest.approx(slow.duration, abs=1e-3)
    line = plans[True][0]
    a, b = start.position, line_end.position
    for s, q in zip(line._s, line._knots):
        assert np.linalg.norm(kin.fk(q).position - (a + s * (b - a))) < 1e-4
    arc = plans[True][1]
    centre = motion.circle_through(start.position, via.position, arc_end.position, "arc")[0]
    radius = np.linalg.norm(start.position - centre)
    for q in arc._knots:
        assert abs(np.linalg.norm(kin.fk(q).position - centre) - radius) < 1e-4
