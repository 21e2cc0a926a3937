"""Campaign throughput: scenarios per minute and parallel efficiency with 1 and 2 workers, on the local
process pool and on a Dask cluster started on loopback, and the per-scenario overhead (process start,
station load) against the simulated work, side by side in one run.

    python -m bench campaign [--scenarios N] [--seconds S] [--no-cluster]

The campaign: the ring bench (the ring rig's gripper, its PLC gripping the ring, then holding it) for S
seconds of simulated time per scenario, N scenarios over ring offsets. Every configuration runs the same
scenarios; the tables they produce are compared (they must be identical).
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BENCH_STATION = ROOT / "tests" / "plc" / "stations" / "ring_bench"

SPEC = """
[campaign]
name = "bench"
station = "{station}"
[driver]
plc = "stations.ring_rig_plc.plc_logic:sequence"
scan = 0.012
[start]
grip_request = true
[run]
max_time = {seconds}
[sample]
count = {count}
seed = 1
ring.offset_x_mm = {{ uniform = [-5.0, 5.0] }}
ring.offset_y_mm = {{ uniform = [-5.0, 5.0] }}
[expect]
outcome = "completed"
grip = "confirmed"
"""


def measure(campaign, backend, out: Path) -> dict:
    from twin_app.campaign import run_campaign

    t0 = time.perf_counter()
    result = run_campaign(campaign, backend, out, quiet=True)
    wall = time.perf_counter() - t0
    recs = result.records
    per = {k: statistics.fmean(r[k] for r in recs if r.get(k) is not None) for k in ("wall", "wall_run", "wall_load", "wall_sim")}
    return {"wall": wall, "rate": len(recs) / wall * 60.0, "per": per, "sim": statistics.fmean(r["measured"]["time"] for r in recs),
            "passed": result.counts.get("pass", 0), "n": len(recs), "table": (out / "results.csv").read_bytes()}


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench campaign", description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenarios", type=int, default=12)
    parser.add_argument("--seconds", type=float, default=4.0, help="simulated seconds per scenario")
    parser.add_argument("--no-cluster", action="store_true", help="skip the loopback Dask cluster")
    args = parser.parse_args(argv)

    from twin_app.campaign import DaskBackend, LocalBackend, load_campaign

    with tempfile.TemporaryDirectory(prefix="bench-campaign-") as tmp:
        tmp = Path(tmp)
        spec = tmp / "bench.toml"
        spec.write_text(SPEC.format(station=BENCH_STATION, seconds=args.seconds, count=args.scenarios))
        campaign = load_campaign(spec)
        rows = {}
        for workers in (1, 2):
            rows[f"local, {workers} worker{'s' if workers > 1 else ''}"] = measure(campaign, LocalBackend(workers), tmp / f"local{workers}")
        if not args.no_cluster:
            try:
                from twin_app.campaign.loopback import loopback_cluster
            except ImportError:
                print("(no Dask: pip install 'gripper-twin[cluster]' for the cluster rows)")
            else:
                for workers in (1, 2):
                    with loopback_cluster(workers) as address:
                        rows[f"dask loopback, {workers} worker{'s' if workers > 1 else ''}"] = measure(
                            campaign, DaskBackend(address), tmp / f"dask{workers}")

    print(f"campaign bench: {args.scenarios} scenarios of {args.seconds:g} s simulated (ring bench, PLC grip and hold); "
          f"this machine is shared: compare the rows of one run")
    head = ("backend", "wall s", "scen/min", "efficiency", "workers busy", "per scenario: wall", "start", "load",
            "sim work", "overhead", "passed")
    print(" | ".join(head))
    print(" | ".join("---" for _ in head))
    base = {}
    for name, r in rows.items():
        kind = name.split(",")[0]
        one = base.setdefault(kind, r) if name.endswith(" 1 worker") else base.get(kind)
        workers = 1 if name.endswith(" 1 worker") else 2
        eff = r["rate"] / (workers * one["rate"]) if one else float("nan")
        p = r["per"]
        start = p["wall"] - p["wall_run"]
        overhead = p["wall"] - p["wall_sim"]
        busy = r["n"] * p["wall"] / (workers * r["wall"])
        print(" | ".join([name, f"{r['wall']:.1f}", f"{r['rate']:.1f}", f"{eff * 100:.0f} %", f"{busy * 100:.0f} %", f"{p['wall']:.2f} s",
                          f"{start:.2f} s", f"{p['wall_load']:.2f} s", f"{p['wall_sim']:.2f} s", f"{overhead:.2f} s",
                          f"{r['passed']}/{r['n']}"]))
    tables = {r["table"] for r in rows.values()}
    print(f"results tables identical across the {len(rows)} runs: {'yes' if len(tables) == 1 else 'NO'}")
    print("efficiency: the rate with N workers over N times the rate with one; workers busy: the share of the run each "
          "worker spent in a scenario (what the backend controls; on a shared machine the efficiency also pays for "
          "the cores other processes take). start: fork to scenario code; load: station and faults; overhead: "
          "wall per scenario minus its simulated work")
    print("targets: efficiency >= 85 % on 2 workers; overhead < 0.5 s per scenario")
    return 0 if len(tables) == 1 else 1
