"""`python -m bench load` (everything at once beside a quiet run) runs with tiny parameters, so it cannot rot; its
figures are the benchmark's business, here only that it runs every load and states its verdict."""
from __future__ import annotations

import subprocess
import sys

from tests.conftest import ROOT


def test_bench_load_runs_every_load_and_states_the_targets():
    run = subprocess.run([sys.executable, "-m", "bench", "load", "--seconds", "1", "--connections", "2", "--items", "10",
                          "--no-browser", "--no-hog", "--station", str(ROOT / "stations" / "ring_rig")], cwd=ROOT, capture_output=True, text=True, timeout=180)
    assert run.returncode == 0, run.stderr
    assert "flood answers/s" in run.stdout and "OPC UA notifications/s" in run.stdout
    assert "late steps" in run.stdout and "(target under 20)" in run.stdout
