"""Grip by physics (issue 9), in real pybullet physics, against statics and geometry: friction holds what
mu x sum(N) can carry and drops what it cannot, with doGripped and slip telling the PLC; setpoints short of a
part give no grip; the per-finger object status; contact onset on faces, edges and corners; start overlaps."""
import itertools
import math
import shutil

import pybullet
import pytest

from tests.conftest import ROOT, STATIONS
from twin.core import Twin
from twin.core.errors import StationError
from tests.station_copies import edited_station

RING_RIG = STATIONS / "ring_rig"
G = 9.81
MU = 1.0 * 0.4  # the ring rig's finger pads on the steel ring (pybullet multiplies the two)
FINGERS3 = ("L2", "L3", "L5")


def ring_rig_with_drives(tmp_path, effort: float) -> Twin:
    """The ring rig with weaker (or stronger) finger drives that reach `effort` 1 mm past the ring."""
    folder = tmp_path / f"rig_{effort:g}"
    shutil.copytree(RING_RIG, folder)
    toml = folder / "station.toml"
    text = toml.read_text().replace("effort = 4000.0", f"effort = {effort}")
    text = text.replace('"../robots/arm6700.urdf"', f'"{STATIONS / "robots" / "arm6700.urdf"}"')
    text = text.replace('program = "ring_rig.mod"', f'program = "{RING_RIG / "ring_rig.mod"}"')
    text = text.replace("stiffness = 2.5e6", f"stiffness = {effort * 1000.0}")
    text = text.replace("grip_force = 1500.0", "#")
    toml.write_text(text)
    return Twin.from_station(folder)


def grip_from_outside(twin: Twin) -> float:
    """Close the fingers 5 mm past the ring (full effort) where it lies; the ring's weight (N)."""
    for f in ("L2", "L3", "L4"):
        twin.write(f, 0.315)
    twin.step(round(1.5 / twin.dt))
    mass = twin.world.client.getDynamicsInfo(twin.world.body_ids["ring"], -1)[0]
    return mass * G


def lift(twin: Twin, speed: float):
    """MoveL up to the approach at `speed`; per step (doGripped, slip, ring z - tcp z)."""
    twin.move("MoveL", "app_right", speed)
    trace = []
    while twin.robot_busy:
        twin.step()
        trace.append((twin.read("doGripped"), twin.read("slip"), twin.read("ring.z") - twin.tcp_pose().position[2]))
    return trace


def test_a_grip_whose_friction_capacity_is_below_the_weight_drops_the_ring_with_slip_raised(tmp_path):
    with ring_rig_with_drives(tmp_path, 400.0) as twin:
        weight = grip_from_outside(twin)
        forces = [twin.read(f"{f}.force") for f in FINGERS3]
        assert twin.read("doGripped") and not twin.read("slip")
        assert MU * sum(forces) < 0.8 * weight  # statics: the fingers cannot carry it
        trace = lift(twin, 0.5)
        assert any(slip and gripped for gripped, slip, _ in trace)  # it slipped while still gripped...
        assert not trace[-1][0] and trace[-1][1]  # ...then doGripped fell, and slip stays raised
        assert twin.read("ring.z") < 0.2  # the ring stayed on the pallet (the TCP went up to 0.58)


def test_three_times_the_weight_in_friction_holds_through_a_movel_at_v1000(tmp_path):
    effort = 3 * 66.0 * G / (3 * MU)  # per finger: mu x 3 x effort = 3 x the ring's weight
    with ring_rig_with_drives(tmp_path, effort) as twin:
        weight = grip_from_outside(twin)
        forces = [twin.read(f"{f}.force") for f in FINGERS3]
        assert MU * sum(forces) == pytest.approx(3 * weight, rel=0.1)  # measured forces: the drives' limits
        trace = lift(twin, 1.0)
        assert all(gripped and not slip for gripped, slip, _ in trace)
        moved = max(abs(dz - trace[0][2]) for _, _, dz in trace)
        assert moved < 0.002  # the ring stayed within 2 mm of where it was gripped, relative to the tool
        assert twin.read("ring.z") == pytest.approx(0.58, abs=0.003)


