"""Mechanism discovery: inputs per independent joint, mimic joints, fingers, on our and foreign URDFs."""
import json
import math
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from tests.conftest import PYBULLET_DATA, STATIONS
from twin.core.errors import MechanismError
from twin.core.mechanism import load_mechanism


def test_ring_gripper_has_inputs_L2_to_L5_with_the_thesis_range():
    mech = load_mechanism(STATIONS / "ring_rig" / "gripper3.urdf")
    assert [i.name for i in mech.inputs] == ["L2", "L3", "L4", "L5"]
    for inp in mech.inputs[:3]:
        assert (inp.min, inp.max, inp.unit, inp.type) == (0.0, 0.441, "m", "prismatic")
    assert mech.base_link == "L1"
    # L4 is only the carriage of finger 3 (no collision geometry); its fine axis L5 carries the finger.
    assert [f.name for f in mech.fingers] == ["L2", "L3", "L5"]


def test_mimic_coupled_parallel_gripper_shows_exactly_one_input():
    mech = load_mechanism(STATIONS / "smart_gripper" / "smart_gripper.urdf")
    assert len(mech.inputs) == 1
    assert mech.mimics[0].master == mech.inputs[0].joint
    assert len(mech.fingers) == 2  # the mimic jaw is still a finger


def test_foreign_gripper_with_five_mimic_joints_gets_one_input_per_independent_joint():
    urdf = PYBULLET_DATA / "xarm" / "xarm6_with_gripper.urdf"
    root = ET.parse(urdf).getroot()
    movable = [j for j in root.findall("joint") if j.get("type") in ("revolute", "prismatic", "continuous")]
    independent = [j.find("child").get("link") for j in movable if j.find("mimic") is None]
    mech = load_mechanism(urdf)
    assert [i.name for i in mech.inputs] == independent
    assert len(mech.mimics) == len(movable) - len(independent) == 5
    drive = mech.input("left_outer_knuckle")
    assert drive.unit == "rad" and drive.max == pytest.approx(0.85)


def test_foreign_pr2_gripper_fingers_include_their_rigidly_fixed_tips():
    mech = load_mechanism(PYBULLET_DATA / "pr2_gripper.urdf")
    assert [i.name for i in mech.inputs] == ["left_gripper", "right_gripper"]
    assert {f.name: f.links for f in mech.fingers} == {
        "left_gripper": ("left_gripper", "left_tip"), "right_gripper": ("right_gripper", "right_tip")}


def test_chained_mimic_composes_to_the_independent_joint(tmp_path):
    urdf = tmp_path / "chain.urdf"
    link = '<link name="{0}"><collision><geometry><box size="0.01 0.01 0.01"/></geometry></collision></link>'
    urdf.write_text(f"""<robot name="chain">{link.format('base')}{link.format('a')}{link.format('b')}{link.format('c')}
      <joint name="ja" type="revolute"><parent link="base"/><child link="a"/><limit lower="-1" upper="1"/></joint>
      <joint name="jb" type="revolute"><parent link="base"/><child link="b"/><limit lower="-2" upper="2"/>
        <mimic joint="ja" multiplier="2" offset="0.1"/></joint>
      <joint name="jc" type="revolute"><parent link="base"/><child link="c"/><limit lower="-9" upper="9"/>
        <mimic joint="jb" multiplier="-3" offset="0.5"/></joint></robot>""")
    mech = load_mechanism(urdf)
    assert [i.name for i in mech.inputs] == ["a"]
    jc = next(m for m in mech.mimics if m.joint == "jc")
    assert (jc.master, jc.multiplier, jc.offset) == ("ja", -6.0, pytest.approx(0.2))


def test_station_can_name_its_fingers_and_a_wrong_name_is_reported():
    urdf = STATIONS / "four_finger" / "gripper4.urdf"
    assert [f.name for f in load_mechanism(urdf, ("F1", "F3")).fingers] == ["F1", "F3"]
    with pytest.raises(MechanismError, match="'hub' is not a link of a finger"):
        load_mechanism(urdf, ("hub",))


