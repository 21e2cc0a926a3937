"""Station files: a wrong file stops with a message naming the file and the key."""
import pytest

from tests.conftest import STATIONS
from twin.core.errors import StationError
from twin.core.station import load_station

GOOD = (STATIONS / "four_finger" / "station.toml").read_text().replace(
    'urdf = "gripper4.urdf"', f'urdf = "{STATIONS / "four_finger" / "gripper4.urdf"}"')


def write(tmp_path, text):
    path = tmp_path / "station.toml"
    path.write_text(text)
    return path


def error_for(tmp_path, text) -> str:
    path = write(tmp_path, text)
    with pytest.raises(StationError) as info:
        load_station(path)
    assert str(path) in str(info.value)  # always names the file
    return str(info.value)


def test_the_shipped_stations_load():
    for name in ("ring_rig", "smart_gripper", "four_finger"):
        station = load_station(STATIONS / name)
        assert station.name == name and station.targets


def test_ring_dimensions_and_mass_are_read():
    ring = load_station(STATIONS / "ring_rig").targets[0]
    assert (ring.shape, ring.outer_diameter, ring.inner_diameter, ring.height) == ("ring", 0.64, 0.48, 0.06)
    assert ring.mass == pytest.approx(7850 * 3.14159265 / 4 * (0.64**2 - 0.48**2) * 0.06)


def test_missing_required_key_is_named(tmp_path):
    msg = error_for(tmp_path, GOOD.replace("radius = 0.04\n", ""))
    assert "targets[0].radius: is required" in msg


def test_a_misspelt_required_key_is_named_with_the_key_it_stands_for(tmp_path):
    msg = error_for(tmp_path, GOOD.replace("radius = 0.04\n", "radus = 0.04\n"))
    assert "targets[0].radius: is required (is 'radus' a misspelling of it?)" in msg


def test_wrong_type_is_named(tmp_path):
    msg = error_for(tmp_path, GOOD.replace("density = 1200.0", 'density = "heavy"'))
    assert "targets[0].density: must be a number" in msg


def test_unknown_key_is_named_so_typos_do_not_pass(tmp_path):
    msg = error_for(tmp_path, GOOD.replace("friction = 0.6", "fricton = 0.6"))
    assert "targets[0].fricton: is not a known key here" in msg


def test_ring_whose_bore_is_wider_than_its_outside_is_refused(tmp_path):
    ring = GOOD.replace('shape = "cylinder"\nradius = 0.04\nheight = 0.05',
                        'shape = "ring"\nouter_diameter = 0.1\ninner_diameter = 0.2\nheight = 0.05')
    msg = error_for(tmp_path, ring)
    assert "targets[0].inner_diameter: must be between 0 and outer_diameter (0.1)" in msg


def test_missing_urdf_file_is_named_with_the_key(tmp_path):
    msg = error_for(tmp_path, GOOD.replace(str(STATIONS / "four_finger" / "gripper4.urdf"), "nowhere.urdf"))
    assert "gripper.urdf: file 'nowhere.urdf' not found" in msg


def test_bad_toml_syntax_is_reported_with_the_file(tmp_path):
    msg = error_for(tmp_path, GOOD + "\n[[targets]\n")
    assert "not valid TOML" in msg


def test_duplicate_object_names_are_refused(tmp_path):
    msg = error_for(tmp_path, GOOD.replace('name = "loose_box"', 'name = "puck"'))
    assert "fixtures[1].name: 'puck' is already the name of a target" in msg


def test_unknown_shape_and_negative_step(tmp_path):
    assert "targets[0].shape: must be one of ring, box, cylinder, plane" in error_for(
        tmp_path, GOOD.replace('shape = "cylinder"', 'shape = "sphere"'))
    assert "station.step: must be greater than 0" in error_for(
        tmp_path, GOOD.replace('name = "four_finger"', 'name = "four_finger"\nstep = -0.01'))


