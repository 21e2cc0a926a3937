"""The gripper's behaviour in real pybullet physics, on small stations (no robot: fast)."""
import math

import pytest

from tests.conftest import STATIONS
from twin.core import Twin, load_station
from twin.core.errors import SignalError, SignalRangeError

FOUR = STATIONS / "four_finger"
FINGERS4 = ("F1", "F2", "F3", "F4")


def settle(twin, seconds):
    twin.step(round(seconds / twin.dt))


@pytest.fixture
def four():
    with Twin.from_station(FOUR) as twin:
        yield twin


def close_all(twin, value=0.0, fingers=FINGERS4):
    for f in fingers:
        twin.write(f, value)


def test_parallel_gripper_grips_the_cube_with_its_one_input_and_lets_go_when_opened():
    with Twin.from_station(STATIONS / "smart_gripper") as twin:
        assert [s.name for s in twin.signals if s.direction == "input" and s.group == "gripper"] == ["Active", "jaw_left"]
        twin.write("jaw_left", 0.0)
        settle(twin, 1.0)
        assert twin.read("doGripped") and twin.read("GrippedPart") == "cube"
        # both jaws stopped on the 20 mm cube: the input's actual position is its half width
        assert twin.read("jaw_left.actual") == pytest.approx(0.010, abs=0.0015)
        # one 5 N motor drives both jaws through a 1:1 linkage: statics splits it, 2.5 N on each jaw
        assert twin.read("jaw_left.force") + twin.read("jaw_right.force") == pytest.approx(5.0, rel=0.1)
        assert twin.read("jaw_left.force") == pytest.approx(2.5, rel=0.1)
        twin.write("jaw_left", 0.025)
        settle(twin, 0.5)
        assert not twin.read("doGripped") and twin.read("GrippedPart") == ""
        assert not twin.read("jaw_left.contact") and not twin.read("jaw_right.contact")


def test_parallel_gripper_set_to_11_mm_opens_each_jaw_to_11_mm():
    with Twin.from_station(STATIONS / "smart_gripper") as twin:
        twin.write("jaw_left", 0.011)
        settle(twin, 1.0)
        assert twin.read("jaw_left.actual") == pytest.approx(0.011, abs=2e-4)
        assert twin.read("jaw_left.in_position") and not twin.read("jaw_left.moving")
        body, joints = twin.world.machine, twin.world.joint_index
        right = twin.world.client.getJointState(body, joints["jaw_right_joint"])[0]
        assert right == pytest.approx(0.011, abs=2e-4)  # the mimic jaw followed


def test_a_finger_at_its_setpoint_squeezed_by_the_others_reads_their_force(four):
    four.write("F4", 0.040)  # F4 stands at the puck's side, F1 and F3 stay open: F2 pushes the puck against F4
    four.write("F2", 0.0)
    settle(four, 3.0)
    # statics: F4 carries what F2's drive pushes with (its 40 N effort), less the floor's friction on the puck
    assert four.read("F4.force") == pytest.approx(-four.read("F2.effort"), rel=0.1)
    assert four.read("F4.force") == pytest.approx(40.0, rel=0.1) and four.read("F4.contact")
    assert not four.read("doGripped")  # two fingers of four: no grip


def test_four_fingers_grip_when_all_four_press_and_let_go_when_one_opens(four):
    close_all(four, 0.0)
    settle(four, 2.0)
    assert four.read("doGripped") and four.read("GrippedPart") == "puck"
    close_all(four, 0.08)
    settle(four, 1.0)
    assert not four.read("doGripped") and four.gripped_part == ""


def test_contact_turns_on_at_a_real_touch_never_before(four):
    four.write("F3", 0.040)  # F3 stands at the puck's far side
    four.write("F1", 0.041)  # the puck's radius is 40 mm: the finger's face stops 1 mm short
    settle(four, 2.0)
    assert four.read("F1.actual") == pytest.approx(0.041, abs=2e-4)
    assert not four.read("F1.contact")
    four.write("F1", 0.0402)  # 0.2 mm short: no contact, no force
    settle(four, 0.5)
    assert not four.read("F1.contact") and four.read("F1.force") == 0.0
    four.write("F1", 0.0395)  # 0.5 mm past the puck's side: it presses the puck against F3
    settle(four, 1.0)
    assert four.read("F1.contact") and four.read("F1.force") > 0.0