def test_broken_urdf_is_reported_with_its_file(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><joint name='j' type='prismatic'><parent link='a'/>"
                   "<child link='b'/></joint></robot>")
    with pytest.raises(MechanismError, match=r"bad\.urdf: joint 'j'"):
        load_mechanism(bad)


def run_twin(*args):
    return subprocess.run([sys.executable, "-m", "twin", *args], capture_output=True, text=True, timeout=60)


def test_twin_info_json_prints_the_documented_shape():
    out = run_twin("info", str(STATIONS / "ring_rig" / "gripper3.urdf"), "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["base_link"] == "L1"
    assert data["fingers"] == ["L2", "L3", "L5"]
    assert data["inputs"][0] == {"name": "L2", "joint": "J1", "type": "prismatic", "min": 0.0, "max": 0.441, "unit": "m"}


def test_twin_info_table_on_a_station_lists_inputs_and_fingers():
    out = run_twin("info", str(STATIONS / "smart_gripper"))
    assert out.returncode == 0, out.stderr
    assert "jaw_left" in out.stdout and "jaw_right_joint follows jaw_left_joint" in out.stdout
    assert "fingers (2)" in out.stdout


def test_twin_info_on_a_missing_file_is_a_one_line_error():
    out = run_twin("info", "no/such/gripper.urdf")
    assert out.returncode == 2
    assert out.stderr.strip().splitlines()[-1] == "twin: error: no/such/gripper.urdf: no such file"


# -- URDFs that nobody on this team wrote: what the twin accepts, refuses and tells --------------------------
from tests.core.urdfs import joint, link, station, two_jaws, urdf  # noqa: E402


def test_twin_info_on_a_urdf_without_movable_joints_is_an_error(tmp_path):
    rigid = urdf(tmp_path / "rigid.urdf", link("a"), link("b"), joint("f", "fixed", "a", "b", limit=""))
    out = run_twin("info", str(rigid))
    assert out.returncode == 2
    assert out.stderr.strip().splitlines()[-1] == (
        f"twin: error: {rigid}: has no movable joint (prismatic or revolute): nothing to drive")


def test_twin_info_warns_when_no_finger_is_detected(tmp_path):
    g = two_jaws(tmp_path / "g.urdf", collision=False)
    out = run_twin("info", str(g))
    assert out.returncode == 0, out.stderr
    assert "fingers (0)" in out.stdout and "warning: no finger detected" in out.stdout
    out = run_twin("info", str(g), "--json")
    assert json.loads(out.stdout)["fingers"] == [] and "warning: no finger detected" in out.stderr


@pytest.mark.parametrize("name", ["Active", "doGripped", "GrippedPart"])
def test_a_link_named_like_a_built_in_signal_is_refused(tmp_path, name):
    with pytest.raises(MechanismError, match=f"link '{name}' .*one of the twin's own signals"):
        load_mechanism(two_jaws(tmp_path / "g.urdf", a=name))


def test_twin_info_names_what_it_needs_for_anything_else(tmp_path):
    sdf = tmp_path / "gripper.sdf"
    sdf.write_text("<sdf/>")
    out = run_twin("info", str(sdf))
    assert out.returncode == 2
    assert out.stderr.strip() == (f"twin: error: {sdf}: twin info needs a gripper .urdf, a station folder or a "
                                  "station.toml, not a .sdf")
    out = run_twin("info", str(tmp_path))  # a folder, but not a station
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "a folder without station.toml: twin info needs a gripper .urdf" in out.stderr
    (tmp_path / "dir.urdf").mkdir()
    out = run_twin("info", str(tmp_path / "dir.urdf"))
    assert out.returncode == 2 and out.stderr.strip() == f"twin: error: {tmp_path / 'dir.urdf'}: is a folder, not a URDF file"


def test_planar_and_floating_joints_are_rigid_and_twin_info_says_so(tmp_path):
    g = urdf(tmp_path / "pf.urdf", link("root"), joint("pl", "planar", "root", "carriage", limit=""), link("carriage"),
             joint("fl", "floating", "root", "puck", limit=""), link("puck"),
             joint("slide", "prismatic", "root", "jaw"), link("jaw"))
    mech = load_mechanism(g)
    assert [i.name for i in mech.inputs] == ["jaw"]
    assert mech.rigid_joints == (("pl", "planar"), ("fl", "floating"))
    out = run_twin("info", str(g))
    assert "joint pl (planar), joint fl (floating): treated as rigid" in out.stdout
    assert "only prismatic, revolute and continuous joints become inputs" in out.stdout


def test_an_unknown_joint_type_is_refused_not_taken_for_rigid(tmp_path):
    g = urdf(tmp_path / "typo.urdf", link("root"), joint("j", "revolut", "root", "jaw"), link("jaw"))
    with pytest.raises(MechanismError, match="joint 'j': type 'revolut' is not a URDF joint type"):
        load_mechanism(g)


def test_a_continuous_joint_gets_plus_minus_pi_and_says_so(tmp_path):
    g = urdf(tmp_path / "spin.urdf", link("root"), joint("spin", "continuous", "root", "rotor", limit=""), link("rotor"))
    inp = load_mechanism(g).input("rotor")
    assert (inp.min, inp.max, inp.unit) == (-math.pi, math.pi, "rad")
    assert "continuous" in inp.note and "-pi to pi" in inp.note
    assert "note: input rotor: continuous joint: range -pi to pi" in run_twin("info", str(g)).stdout


def chain_mimic(tmp_path, m1_limits='lower="-2" upper="2"'):
    return urdf(tmp_path / "cm.urdf", link("b"),
                joint("m0", "revolute", "b", "l0", limit='lower="0" upper="1"'), link("l0"),
                joint("m1", "revolute", "b", "l1", limit=m1_limits, extra='<mimic joint="m0" multiplier="2" offset="0.1"/>'),
                link("l1"),
                joint("m2", "revolute", "l1", "l2", limit='lower="-5" upper="5"', extra='<mimic joint="m1" multiplier="-1"/>'),
                link("l2"))


def test_the_master_range_is_narrowed_so_that_every_mimic_follower_stays_within_its_limits(tmp_path):
    mech = load_mechanism(chain_mimic(tmp_path))
    inp = mech.input("l0")
    assert (inp.min, inp.max) == (0.0, pytest.approx(0.95))  # m1 = 2 q + 0.1 <= 2
    assert "narrowed" in inp.note and "m1" in inp.note
    assert "note: input l0: range narrowed from the URDF's 0 to 1" in run_twin("info", str(tmp_path / "cm.urdf")).stdout


def test_a_follower_that_cannot_stay_within_its_limits_is_refused(tmp_path):
    with pytest.raises(MechanismError, match="mimic joint 'm1'.* cannot stay within its limits 3 to 4"):
        load_mechanism(chain_mimic(tmp_path, 'lower="3" upper="4"'))


def test_shipped_and_foreign_mimic_grippers_keep_their_urdf_ranges():
    for urdf_path in (STATIONS / "smart_gripper" / "smart_gripper.urdf", PYBULLET_DATA / "xarm" / "xarm6_with_gripper.urdf"):
        assert all(not i.note for i in load_mechanism(urdf_path).inputs)


def test_a_station_may_name_a_finger_by_any_link_of_its_rigid_group():
    urdf_path = PYBULLET_DATA / "pr2_gripper.urdf"
    mech = load_mechanism(urdf_path, ("left_tip", "right_gripper"))
    assert [(f.name, f.links) for f in mech.fingers] == [
        ("left_gripper", ("left_gripper", "left_tip")), ("right_gripper", ("right_gripper", "right_tip"))]
    with pytest.raises(MechanismError, match="'left_tip' is finger 'left_gripper', which is already named"):
        load_mechanism(urdf_path, ("left_gripper", "left_tip"))
