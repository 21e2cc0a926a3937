"""Map benchmark: how long a station's map takes from its files (static signal table) vs from a running cell.

    python -m bench map [--runs N]

Per shipped station, side by side in one run: `twin map STATION` as a user runs it (a fresh process:
interpreter start, imports, the static table, the register map, the md export; target under 0.5 s for
the ring rig; wall time and the CPU time it used, which a busy machine does not inflate), the static table alone in this process, and the old way's cost: starting the cell (pybullet
world, RAPID program) to read its table.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STATIONS = ("ring_rig_plc", "ring_rig", "smart_gripper", "four_finger")


def _median(f, runs: int) -> float:
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _process(cmd: list[str], runs: int) -> tuple[float, float]:
    """Median wall and CPU (user + system) seconds of a child process."""
    wall, cpu = [], []
    for _ in range(runs):
        c0, t0 = os.times(), time.perf_counter()
        subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        wall.append(time.perf_counter() - t0)
        c1 = os.times()
        cpu.append(c1.children_user - c0.children_user + c1.children_system - c0.children_system)
    return statistics.median(wall), statistics.median(cpu)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench map")
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args(argv)
    from twin.core.signal_table import station_signals
    from twin_app.cell import Cell

    print(f"{'station':<16}{'twin map wall':>14}{'(cpu)':>9}{'static table':>14}{'running cell':>14}{'cell/static':>13}")
    for name in STATIONS:
        station = ROOT / "stations" / name
        cli, cpu = _process([sys.executable, "-m", "twin", "map", str(station)], args.runs)
        static = _median(lambda: station_signals(station), args.runs)

        def running():
            with Cell(station) as cell:
                return cell.signals
        cell = _median(running, max(1, args.runs // 2))
        print(f"{name:<16}{cli * 1000:>11.0f} ms{cpu * 1000:>6.0f} ms{static * 1000:>11.1f} ms{cell * 1000:>11.0f} ms{cell / static:>12.0f}x")
    return 0