def test_servo_is_velocity_limited_and_stops_on_contact_with_force(four):
    start = four.read("F1.actual")
    four.write("F1", 0.0)
    four.step(1)
    # URDF velocity 0.05 m/s over one 12 ms step
    assert start - four.read("F1.actual") <= 0.05 * four.dt * 1.05
    assert four.read("F1.moving") and not four.read("F1.in_position")
    close_all(four)
    settle(four, 2.0)
    assert four.read("F1.actual") == pytest.approx(0.04, abs=0.002)  # stopped on the puck, not at 0
    assert four.read("F1.force") > 10.0  # pressing (URDF effort 40 N)
    close_all(four, 0.08)
    settle(four, 1.5)
    assert four.read("F1.force") == 0.0  # free again


def test_off_centre_part_is_pushed_to_the_centre_by_the_first_finger(tmp_path):
    station = (FOUR / "station.toml").read_text().replace("xyz = [0.0, 0.0, 0.025]", "xyz = [0.02, 0.0, 0.025]")
    path = tmp_path / "station.toml"
    path.write_text(station.replace('urdf = "gripper4.urdf"', f'urdf = "{FOUR / "gripper4.urdf"}"'))
    with Twin.from_station(path) as twin:
        close_all(twin, 0.03)
        first_touch = None
        for _ in range(300):
            twin.step(1)
            touching = [f for f, c in twin.finger_contacts().items() if c]
            if touching and first_touch is None:
                first_touch = touching
            if twin.read("doGripped"):
                break
        assert first_touch == ["F1"]  # the +x finger meets the part first
        (x, y, _), _ = twin.object_pose("puck")
        assert twin.read("doGripped")
        assert abs(x) < 0.002 and abs(y) < 0.002  # pushed along the floor into the centre


def test_an_object_outside_the_target_group_is_never_gripped(tmp_path):
    text = (FOUR / "station.toml").read_text().replace("[[targets]]", "[[fixtures]]")
    text = text.replace('urdf = "gripper4.urdf"', f'urdf = "{FOUR / "gripper4.urdf"}"')
    path = tmp_path / "station.toml"
    path.write_text(text)
    with Twin.from_station(path) as twin:
        close_all(twin)
        settle(twin, 2.0)
        assert twin.read("F1.actual") == pytest.approx(0.04, abs=0.002)  # physically blocked by it
        assert not twin.read("doGripped") and twin.read("GrippedPart") == ""
        assert not any(twin.read(f"{f}.contact") for f in FINGERS4)
        assert [s.choices for s in twin.signals if s.name == "GrippedPart"] == [("",)]


def test_setpoint_outside_the_range_is_rejected_naming_input_and_range(four):
    four.write("F2", 0.05)
    with pytest.raises(SignalRangeError, match=r"'F2'.*0\.2 m is outside the range 0 to 0\.1 m"):
        four.write("F2", 0.2)
    assert four.read("F2") == 0.05  # unchanged, not clamped
    with pytest.raises(SignalError, match="no such signal"):
        four.write("F9", 0.0)
    with pytest.raises(SignalError, match="output"):
        four.write("doGripped", True)


def test_fingers_hold_still_while_active_is_low(tmp_path):
    text = (FOUR / "station.toml").read_text().replace("always_active = true", "always_active = false")
    text = text.replace('urdf = "gripper4.urdf"', f'urdf = "{FOUR / "gripper4.urdf"}"')
    (tmp_path / "station.toml").write_text(text)
    with Twin.from_station(tmp_path) as twin:
        assert twin.read("Active") is False
        twin.write("F1", 0.06)
        settle(twin, 0.5)
        assert twin.read("F1.actual") == pytest.approx(0.08, abs=1e-4)
        twin.write("Active", True)
        settle(twin, 0.5)
        assert twin.read("F1.actual") == pytest.approx(0.06, abs=2e-4)
        twin.write("F1", 0.09)
        twin.step(3)
        twin.write("Active", False)
        held = twin.read("F1.actual")
        settle(twin, 0.5)
        assert twin.read("F1.actual") == pytest.approx(held, abs=5e-4)
        assert twin.read("F1.actual") < 0.09 - 0.005


def scenario(path):
    with Twin.from_station(path) as twin:
        close_all(twin, 0.0)
        settle(twin, 1.5)
        twin.write("F3", 0.08)
        settle(twin, 1.0)
        return twin.object_pose("puck"), twin.joint_positions(), twin.step_count


def test_two_runs_of_the_same_scenario_are_bit_identical():
    assert scenario(FOUR) == scenario(FOUR)


def test_signal_table_order_is_stable_and_complete(four):
    names = [s.name for s in four.signals]
    assert names[:5] == ["Active", "F1", "F2", "F3", "F4"]
    for f in FINGERS4:
        assert {f"{f}.actual", f"{f}.in_position", f"{f}.moving", f"{f}.contact", f"{f}.force"} <= set(names)
    assert [s.name for s in Twin.from_station(FOUR).signals] == names
    assert math.isclose(four.time, 0.0) and four.dt == load_station(FOUR).step
