"""The whole cell, one full automatic cycle in lockstep: the gripper PLC in process (no network) against the
same PLC across Modbus/TCP (`twin serve` in a subprocess), side by side, so the price of the network is a
ratio measured in one run.

    python -m bench cell [--cycles N]

Each is run twice: with the Python gripper PLC and with the same sequence in Structured Text
(`stations/ring_rig_plc/gripper.st`, in the project's ST runtime, its located variables bound through the
twin's PLC layout; over Modbus against `twin serve --layout plc`).

Both runs use `stations/ring_rig_plc` (physics, the RAPID robot controller and the grip sequence) and the
same PLC program (`stations.ring_rig_plc.plc_logic.cell_sequence` and the demo's operator), scanning every 10 ms.
Over Modbus the PLC exchanges its process image through the server's process-image windows: one function
23 per scan (outputs and sim.advance written, inputs read once the steps are done). Besides the wall
time, which a loaded machine inflates for the two-process run (every scan waits for both processes to be
scheduled), the CPU seconds per cycle (the PLC's process plus twin serve's) show the cost itself.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STATION = ROOT / "stations" / "ring_rig_plc"


def gripper_plc(plc: str):
    """The gripper PLC: the Python sequence, or gripper.st on the station's PLC layout."""
    from stations.ring_rig_plc import plc_logic as ring_rig

    if plc == "python":
        return ring_rig.cell_sequence()
    from plc_client.st_io import StLogic
    from stations.ring_rig_plc.demo import DEFAULT_STATION, ST_FILES
    from twin.frontends.modbus.register_map import build_map

    return StLogic([DEFAULT_STATION / f for f in ST_FILES], build_map(STATION, "plc"))


def in_process(cycles: int, plc_kind: str = "python") -> dict:
    from stations.ring_rig_plc.demo import operator
    from plc_client.scan import Combined, ScanCycle, TwinIO
    from twin_app.cell import open_cell

    t0 = time.perf_counter()
    with open_cell(STATION) as twin:
        load = time.perf_counter() - t0
        plc = ScanCycle(TwinIO(twin), Combined(gripper_plc(plc_kind), operator(cycles)))
        t1, c1 = time.perf_counter(), time.process_time()
        while twin.read("goCyclesDone") < cycles:
            plc.scan()
            if twin.time > 120 * cycles:
                raise RuntimeError("the cycle did not end")
        wall, cpu = time.perf_counter() - t1, time.process_time() - c1
        return {"sim": twin.time, "wall": wall, "scans": plc.scans, "load": load, "requests": 0, "cpu": cpu}


def across_the_network(cycles: int, plc_kind: str = "python") -> dict:
    from stations.ring_rig_plc.demo import CellDemo

    demo = CellDemo(STATION, cycles, out=lambda line: None, plc=plc_kind)
    t0 = time.perf_counter()
    s = demo.run()
    if s.cycles_done != cycles:
        raise RuntimeError("the cycle did not end")
    return {"sim": s.sim_time, "wall": sum(s.cycle_wall), "scans": demo.scans, "load": time.perf_counter() - t0 - s.wall_time,
            "requests": demo.requests, "cpu": sum(demo.cpu)}


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench cell", description=__doc__.split("\n\n")[0])
    parser.add_argument("--cycles", type=int, default=1)
    args = parser.parse_args(argv)
    for kind in ("python", "st"):
        report(args.cycles, kind, in_process(args.cycles, kind), across_the_network(args.cycles, kind))
    return 0


def report(cycles: int, kind: str, local: dict, remote: dict) -> None:
    class args:  # noqa: N801 - the table below reads args.cycles
        pass
    args.cycles = cycles
    what = "the Python PLC (plc_logic.py)" if kind == "python" else "the ST PLC (gripper.st, PLC layout)"
    print(f"ring_rig_plc, {args.cycles} full cycle(s) in lockstep, PLC scan 10 ms, {what}")
    print(f"{'':34}{'in process':>12}{'over Modbus':>13}{'ratio':>8}")
    rows = [
        ("simulated s per cycle", local["sim"] / args.cycles, remote["sim"] / args.cycles, "{:.2f}"),
        ("wall s per cycle", local["wall"] / args.cycles, remote["wall"] / args.cycles, "{:.2f}"),
        ("CPU s per cycle (PLC + twin)", local["cpu"] / args.cycles, remote["cpu"] / args.cycles, "{:.2f}"),
        ("x real time", local["sim"] / local["wall"], remote["sim"] / remote["wall"], "{:.1f}"),
        ("PLC scans per wall s", local["scans"] / local["wall"], remote["scans"] / remote["wall"], "{:.0f}"),
        ("Modbus requests per scan", 0.0, remote["requests"] / max(1, remote["scans"]), "{:.1f}"),
    ]
    for name, a, b, f in rows:
        ratio = f"{b / a:.2f}" if a else ""
        print(f"{name:34}{f.format(a):>12}{f.format(b):>13}{ratio:>8}")
    print(f"(start-up: {local['load']:.1f} s to load the cell in process, {remote['load']:.1f} s for twin serve)")
