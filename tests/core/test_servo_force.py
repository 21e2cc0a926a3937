"""The drives and the measured forces, against statics: a finger's force is the normal force of its contacts,
its drive's effort what the motor applies, and a finger pressing on a part presses with its stiffness times
how far its setpoint lies past the part, up to the effort limit."""
import shutil

import pytest

from tests.conftest import STATIONS
from twin.core import Twin

FOUR = STATIONS / "four_finger"  # 4 fingers, URDF effort 40 N, velocity 0.05 m/s; the puck's radius is 40 mm
FINGERS = ("F1", "F2", "F3", "F4")


def four_finger(tmp_path, **override):
    folder = tmp_path / ("four_" + "_".join(f"{k}{v}" for k, v in override.items()))
    shutil.copytree(FOUR, folder)
    if override:
        toml = folder / "station.toml"
        lines = "\n".join(f"{k} = {v}" for k, v in override.items())
        tables = "\n".join(f"[gripper.joints.{f}]\n{lines}" for f in FINGERS)
        toml.write_text(toml.read_text().replace("[[targets]]", tables + "\n\n[[targets]]", 1))
    return Twin.from_station(folder)


def squeeze(twin, setpoint, seconds=2.0):
    for f in FINGERS:
        twin.write(f, setpoint)
    twin.step(round(seconds / twin.dt))
    return twin.read("F1.force")


def test_the_force_builds_with_the_squeeze_up_to_the_effort_limit_at_any_speed(tmp_path):
    for velocity in (0.05, 0.2):
        with four_finger(tmp_path, velocity=velocity) as twin:
            f = [squeeze(twin, sp) for sp in (0.041, 0.0402, 0.0397, 0.0394, 0.0)]
        assert f[0] == 0.0 and f[1] == 0.0  # 1 mm and 0.2 mm short of the puck: nothing
        assert 0.0 < f[2] < f[3] < f[4]  # further past the puck's side: more force
        assert f[4] == pytest.approx(40.0, rel=0.05)  # far past: the effort limit, however fast the finger


def test_the_forces_on_a_part_squeezed_at_the_effort_limit_add_up_to_the_drives_limits(tmp_path):
    with four_finger(tmp_path, effort=60.0) as twin:
        squeeze(twin, 0.0)
        forces = [twin.read(f"{f}.force") for f in FINGERS]
        efforts = [-twin.read(f"{f}.effort") for f in FINGERS]
        assert sum(forces) == pytest.approx(4 * 60.0, rel=0.1)
        assert forces == pytest.approx(efforts, rel=0.1)  # what the drives push is what the part feels
        assert twin.read("F1.actual") == pytest.approx(0.040, abs=0.0015)  # stopped at the puck's side


def test_a_free_finger_reads_nothing_even_while_moving(tmp_path):
    with four_finger(tmp_path) as twin:
        for f in FINGERS:
            twin.write(f, 0.1)
        worst_force = worst_effort = 0.0
        for _ in range(30):  # 20 mm at 50 mm/s: moving the whole time
            twin.step()
            worst_force = max(worst_force, twin.read("F1.force"))
            worst_effort = max(worst_effort, abs(twin.read("F1.effort")))
        assert twin.read("F1.moving") and worst_force == 0.0 and worst_effort < 0.1 * 40.0


def test_opening_from_a_hard_squeeze_acts_at_once(tmp_path):
    with four_finger(tmp_path) as twin:
        squeeze(twin, 0.0)
        for f in FINGERS:
            twin.write(f, 0.08)
        twin.step(round(0.25 / twin.dt))
        assert twin.read("F1.actual") > 0.045  # already moving away: the command did not run on to 0
        assert twin.read("F1.force") == 0.0 and not twin.read("doGripped")


def test_a_stiffer_drive_presses_harder_for_the_same_setpoint(tmp_path):
    forces = {}
    for stiffness in (10000.0, 20000.0):  # N/m: 10 and 20 N per mm past the part
        with four_finger(tmp_path, stiffness=stiffness) as twin:
            forces[stiffness] = squeeze(twin, 0.0385, seconds=3.0)  # 1.5 mm past the puck's side
    assert forces[20000.0] > 1.5 * forces[10000.0]
    assert forces[10000.0] == pytest.approx(15.0, rel=0.3)  # 10 N/mm x ~1.5 mm (less what the contact gives)
