"""`python -m bench record` (the flight recorder's cost) runs with tiny parameters, so it cannot rot; its
figures are the benchmark's business, here only that it measures both formats and states its verdict."""
from __future__ import annotations

import subprocess
import sys

from tests.conftest import ROOT


def test_bench_record_runs_and_states_the_target():
    run = subprocess.run([sys.executable, "-m", "bench", "record", "--steps", "20", "--blocks", "1"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "Parquet" in run.stdout and "CSV" in run.stdout
    assert "target: the recorder costs at most 10 %" in run.stdout
