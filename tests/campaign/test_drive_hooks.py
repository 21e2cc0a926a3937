"""The core's small hooks for fault injection: drive limits changed at run time, readings overridden."""
import pytest

from tests.conftest import ROOT
from twin.core import Twin
from twin.core.errors import SignalError

BENCH = ROOT / "tests" / "plc" / "stations" / "ring_bench"  # fingers at 330 mm around a ring of radius 320 mm


def squeeze(twin, steps=150):
    for name in ("L2", "L3", "L4"):
        twin.write(name, 0.300)  # 20 mm inside the ring's surface: every finger presses on it
    twin.step(steps)


def test_a_lower_effort_limit_presses_with_less_force():
    with Twin.from_station(BENCH) as full, Twin.from_station(BENCH) as weak:
        _, effort = full.drive_limits("L2")
        weak.set_drive_limits("L2", effort=effort / 4)
        assert weak.drive_limits("L2") == (full.drive_limits("L2")[0], effort / 4)
        squeeze(full), squeeze(weak)
        # a blocked servo reads its effort limit: the weakened one a quarter of the other's
        assert full.read("L2.force") == pytest.approx(effort, rel=0.02)
        assert weak.read("L2.force") == pytest.approx(effort / 4, rel=0.05)


def test_a_lower_velocity_limit_moves_slower():
    with Twin.from_station(BENCH) as twin:
        velocity, _ = twin.drive_limits("L2")
        twin.set_drive_limits("L2", velocity=velocity / 10)
        twin.write("L2", 0.34)
        twin.write("L3", 0.34)
        twin.step(25)  # 0.3 s
        moved_l2, moved_l3 = twin.read("L2.actual") - 0.33, twin.read("L3.actual") - 0.33
        assert moved_l3 == pytest.approx(min(0.01, velocity * 0.3), abs=0.001)
        assert moved_l2 == pytest.approx(velocity / 10 * 0.3, rel=0.15)


def test_bad_limits_and_overrides_are_refused():
    with Twin.from_station(BENCH) as twin:
        with pytest.raises(ValueError, match="effort"):
            twin.set_drive_limits("L2", effort=-1.0)
        with pytest.raises(SignalError):
            twin.set_drive_limits("nope", effort=1.0)
        with pytest.raises(SignalError, match="input"):
            twin.override_outputs({"L2": 0.1})


def test_an_overridden_reading_lasts_until_the_next_step():
    with Twin.from_station(BENCH) as twin:
        twin.step(1)
        twin.override_outputs({"L2.force": 123.0})
        assert twin.read("L2.force") == 123.0
        twin.step(1)
        assert twin.read("L2.force") == pytest.approx(0.0, abs=5.0)
