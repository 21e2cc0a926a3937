"""A finger's force is its servo's: it builds with the following error against a part, up to the effort limit,
whatever the finger's speed or mass, and a free finger reads almost nothing (the PLC's torque threshold)."""
import shutil

import pytest

from tests.conftest import STATIONS
from twin.core import Twin

FOUR = STATIONS / "four_finger"  # 4 fingers, URDF effort 40 N, velocity 0.05 m/s; the puck's radius is 40 mm


def four_finger(tmp_path, velocity=None, effort=None):
    folder = tmp_path / f"four_{velocity}_{effort}"
    shutil.copytree(FOUR, folder)
    if velocity or effort:
        toml = folder / "station.toml"
        parts = [f"velocity = {velocity}" if velocity else "", f"effort = {effort}" if effort else ""]
        overrides = "\n".join(f"[gripper.joints.F{i}]\n" + "\n".join(p for p in parts if p) for i in range(1, 5))
        text = toml.read_text().replace("[[targets]]", overrides + "\n\n[[targets]]", 1)
        toml.write_text(text)
    return Twin.from_station(folder)


def squeeze(twin, setpoint, seconds=2.0):
    for f in ("F1", "F2", "F3", "F4"):
        twin.write(f, setpoint)
    twin.step(round(seconds / twin.dt))
    return twin.read("F1.force")


def test_the_force_builds_with_the_squeeze_up_to_the_effort_limit_at_any_speed(tmp_path):
    for velocity in (0.01, 0.05, 0.2):
        with four_finger(tmp_path, velocity=velocity) as twin:
            f = [squeeze(twin, sp) for sp in (0.041, 0.039, 0.0385, 0.037, 0.0)]
        assert f[0] == pytest.approx(0.0, abs=0.5)  # 1 mm short of the puck: nothing
        assert f[1] <= f[2] <= f[3] <= f[4] and f[2] > 0.0  # further past the puck's side: more force
        assert f[4] == pytest.approx(40.0, abs=0.5)  # far past: the effort limit, however fast the finger


@pytest.mark.parametrize("effort", [10.0, 400.0])
def test_squeezing_hard_reaches_the_effort_limit_and_no_more(tmp_path, effort):
    with four_finger(tmp_path, effort=effort) as twin:
        assert squeeze(twin, 0.0) == pytest.approx(effort, rel=0.02)
        assert twin.read("F1.actual") == pytest.approx(0.040, abs=0.0015)  # stopped at the puck's side


def test_a_free_finger_reads_almost_nothing_even_while_moving(tmp_path):
    with four_finger(tmp_path) as twin:
        for f in ("F1", "F2", "F3", "F4"):
            twin.write(f, 0.1)
        worst = 0.0
        for _ in range(30):  # 20 mm at 50 mm/s: moving the whole time
            twin.step()
            worst = max(worst, twin.read("F1.force"))
        assert twin.read("F1.moving") and worst < 0.05 * 40.0


def test_opening_from_a_hard_squeeze_acts_at_once(tmp_path):
    with four_finger(tmp_path) as twin:
        squeeze(twin, 0.0)
        for f in ("F1", "F2", "F3", "F4"):
            twin.write(f, 0.08)
        twin.step(round(0.25 / twin.dt))
        assert twin.read("F1.actual") > 0.045  # already moving away: the command did not run on to 0
        assert twin.read("F1.force") < 2.0 and not twin.read("doGripped")


def test_a_held_part_is_not_squeezed_into_the_fingers(tmp_path):
    with four_finger(tmp_path, effort=400.0) as twin:
        squeeze(twin, 0.0, seconds=4.0)  # far past the puck's side, for seconds, with 400 N
        assert twin.read("doGripped") and twin.read("F1.force") == pytest.approx(400.0)
        for f in ("F1", "F2", "F3", "F4"):
            assert twin.read(f"{f}.actual") == pytest.approx(0.040, abs=0.0003)  # at the puck's side, not in it
