"""The station's `[profile]` table: the shipped stations map, mistakes name the file and the key."""
from __future__ import annotations

import shutil

import pytest
from conftest import ROOT

from twin.core import Twin
from twin.core.errors import StationError
from twin.profiles.robotiq import open_profile

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
