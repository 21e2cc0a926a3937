"""Drives standing quiet at their goals rest (gripper.py `_still_resting`): pybullet's position motor holds them and
the drive loop does not run. What a user sees must not change: fingers stay where they were sent, a new setpoint,
`Active` or limit acts at the next step, and a push on a resting finger is resisted as before."""
import shutil

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


def test_a_resting_drive_answers_a_new_setpoint_at_the_next_step():
    # the URDF's 50 mm/s velocity limit: a step of 12 ms moves the finger 0.6 mm towards a new setpoint, from rest
    with Twin.from_station(GRIPPERS["newcomer_2f"]) as tw:
        tw.step(50)
        assert resting(tw)
        before = tw.read("finger_left.actual")
        tw.write("finger_left", 0.02)
        tw.step()
        moved = before - tw.read("finger_left.actual")
        assert 0.3 * 0.05 * tw.dt <= moved <= 1.05 * 0.05 * tw.dt, moved
        tw.step(round(0.3 / tw.dt))
        assert abs(tw.read("finger_left.actual") - 0.02) <= IN_POSITION_TOLERANCE["m"]


def test_a_resting_gripper_made_inactive_holds_and_made_active_moves_at_the_next_step(tmp_path):
    # docs/signals.md: an inactive gripper holds its fingers where they are; its setpoints act once it is active
    source = GRIPPERS["newcomer_2f"]
    station = tmp_path / "newcomer_2f"
    shutil.copytree(source, station)
    toml = station / "station.toml"
    arm = (source / "../../../stations/robots/arm6700.urdf").resolve()
    toml.write_text(toml.read_text().replace("always_active = true", "always_active = false")
                    .replace('"../../../stations/robots/arm6700.urdf"', f'"{arm}"'))
    with Twin.from_station(station) as tw:
        tw.write("Active", True)
        tw.step(50)
        assert resting(tw)
        before = tw.read("finger_left.actual")
        tw.write("Active", False)
        tw.write("finger_left", 0.02)
        tw.step(20)
        assert abs(tw.read("finger_left.actual") - before) <= IN_POSITION_TOLERANCE["m"]
        tw.write("Active", True)
        tw.step()
        moved = before - tw.read("finger_left.actual")
        assert 0.3 * 0.05 * tw.dt <= moved <= 1.05 * 0.05 * tw.dt, moved


def test_a_resting_drive_given_a_lower_velocity_limit_moves_at_it():
    # 10 mm/s set while the drive rests: ten steps of 12 ms later the finger has moved 1.2 mm, not the 6 mm its
    # URDF's 50 mm/s would give (the first step starts from rest: a fifth of a step's travel allowed for it)
    with Twin.from_station(GRIPPERS["newcomer_2f"]) as tw:
        tw.step(50)
        assert resting(tw)
        tw.set_drive_limits("finger_left", velocity=0.01)
        tw.step(5)
        before = tw.read("finger_left.actual")
        tw.write("finger_left", 0.02)
        tw.step(10)
        moved = before - tw.read("finger_left.actual")
        assert 0.8 * 0.01 * 10 * tw.dt <= moved <= 1.05 * 0.01 * 10 * tw.dt, moved
