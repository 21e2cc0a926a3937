"""Every benchmark of `bench/` runs with tiny parameters, so none can rot (a renamed attribute, a changed event,
a moved module fail here, not in the hands of whoever measures next). Their figures are the benchmarks' business;
here only that each runs to its end and prints what it compares (a missed target, exit 1, is no failure here). `st`, `record`, `load` and `adapter` have
theirs beside their subjects (tests/structured_text, tests/app/test_bench_record.py, test_bench_load.py,
test_frontend_process.py)."""
from __future__ import annotations

import subprocess
import sys

import pytest

from bench.__main__ import BENCHMARKS
from tests.conftest import ROOT

TINY = {
    "core": (["--steps", "5", "--targets", "0,10"], "naive/ours"),
    "modbus": (["--requests", "50", "--seconds", "0.5", "--clients", "2", "--flood", "2", "--flood-seconds", "0.5"],
               "targets under the flood"),
    "cell": (["--rounds", "1", "--scans", "60"], "same run on both sides"),
    "campaign": (["--scenarios", "2", "--seconds", "0.3", "--no-cluster"], "results tables identical"),
    "rapid": (["--seconds", "0.2", "--no-planning"], "wall s per simulated s"),
    "opcua": (["--requests", "5", "--changes", "2", "--items", "5", "--seconds", "0.3"], "monitored items"),
    "view": (["--seconds", "0.5", "--steps", "20", "--no-browser", "--windows", "view+record"],
             "recording cost, us per step"),
    "map": (["--runs", "1"], "cell/static"),
    "pollimage": (["--seconds", "0.3"], "torn"),
}
ELSEWHERE = {"st", "record", "load", "adapter"}


def test_every_benchmark_has_a_tiny_run():
    assert set(BENCHMARKS) == set(TINY) | ELSEWHERE


@pytest.mark.parametrize("name", sorted(TINY))
def test_the_benchmark_runs_with_tiny_parameters(name):
    args, says = TINY[name]
    run = subprocess.run([sys.executable, "-m", "bench", name, *args], cwd=ROOT, capture_output=True, text=True,
                         timeout=240)
    # a benchmark may exit 1 for a missed target (tiny runs are noise); it must not crash
    assert run.returncode in (0, 1) and "Traceback" not in run.stderr, run.stderr[-3000:]
    assert says in run.stdout, run.stdout[-3000:]
