"""The live page in a real browser (headless Chromium): `twin serve STATION --lockstep --view 0`.

The page is checked the way a person uses it: the 3D canvas shows the cell in the station's colours,
the signal table follows Modbus writes, a finger setpoint typed on the page reaches the twin (read back
over Modbus), and an out-of-range entry is refused with the message `Twin.write` itself gives.
"""
from __future__ import annotations

import pytest

from plc_client.testing import twin_server
from tests.conftest import STATIONS
from tests.view.conftest import image_stats, signal_cell, wait_for_cell
from twin.core import SignalRangeError, Twin

STATION = STATIONS / "ring_rig_plc"


@pytest.fixture(scope="module")
def served():
    pytest.importorskip("viser")
    with twin_server(STATION, lockstep=True, extra_args=["--view", "0"]) as server:
        yield server, server.endpoint("view")["url"]


@pytest.fixture
def page(browser, served):
    server, url = served
    page = browser.new_page(viewport={"width": 1100, "height": 760})
    page.goto(url)
    page.wait_for_selector("#signal-table", timeout=90000)
    yield page
    page.close()


def test_canvas_shows_the_cell_in_the_stations_colours(page, tmp_path):
    canvas = max(page.locator("canvas").all(), key=lambda c: (c.bounding_box() or {"width": 0})["width"])
    page.wait_for_timeout(3000)  # the first frames
    png = canvas.screenshot(timeout=90000)
    (tmp_path / "canvas.png").write_bytes(png)
    w, h, colours, orange = image_stats(png)
    assert w > 300 and h > 300
    assert colours > 50, f"the canvas is blank ({colours} colours)"
    # the arm's URDF material is orange (0.93, 0.45, 0.1): a drawn arm covers a visible part of the picture
    assert orange > 0.005, f"no orange arm drawn ({orange:.4%} orange pixels)"


def test_signal_table_follows_a_modbus_write(page, served):
    server, _ = served
    assert signal_cell(page, "Active") == "1"
    with server.client() as plc:
        plc.write(Active=0)
        plc.advance(1)
    assert wait_for_cell(page, "Active", lambda t: t == "0") == "0"
    with server.client() as plc:
        plc.write(Active=1, L3=300.0)
        plc.advance(1)
    assert wait_for_cell(page, "L3", lambda t: t.startswith("300.00")) == "300.00 mm"
    assert signal_cell(page, "Active") == "1"


def test_setpoint_typed_on_the_page_reaches_the_twin(page, served):
    server, _ = served
    box = page.get_by_label("L2 [mm]")
    box.fill("312.5")
    box.press("Enter")
    page.get_by_text("set L2").wait_for(timeout=60000)
    with server.client() as plc:
        for _ in range(50):  # the write is queued for the next step: step until it is applied
            plc.advance(1)
            if abs(plc.get("L2") - 312.5) < 0.01:
                break
        assert plc.get("L2") == pytest.approx(312.5, abs=0.01)
    wait_for_cell(page, "L2", lambda t: t == "312.50 mm")


def test_out_of_range_entry_is_refused_with_the_apis_message(page, served):
    server, _ = served
    with server.client() as plc:
        before = plc.get("L4")
    box = page.get_by_label("L4 [mm]")
    box.fill("500")  # the axis travels 0..441 mm
    box.press("Enter")
    refusal = page.locator("#refusal")
    refusal.wait_for(timeout=60000)
    with Twin.from_station(STATION) as twin:  # what the simulation API says of the same value
        with pytest.raises(SignalRangeError) as exc:
            twin.write("L4", 0.5)
    assert refusal.inner_text() == f"refused: {exc.value}"
    with server.client() as plc:
        plc.advance(2)
        assert plc.get("L4") == pytest.approx(before)
