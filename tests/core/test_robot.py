"""The robot that carries the gripper: IK at the rig's targets, refused targets, MoveL/MoveJ/MoveC/MoveAbsJ
timing and tracking in a real pybullet world with a 70 kg payload on the flange, and determinism."""
import math

import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from tests.conftest import STATIONS
from twin.core.errors import MotionError
from twin.core.geometry import Pose, slerp
from twin.core.kinematics import ArmKinematics
from twin.core.motion import Speed, movec, movej, movel, moveabsj
from twin.core.robot import Robot
from twin.core.twin import Twin

ARM = STATIONS / "robots" / "arm6700.urdf"
DOWN = (math.pi, 0.0, 0.0)  # the tool points straight down
HOME = np.radians([0.0, 0.0, 0.0, 0.0, 90.0, 0.0])
TOOL = Pose((0.0, 0.0, 0.35))  # the ring gripper's TCP, 350 mm out of the flange
DT, SUBSTEPS = 0.012, 4
PAYLOAD_KG = 70.0


def down(x, y, z):
    return Pose.from_xyz_rpy((x, y, z), DOWN)


@pytest.fixture(scope="module")
def kin():
    k = ArmKinematics(ARM, tool=TOOL)
    yield k
    k.close()


class Cell:
    """The arm in a physics world (dt 12 ms, 4 sub-steps) with a payload fixed under the flange."""

    def __init__(self, kin, tmp_path, q0):
        urdf = tmp_path / "arm_with_payload.urdf"
        urdf.write_text(ARM.read_text().replace("</robot>", f"""
  <joint name="payload_mount" type="fixed"><parent link="flange"/><child link="payload"/>
    <origin xyz="0 0 0.2"/></joint>
  <link name="payload">
    <inertial><origin xyz="0 0 0"/><mass value="{PAYLOAD_KG}"/><inertia ixx="4" ixy="0" ixz="0" iyy="4" iyz="0" izz="7"/></inertial>
    <collision><geometry><box size="0.5 0.5 0.3"/></geometry></collision>
  </link>
</robot>"""))
        self.client = BulletClient(connection_mode=pybullet.DIRECT)
        self.client.setGravity(0, 0, -9.81)
        self.client.setPhysicsEngineParameter(fixedTimeStep=DT, numSubSteps=SUBSTEPS, numSolverIterations=50,
                                              deterministicOverlappingPairs=1)
        body = self.client.loadURDF(str(urdf), useFixedBase=True, flags=pybullet.URDF_USE_INERTIA_FROM_FILE)
        self.robot = Robot(self.client, body, kinematics=kin)
        self.robot.reset(q0)
        self.steps = 0

    @property
    def t(self):
        return self.steps * DT

    def step(self):
        self.robot.update(self.t)
        self.client.stepSimulation()
        self.steps += 1

    def run(self, traj, max_steps=2000):
        """Execute a trajectory; the TCP position after every step."""
        self.robot.start(traj, self.t)
        tcp = []
        while self.robot.busy(self.t):
            assert self.steps < max_steps
            self.step()
            tcp.append(self.robot.tcp_pose().position)
        return np.array(tcp)

    def close(self):
        self.client.disconnect()


@pytest.fixture
def cell(kin, tmp_path):
    c = Cell(kin, tmp_path, kin.ik(down(1.6, -0.8, 0.58), HOME, "app_right"))
    yield c
    c.close()


def line_deviation(points, a, b):
    u = (b - a) / np.linalg.norm(b - a)
    d = points - a
    return float(np.max(np.linalg.norm(d - np.outer(d @ u, u), axis=1)))


# -- geometry -------------------------------------------------------------------------------------------
def test_pose_rpy_matches_pybullet_and_composes_with_its_inverse():
    rpy = (0.3, -1.2, 2.0)
    assert np.allclose(Pose.from_xyz_rpy((0, 0, 0), rpy).orientation, pybullet.getQuaternionFromEuler(rpy), atol=1e-12)
    a, b = Pose.from_xyz_rpy((1, 2, 3), rpy), Pose.from_xyz_rpy((-0.5, 0.1, 0.7), (3.0, 0.2, -1.0))
    pos, orn = pybullet.multiplyTransforms(a.position, a.orientation, b.position, b.orientation)
    ab = a * b
    assert np.allclose(ab.position, pos, atol=1e-6) and ab.angle(Pose((0, 0, 0), orn)) < 1e-6
    ident = a * a.inverse()
    assert np.allclose(ident.position, 0, atol=1e-12) and ident.angle(Pose.identity()) < 1e-7
    assert np.allclose(a.rpy, rpy)


