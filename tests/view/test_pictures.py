"""`twin plot`, `twin snapshot` and the run report: pictures of the right size that show something."""
from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from tests.conftest import STATIONS
from twin_app.cli import main as twin_main
from twin.core import Twin
from twin.observe.recording import Recording, record

pytest.importorskip("matplotlib")
pytest.importorskip("pyarrow")
from PIL import Image  # noqa: E402  (comes with matplotlib)

SMART = STATIONS / "smart_gripper"
RING = STATIONS / "ring_rig_plc"


def pixels(path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB")).astype(int)


def colours(img: np.ndarray) -> int:
    return len(np.unique(img.reshape(-1, 3), axis=0))


def green(img: np.ndarray) -> int:
    """Pixels in the highlight colour of a held part."""
    return int(((img[..., 1] > 150) & (img[..., 1] > img[..., 0] + 60) & (img[..., 1] > img[..., 2] + 40)).sum())


@pytest.fixture(scope="module")
def grip_recording(tmp_path_factory):
    """The smart gripper closes on its cube (held), then opens (released)."""
    path = tmp_path_factory.mktemp("rec") / "grip.parquet"
    with Twin.from_station(SMART) as twin, record(twin, path):
        twin.step(5)
        twin.write("jaw_left", twin.spec("jaw_left").min)
        twin.step(70)
        assert twin.read("doGripped")
        twin.write("jaw_left", twin.spec("jaw_left").max)
        twin.step(60)
        assert not twin.read("doGripped")
    return path


def test_plot_png_has_one_panel_per_unit_and_is_drawn(grip_recording, tmp_path, capsys):
    out = tmp_path / "plot.png"
    assert twin_main(["plot", str(grip_recording), "-o", str(out), "--threshold", "20"]) == 0
    assert capsys.readouterr().out.strip() == str(out)
    img = pixels(out)
    assert img.shape[1] == 11 * 110  # 11 inches at 110 dpi
    assert colours(img) > 20 and (img < 200).any(axis=2).mean() > 0.01  # lines and text, not a blank page


def test_plot_svg_of_named_signals(grip_recording, tmp_path):
    out = tmp_path / "forces.svg"
    assert twin_main(["plot", str(grip_recording), "jaw_left.actual", "*.force", "-o", str(out)]) == 0
    root = ET.parse(out).getroot()
    assert root.tag.endswith("svg") and root.get("width", "").startswith("792")  # 11 in = 792 pt
    text = out.read_text()
    assert "jaw_left.actual" in text or "jaw" in text


def test_plot_names_an_unknown_signal(grip_recording, tmp_path, capsys):
    assert twin_main(["plot", str(grip_recording), "no_such_signal", "-o", str(tmp_path / "x.png")]) == 2
    assert "no_such_signal" in capsys.readouterr().err


def test_snapshot_of_a_station_is_the_asked_size_in_its_colours(tmp_path):
    out = tmp_path / "cell.png"
    assert twin_main(["snapshot", str(RING), "-o", str(out), "--width", "320", "--height", "240"]) == 0
    img = pixels(out)
    assert img.shape == (240, 320, 3)
    assert colours(img) > 50
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    assert ((r > 150) & (r > g + 60) & (g > b + 20)).mean() > 0.01  # the arm's orange (0.93, 0.45, 0.1)


def test_snapshot_of_a_recording_shows_the_recorded_moment(grip_recording, tmp_path):
    rec = Recording.open(grip_recording)
    held = np.flatnonzero(rec.column("doGripped"))
    t_held, t_start = float(rec.time[held[len(held) // 2]]), 0.0
    a, b = tmp_path / "start.png", tmp_path / "held.png"
    for t, out in ((t_start, a), (t_held, b)):
        assert twin_main(["snapshot", str(grip_recording), "--at", str(t), "-o", str(out),
                          "--width", "200", "--height", "150"]) == 0
    start, held_img = pixels(a), pixels(b)
    assert start.shape == held_img.shape == (150, 200, 3)

    assert green(held_img) > 0 and green(start) == 0
    assert np.abs(start - held_img).sum() > 0  # the jaws moved


def test_snapshot_outside_the_recording_is_refused(grip_recording, tmp_path, capsys):
    assert twin_main(["snapshot", str(grip_recording), "--at", "99", "-o", str(tmp_path / "x.png")]) == 2
    assert "outside the recording" in capsys.readouterr().err


def test_report_has_a_picture_per_grip_and_release(grip_recording, tmp_path):
    from twin.observe.report import write_report

    index = write_report(grip_recording, tmp_path / "report", width=320, height=240)
    html = index.read_text()
    for name in ("signals.png", "grip_1.png", "release_1.png"):
        assert name in html and (tmp_path / "report" / name).is_file()
    assert colours(pixels(tmp_path / "report" / "signals.png")) > 20
    grip, release = pixels(tmp_path / "report" / "grip_1.png"), pixels(tmp_path / "report" / "release_1.png")
    assert grip.shape == release.shape == (240, 320, 3)
    assert green(grip) > 20 and green(release) == 0  # held: the cube in the highlight colour; released: not
    assert "grip_2.png" not in html  # one grip in this run
