"""`twin campaign` on a local pool: counts, isolation of crashes and hangs, identical tables, resume, JUnit."""
import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

from twin_app.campaign import LocalBackend, load_campaign, run_campaign

DATA = Path(__file__).resolve().parent / "data"
BENCH = DATA / "bench.toml"


@pytest.fixture(scope="module")
def bench_runs(tmp_path_factory):
    """The 12-scenario bench campaign run three times: 2 workers, 1 worker, 2 workers again."""
    campaign = load_campaign(BENCH)
    runs = {}
    for label, workers in (("two", 2), ("one", 1), ("two_again", 2)):
        out = tmp_path_factory.mktemp(label)
        runs[label] = run_campaign(campaign, LocalBackend(workers), out, quiet=True)
    return runs


def test_small_campaign_passes_with_the_right_counts(bench_runs):
    result = bench_runs["two"]
    assert result.total == 12 and result.counts == {"pass": 12, "fail": 0, "error": 0}
    rows = list(csv.DictReader((result.out_dir / "results.csv").open()))
    assert len(rows) == 12
    missing = [r for r in rows if r["injected"] == "ring_missing"]
    present = [r for r in rows if r["injected"] == "none"]
    assert len(missing) == len(present) == 6
    # with the ring there: one grip confirmed by force, the ring still where it was, centred by the fingers
    for r in present:
        assert (r["outcome"], r["grip"], r["grips"], r["misses"]) == ("completed", "confirmed", "1", "0")
        assert float(r["max_finger_force"]) >= float(r["plc.threshold"])  # the PLC's threshold was reached
        # an off-centre ring is pushed towards the centre; fingers that the PLC stops one by one at its force threshold
        # (servo drives with finite stiffness) leave it up to ~3 mm off its 4 mm offset, as real ones would
        assert abs(float(r["part_end_x_mm"]) - 1600.0) < 3.5
    # without it: the fingers ran to the end of travel (290 mm from 330 mm at 20 mm/s: 2 s) and the PLC said so
    for r in missing:
        assert (r["outcome"], r["fault"], r["grip"], r["plc_faults"]) == ("stopped", "missed", "missed", "missed")
        assert float(r["time"]) == pytest.approx(40.0 / 20.0, abs=0.1)


def test_two_runs_and_one_or_two_workers_give_identical_tables(bench_runs):
    tables = {k: (r.out_dir / "results.csv").read_bytes() for k, r in bench_runs.items()}
    assert tables["two"] == tables["one"] == tables["two_again"]


def test_junit_xml_validates_against_the_junit_schema(bench_runs, tmp_path):
    xmlschema = pytest.importorskip("xmlschema")
    schema = xmlschema.XMLSchema(DATA / "junit.xsd")
    junit = bench_runs["two"].out_dir / "junit.xml"
    schema.validate(junit)
    import xml.etree.ElementTree as ET

    cases = ET.parse(junit).getroot().findall("./testsuite/testcase")
    assert len(cases) == 12
    assert cases[1].get("name") == "ring.offset_x_mm=-4, plc.threshold=150, fault=ring_missing"


