"""Robots and grippers that nobody on this team wrote, in a running twin: joint names, a base link whose
centre of mass is off its frame, `package://` meshes, link names that would clash, and fixed tips
named as fingers."""
import math
import subprocess
import sys

import numpy as np
import pytest

from tests.conftest import PYBULLET_DATA, STATIONS
from tests.core.urdfs import block_and_floor, joint, link, station, two_jaws, urdf
from twin.core import Twin
from twin.core.errors import StationError
from twin.core.station import load_station

ARM = STATIONS / "robots" / "arm6700.urdf"
HOME = "[0.0, -20.96, 42.09, 0.0, 68.87, -180.0]"  # the ring rig's: TCP at [1.0, 0, 1.2], pointing down

ROBOT_STATION = """[station]
name = "arm"

[robot]
urdf = "{arm}"
home_deg = {home}
{robot_extra}

[robot.targets]
app = { xyz = [1.6, -0.8, 0.58], rpy_deg = [180.0, 0.0, 0.0] }

[gripper]
urdf = "{urdf}"
tcp = { xyz = [0.0, 0.0, 0.35] }
always_active = true
{gripper_extra}

""" + block_and_floor("1.6, 0.0, 0.02")


def robot_station(tmp_path, arm=ARM, robot_extra="", gripper=None, gripper_extra=""):
    text = ROBOT_STATION.replace("{arm}", str(arm)).replace("{home}", HOME).replace("{robot_extra}", robot_extra)
    return station(tmp_path, gripper or two_jaws(tmp_path / "g.urdf"), gripper_extra, text=text)


def flange_in_physics(twin):
    link = twin.world.link_index["robot/flange"]
    state = twin.world.client.getLinkState(twin.world.machine, link, computeForwardKinematics=True)
    return np.array(state[4])


def reaches_app(twin):
    twin.run_motion("MoveJ", "app", 2.0)
    tcp = twin.tcp_pose()
    assert np.allclose(tcp.position, [1.6, -0.8, 0.58], atol=1e-3)
    # the kinematics' flange is where the physics body's flange is
    flange = twin.kinematics.flange_pose(twin.robot_q).position
    assert np.allclose(flange, flange_in_physics(twin), atol=1e-4)


def test_the_station_robot_joints_are_used(tmp_path):
    arm = tmp_path / "arm_a.urdf"
    text = ARM.read_text()
    for i in range(1, 7):
        text = text.replace(f'"joint_{i}"', f'"a{i}"')
    arm.write_text(text)
    with Twin.from_station(robot_station(tmp_path, arm, 'joints = ["a1", "a2", "a3", "a4", "a5", "a6"]')) as twin:
        assert twin.kinematics.joint_names == ("a1", "a2", "a3", "a4", "a5", "a6")
        reaches_app(twin)


@pytest.mark.parametrize("base", ["[0.0, 0.0, 0.0]", "[0.3, -0.2, 0.1]"])
def test_a_robot_whose_base_centre_of_mass_is_off_its_frame_loads_and_moves(tmp_path, base):
    arm = tmp_path / "arm_com.urdf"
    text = ARM.read_text()
    first = text.index('<origin xyz="0 0 0"/><mass value="600"/>')
    arm.write_text(text[:first] + '<origin xyz="0.05 0 0.15"/><mass value="600"/>'
                   + text[first + len('<origin xyz="0 0 0"/><mass value="600"/>'):])
    path = robot_station(tmp_path, arm, f"base = {{ xyz = {base} }}")
    if base != "[0.0, 0.0, 0.0]":  # the targets are in the world frame: move them with the base
        path.write_text(path.read_text().replace("[1.6, -0.8, 0.58]", "[1.9, -1.0, 0.68]"))
    with Twin.from_station(path) as twin:
        twin.run_motion("MoveJ", "app", 2.0)
        want = [1.6, -0.8, 0.58] if base == "[0.0, 0.0, 0.0]" else [1.9, -1.0, 0.68]
        assert np.allclose(twin.tcp_pose().position, want, atol=1e-3)
        assert np.allclose(twin.kinematics.flange_pose(twin.robot_q).position, flange_in_physics(twin), atol=1e-4)


def test_a_robot_joint_order_that_does_not_match_the_urdf_is_a_station_error(tmp_path):
    path = robot_station(tmp_path, robot_extra='joints = ["joint_2", "joint_1", "joint_3", "joint_4", "joint_5", "joint_6"]')
    with pytest.raises(StationError, match=r"station\.toml: robot\.joints: .*movable joints must be exactly"):
        Twin.from_station(path)