def test_slerp_takes_the_short_way_at_constant_rate():
    q0 = Pose.identity().orientation
    q1 = Pose.from_xyz_rpy((0, 0, 0), (0, 0, math.radians(120))).orientation
    for s in (0.25, 0.5, 0.75):
        assert Pose((0, 0, 0), slerp(q0, q1, s)).angle(Pose.identity()) == pytest.approx(math.radians(120) * s)
    assert Pose((0, 0, 0), slerp(q0, -q1, 0.5)).angle(Pose.identity()) == pytest.approx(math.radians(60))


# -- kinematics -----------------------------------------------------------------------------------------
def test_zero_pose_is_abbs_flange_forward_and_tool_down_at_j5_90(kin):
    flange = kin.flange_pose(np.zeros(6))
    assert np.allclose(flange.position, (0.32 + 1.1425 + 0.2, 0, 0.78 + 1.28 + 0.2), atol=1e-6)
    assert np.allclose(flange.matrix[:3, 2], (1, 0, 0), atol=1e-6)  # z out of the flange, forward
    assert np.allclose(kin.fk(HOME).matrix[:3, 2], (0, 0, -1), atol=1e-6)  # j5 = 90 deg: tool points down


@pytest.mark.parametrize("xyz", [(1.6, -0.8, 0.18), (1.6, 0.8, 0.18), (1.6, -0.8, 0.6), (1.6, 0.8, 0.6),
                                 (1.6, 0.8, 0.15), (1.6, -0.8, 0.8), (1.2, 0.0, 1.2)])
def test_rig_targets_with_the_tool_down_are_solved_within_a_tenth_of_a_millimetre(kin, xyz):
    target = down(*xyz)
    q = kin.ik(target, HOME, "rig")
    tcp = kin.fk(q)
    assert tcp.distance(target) < 1e-4 and tcp.angle(target) < math.radians(0.01)
    assert all(lim.contains(v) for lim, v in zip(kin.limits, q))


@pytest.mark.parametrize("deg", [[-119, 3, -97, 20, 16, -221], [-58, -2, -88, 165, 67, -23], [139, 4, -70, 125, -83, 140]])
def test_a_reachable_target_far_from_the_seed_is_still_found(kin, deg):
    target = kin.fk(np.radians(deg))
    q = kin.ik(target, HOME, "far_from_home")
    assert kin.fk(q).distance(target) < 1e-4 and kin.fk(q).angle(target) < math.radians(0.01)


def test_ik_picks_the_turn_of_joint_6_nearest_the_seed(kin):
    seed = np.radians([0, 0, 0, 0, 90, 300])
    q = kin.ik(kin.fk(np.radians([0, 0, 0, 0, 90, -50])), seed, "turned")
    assert math.degrees(q[5]) == pytest.approx(310, abs=0.01)


def test_ik_is_deterministic_and_independent_of_earlier_queries(kin):
    target = down(1.6, 0.8, 0.3)
    first = kin.ik(target, HOME, "t")
    kin.ik(down(1.6, -0.8, 0.6), np.radians([10, 20, 5, 30, 40, 50]), "other")
    kin.fk(np.ones(6))
    assert np.array_equal(kin.ik(target, HOME, "t"), first)


def test_a_target_out_of_reach_is_an_error_naming_it(kin):
    with pytest.raises(MotionError, match=r"target 'far_away': cannot be reached: closest is \d+\.\d mm away") as e:
        kin.ik(down(5.0, 0.0, 1.0), HOME, "far_away")
    assert e.value.target == "far_away"


def test_a_target_needing_a_joint_beyond_its_limit_is_an_error_naming_target_and_joint(kin):
    # the tool pointing back at the robot would need the wrist bent past joint_5's 130 degrees
    with pytest.raises(MotionError, match=r"target 'backwards': would need joint_5 beyond its limit"):
        kin.ik(Pose.from_xyz_rpy((1.6, 0.0, 1.0), (0.0, -math.pi / 2, 0.0)), HOME, "backwards")