def test_setpoints_two_tenths_of_a_millimetre_short_of_a_part_give_no_grip():
    with Twin.from_station(STATIONS / "four_finger") as twin:  # the puck's radius is 40 mm
        for f in ("F1", "F2", "F3", "F4"):
            twin.write(f, 0.0402)
        twin.step(round(2.0 / twin.dt))
        assert not twin.read("doGripped") and twin.read("GrippedPart") == ""
        for f in ("F1", "F2", "F3", "F4"):
            assert not twin.read(f"{f}.contact") and twin.read(f"{f}.force") == 0.0
            assert twin.read(f"{f}.status") == 3  # at its setpoint, in free air


def test_object_status_closing_on_a_part_moving_and_in_free_air():
    with Twin.from_station(STATIONS / "four_finger") as twin:
        assert twin.read("F1.status") == 3  # at its setpoint
        for f in ("F1", "F2", "F3", "F4"):
            twin.write(f, 0.0)
        twin.step(5)
        assert twin.read("F1.status") == 0  # moving towards the setpoint
        twin.step(round(1.5 / twin.dt))
        assert [twin.read(f"{f}.status") for f in ("F1", "F2", "F3", "F4")] == [2, 2, 2, 2]  # stopped closing
        for f in ("F1", "F2", "F3", "F4"):
            twin.write(f, 0.07)
        twin.step(round(1.5 / twin.dt))
        assert [twin.read(f"{f}.status") for f in ("F1", "F2", "F3", "F4")] == [3, 3, 3, 3]


def test_object_status_opening_into_a_bore():
    with Twin.from_station(ROOT / "tests" / "plc" / "stations" / "ring_bench_inside") as twin:
        for f in ("L2", "L3", "L4"):
            twin.write(f, 0.230)  # the bore is at 200 mm (+ 40 mm finger): opening stops at the ring
        twin.step(round(1.5 / twin.dt))
        assert twin.read("L2.status") == 1 and twin.read("L3.status") == 1  # stopped by contact while opening
        assert twin.read("doGripped") and twin.read("L2.force") > 0.1 * 1500


# -- contact onset against the nominal geometry -----------------------------------------------------------
FINGER_HALF = 0.01  # the finger is a 20 mm cube
TARGET_HALF = 0.02  # the target a 40 mm cube, floating (no gravity) at x = 0.15


def leading_extent(rpy, half, sign):
    """How far a cube of half-size `half` turned by `rpy` (degrees) reaches along +x (sign 1) or -x (sign -1)."""
    m = pybullet.getMatrixFromQuaternion(pybullet.getQuaternionFromEuler([math.radians(a) for a in rpy]))
    xs = [m[0] * a * half + m[1] * b * half + m[2] * c * half for a, b, c in itertools.product((-1, 1), repeat=3)]
    return max(xs) if sign > 0 else -min(xs)


def onset_station(tmp_path, finger_rpy, target_rpy, grip):
    gap = 0.003
    finger_reach = leading_extent(finger_rpy, FINGER_HALF, +1)
    target_reach = leading_extent(target_rpy, TARGET_HALF, -1)
    contact_at = 0.15 - target_reach - finger_reach  # the joint value at which the shapes touch
    folder = tmp_path / f"onset_{grip}_{'_'.join(map(str, finger_rpy))}_{'_'.join(map(str, target_rpy))}"
    folder.mkdir()
    box = f'<box size="{2 * FINGER_HALF} {2 * FINGER_HALF} {2 * FINGER_HALF}"/>'
    (folder / "slide.urdf").write_text(f"""<?xml version="1.0"?>
<robot name="slide">
  <link name="palm"><inertial><mass value="1"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="palm"/><child link="finger"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" effort="20" velocity="0.002"/></joint>
  <link name="finger"><inertial><mass value="0.1"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
    <collision><origin rpy="{' '.join(str(math.radians(a)) for a in finger_rpy)}"/><geometry>{box}</geometry></collision></link>
</robot>
""")
    (folder / "station.toml").write_text(f"""[station]
gravity = [0.0, 0.0, 0.0]
[gripper]
urdf = "slide.urdf"
always_active = true
grip = "{grip}"
initial = {{ finger = {contact_at - gap!r} }}
[[targets]]
name = "block"
shape = "box"
size = [{2 * TARGET_HALF}, {2 * TARGET_HALF}, {2 * TARGET_HALF}]
xyz = [0.15, 0.0, 0.0]
rpy_deg = [{', '.join(map(str, target_rpy))}]
density = 1000.0
""")
    return folder, contact_at