# -- meshes ------------------------------------------------------------------------------------------------
def mesh_gripper(root, filename: str):
    """A ROS-like package `jaws_pkg` with the URDF in urdf/ and an OBJ mesh in meshes/."""
    pkg = root / "src" / "jaws_pkg"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "meshes").mkdir()
    (pkg / "meshes" / "jaw.obj").write_text(
        "v -0.005 -0.01 0\nv 0.005 -0.01 0\nv 0.005 0.01 0\nv -0.005 0.01 0\n"
        "v -0.005 -0.01 0.05\nv 0.005 -0.01 0.05\nv 0.005 0.01 0.05\nv -0.005 0.01 0.05\n"
        "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n")
    mesh = f'<mesh filename="{filename}"/>'
    return urdf(pkg / "urdf" / "jaws.urdf", link("palm", geometry='<box size="0.1 0.04 0.02"/>'),
                joint("ja", "prismatic", "palm", "jaw_a"), link("jaw_a", geometry=mesh),
                joint("jb", "prismatic", "palm", "jaw_b", extra='<mimic joint="ja"/>', axis="-1 0 0"),
                link("jaw_b", geometry=mesh))


@pytest.mark.parametrize("filename", ["package://jaws_pkg/meshes/jaw.obj", "../meshes/jaw.obj"])
@pytest.mark.parametrize("with_robot", [True, False])
def test_package_and_relative_mesh_paths_load_with_and_without_a_robot(tmp_path, filename, with_robot):
    g = mesh_gripper(tmp_path, filename)
    path = robot_station(tmp_path, gripper=g) if with_robot else station(tmp_path, g)
    with Twin.from_station(path) as twin:
        twin.write("jaw_a", 0.03)
        twin.step(40)
        assert twin.read("jaw_a.actual") == pytest.approx(0.03, abs=1e-3)


def test_the_franka_panda_from_pybullet_data_loads_under_a_robot(tmp_path):
    path = robot_station(tmp_path, gripper=PYBULLET_DATA / "franka_panda" / "panda.urdf")
    with Twin.from_station(path) as twin:
        assert "panda_leftfinger" in [i.name for i in twin.mechanism.inputs]


@pytest.mark.parametrize("with_robot", [True, False])
def test_a_missing_mesh_names_the_urdf_and_the_mesh(tmp_path, with_robot):
    g = mesh_gripper(tmp_path, "package://jaws_pkg/meshes/nothere.obj")
    path = robot_station(tmp_path, gripper=g) if with_robot else station(tmp_path, g)
    with pytest.raises(StationError) as info:
        Twin.from_station(path)
    msg = str(info.value)
    assert msg.startswith(f"{path}: gripper.urdf: {g}: mesh 'package://jaws_pkg/meshes/nothere.obj' not found")


# -- links, joints and fingers -------------------------------------------------------------------------------
def test_link_names_that_would_make_the_same_signal_twice_are_refused(tmp_path):
    g = two_jaws(tmp_path / "g.urdf", a="jaw", b="jaw.moving")  # jaw.moving: an input, and jaw's output
    g.write_text(g.read_text().replace('<mimic joint="ja"/>', ""))
    with pytest.raises(StationError, match=r"gripper\.urdf: two signals would be named 'jaw\.moving'"):
        Twin.from_station(station(tmp_path, g))


def test_planar_and_floating_joints_stay_rigid_in_the_physics(tmp_path):
    g = urdf(tmp_path / "pf.urdf", link("palm", geometry='<box size="0.1 0.04 0.02"/>'),
             joint("pl", "planar", "palm", "carriage", limit="", axis="0 0 1"), link("carriage", collision=False),
             joint("slide", "prismatic", "palm", "jaw"), link("jaw"))
    with Twin.from_station(station(tmp_path, g)) as twin:
        c, body = twin.world.client, twin.world.machine
        carriage = twin.world.link_index["carriage"]
        assert c.getJointInfo(body, carriage)[2] == 4  # pybullet.JOINT_FIXED
        before = c.getLinkState(body, carriage)[4]
        twin.step(50)
        assert np.allclose(c.getLinkState(body, carriage)[4], before, atol=1e-6)