# -- planning -------------------------------------------------------------------------------------------
def test_movej_duration_respects_every_axis_speed_limit(kin):
    q1 = np.radians([150.0, 10.0, -20.0, 100.0, 45.0, 200.0])
    traj = movej(kin, HOME, None, q1, Speed(v_tcp=100.0, v_ori=100.0), "far_axes")
    vmax = np.array([lim.velocity for lim in kin.limits])
    assert traj.duration >= np.max(np.abs(q1 - HOME) / vmax)
    ts = np.arange(0.0, traj.duration + DT, DT / 4)
    qd = np.array([traj.qd(t) for t in ts])
    assert np.all(np.abs(qd) <= vmax * (1 + 1e-9))
    assert np.allclose(traj.q(traj.duration), q1) and np.allclose(traj.q(0.0), HOME)
    half = movej(kin, HOME, None, q1, Speed(v_tcp=100.0, v_ori=100.0, joint_fraction=0.5), "half")
    assert half.profile.rate == pytest.approx(traj.profile.rate / 2)  # half the axes' speed: half the rate


def test_movej_to_a_pose_is_limited_by_tcp_speed(kin):
    q0 = kin.ik(down(1.6, -0.8, 0.58), HOME, "a")
    slow = movej(kin, q0, down(1.6, 0.8, 0.58), None, Speed(v_tcp=0.1), "app_left")
    assert slow.duration >= 1.6 / 0.1
    assert kin.fk(slow.q(slow.duration)).distance(down(1.6, 0.8, 0.58)) < 1e-4


def test_movel_through_an_unreachable_stretch_is_refused_before_moving(kin):
    q0 = kin.ik(down(1.6, -0.8, 0.58), HOME, "a")
    with pytest.raises(MotionError, match="'too_far'"):
        movel(kin, q0, down(3.5, -0.8, 0.58), Speed(), "too_far")
    # both ends reachable, but the straight line between them passes too close to the robot's base
    q_right = kin.ik(down(0.6, -1.5, 0.5), np.radians([-80, 0, 0, 0, 90, 0]), "right")
    kin.ik(down(0.6, 1.5, 0.5), np.radians([80, 0, 0, 0, 90, 0]), "left")
    with pytest.raises(MotionError, match=r"'past_the_base': at \(600, -?\d+, 500\) mm, \d+% along the path: would need "
                                          r"joint_\d beyond its limit"):
        movel(kin, q_right, down(0.6, 1.5, 0.5), Speed(), "past_the_base")


def test_moveabsj_beyond_a_joint_limit_is_refused(kin):
    with pytest.raises(MotionError, match=r"target 'park': would need joint_1 beyond its limit \(200\.0 deg"):
        moveabsj(HOME, np.radians([200, 0, 0, 0, 90, 0]), Speed(), kin.limits, "park")
    traj = moveabsj(HOME, np.radians([90, 0, 0, 0, 90, 0]), Speed(), kin.limits, "quarter")
    v, a = kin.limits[0].velocity, kin.accel[0]  # a trapezoid at the axis's limits, and the jerk's ramp at most
    assert math.radians(90) / v + v / a <= traj.duration <= math.radians(90) / v + v / a + 0.1


def test_movec_follows_the_circle_and_refuses_three_points_on_a_line(kin):
    q0 = kin.ik(down(1.6, -0.8, 0.58), HOME, "a")
    traj = movec(kin, q0, Pose((1.9, 0.0, 0.58)), down(1.6, 0.8, 0.58), Speed(v_tcp=1.0), "arc")
    # the circle through (1.6, -0.8), (1.9, 0) and (1.6, 0.8) has its centre on y = 0
    centre = np.array([(1.9 ** 2 - 1.6 ** 2 - 0.8 ** 2) / (2 * (1.9 - 1.6)), 0.0, 0.58])
    radius = np.linalg.norm(np.array([1.6, -0.8, 0.58]) - centre)
    for t in np.linspace(0, traj.duration, 23):
        assert np.linalg.norm(kin.fk(traj.q(t)).position - centre) == pytest.approx(radius, abs=2e-4)
    assert traj.duration >= traj.tcp_path_length / 1.0
    with pytest.raises(MotionError, match="'straight': no circle"):
        movec(kin, q0, Pose((1.6, 0.0, 0.58)), down(1.6, 0.8, 0.58), Speed(), "straight")


