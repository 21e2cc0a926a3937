"""The whole cell, its full automatic cycle in lockstep: the gripper PLC in process (no network) against the
same PLC across Modbus/TCP (`twin serve --lockstep` in a subprocess, on loopback), side by side in one run, so
the price of the network is a ratio. Target: over Modbus within 1.3x of in process (wall time per cycle).

    python -m bench cell [--cycles N] [--rounds R] [--plc python,st] [--scans N] [--any-core]

Both sides run the same thing: `stations/ring_rig_plc` (physics, the RAPID robot controller), the same gripper
PLC (the Python sequence `plc_logic.cell_sequence`, or `gripper.st` in the project's ST runtime on the PLC
layout, `twin serve --layout plc`) beside the demo's operator, one `plc_client.scan.ScanCycle` scanning every
10 ms and reading the same inputs, until the cycles are done. In process the PLC reads and writes the cell
through the register map's resolution (`TwinIO(..., wire=map)`), exactly what it reads and writes over Modbus,
so both runs take the same steps to the same state: the bench checks it (steps, scans, the ring's pose) and
says so. Over Modbus one function 23 per scan carries the outputs and `sim.advance` and brings the inputs
back once the steps are done.

Both sides run on one core by default (the bench process, and twin serve which it starts, pinned to the same CPU):
in lockstep the PLC and the twin take turns and never run at once, so a second core gives nothing but a wake-up of a
halted core at every exchange, twice a scan, which on a virtual machine costs more than the request itself (a
halted vCPU is woken through the hypervisor). That is how to run a lockstep cell (docs/performance.md); `--any-core`
measures it where the OS puts the processes, and the verdict line gives that ratio too.

Rounds alternate the order (in process first, then over Modbus first, ...); each side's figure is its median.
Besides the wall time, the CPU seconds (the PLC's process plus twin serve's) show the cost itself: in lockstep
the two processes take turns, so on a loaded machine every scan also waits to be scheduled twice. The load
average is printed before and after. `--scans N` stops each run after N scans (the test suite's tiny run).
"""
from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STATION = ROOT / "stations" / "ring_rig_plc"
TARGET = 1.3
POSE = ("ring.x", "ring.y", "ring.z")


def gripper_plc(plc: str, rmap):
    """The gripper PLC: the Python sequence, or gripper.st bound through the map's PLC layout."""
    from stations.ring_rig_plc import plc_logic as ring_rig

    if plc == "python":
        return ring_rig.cell_sequence()
    from plc_client.st_io import StLogic
    from stations.ring_rig_plc.demo import DEFAULT_STATION, ST_FILES

    return StLogic([DEFAULT_STATION / f for f in ST_FILES], rmap)


def layout_of(plc: str) -> str:
    return "plc" if plc == "st" else ""


def _scan_cycle(io, plc: str, rmap, cycles: int):
    from plc_client.scan import Combined, ScanCycle
    from stations.ring_rig_plc.demo import operator

    logic = Combined(gripper_plc(plc, rmap), operator(cycles))
    return ScanCycle(io, logic, cycle=0.010, inputs=tuple(dict.fromkeys((*logic.inputs, "goCyclesDone", *POSE))))


def _run(plc, cycles: int, scans: int | None) -> tuple[float, dict]:
    """Scan until the cycles are done (or `scans` scans): (wall s, the last input image)."""
    limit = 12000 * cycles  # 120 s of simulated time per cycle
    t0 = time.perf_counter()
    while True:
        image = plc.scan()
        if image["goCyclesDone"] >= cycles or plc.scans == scans:
            break
        if plc.scans >= limit:
            raise RuntimeError("the cycle did not end")
    return time.perf_counter() - t0, image


def in_process(cycles: int, plc_kind: str = "python", scans: int | None = None) -> dict:
    from plc_client.scan import TwinIO
    from twin_app.cell import Cell

    with Cell(STATION, layout=layout_of(plc_kind)) as cell:
        plc = _scan_cycle(TwinIO(cell, wire=cell.register_map), plc_kind, cell.register_map, cycles)
        c0 = time.process_time()
        wall, image = _run(plc, cycles, scans)
        cpu = time.process_time() - c0
        return {"wall": wall, "cpu": cpu, "scans": plc.scans, "steps": cell.step_count, "requests": 0,
                "pose": tuple(image[n] for n in POSE)}


def over_modbus(cycles: int, plc_kind: str = "python", scans: int | None = None) -> dict:
    from plc_client.client import ClientIO
    from plc_client.testing import twin_server
    from stations.ring_rig_plc.demo import _process_cpu

    with twin_server(STATION, lockstep=True, layout=layout_of(plc_kind)) as server, server.client() as client:
        plc = _scan_cycle(ClientIO(client, lockstep=True), plc_kind, server.map, cycles)
        c0, s0 = time.process_time(), _process_cpu(server.process.pid)
        r0 = client.requests
        wall, image = _run(plc, cycles, scans)
        cpu = time.process_time() - c0 + _process_cpu(server.process.pid) - s0
        requests = client.requests - r0
        return {"wall": wall, "cpu": cpu, "scans": plc.scans, "steps": client.get("sim.step"), "requests": requests,
                "pose": tuple(image[n] for n in POSE)}


