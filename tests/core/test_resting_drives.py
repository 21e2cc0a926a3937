"""Drives standing quiet at their goals rest (gripper.py `_still_resting`): pybullet's position motor holds them and
the drive loop does not run. What a user sees must not change: fingers stay where they were sent, a new setpoint,
`Active` or limit acts at the next step, and a push on a resting finger is resisted as before."""
import pytest

from tests.grippers import GRIPPERS
from twin.core import Twin
from twin.core.signal_table import IN_POSITION_TOLERANCE


def resting(twin: Twin) -> bool:
    return twin.gripper._resting is not None


def test_fingers_at_rest_stay_at_their_setpoints_for_a_minute():
    # a minute of simulated time at rest, the arm holding: no finger moves off its setpoint by more than the
    # in-position tolerance, and every one reads in position, not moving, status 3
    with Twin.from_station(GRIPPERS["newcomer_2f"]) as tw:
        tw.step(50)
        assert resting(tw)  # (else this test proves nothing about resting drives)
        for _ in range(round(60.0 / tw.dt)):
            tw.step()
        for f in ("finger_left", "finger_right"):
            assert abs(tw.read(f + ".actual") - 0.03) <= IN_POSITION_TOLERANCE["m"]
            assert tw.read(f + ".in_position") and not tw.read(f + ".moving") and tw.read(f + ".status") == 3


@pytest.mark.parametrize("write", ["setpoint", "inactive"])
def test_a_resting_drive_answers_a_new_setpoint_at_the_next_step(write):
    # the URDF's 50 mm/s velocity limit: a step of 12 ms moves the finger 0.6 mm towards a new setpoint, from rest
    with Twin.from_station(GRIPPERS["newcomer_2f"]) as tw:
        tw.step(50)
        assert resting(tw)
        before = tw.read("finger_left.actual")
        tw.write("finger_left", 0.02)
        if write == "inactive":  # (an always-active gripper ignores Active: the setpoint acts all the same)
            tw.write("Active", False)
        tw.step()
        moved = before - tw.read("finger_left.actual")
        assert 0.3 * 0.05 * tw.dt <= moved <= 1.05 * 0.05 * tw.dt, moved
        tw.step(round(0.3 / tw.dt))
        assert abs(tw.read("finger_left.actual") - 0.02) <= IN_POSITION_TOLERANCE["m"]


def test_a_resting_drive_given_a_lower_velocity_limit_moves_at_it():
    with Twin.from_station(GRIPPERS["newcomer_2f"]) as tw:
        tw.step(50)
        assert resting(tw)
        tw.set_drive_limits("finger_left", velocity=0.01)
        before = tw.read("finger_left.actual")
        tw.write("finger_left", 0.02)
        tw.step(10)
        moved = before - tw.read("finger_left.actual")
        assert moved <= 1.05 * 0.01 * 10 * tw.dt, moved
