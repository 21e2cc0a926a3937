"""A master that reads one poll's inputs in two requests, as OpenPLC does, against `twin serve --realtime`:
how often are the pieces of two different steps? Side by side: `--poll-hold 0` (every read from the latest
step) and the default hold (a connection's reads of one poll from the step of its first read).

    python -m bench pollimage [--station DIR] [--seconds 3] [--poll-ms 10] [--gap-ms 1.2]

Each poll reads `sim.step` (input registers 0-1), waits `--gap-ms` (OpenPLC sleeps between its requests),
then reads `sim.time_ms` (2-3): a poll is torn when time_ms is not step x dt.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run(station: Path, hold: str | None, seconds: float, poll: float, gap: float) -> tuple[int, int]:
    from pymodbus.client import ModbusTcpClient

    sys.path.insert(0, str(ROOT / "tests" / "modbus"))
    from modbus_helpers import ServerProcess

    args = ["--realtime", "--layout", "plc"] + (["--poll-hold", hold] if hold is not None else [])
    with ServerProcess(station, *args) as server:
        c = ModbusTcpClient("127.0.0.1", port=server.port, timeout=5, retries=0)
        assert c.connect()
        dt_ms = c.read_input_registers(6, count=1).registers[0] / 1000.0
        polls = torn = 0
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            t0 = time.monotonic()
            a = c.read_input_registers(0, count=2).registers
            time.sleep(gap)
            b = c.read_input_registers(2, count=2).registers
            step, ms = a[0] << 16 | a[1], b[0] << 16 | b[1]
            polls += 1
            torn += round(step * dt_ms) != ms
            time.sleep(max(0.0, poll - (time.monotonic() - t0)))
        c.close()
    return polls, torn


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="python -m bench pollimage", description=__doc__.split("\n\n")[0])
    p.add_argument("--station", default=str(ROOT / "tests" / "plc" / "stations" / "ring_bench"))
    p.add_argument("--seconds", type=float, default=3.0)
    p.add_argument("--poll-ms", type=float, default=10.0)
    p.add_argument("--gap-ms", type=float, default=1.2)
    a = p.parse_args(argv)
    print(f"{'server':<28} {'polls':>6} {'torn':>6} {'torn %':>7}")
    for label, hold in (("--poll-hold 0 (no hold)", "0"), ("default hold (0.1 s)", None)):
        polls, torn = run(Path(a.station), hold, a.seconds, a.poll_ms / 1000, a.gap_ms / 1000)
        print(f"{label:<28} {polls:>6} {torn:>6} {100 * torn / max(1, polls):>6.1f}%")
    return 0
