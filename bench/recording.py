"""The flight recorder's cost: microseconds per lockstep step of the ring rig with and without a recorder.

    python -m bench record [--steps N] [--blocks B]

In process, lockstep, the robot running its program: blocks of N steps without and with a recorder attached,
alternately (so the machine's load hits both alike), for a Parquet and a CSV recording. The cost is the
difference of the medians, the hand-over of each block's last group included, as a share of the step's own
compute time (target: at most 10 %) and of the 12 ms real-time step. CPU time of the whole simulation's
process (every thread's work counts: it shares the interpreter with the steps). Apart: the CPU time of the
recorder's writer process (encoding and writing the groups, and at the stop finishing the file: a Parquet
recording is converted from its crash-safe stream), per step recorded.
"""
from __future__ import annotations

import argparse
import resource
import statistics
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STATION = ROOT / "stations" / "ring_rig_plc"
TARGET = 0.10  # the recorder may cost at most this share of a lockstep step's compute


def lockstep_cost(steps: int, blocks: int = 6, suffix: str = ".parquet") -> dict:
    """Blocks of steps without and with the recorder subscribed, alternately, as `twin serve --lockstep --record`
    runs it (the cell publishes a snapshot per step either way)."""
    from twin.observe.recording import Recorder
    from twin_app.cell import open_cell

    bare, recorded = [], []
    with tempfile.TemporaryDirectory(prefix="bench-rec-") as tmp, open_cell(STATION) as cell:
        cell.write("fullAutoRun", True)
        cell.step(50)
        path = Path(tmp) / f"run{suffix}"
        children = _children_cpu()
        Recorder(cell.twin, Path(tmp) / f"empty{suffix}", exchange=cell.exchange).close()  # start-up, one row
        startup = _children_cpu() - children
        children = _children_cpu()
        rec = Recorder(cell.twin, path, exchange=cell.exchange)
        listeners = cell.exchange._on_snapshot
        on_snapshot = rec._on_snapshot
        listeners.remove(on_snapshot)
        for _ in range(blocks):
            t0 = time.process_time()
            cell.step(steps)
            bare.append((time.process_time() - t0) / steps)
            listeners.append(on_snapshot)
            t0 = time.process_time()
            cell.step(steps)
            rec._flush()  # the last group of the block: its hand-over is the block's cost
            recorded.append((time.process_time() - t0) / steps)
            listeners.remove(on_snapshot)
        listeners.append(on_snapshot)
        t0 = time.process_time()
        rec.close()  # (waits for the writer process to finish the file)
        closing = time.process_time() - t0
        writer = _children_cpu() - children - startup
        columns, rows, size = len(rec.columns), rec.rows, path.stat().st_size
    b, r = statistics.median(bare), statistics.median(recorded)
    return {"bare_us": b * 1e6, "rec_us": r * 1e6, "cost_us": (r - b) * 1e6, "columns": columns, "dt": cell.dt,
            "bytes_per_row": size / rows, "close_us": closing / rows * 1e6, "writer_us": writer / rows * 1e6,
            "startup_ms": startup * 1e3}


def _children_cpu() -> float:
    """CPU time (s) of the ended child processes (the recorder's writers, once closed)."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench record", description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=300, help="steps per block (default 300)")
    parser.add_argument("--blocks", type=int, default=6, help="blocks of each kind (default 6)")
    args = parser.parse_args(argv)
    runs = {fmt: lockstep_cost(args.steps, args.blocks, suffix) for fmt, suffix in (("Parquet", ".parquet"), ("CSV", ".csv"))}
    first = next(iter(runs.values()))
    print(f"ring_rig_plc, lockstep, in process: median of {args.blocks} blocks of {args.steps} steps "
          f"({first['columns']} columns per row); CPU time of the simulation's process")
    print(f"{'':40}" + "".join(f"{k:>12}" for k in runs))
    for label, key in (("us per step, bare", "bare_us"), ("us per step, recording", "rec_us"),
                       ("recording cost, us per step", "cost_us"), ("file size, bytes per step", "bytes_per_row")):
        print(f"{label:40}" + "".join(f"{r[key]:>12.0f}" for r in runs.values()))
    shares = {k: r["cost_us"] / r["bare_us"] for k, r in runs.items()}
    print(f"{'  share of the step compute time':40}" + "".join(f"{100 * s:>11.1f}%" for s in shares.values()))
    print(f"{'  share of the 12 ms real-time step':40}"
          + "".join(f"{100 * r['cost_us'] / (r['dt'] * 1e6):>11.1f}%" for r in runs.values()))
    print(f"{'closing the file, us/step (simulation)':40}" + "".join(f"{r['close_us']:>12.1f}" for r in runs.values()))
    print(f"{'writer process CPU, us per step recorded':40}" + "".join(f"{r['writer_us']:>12.0f}" for r in runs.values()))
    print(f"{'  its start-up and stop, ms CPU once':40}" + "".join(f"{r['startup_ms']:>12.0f}" for r in runs.values()))
    verdict = ", ".join(f"{k} {'met' if s <= TARGET else 'MISSED'} ({100 * s:.1f} %)" for k, s in shares.items())
    print(f"target: the recorder costs at most {100 * TARGET:g} % of a lockstep step's compute: {verdict}")
    return 0
