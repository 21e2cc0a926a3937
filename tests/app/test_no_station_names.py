"""The general packages hold no station: no shipped station's name, model, target, signal or I/O name appears
in their Python sources (code, docstrings, comments). Station code lives beside its station and plugs in by
a name given at run time (`[plugins]` in station.toml, twin_app.plugins). The identifiers are read from the
stations/ folder itself, so a new station is covered without touching this test."""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

from tests.conftest import ROOT, STATIONS
from tests.app.test_package_graph import imports_of

GENERAL_PACKAGES = ("twin", "twin_app", "plc_client", "rapid_like", "structured_text")
# Words a station uses that are also the general vocabulary of every cell, with the reason.
GENERAL_WORDS = {
    "ring": "a body shape of the station format (shape = \"ring\"), not only the ring rig's part",
    "home": "the robot's home pose, a target name every robot station may use",
    "floor": "the ground plane, a fixture name every station may use",
}
MODEL_SUFFIXES = (".urdf", ".mod", ".sys", ".obj", ".stl", ".dae")


def station_identifiers() -> dict[str, str]:
    """identifier -> where it comes from, for every shipped station and model folder under stations/."""
    from twin.core.station import gripper_mechanism, load_station

    found: dict[str, str] = {}

    def add(name: str, where: str) -> None:
        if name and name not in GENERAL_WORDS:
            found.setdefault(name, where)

    for folder in sorted(p for p in STATIONS.iterdir() if p.is_dir() and not p.name.startswith(("_", "."))):
        add(folder.name, f"stations/{folder.name}")
        for model in sorted(folder.iterdir()):
            if model.suffix.lower() in MODEL_SUFFIXES:
                add(model.stem, f"stations/{folder.name}/{model.name}")
            if model.suffix.lower() == ".urdf":
                add(ET.parse(model).getroot().get("name", ""), f"robot name in {model.name}")
        if not (folder / "station.toml").exists():
            continue
        st = load_station(folder)
        where = f"stations/{folder.name}/station.toml"
        add(st.name, where)
        for body in (*st.targets, *st.fixtures):
            add(body.name, f"{where}: a body")
        for target in st.robot_targets:
            add(target, f"{where}: a robot target")
        for sig in st.controller.io if st.controller else ():
            add(sig.name, f"{where}: controller I/O")
        mech = gripper_mechanism(st)
        for item in (*mech.inputs, *mech.fingers):
            add(item.name, f"{where}: a gripper input or finger")
    return found


def general_sources():
    for pkg in GENERAL_PACKAGES:
        yield from sorted((ROOT / pkg).rglob("*.py"))


def test_the_identifiers_come_from_the_stations_folder():
    ids = station_identifiers()
    # an independent look at what is shipped: the thesis rig's names, its PLC cell's handshake, the others' parts
    for name in ("ring_rig", "ring_rig_plc", "smart_gripper", "four_finger", "gripper3", "arm6700", "L2", "L5",
                 "doGripRequest", "aoAxis1", "app_right", "pallet_left", "cube", "puck", "jaw_left", "F4"):
        assert name in ids, name
    assert not set(GENERAL_WORDS) & set(ids)


def test_no_general_package_mentions_a_station():
    ids = station_identifiers()
    pattern = re.compile(r"(?<![A-Za-z0-9_])(" + "|".join(sorted(map(re.escape, ids), key=len, reverse=True))
                         + r")(?![A-Za-z0-9_])")
    hits = []
    for path in general_sources():
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for m in pattern.finditer(line):
                hits.append(f"{path.relative_to(ROOT)}:{n}: {m.group(1)!r} ({ids[m.group(1)]}): {line.strip()[:100]}")
    assert not hits, ("general packages must not name a station (move the code beside it, or plug it in by "
                      "[plugins]); found:\n" + "\n".join(hits))


def test_the_scan_finds_a_station_name_where_one_is_written(tmp_path):
    ids = station_identifiers()
    pattern = re.compile(r"(?<![A-Za-z0-9_])(" + "|".join(map(re.escape, ids)) + r")(?![A-Za-z0-9_])")
    assert pattern.search('DEFAULT = "stations/ring_rig"') and pattern.search("io.set('doGripRequest', True)")
    assert not pattern.search("ring_rigs = 2; aoAxis10 = L25")  # whole names only


def test_no_general_package_imports_station_code():
    bad = [f"{path.relative_to(ROOT)} imports {target}" for path in general_sources()
           for target in imports_of(path) if target.split(".")[0] == "stations"]
    assert not bad, "station code is loaded by a name given at run time (twin_app.plugins), never imported: " + "; ".join(bad)