def test_twin_cli_reports_a_station_error_in_one_line(tmp_path):
    import subprocess
    import sys

    path = write(tmp_path, GOOD.replace("height = 0.05", "height = -0.05"))
    out = subprocess.run([sys.executable, "-m", "twin", "info", str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip().splitlines()[-1] == f"twin: error: {path}: targets[0].height: must be greater than 0, not -0.05"


# -- what the station says about its gripper and robot must match their URDFs ----------------------------
import math  # noqa: E402

from tests.core.urdfs import joint, link, station, two_jaws, urdf  # noqa: E402

ARM = STATIONS / "robots" / "arm6700.urdf"


def station_error(path) -> str:
    with pytest.raises(StationError) as info:
        load_station(path)
    assert str(path) in str(info.value)
    assert "\n" not in str(info.value)
    return str(info.value)


@pytest.mark.parametrize("extra, key, words", [
    ('initial = { nosuch = 0.01 }', "gripper.initial.nosuch", "has no input 'nosuch' (its inputs: jaw_a)"),
    ('[gripper.joints.nosuch]\nvelocity = 0.1', "gripper.joints.nosuch", "has no input 'nosuch'"),
    ('initial = { jaw_a = 0.5 }', "gripper.initial.jaw_a", "0.5 m is outside the input's range 0 to 0.04 m"),
    ('fingers = ["nosuch"]', "gripper.fingers", "finger 'nosuch' is not a link of a finger"),
    ('fingers = []', "gripper.fingers", "one or more link names"),
    ('initial = { jaw_a = nan }', "gripper.initial.jaw_a", "must be a finite number, not nan"),
    ('contact_distance = inf', "gripper.contact_distance", "must be a finite number, not inf"),
    ('tcp = { xyz = [0.0, nan, 0.0] }', "gripper.tcp.xyz", "must be a list of 3 finite numbers"),
])
def test_gripper_settings_are_checked_against_the_urdf_and_name_the_key(tmp_path, extra, key, words):
    msg = station_error(station(tmp_path, two_jaws(tmp_path / "g.urdf"), extra))
    assert f"station.toml: {key}: " in msg and words in msg


@pytest.mark.parametrize("old, new, key", [
    ("density = 1000.0", "density = nan", "targets[0].density"),
    ("size = [0.03, 0.03, 0.04]", "size = [0.03, inf, 0.04]", "targets[0].size"),
    ('xyz = [0.0, 0.0, 0.02]', 'xyz = [0.0, 0.0, -inf]', "targets[0].xyz"),
    ('name = "t"', 'name = "t"\nstep = inf', "station.step"),
])
def test_nan_and_infinite_numbers_are_refused(tmp_path, old, new, key):
    path = station(tmp_path, two_jaws(tmp_path / "g.urdf"))
    path.write_text(path.read_text().replace(old, new))
    msg = station_error(path)
    assert f": {key}: must be " in msg and "finite number" in msg


def test_an_integer_key_says_an_integer(tmp_path):
    path = station(tmp_path, two_jaws(tmp_path / "g.urdf"))
    path.write_text(path.read_text().replace('name = "t"', 'name = "t"\nsubsteps = 2.5'))
    assert "station.substeps: must be an integer, not 2.5" in station_error(path)


def test_a_malformed_gripper_urdf_is_a_station_error_naming_the_key_and_the_problem(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'></robot>")
    msg = station_error(station(tmp_path, bad))
    assert f"gripper.urdf: {bad}: not valid XML" in msg


def test_a_gripper_urdf_that_is_a_folder_is_refused_in_one_line(tmp_path):
    (tmp_path / "g.urdf").mkdir()
    msg = station_error(station(tmp_path, tmp_path / "g.urdf"))
    assert "gripper.urdf: " in msg and "is a folder, not a file" in msg


def test_a_gripper_without_movable_joints_is_refused(tmp_path):
    rigid = urdf(tmp_path / "rigid.urdf", link("a"), link("b"), joint("f", "fixed", "a", "b", limit=""))
    msg = station_error(station(tmp_path, rigid))
    assert "gripper.urdf: " in msg and "has no movable joint (prismatic or revolute): nothing to drive" in msg


def test_a_gripper_with_no_finger_is_refused_unless_the_station_names_its_fingers(tmp_path):
    g = two_jaws(tmp_path / "g.urdf", collision=False)
    msg = station_error(station(tmp_path, g))
    assert "gripper.urdf: g.urdf has no finger" in msg and "gripper.fingers" in msg
    named = load_station(station(tmp_path, g, 'fingers = ["jaw_a", "jaw_b"]'))
    assert named.gripper.fingers == ("jaw_a", "jaw_b")


def test_a_link_named_like_a_built_in_signal_is_refused(tmp_path):
    g = two_jaws(tmp_path / "g.urdf", a="Active")
    msg = station_error(station(tmp_path, g))
    assert "gripper.urdf: " in msg and "link 'Active'" in msg and "one of the twin's own signals" in msg


ROBOT = """
[robot]
urdf = "{arm}"
{robot_extra}
"""


def robot_station(tmp_path, robot_extra: str, arm=ARM) -> str:
    path = station(tmp_path, two_jaws(tmp_path / "g.urdf"))
    path.write_text(path.read_text() + ROBOT.format(arm=arm, robot_extra=robot_extra))
    return station_error(path)


def test_robot_joints_of_the_wrong_type_are_a_station_error(tmp_path):
    assert "robot.joints: must be a list of joint names (strings), not [1, 2, 3, 4, 5, 6]" in robot_station(
        tmp_path, "joints = [1, 2, 3, 4, 5, 6]")


def test_a_robot_joint_that_is_not_in_its_urdf_is_a_station_error(tmp_path):
    msg = robot_station(tmp_path, 'joints = ["joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "wrist"]')
    assert "robot.joints: arm6700.urdf has no joint 'wrist'" in msg and "joint_6" in msg


def test_the_default_robot_joints_missing_from_the_urdf_say_how_to_name_them(tmp_path):
    arm = tmp_path / "renamed.urdf"
    arm.write_text(ARM.read_text().replace('"joint_', '"axis_'))
    msg = robot_station(tmp_path, "", arm=arm)
    assert "robot.joints: renamed.urdf has no joint 'joint_1'" in msg and "name the arm's joints with robot.joints" in msg


def test_an_unknown_flange_link_is_a_station_error(tmp_path):
    msg = robot_station(tmp_path, 'flange_link = "tool0"')
    assert "robot.flange_link: arm6700.urdf has no link 'tool0'" in msg


def test_nan_in_robot_home_is_refused(tmp_path):
    assert "robot.home_deg: must be a list of finite numbers" in robot_station(
        tmp_path, "home_deg = [0, 0, 0, 0, nan, 0]")
