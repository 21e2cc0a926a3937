"""Mechanism discovery: inputs per independent joint, mimic joints, fingers, on our and foreign URDFs."""
import json
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
    with pytest.raises(MechanismError, match="'hub' is not the child link of a movable joint"):
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
