"""`python -m bench core --against REV` (before and after side by side) runs with tiny parameters, so it cannot rot;
its figures are the benchmark's business, here only that both trees are measured, row by row."""
from __future__ import annotations

import subprocess
import sys

from tests.conftest import ROOT


def test_bench_core_against_a_revision_measures_both_trees():
    run = subprocess.run([sys.executable, "-m", "bench", "core", "--against", "HEAD", "--rounds", "1", "--steps", "5"],
                         cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert "HEAD" in lines[1] and "this tree" in lines[1]
    for row in ("at rest ring_rig twin/physics", "in motion x real time (wall)", "in motion, the twin's step adds (%)"):
        line = next(line for line in lines if line.startswith(row))
        assert line.count("[") == 2, line  # one figure per tree


def test_bench_core_against_an_unknown_revision_is_one_clear_line():
    run = subprocess.run([sys.executable, "-m", "bench", "core", "--against", "no-such-revision"], cwd=ROOT,
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and run.stderr.startswith("python -m bench core: --against no-such-revision:")
    assert len(run.stderr.strip().splitlines()) == 1
