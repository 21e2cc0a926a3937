"""`twin view --replay FILE` in a real browser: the recorded cell, a timeline to scrub and step."""
from __future__ import annotations

import re
import subprocess
import sys

import pytest

from plc_client.events import EventLog
from tests.conftest import ROOT, STATIONS
from tests.view.conftest import signal_cell, wait_for_cell
from twin.core import Twin
from twin.observe.recording import record


@pytest.fixture(scope="module")
def replay(tmp_path_factory):
    pytest.importorskip("viser")
    pytest.importorskip("pyarrow")
    path = tmp_path_factory.mktemp("replay") / "grip.parquet"
    with Twin.from_station(STATIONS / "smart_gripper") as twin, record(twin, path):
        twin.step(5)
        twin.write("jaw_left", twin.spec("jaw_left").min)
        twin.step(70)
    events = path.with_suffix(".events.jsonl")
    proc = subprocess.Popen([sys.executable, "-m", "twin", "view", "--replay", str(path), "--port", "0",
                             "--events", str(events)], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        stream = EventLog(events, proc)
        assert stream.wait("ready", 60) is not None, "`twin view --replay` did not get ready"
        yield stream.endpoint("view")["url"]
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def step_shown(page) -> int:
    return int(re.search(r"step (\d+)", page.locator("#sim-state").inner_text()).group(1))


def test_replay_steps_and_plays_the_recording(browser, replay):
    page = browser.new_page(viewport={"width": 1000, "height": 700})
    try:
        page.goto(replay)
        page.wait_for_selector("#sim-state", timeout=90000)
        assert step_shown(page) == 0 and signal_cell(page, "doGripped") == "0"
        page.get_by_role("button", name="Step", exact=True).click()
        page.wait_for_function("() => /step 1\\b/.test(document.querySelector('#sim-state').textContent)",
                               timeout=60000)
        page.get_by_role("button", name="Run", exact=True).click()  # to the end: the jaws close and hold the cube
        wait_for_cell(page, "doGripped", lambda t: t == "1", timeout=90)
        page.wait_for_function("() => /step 75\\b/.test(document.querySelector('#sim-state').textContent)",
                               timeout=90000)
        assert signal_cell(page, "GrippedPart") == "cube"
    finally:
        page.close()
