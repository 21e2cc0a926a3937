"""The thesis rig with its robot: outside and inside grips, lifted, carried and released."""
import pytest

from tests.conftest import STATIONS
from twin.core import Twin
from twin.core.errors import MotionError
from stations.ring_rig.demo import FINGERS, Script

RIG = STATIONS / "ring_rig"


@pytest.fixture(scope="module")
def rig():
    with Twin.from_station(RIG) as twin:
        yield twin


def quiet_script(twin):
    s = Script(twin)
    s.say = lambda text: None
    return s


def test_outside_grip_lift_and_release(rig):
    s = quiet_script(rig)
    s.move("MoveJ", "app_right", 2.0)
    s.fingers_to(0.330)
    assert not rig.read("doGripped")
    s.move("MoveL", "grip_right", 0.5)
    assert not any(rig.read(f"{f}.contact") for f in ("L2", "L3", "L5"))  # 330 mm clears the outside
    assert s.grip(inside=False)
    assert rig.read("GrippedPart") == "ring"
    assert rig.read("L2.actual") == pytest.approx(0.320, abs=0.0015)  # closed below 330, on the 320 mm outside
    z0 = rig.object_pose("ring")[0][2]
    s.move("MoveL", "app_right", 0.5)
    (x, y, z), _ = rig.object_pose("ring")
    assert z == pytest.approx(z0 + 0.4, abs=0.005) and rig.read("doGripped")  # it came along
    s.move("MoveJ", "app_left", 2.0)
    s.move("MoveL", "grip_left", 0.5)
    s.release(inside=False)
    assert not rig.read("doGripped") and rig.read("GrippedPart") == ""
    assert rig.read("L2") <= 0.440  # opening towards 440 released it
    s.move("MoveL", "app_left", 0.5)
    (x, y, z), _ = rig.object_pose("ring")
    assert (x, y) == pytest.approx((1.6, 0.8), abs=0.005) and z == pytest.approx(0.18, abs=0.002)  # on the left pallet


def test_inside_grip_lift_and_release(rig):
    s = quiet_script(rig)  # continues from the previous test: the ring is on the left pallet
    s.fingers_to(0.150)
    s.move("MoveL", "grip_left", 0.5)
    assert not rig.read("doGripped")
    assert s.grip(inside=True)
    assert rig.read("L2.actual") == pytest.approx(0.200, abs=0.0015)  # opened in the bore: 200 + 40 = 240 mm
    s.move("MoveL", "app_left", 0.5)
    assert rig.object_pose("ring")[0][2] == pytest.approx(0.58, abs=0.005) and rig.read("doGripped")
    s.move("MoveJ", "app_right", 2.0)
    s.move("MoveL", "grip_right", 0.5)
    s.release(inside=True)
    assert not rig.read("doGripped")
    s.move("MoveL", "app_right", 0.5)
    (x, y, z), _ = rig.object_pose("ring")
    assert (x, y) == pytest.approx((1.6, -0.8), abs=0.005) and z == pytest.approx(0.18, abs=0.002)


def test_unreachable_target_is_an_error_naming_it(rig):
    from twin.core.geometry import Pose

    with pytest.raises(MotionError, match="far_away"):
        rig.move("MoveL", Pose.from_xyz_rpy((6.0, 0.0, 1.0), (3.14159, 0, 0)), 1.0, name="far_away")
    with pytest.raises(MotionError, match="no_such_target"):
        rig.move("MoveJ", "no_such_target", 1.0)