def test_a_continuous_joints_input_describes_its_range(tmp_path):
    g = urdf(tmp_path / "spin.urdf", link("palm", geometry='<box size="0.1 0.04 0.02"/>'),
             joint("spin", "continuous", "palm", "rotor", limit="", axis="0 0 1"), link("rotor"))
    with Twin.from_station(station(tmp_path, g)) as twin:
        spec = twin.spec("rotor")
        assert (spec.min, spec.max) == (-math.pi, math.pi) and "range -pi to pi" in spec.description


def test_the_master_input_of_a_mimic_follower_is_narrowed_in_the_twin(tmp_path):
    g = urdf(tmp_path / "m.urdf", link("palm", geometry='<box size="0.1 0.04 0.02"/>'),
             joint("ja", "prismatic", "palm", "jaw_a", limit='lower="0" upper="0.04"'), link("jaw_a"),
             joint("jb", "prismatic", "palm", "jaw_b", limit='lower="0" upper="0.03"', extra='<mimic joint="ja"/>',
                   axis="-1 0 0"), link("jaw_b"))
    with Twin.from_station(station(tmp_path, g)) as twin:
        assert (twin.spec("jaw_a").min, twin.spec("jaw_a").max) == (0.0, 0.03)
        with pytest.raises(Exception, match="outside the range 0 to 0.03"):
            twin.write("jaw_a", 0.035)


def test_a_fixed_tip_named_as_finger_stands_for_its_finger(tmp_path):
    g = urdf(tmp_path / "tips.urdf", link("palm", geometry='<box size="0.1 0.04 0.02"/>'),
             joint("ja", "prismatic", "palm", "knuckle_a"), link("knuckle_a", collision=False),
             joint("ta", "fixed", "knuckle_a", "tip_a", limit=""), link("tip_a"),
             joint("jb", "prismatic", "palm", "knuckle_b", extra='<mimic joint="ja"/>', axis="-1 0 0"),
             link("knuckle_b", collision=False),
             joint("tb", "fixed", "knuckle_b", "tip_b", limit=""), link("tip_b"))
    path = station(tmp_path, g, 'fingers = ["tip_a", "tip_b"]')
    assert load_station(path).gripper.fingers == ("tip_a", "tip_b")
    with Twin.from_station(path) as twin:
        assert [f.name for f in twin.mechanism.fingers] == ["knuckle_a", "knuckle_b"]
        assert "knuckle_a.contact" in [s.name for s in twin.signals]


# -- twin demo ---------------------------------------------------------------------------------------------------
def twin_demo(*args):
    return subprocess.run([sys.executable, "-m", "twin", "demo", *map(str, args)], capture_output=True, text=True,
                          timeout=60)


def test_twin_demo_refuses_a_station_without_a_demo_in_one_line_naming_those_with_one():
    out = twin_demo(STATIONS / "four_finger")
    assert out.returncode == 2, out.stderr
    assert out.stderr.count("\n") == 1 and "Traceback" not in out.stderr
    assert "station 'four_finger' has no twin demo" in out.stderr and "[plugins] twin_demo" in out.stderr
    assert "shipped stations with one: ring_rig" in out.stderr


def test_the_ring_rig_demo_named_by_another_station_refuses_it_in_one_line(tmp_path):
    toml = tmp_path / "station.toml"
    text = (STATIONS / "four_finger" / "station.toml").read_text().replace('"gripper4.urdf"', f'"{STATIONS / "four_finger" / "gripper4.urdf"}"')
    toml.write_text(text + '\n[plugins]\ntwin_demo = "stations.ring_rig.demo"\n')
    out = twin_demo(tmp_path)
    assert out.returncode == 2, out.stderr
    assert out.stderr.count("\n") == 1 and "Traceback" not in out.stderr
    assert "twin demo plays the ring rig" in out.stderr and "needs a robot; a target named ring" in out.stderr


def test_a_station_plugin_that_cannot_be_loaded_is_named_by_its_key(tmp_path):
    toml = tmp_path / "station.toml"
    text = (STATIONS / "four_finger" / "station.toml").read_text().replace('"gripper4.urdf"', f'"{STATIONS / "four_finger" / "gripper4.urdf"}"')
    toml.write_text(text + '\n[plugins]\ntwin_demo = "no_such_demo.py"\n')
    out = twin_demo(tmp_path)
    assert out.returncode == 2 and out.stderr.count("\n") == 1, out.stderr
    assert f"{toml}: plugins.twin_demo: 'no_such_demo.py': no file" in out.stderr
