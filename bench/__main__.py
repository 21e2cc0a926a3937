"""Benchmarks: `python -m bench NAME [ARGS...]` (or `python3 tasks.py bench NAME`).

Each benchmark is a module of this package with a `main(argv) -> int`; add yours to BENCHMARKS.
"""
from __future__ import annotations

import importlib
import sys

BENCHMARKS = {
    "core": "bench.core_step",  # simulation steps per second, grip-check cost vs target count
    "modbus": "bench.modbus_latency",  # twin serve vs bare pymodbus: latency, throughput, late steps
    "cell": "bench.cell",  # the full cycle: the PLC in process vs across Modbus/TCP, lockstep
    "campaign": "bench.campaign",  # scenarios/min and parallel efficiency, local pool vs Dask on loopback
    "rapid": "bench.rapid_polling",  # RAPID polling loops offline: wall time per simulated second
    "opcua": "bench.opcua",  # OPC UA vs Modbus on the same cell: latency, change delay, 1000 monitored items
    "view": "bench.view",  # the live page and recording: late steps, page updates per s, recording cost per step
    "map": "bench.signal_map",
    "st": "bench.st_scan",  # Structured Text PLC scan vs the Python PLC's, and a 2000-statement program  # twin map from the static signal table vs from a running cell
    "pollimage": "bench.poll_image",  # a master reading a poll in two requests: torn images with and without the hold
    "record": "bench.recording",  # the flight recorder's cost per lockstep step, Parquet and CSV
    "load": "bench.load",  # everything at once (Modbus flood, OPC UA items, the page, recording) beside a quiet run
    "adapter": "bench.adapter",  # a front end in its own process: a snapshot through a socket pair vs shared memory
}


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ("-h", "--help") or argv[0] not in BENCHMARKS:
        print("usage: python -m bench NAME [ARGS...]   (NAME --help for its options)", file=sys.stderr)
        for name, module in BENCHMARKS.items():
            print(f"  {name:<8} {module}", file=sys.stderr)
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    return importlib.import_module(BENCHMARKS[argv[0]]).main(argv[1:])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