def test_a_failing_expectation_names_the_expectation_and_the_measured_value(tmp_path):
    text = BENCH.read_text().replace("cycle_time_max = 3.0", "cycle_time_max = 0.3")
    spec = DATA / "_tight.toml"
    spec.write_text(text)
    try:
        campaign = load_campaign(spec)
        result = run_campaign(campaign, LocalBackend(2), tmp_path, quiet=True, indices=[0, 1])
    finally:
        spec.unlink()
    assert result.counts["fail"] == 2
    import xml.etree.ElementTree as ET

    failures = ET.parse(tmp_path / "junit.xml").getroot().findall("./testsuite/testcase/failure")
    assert len(failures) == 2
    assert failures[0].get("message").startswith("cycle_time_max: expected at most 0.3 s, measured 0.")
    xmlschema = pytest.importorskip("xmlschema")
    xmlschema.XMLSchema(DATA / "junit.xsd").validate(tmp_path / "junit.xml")
    # each failing scenario re-run with a recording (every signal at every step): the same run, step for step
    from twin.observe.recording import Recording

    for r in result.records:
        rec = Recording.open(tmp_path / "failures" / f"{r['index']:04d}.csv")
        assert len(rec) == r["measured"]["steps"] + 1  # the state before the first step, then each step
        assert rec.time[-1] == pytest.approx(r["measured"]["time"])
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            pass
        else:  # and its plot
            assert (tmp_path / "failures" / f"{r['index']:04d}.png").stat().st_size > 10_000
        if r["measured"]["part_present"]:
            assert rec.column("ring.x")[-1] * 1000.0 == r["measured"]["part_end_mm"][0]  # the very run, bit for bit
        else:
            assert not rec.column("ring.present")[-1]


def test_a_crash_and_a_hang_fail_alone_with_a_clear_reason(tmp_path):
    campaign = load_campaign(DATA / "crash.toml")
    result = run_campaign(campaign, LocalBackend(2, timeout=6.0), tmp_path, quiet=True)
    status = {r["params"]["var.mode"] + str(r["params"].get("var.n", "")): r for r in result.records}
    assert result.counts == {"pass": 3, "fail": 0, "error": 2}
    crash, hang = status["crash"], status["hang"]
    assert crash["status"] == "error" and "SIGABRT" in crash["measured"]["message"]
    assert hang["status"] == "error" and "timeout of 6 s" in hang["measured"]["message"]
    for key in ("ok", "ok2", "ok3"):
        assert status[key]["status"] == "pass"
        assert status[key]["measured"]["l2_mm"] == pytest.approx(325.0, abs=0.5)


def test_resume_runs_only_what_is_missing_and_gives_the_same_table(bench_runs, tmp_path):
    full = bench_runs["one"].out_dir
    lines = (full / "results.jsonl").read_text().splitlines()
    kept = [line for line in lines if json.loads(line)["index"] < 5]
    (tmp_path / "results.jsonl").write_text("\n".join(kept) + "\n" + lines[-1][:40])  # cut short by a kill

    class Counting(LocalBackend):
        ran: list = []

        def run(self, campaign, indices, on_result):
            self.ran.extend(indices)
            super().run(campaign, indices, on_result)

    backend = Counting(2)
    result = run_campaign(load_campaign(BENCH), backend, tmp_path, resume=True, quiet=True)
    assert sorted(backend.ran) == list(range(5, 12))
    assert result.counts["pass"] == 12
    assert (tmp_path / "results.csv").read_bytes() == (full / "results.csv").read_bytes()


def test_the_command_prints_a_summary_and_exits_by_the_verdict(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "twin", "campaign", str(BENCH), "--only", "0,1", "-j", "2",
                           "--out", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "2 of 2 scenarios run: 2 passed, 0 failed, 0 errors" in proc.stdout
    assert "[2/2] pass 2 fail 0 error 0" in proc.stderr  # the progress line
    assert (tmp_path / "junit.xml").exists() and (tmp_path / "results.csv").exists()


def test_without_a_fork_server_each_scenario_is_a_fresh_interpreter(tmp_path, monkeypatch):
    import twin_app.campaign.backends as backends

    monkeypatch.setattr(backends, "_may_fork", lambda: False)
    campaign = load_campaign(DATA / "crash.toml")
    result = run_campaign(campaign, LocalBackend(2, timeout=30.0), tmp_path, indices=[0, 1], quiet=True)
    status = {r["params"]["var.mode"]: r for r in result.records}
    assert status["ok"]["status"] == "pass" and status["ok"]["measured"]["l2_mm"] == pytest.approx(325.0, abs=0.5)
    assert status["crash"]["status"] == "error" and "SIGABRT" in status["crash"]["measured"]["message"]
