"""The station's `[profile]` table: the shipped stations map, mistakes name the file and the key."""
from __future__ import annotations

import shutil

import pytest
from conftest import ROOT

from twin.core import Twin
from twin.core.errors import StationError
from twin.devices.robotiq import open_profile

SMART = ROOT / "stations" / "smart_gripper"


def _station(tmp_path, profile_text: str):
    folder = tmp_path / "sg"
    shutil.copytree(SMART, folder)
    toml = folder / "station.toml"
    text = toml.read_text()
    start = text.index("[profile]")
    end = text.index("[[targets]]")
    toml.write_text(text[:start] + profile_text + "\n" + text[end:])
    return folder


def test_shipped_stations_map():
    with Twin.from_station(SMART) as twin:
        g = open_profile(twin, "robotiq-2f")
        jaw = g.mapping.axes["jaw"]
        assert (jaw.input, jaw.open, jaw.closed) == ("jaw_left", 0.025, 0.0)
        assert jaw.speed == pytest.approx((0.05 * 20 / 150, 0.05))  # spec-sheet ratio, the URDF's 50 mm/s
        assert jaw.force == pytest.approx((5.0 * 20 / 235, 5.0))
        with pytest.raises(StationError, match=r"station\.toml: profile\.A: is required"):
            open_profile(twin, "robotiq-3f")
    with Twin.from_station(ROOT / "stations" / "ring_rig") as twin:
        g = open_profile(twin, "robotiq-3f")
        assert [g.mapping.axes[a].input for a in "ABC"] == ["L2", "L3", "L4"]
        assert g.axes["C"].fingers[0] == "L5"  # finger C rides on L4


@pytest.mark.parametrize("table, key, words", [
    ('[profile]\njaw = { input = "nope", open = 0.025, closed = 0.0 }', "profile.jaw.input", "not a joint input"),
    ('[profile]\njaw = { input = "jaw_left", open = 0.03, closed = 0.0 }', "profile.jaw.open", "outside"),
    ('[profile]\njaw = { input = "jaw_left", open = 0.01, closed = 0.01 }', "profile.jaw.closed", "must differ"),
    ('[profile]\njaw = { input = "jaw_left", open = 0.025, closed = 0.0, speed = [0.2, 0.1] }', "profile.jaw.speed",
     "two positive numbers"),
    ('[profile]\njaw = { input = "jaw_left", open = 0.025, closed = 0.0, colour = 1 }', "profile.jaw.colour",
     "not a known key"),
    ('[profile]\njaws = { input = "jaw_left", open = 0.025, closed = 0.0 }', "profile.jaws", "not a known key"),
    ('[profile]\nactivation_time = -1\njaw = { input = "jaw_left", open = 0.025, closed = 0.0 }',
     "profile.activation_time", "seconds"),
    ("", "profile", "no [profile] table"),
])
def test_mistakes_name_the_key(tmp_path, table, key, words):
    folder = _station(tmp_path, table)
    with Twin.from_station(folder) as twin:
        with pytest.raises(StationError) as err:
            open_profile(twin, "robotiq-2f")
    assert err.value.key == key and words in str(err.value) and str(folder / "station.toml") in str(err.value)


def test_serve_refuses_a_profile_the_station_does_not_map():
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-m", "twin", "serve", str(SMART), "--profile", "robotiq-3f", "--port", "0"],
                       capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert r.returncode == 2
    assert "profile.A: is required" in r.stderr


def test_a_gripper_that_is_not_always_active_moves_once_activated(tmp_path):
    """rACT drives the twin's `Active`: without it the jaws stand (fault 0x07 for a go-to), activated they close."""
    folder = _station(tmp_path, '[profile]\njaw = { input = "jaw_left", open = 0.025, closed = 0.0 }')
    toml = folder / "station.toml"
    toml.write_text(toml.read_text().replace("always_active = true", "always_active = false"))
    with Twin.from_station(folder) as twin:
        g = open_profile(twin, "robotiq-2f")
        g.write_output_word(0, 0x0800)  # go-to without activation
        g.write_output_word(1, 0x00FF)
        g.write_output_word(2, 0xFFFF)
        twin.step(50)
        assert g.input[2] == 0x07 and twin.read("jaw_left.actual") == pytest.approx(0.025, abs=1e-4)
        assert twin.read("Active") is False
        g.write_output_word(0, 0x0900)
        twin.step(round(1.5 / twin.dt) + 100)
        assert twin.read("Active") is True
        assert g.input[0] == 0xB9  # activated, go-to, stopped on the cube while closing
        assert twin.read("jaw_left.actual") == pytest.approx(0.010, abs=0.001)  # the 20 mm cube's faces
