"""A station's own code (its demo, its PLC logic) plugs into the general commands through `[plugins]` in its
station file."""
from __future__ import annotations

import subprocess
import sys

import pytest

from plc_client.testing import twin_server
from tests.conftest import ROOT, STATIONS
from twin.core.errors import StationError
from twin.core.station import load_station

CELL = STATIONS / "ring_rig_plc"


def run(*args, timeout=60):
    return subprocess.run([sys.executable, *args], cwd=ROOT, capture_output=True, text=True, timeout=timeout)


def test_plc_run_without_a_logic_runs_the_one_the_station_names():
    with twin_server(CELL, lockstep=True) as server:
        with server.client() as client:
            client.write(fullAutoRun=True)  # the robot program starts: it asks the PLC for the fingers at 330 mm
        r = run("-m", "plc_client", "--port", str(server.port), "--station", str(CELL), "run", "--scans", "110",
                "--quiet")
        assert r.returncode == 0, r.stderr
        assert r.stderr.startswith("plc: stations.ring_rig_plc.plc_logic:cell_sequence every 10 ms, lockstep")
        with server.client() as client:
            values = client.read("L2", "L3", "L4", "aoFingerReady", "sim.step")
    # the robot's first request (station.toml, ring_rig_plc.mod): fingers ready for an outside grip
    assert values["aoFingerReady"] == pytest.approx(330.0)
    fingers = [values[a] for a in ("L2", "L3", "L4")]  # only the PLC writes them: from 350 mm, on the way to 330
    assert fingers[0] == fingers[1] == fingers[2] and 330.0 <= fingers[0] < 349.0, fingers
    assert values["sim.step"] == int(110 * 0.010 / 0.012)  # the PLC stepped the cell: 110 scans of 10 ms, 12 ms steps


def test_plc_run_without_a_logic_on_a_station_that_names_none_is_one_line():
    r = run("-m", "plc_client", "--station", str(STATIONS / "smart_gripper"), "run", "--scans", "1")
    assert r.returncode == 2 and len(r.stderr.splitlines()) == 1, r.stderr
    assert "names no PLC logic ([plugins] plc_logic): give MODULE:NAME" in r.stderr


def test_a_demo_shows_its_own_options_under_the_general_command():
    r = run("-m", "plc_client", "demo", "--help")
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("usage: plc demo") and "--remove-ring CYCLE" in r.stdout and "--station DIR" in r.stdout
    r = run("-m", "twin", "demo", "--help")
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("usage: twin demo") and "--cycles" in r.stdout
    r = run("-m", "twin", "demo", "--no-such-option")
    assert r.returncode == 2 and "unrecognized arguments: --no-such-option" in r.stderr


@pytest.mark.parametrize("table, key, message", [
    ('twin_dmo = "x.py"', "plugins.twin_dmo", "is not a known key here"),
    ('plc_demo = "two words"', "plugins.plc_demo", 'must be "package.module", "file.py", or either with ":name"'),
    ("plc_logic = 3", "plugins.plc_logic", "must be a string"),
    ('moved = { "plc_client.x" = "y" }', "plugins.moved", "is not a known key here"),
])
def test_a_bad_plugins_table_names_its_key(tmp_path, table, key, message):
    text = (STATIONS / "smart_gripper" / "station.toml").read_text()
    (tmp_path / "smart_gripper.urdf").write_text((STATIONS / "smart_gripper" / "smart_gripper.urdf").read_text())
    (tmp_path / "station.toml").write_text(text + f"\n[plugins]\n{table}\n")
    with pytest.raises(StationError) as err:
        load_station(tmp_path)
    assert f"{key}: " in str(err.value) and message in str(err.value)


def test_the_shipped_stations_name_their_code_and_it_loads():
    from twin_app.plugins import station_plugin

    assert callable(station_plugin(CELL, "plc_logic")().inputs.__len__)
    for station, key in ((CELL, "plc_demo"), (STATIONS / "ring_rig", "twin_demo")):
        demo = station_plugin(station, key)
        assert callable(demo.add_arguments) and callable(demo.main)
