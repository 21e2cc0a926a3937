"""Runs a campaign on a backend and writes its outputs; `--resume` picks up from the results file.

    campaign = load_campaign("stations/my_cell/campaign.toml")
    result = run_campaign(campaign, LocalBackend(workers=2), out_dir="campaign-results/my_cell")
    result.counts        # {"pass": 9, "fail": 0, "error": 0}

The results file (`results.jsonl`) gets one line per finished scenario as soon as it ends, so an
interrupted campaign loses nothing; with `resume=True` the scenarios already in it (same parameters and
expectations) are not run again. At the end: `results.csv` (the table, in scenario order, identical for
identical scenarios whatever the backend and worker count), `junit.xml`, `summary.txt`, and for the first
`max_recordings` failing scenarios a recording and a plot in `failures/` (re-run on this machine).
"""
from __future__ import annotations

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
                 indices: list[int] | None = None, progress_stream=None, quiet: bool = False,
                 max_recordings: int = 10) -> CampaignResult:
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
    if max_recordings:
        _record_failures(campaign, out, recs, max_recordings)
    counts = {s: sum(r["status"] == s for r in recs) for s in ("pass", "fail", "error")}
    return CampaignResult(recs, len(wanted), wall, out, counts)


def _record_failures(campaign: Campaign, out: Path, records: list[dict], limit: int) -> list[int]:
    """Run each failing scenario once more, recorded (twin.observe.recording: every signal and body pose at every
    step, as CSV), and plot it when matplotlib is installed (twin.observe.plot): `failures/NNNN.csv`, `.png`. The
    runs are deterministic, so the re-run is the failing run. Crashed and hung scenarios are not re-run."""
    from .backends import LocalBackend

    wanted = [r["index"] for r in records if r["status"] == "fail"
              or (r["status"] == "error" and r["measured"].get("outcome") == "error")][:limit]
    if not wanted:
        return []
    folder = out / "failures"
    folder.mkdir(exist_ok=True)
    paths = {i: str(folder / f"{i:04d}.csv") for i in wanted}
    done: list[int] = []
    LocalBackend(1, timeout=campaign.timeout).run(campaign, wanted, lambda i, env: done.append(i), record=paths)
    by_index = {r["index"]: r for r in records}
    for i in done:
        _plot(Path(paths[i]), by_index[i], campaign)
    return sorted(done)


def _plot(path: Path, record: dict, campaign: Campaign) -> None:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return
    from twin.observe.plot import plot_recording
    from twin.observe.recording import Recording

    if not path.exists():
        return
    rec = Recording.open(path)
    signals = [n for n in campaign.record if n in {s["name"] for s in rec.scene.signals}] or None
    title = f"[{record['index']}] {record['name']}: " + ("; ".join(record["failures"]) or "")
    plot_recording(rec, signals, path.with_suffix(".png"), title=title[:160])