# -- execution in the physics world ----------------------------------------------------------------------
def test_movel_keeps_the_tcp_on_the_line_and_arrives(kin, cell):
    for name, xyz in [("grip_right", (1.6, -0.8, 0.18)), ("app_right", (1.6, -0.8, 0.58)),
                      ("app_left", (1.6, 0.8, 0.58))]:
        a = cell.robot.tcp_pose().position
        traj = movel(kin, cell.robot.q, down(*xyz), Speed(v_tcp=1.0), name)
        path = cell.run(traj)
        assert line_deviation(path, a, np.array(xyz)) < 0.002
        end = cell.robot.tcp_pose()
        assert end.distance(down(*xyz)) < 0.0005 and end.angle(down(*xyz)) < math.radians(0.05)
        assert len(path) * DT <= traj.duration + 0.1  # in position soon after the planned end
        assert cell.robot.fault is None


def test_the_robot_holds_still_when_idle(cell):
    before = cell.robot.tcp_pose()
    for _ in range(100):
        cell.step()
    assert not cell.robot.busy(cell.t)
    assert cell.robot.tcp_pose().distance(before) < 1e-4


def test_two_runs_of_the_same_motion_give_bit_identical_joint_positions(kin, tmp_path):
    runs = []
    for _ in range(2):
        c = Cell(kin, tmp_path, kin.ik(down(1.6, -0.8, 0.58), HOME, "app_right"))
        traj = movej(kin, c.robot.q, down(1.6, 0.8, 0.3), None, Speed(v_tcp=2.0), "grip_left")
        c.run(traj)
        c.run(movel(kin, c.robot.q, down(1.6, 0.8, 0.58), Speed(v_tcp=1.0), "app_left"))
        runs.append(np.concatenate([c.robot.q, c.robot.qd]))
        c.close()
    assert np.array_equal(runs[0], runs[1])


def test_a_kinematics_on_the_wrong_base_frame_is_refused(kin, tmp_path):
    shifted = ArmKinematics(ARM, (0.0, 0.0, 0.15), tool=TOOL)
    try:
        with pytest.raises(MotionError, match="do not match the physics body"):
            Cell(shifted, tmp_path, HOME)
    finally:
        shifted.close()


def test_a_blocked_motion_ends_with_a_fault_naming_the_target(kin, cell):
    c = cell.client
    block = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.4, 0.4, 0.15])
    c.createMultiBody(0, block, basePosition=[1.6, -0.8, 0.2])  # its top at z 0.35, above grip_right
    traj = movel(kin, cell.robot.q, down(1.6, -0.8, 0.18), Speed(v_tcp=0.5), "grip_right")
    cell.robot.start(traj)  # from the next update
    steps = 0
    while cell.robot.busy(cell.t):
        cell.step()
        steps += 1
    assert steps * DT == pytest.approx(traj.duration + cell.robot.settle_timeout, abs=2 * DT)
    assert cell.robot.fault is not None and "'grip_right': not reached" in cell.robot.fault
    assert cell.robot.tcp_pose().position[2] > 0.3


def test_run_motion_raises_naming_the_target_when_the_table_stops_the_arm_short(tmp_path):
    # tests/grippers/newcomer_2f with a target 80 mm below the grip: the open fingers' tips meet the table before the
    # TCP gets there, and the motion must not end as if it had arrived
    import shutil

    from tests.grippers import GRIPPERS

    folder = tmp_path / "blocked"
    shutil.copytree(GRIPPERS["newcomer_2f"], folder)
    toml = folder / "station.toml"
    text = toml.read_text().replace('urdf = "../../../stations/robots/arm6700.urdf"',
                                    f'urdf = "{(STATIONS / "robots" / "arm6700.urdf").as_posix()}"')
    toml.write_text(text.replace("[robot.targets]\n",
                                 '[robot.targets]\nthrough = { xyz = [1.6, -0.8, 0.36], rpy_deg = [180.0, 0.0, 0.0] }\n'))
    with Twin.from_station(folder) as twin:
        with pytest.raises(MotionError, match=r"'through'.*not reached"):
            twin.run_motion("MoveL", "through", 0.1)
        # it stood where the fingers' tips (20 mm below the TCP: 0.03 + 0.08 - 0.09 m) met the table's top (0.41 m)
        assert twin.tcp_pose().position[2] == pytest.approx(0.41 + 0.02, abs=0.005)