CORNER = (45.0, 54.73561, 0.0)  # a cube turned so that one corner leads along x (a body diagonal on the x axis)
EDGE = (0.0, 0.0, 45.0)  # turned so that one edge leads


@pytest.mark.parametrize("grip", ["attach", "friction"])
@pytest.mark.parametrize("finger_rpy,target_rpy", [((0, 0, 0), (0, 0, 0)), ((0, 0, 0), EDGE), ((0, 0, 0), CORNER),
                                                   (EDGE, (0, 0, 0)), (CORNER, (0, 0, 0))],
                         ids=["face", "target-edge", "target-corner", "finger-edge", "finger-corner"])
def test_contact_turns_on_within_half_a_millimetre_of_true_contact_and_never_before(tmp_path, grip, finger_rpy,
                                                                                   target_rpy):
    folder, contact_at = onset_station(tmp_path, finger_rpy, target_rpy, grip)
    with Twin.from_station(folder) as twin:
        twin.write("finger", 0.2)  # towards the block at 2 mm/s: 0.024 mm per step
        for _ in range(round(2.0 / twin.dt)):
            twin.step()
            if twin.read("finger.contact"):
                break
        assert twin.read("finger.contact"), "no contact at all"
        past = twin.read("finger.actual") - contact_at  # how far past true contact the flag came on
        slack = 0.0 if grip == "attach" else 0.00005  # friction mode: pybullet holds pressed contacts 0.02 mm apart
        assert -slack - 1e-6 <= past <= 0.0005


# -- newcomer traps --------------------------------------------------------------------------------------------
def four_finger_with(tmp_path, old: str, new: str):
    return edited_station(STATIONS / "four_finger", tmp_path / "four", old, new)


def test_a_target_overlapping_a_finger_at_the_start_is_an_error_naming_both(tmp_path):
    folder = four_finger_with(tmp_path, "initial = { F1 = 0.08,", "initial = { F1 = 0.035,")  # 5 mm into the puck
    with pytest.raises(StationError) as err:
        Twin.from_station(folder)
    msg = str(err.value)
    assert "targets[0]" in msg and "'puck'" in msg and "'F1'" in msg and "overlaps" in msg and "mm" in msg


def test_a_target_overlapping_a_fixture_at_the_start_is_an_error_naming_both(tmp_path):
    folder = four_finger_with(tmp_path, "xyz = [0.0, 0.0, 0.025]", "xyz = [0.0, 0.0, 0.015]")  # 10 mm into the floor
    with pytest.raises(StationError, match=r"'puck' overlaps fixture 'floor' by 10\.0 mm"):
        Twin.from_station(folder)


def test_a_station_may_name_a_urdf_shipped_with_pybullet(tmp_path):
    folder = tmp_path / "pr2"
    folder.mkdir()
    (folder / "station.toml").write_text('[station]\n[gripper]\nurdf = "pybullet_data:pr2_gripper.urdf"\nalways_active = true\n')
    with Twin.from_station(folder) as twin:
        assert [s.name for s in twin.signals if s.direction == "input" and s.name != "Active"]
    (folder / "station.toml").write_text('[station]\n[gripper]\nurdf = "pybullet_data:no_such_gripper.urdf"\n')
    with pytest.raises(StationError, match=r"gripper\.urdf: pybullet ships no 'no_such_gripper\.urdf'"):
        Twin.from_station(folder)
