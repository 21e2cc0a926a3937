"""Runs a campaign on a backend and writes its outputs; `--resume` picks up from the results file.

    campaign = load_campaign("stations/ring_rig_plc/campaign.toml")
    result = run_campaign(campaign, LocalBackend(workers=2), out_dir="campaign-results/ring_rig_plc")
    result.counts        # {"pass": 9, "fail": 0, "error": 0}

The results file (`results.jsonl`) gets one line per finished scenario as soon as it ends, so an
interrupted campaign loses nothing; with `resume=True` the scenarios already in it (same parameters and
expectations) are not run again. At the end: `results.csv` (the table, in scenario order, identical for
identical scenarios whatever the backend and worker count), `junit.xml`, `summary.txt`, and for each
failing scenario that traced signals (`campaign.record`) its trace in `failures/`.
"""
from __future__ import annotations

import csv
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

from . import report
from .spec import Campaign
from .verdict import judge

RESULTS = "results.jsonl"


@dataclass
class CampaignResult:
    records: list[dict]
    total: int
    wall: float
    out_dir: Path
    counts: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return len(self.records) == self.total and self.counts.get("pass", 0) == self.total


def _load_previous(path: Path, campaign: Campaign) -> dict[int, dict]:
    keys = {sc.index: sc.key for sc in campaign.scenarios}
    done: dict[int, dict] = {}
    if not path.exists():
        return done
    for line in path.read_text().splitlines():
        try:
            rec = json.loads(line)
        except json.JSONDecodeError:
            continue  # a line cut short by the interruption: that scenario runs again
        if keys.get(rec.get("index")) == rec.get("key"):
            done[rec["index"]] = rec
    return done


def run_campaign(campaign: Campaign, backend, out_dir: str | Path, *, resume: bool = False,
                 indices: list[int] | None = None, progress_stream=None, quiet: bool = False) -> CampaignResult:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results_path = out / RESULTS
    wanted = list(range(len(campaign.scenarios))) if indices is None else list(indices)
    previous = _load_previous(results_path, campaign) if resume else {}
    records = {i: rec for i, rec in previous.items() if i in wanted}
    todo = [i for i in wanted if i not in records]
    # the results file holds exactly what is known: rewrite it with the kept records, then append
    with results_path.open("w") as f:
        for rec in records.values():
            f.write(json.dumps(rec) + "\n")
    progress = None if quiet else report.Progress(len(wanted), progress_stream, already=len(records))
    t0 = time.monotonic()

    def on_result(index: int, envelope: dict) -> None:
        sc = campaign.scenarios[index]
        measured = envelope["measured"]
        status, failures = judge(campaign, sc, measured)
        if status == "pass":
            measured.pop("trace", None)  # traces are kept for the failing scenarios' plots only
        rec = {"index": index, "key": sc.key, "name": sc.name, "params": sc.params, "measured": measured,
               "status": status, "failures": failures, "wall": envelope.get("wall", 0.0),
               "wall_run": envelope.get("wall_run"), "wall_load": envelope.get("wall_load"),
               "wall_sim": envelope.get("wall_sim")}
        records[index] = rec
        with results_path.open("a") as f:
            f.write(json.dumps(rec) + "\n")
        if progress:
            progress.update(status)

    try:
        if todo:
            backend.run(campaign, todo, on_result)
    finally:
        if progress:
            progress.close()
    wall = time.monotonic() - t0
    recs = [records[i] for i in sorted(records)]
    report.write_csv(out / "results.csv", recs)
    report.write_junit(out / "junit.xml", campaign.name, recs)
    text = report.summary_text(campaign.name, recs, len(wanted), wall, getattr(backend, "name", "?"))
    (out / "summary.txt").write_text(text)
    _write_failure_traces(out, recs)
    counts = {s: sum(r["status"] == s for r in recs) for s in ("pass", "fail", "error")}
    return CampaignResult(recs, len(wanted), wall, out, counts)


def _write_failure_traces(out: Path, records: list[dict]) -> None:
    """Each failing scenario's traced signals as CSV, and a plot of them when matplotlib is installed."""
    folder = out / "failures"
    for r in records:
        trace = r["measured"].get("trace")
        if r["status"] == "pass" or not trace:
            continue
        folder.mkdir(exist_ok=True)
        stem = folder / f"{r['index']:04d}"
        with stem.with_suffix(".csv").open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(trace["signals"])
            w.writerows(trace["rows"])
        _plot(stem.with_suffix(".png"), r, trace)


def _plot(path: Path, record: dict, trace: dict) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    names = trace["signals"][1:]
    rows = trace["rows"]
    fig, axes = plt.subplots(len(names), 1, sharex=True, figsize=(9, 1.6 * len(names) + 1), squeeze=False)
    times = [row[0] for row in rows]
    for k, (name, ax) in enumerate(zip(names, axes[:, 0]), start=1):
        ax.plot(times, [float(row[k]) if not isinstance(row[k], str) else 0.0 for row in rows], lw=1)
        ax.set_ylabel(name, rotation=0, ha="right", fontsize=8)
    axes[-1, 0].set_xlabel("simulated time (s)")
    fig.suptitle(f"[{record['index']}] {record['name']}\n" + "; ".join(record["failures"])[:200], fontsize=8)
    fig.savefig(path, dpi=80)
    plt.close(fig)
