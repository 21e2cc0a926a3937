"""The distributed backend on a real Dask cluster started on loopback: a scheduler and two worker processes."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from plc_client.testing import free_port
from twin_app.campaign import DaskBackend, LocalBackend, load_campaign, run_campaign
from twin_app.campaign.loopback import loopback_cluster

distributed = pytest.importorskip("distributed", reason="the [cluster] extra (dask[distributed]) is not installed")

DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="module")
def cluster():
    """`dask scheduler` and two `dask worker` processes on 127.0.0.1, stopped afterwards."""
    with loopback_cluster(workers=2) as address:
        client = distributed.Client(address, timeout=10)
        try:
            assert len(client.scheduler_info()["workers"]) == 2
        finally:
            client.close()
        yield address


def test_the_cluster_runs_the_small_campaign_with_the_same_table(cluster, tmp_path):
    campaign = load_campaign(DATA / "bench.toml")
    local = run_campaign(campaign, LocalBackend(2), tmp_path / "local", quiet=True)
    remote = run_campaign(campaign, DaskBackend(cluster), tmp_path / "dask", quiet=True)
    assert remote.counts == {"pass": 12, "fail": 0, "error": 0}
    assert (tmp_path / "dask" / "results.csv").read_bytes() == (tmp_path / "local" / "results.csv").read_bytes()


def test_a_crash_on_the_cluster_fails_alone_and_the_workers_survive(cluster, tmp_path):
    campaign = load_campaign(DATA / "crash.toml")
    result = run_campaign(campaign, DaskBackend(cluster, timeout=8.0), tmp_path, quiet=True)
    by_mode = {r["params"]["var.mode"] + str(r["params"].get("var.n", "")): r for r in result.records}
    assert result.counts == {"pass": 3, "fail": 0, "error": 2}
    assert "SIGABRT" in by_mode["crash"]["measured"]["message"]
    assert "timeout of 8 s" in by_mode["hang"]["measured"]["message"]
    client = distributed.Client(cluster, timeout=10)
    try:
        assert len(client.scheduler_info()["workers"]) == 2  # nobody died
    finally:
        client.close()


def test_the_command_runs_on_the_cluster(cluster, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "twin", "campaign", str(DATA / "bench.toml"), "--cluster", cluster,
                           "--only", "0-3", "--out", str(tmp_path), "-q"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "4 of 4 scenarios run: 4 passed" in proc.stdout and "on dask" in proc.stdout


def test_an_unreachable_scheduler_is_one_clear_line(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "twin", "campaign", str(DATA / "bench.toml"), "--cluster",
                           f"tcp://127.0.0.1:{free_port()}", "--out", str(tmp_path), "-q"],
                          capture_output=True, text=True, timeout=120, env={**os.environ, "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "2s"})
    assert proc.returncode == 2
    assert "cannot connect to the Dask scheduler at tcp://127.0.0.1:" in proc.stderr
