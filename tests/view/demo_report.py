"""What `python3 tasks.py demo` (= `plc demo`) must end with: a report with the cycle's signal plot and the
cell at each grip and release, its path printed. Checked on the demo run of tests/plc/test_cell.py (one
run of the whole cycle serves both)."""
from __future__ import annotations

import re
from pathlib import Path


def check_demo_report(stdout: str, report: Path) -> None:
    m = re.search(r"^report: (.+index\.html)$", stdout, re.M)
    assert m, stdout[-1500:]
    assert m.group(1) == str((report / "index.html").resolve())
    html = (report / "index.html").read_text()
    # the cycle grips the ring twice (outside, inside) and releases it twice: one picture each
    assert len(re.findall(r"plc: grip confirmed", stdout)) == 2
    for name in ("signals.png", "grip_1.png", "release_1.png", "grip_2.png", "release_2.png"):
        assert name in html and (report / name).stat().st_size > 1000, name
    assert "grip_3.png" not in html
    assert (report / "recording.parquet").is_file() or (report / "recording.csv").is_file()  # replayable
