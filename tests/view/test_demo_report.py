"""`python3 tasks.py demo` (= `plc demo`) ends by writing a report: the cycle's signal plot and the cell at
each grip and release, and prints its path."""
from __future__ import annotations

import re
import subprocess
import sys

import pytest

from tests.conftest import ROOT

pytest.importorskip("matplotlib")


def test_the_demo_writes_its_report_and_prints_where(tmp_path):
    report = tmp_path / "report"
    out = subprocess.run([sys.executable, "-m", "plc_client", "demo", "--report", str(report)], cwd=ROOT,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    m = re.search(r"^report: (.+index\.html)$", out.stdout, re.M)
    assert m, out.stdout[-1500:]
    index = m.group(1)
    assert index == str((report / "index.html").resolve())
    html = (report / "index.html").read_text()
    # the demo's cycle grips the ring twice (outside, inside) and releases it twice: one picture each
    grips = len(re.findall(r"plc: grip confirmed", out.stdout))
    assert grips == 2
    for name in ("signals.png", "grip_1.png", "release_1.png", "grip_2.png", "release_2.png"):
        assert name in html and (report / name).stat().st_size > 1000
    assert "grip_3.png" not in html
    assert (report / "recording.parquet").is_file()  # replayable: twin view --replay