class OneCore:
    """Pin this process (and the processes it starts meanwhile) to one CPU of those it may use, then put its
    affinity back. A no-op where the OS has no affinity (not Linux)."""

    def __init__(self, on: bool = True):
        self.on = on and hasattr(os, "sched_setaffinity")
        self.cpu = None

    def __enter__(self):
        if self.on:
            self._before = os.sched_getaffinity(0)
            self.cpu = min(self._before)
            os.sched_setaffinity(0, {self.cpu})
        return self

    def __exit__(self, *exc) -> None:
        if self.on:
            os.sched_setaffinity(0, self._before)


def load_average() -> str:
    try:
        return "/".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        return "?"


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench cell", description=__doc__.split("\n\n")[0])
    parser.add_argument("--cycles", type=int, default=1, help="full cycles per run (default 1)")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each side, alternating (default 3)")
    parser.add_argument("--plc", default="python,st", help="the gripper PLCs to run: python, st or both (default)")
    parser.add_argument("--scans", type=int, default=None, help="stop each run after N scans (a quick check)")
    parser.add_argument("--any-core", action="store_true",
                        help="only where the OS puts the processes (default: both sides on one core, then anywhere)")
    args = parser.parse_args(argv)
    kinds = [k.strip() for k in args.plc.split(",") if k.strip()]
    if not kinds or any(k not in ("python", "st") for k in kinds) or args.cycles < 1 or args.rounds < 1:
        parser.error("--plc python,st; --cycles and --rounds at least 1")
    print(f"load average (1/5/15 min) before: {load_average()}")
    verdicts = []
    for kind in kinds:
        ratios = {}
        for one_core in ((False,) if args.any_core else (True, False)):
            local, remote = [], []
            with OneCore(one_core) as pin:
                for r in range(args.rounds):
                    sides = [(local, in_process), (remote, over_modbus)]
                    for results, run in (sides if r % 2 == 0 else sides[::-1]):
                        results.append(run(args.cycles, kind, args.scans))
                where = f"both sides on CPU {pin.cpu}" if pin.cpu is not None else "on any core"
            ratios[one_core] = report(args.cycles, kind, local, remote, where)
        (ratio, cpu, alike), anywhere = ratios[not args.any_core], ratios[False]
        met = "met" if ratio <= TARGET and alike else "MISSED"
        line = (f"{kind}: over Modbus {ratio:.2f}x the in-process wall time per cycle"
                f"{'' if args.any_core else ', both on one core'} (target <= {TARGET}x: {met}), CPU {cpu:.2f}x")
        if not args.any_core:
            line += f"; on any core {anywhere[0]:.2f}x (CPU {anywhere[1]:.2f}x)"
        verdicts.append(line)
    print(f"load average (1/5/15 min) after: {load_average()}")
    for line in verdicts:
        print(line)
    return 0


def report(cycles: int, kind: str, local: list[dict], remote: list[dict], where: str) -> tuple[float, float, bool]:
    """Print one side-by-side table; (wall ratio, CPU ratio, both sides the same run)."""
    what = "the Python PLC (plc_logic.py)" if kind == "python" else "the ST PLC (gripper.st, PLC layout)"
    n = len(local)
    print(f"\nring_rig_plc, {cycles} full cycle(s) in lockstep, PLC scan 10 ms, {what}; median of {n} alternating runs, "
          f"{where}")
    print(f"{'':34}{'in process':>12}{'over Modbus':>13}{'ratio':>8}")

    def med(runs, key, per=1.0):
        return statistics.median(r[key] / per for r in runs)

    lw, rw = med(local, "wall", cycles), med(remote, "wall", cycles)
    rows = [
        ("wall s per cycle", lw, rw, "{:.3f}"),
        ("CPU s per cycle (PLC + twin)", med(local, "cpu", cycles), med(remote, "cpu", cycles), "{:.3f}"),
        ("wall us per PLC scan", 1e6 * med(local, "wall") / local[0]["scans"], 1e6 * med(remote, "wall") / remote[0]["scans"], "{:.0f}"),
        ("Modbus requests per scan", 0.0, med(remote, "requests") / max(1, remote[0]["scans"]), "{:.2f}"),
    ]
    for name, a, b, f in rows:
        ratio = f"{b / a:.2f}" if a else ""
        print(f"{name:34}{f.format(a):>12}{f.format(b):>13}{ratio:>8}")
    print("  wall s per run: in process " + " ".join(f"{r['wall']:.3f}" for r in local)
          + "; over Modbus " + " ".join(f"{r['wall']:.3f}" for r in remote)
          + f" (fastest runs: {min(r['wall'] for r in remote) / min(r['wall'] for r in local):.2f}x; a loaded machine "
          "only adds time)")
    same = {(r["scans"], r["steps"], r["pose"]) for r in local + remote}
    if len(same) == 1:
        scans, steps, pose = same.pop()
        print(f"  same run on both sides: {scans} scans, {steps} steps, the ring at "
              f"({', '.join(f'{v:.2f}' for v in pose)}) mm")
        alike = True
    else:
        print(f"  NOT the same run on both sides: (scans, steps, ring pose) {sorted(same)}")
        alike = False
    return rw / lw, med(remote, "cpu") / med(local, "cpu"), alike


if __name__ == "__main__":
    raise SystemExit(main(__import__("sys").argv[1:]))
