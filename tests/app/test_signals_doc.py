"""docs/signals.md is the one definition of every signal: every signal a station has (its gripper, fingers, robot,
targets, controller, watchdog and the simulator's) has its row there, and every name the page defines is one that
some station really has, so the page can neither miss a signal nor keep a stale one."""
from __future__ import annotations

import re

from tests.conftest import ROOT, STATIONS
from twin.core.signal_table import station_signals
from twin.core.signals import INPUT

DOC = ROOT / "docs" / "signals.md"
# shipped stations and test grippers nobody tuned: prismatic and revolute fingers, mimic pairs, a robot, a controller
STATION_DIRS = [STATIONS / "ring_rig_plc", STATIONS / "smart_gripper", STATIONS / "four_finger",
                ROOT / "tests" / "core" / "data" / "chuck3", *sorted(p.parent for p in (ROOT / "tests" / "grippers").glob("*/station.toml"))]


def documented() -> list[str]:
    """The signal names in the first column of the page's tables (`NAME.x`, `.y` after it, `robot.j1`..`robot.jN`)."""
    names = []
    for line in DOC.read_text(encoding="utf-8").splitlines():
        cells = line.split("|")
        if len(cells) < 3 or not line.startswith("| `"):
            continue
        previous = ""
        for token in re.findall(r"`([^`]+)`", cells[1]):
            if token.startswith("."):
                token = previous.rsplit(".", 1)[0] + token
            names.append(token)
            previous = token
    return names


def pattern(name: str) -> re.Pattern:
    text = re.escape(name).replace("NAME", r"[^.]+").replace("TARGET", r"[^.]+").replace(r"robot\.jN", r"robot\.j\d+")
    return re.compile(text + r"\Z")


def test_every_signal_of_every_station_is_defined_once_and_every_definition_is_a_signal():
    names = documented()
    assert len(names) == len(set(names)), "a signal defined twice"
    patterns = {n: pattern(n) for n in names}
    used = set()
    for folder in STATION_DIRS:
        for spec in station_signals(folder):
            if spec.group == "controller" and not spec.name.startswith("rapid."):
                continue  # a station's own controller I/O: one row ("the controller's I/O")
            hits = [spec.name] if spec.name in patterns else [  # a fixed name, else the placeholders that fit
                n for n, p in patterns.items() if p.match(spec.name) and (n != "NAME" or spec.direction == INPUT)]
            assert hits, f"{folder.name}: {spec.name} ({spec.description}) is not defined in docs/signals.md"
            used.update(hits)
    assert set(names) - used == set(), "defined in docs/signals.md but no station has it"
