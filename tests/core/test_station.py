"""Station files: a wrong file stops with a message naming the file and the key."""
import pytest

from tests.conftest import STATIONS
from twin.core.errors import StationError
from twin.core.station import load_station

GOOD = (STATIONS / "four_finger" / "station.toml").read_text().replace(
    'urdf = "gripper4.urdf"', f'urdf = "{STATIONS / "four_finger" / "gripper4.urdf"}"')


def write(tmp_path, text):
    path = tmp_path / "station.toml"
    path.write_text(text)
    return path


def error_for(tmp_path, text) -> str:
    path = write(tmp_path, text)
    with pytest.raises(StationError) as info:
        load_station(path)
    assert str(path) in str(info.value)  # always names the file
    return str(info.value)


def test_the_shipped_stations_load():
    for name in ("ring_rig", "smart_gripper", "four_finger"):
        station = load_station(STATIONS / name)
        assert station.name == name and station.targets


def test_ring_dimensions_and_mass_are_read():
    ring = load_station(STATIONS / "ring_rig").targets[0]
    assert (ring.shape, ring.outer_diameter, ring.inner_diameter, ring.height) == ("ring", 0.64, 0.48, 0.06)
    assert ring.mass == pytest.approx(7850 * 3.14159265 / 4 * (0.64**2 - 0.48**2) * 0.06)


def test_missing_required_key_is_named(tmp_path):
    msg = error_for(tmp_path, GOOD.replace("radius = 0.04\n", ""))
    assert "targets[0].radius: is required" in msg


def test_wrong_type_is_named(tmp_path):
    msg = error_for(tmp_path, GOOD.replace("density = 1200.0", 'density = "heavy"'))
    assert "targets[0].density: must be a number" in msg


def test_unknown_key_is_named_so_typos_do_not_pass(tmp_path):
    msg = error_for(tmp_path, GOOD.replace("friction = 0.6", "fricton = 0.6"))
    assert "targets[0].fricton: is not a known key here" in msg


def test_ring_whose_bore_is_wider_than_its_outside_is_refused(tmp_path):
    ring = GOOD.replace('shape = "cylinder"\nradius = 0.04\nheight = 0.05',
                        'shape = "ring"\nouter_diameter = 0.1\ninner_diameter = 0.2\nheight = 0.05')
    msg = error_for(tmp_path, ring)
    assert "targets[0].inner_diameter: must be between 0 and outer_diameter (0.1)" in msg


def test_missing_urdf_file_is_named_with_the_key(tmp_path):
    msg = error_for(tmp_path, GOOD.replace(str(STATIONS / "four_finger" / "gripper4.urdf"), "nowhere.urdf"))
    assert "gripper.urdf: file 'nowhere.urdf' not found" in msg


def test_bad_toml_syntax_is_reported_with_the_file(tmp_path):
    msg = error_for(tmp_path, GOOD + "\n[[targets]\n")
    assert "not valid TOML" in msg


def test_duplicate_object_names_are_refused(tmp_path):
    msg = error_for(tmp_path, GOOD.replace('name = "loose_box"', 'name = "puck"'))
    assert "fixtures[1].name: 'puck' is already the name of a target" in msg


def test_unknown_shape_and_negative_step(tmp_path):
    assert "targets[0].shape: must be one of ring, box, cylinder, plane" in error_for(
        tmp_path, GOOD.replace('shape = "cylinder"', 'shape = "sphere"'))
    assert "station.step: must be greater than 0" in error_for(
        tmp_path, GOOD.replace('name = "four_finger"', 'name = "four_finger"\nstep = -0.01'))


def test_twin_cli_reports_a_station_error_in_one_line(tmp_path):
    import subprocess
    import sys

    path = write(tmp_path, GOOD.replace("height = 0.05", "height = -0.05"))
    out = subprocess.run([sys.executable, "-m", "twin", "info", str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip().splitlines()[-1] == f"twin: error: {path}: targets[0].height: must be greater than 0, not -0.05"
