"""The front-end adapter's channel (`twin.frontends.process`): what one step's snapshot costs the simulation's
process through a socket pair (as the adapter sends it: length-prefixed pickles) and through shared memory
under a sequence lock (doubles only), with a reader process on the other side of each.

    python -m bench adapter [--snapshots N] [--station DIR]
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import socket
import struct
import time
from multiprocessing import shared_memory
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PERIOD = 0.0005  # s between snapshots (a fast lockstep run)


def _pipe_reader(sock: socket.socket, n: int) -> None:
    import pickle

    f = sock.makefile("rb")
    for _ in range(n):
        size = struct.unpack("!I", f.read(4))[0]
        pickle.loads(f.read(size))


def _shm_reader(name: str, count: int, n: int) -> None:
    shm = shared_memory.SharedMemory(name=name)
    fmt, last = struct.Struct(f"<{count}d"), 0
    while last < n:
        seq = struct.unpack_from("<Q", shm.buf, 0)[0]
        if seq != 2 * last and seq % 2 == 0:
            values = fmt.unpack_from(shm.buf, 8)
            if struct.unpack_from("<Q", shm.buf, 0)[0] == seq:
                last = seq // 2
                del values
        else:
            time.sleep(0.0002)  # shared memory does not wake a reader: it polls
    shm.close()


def snapshot_values(station: Path) -> dict:
    from twin_app.cell import Cell

    with Cell(station) as cell:
        cell.step(3)
        return dict(cell.exchange.snapshot.values)


def measure(values: dict, n: int) -> dict:
    from twin.frontends.process import _frame

    ctx = mp.get_context("spawn")
    mine, theirs = socket.socketpair()
    p = ctx.Process(target=_pipe_reader, args=(theirs, n))
    p.start()
    theirs.close()
    time.sleep(1.0)
    t = time.process_time()
    for i in range(n):
        mine.sendall(_frame(("snap", i, i * 0.012, values)))
        time.sleep(PERIOD)
    pipe_us = (time.process_time() - t) / n * 1e6
    size = len(_frame(("snap", 0, 0.0, values)))
    p.join()
    mine.close()

    numbers = [v for v in values.values() if not isinstance(v, str)]
    shm = shared_memory.SharedMemory(create=True, size=8 + 8 * len(numbers))
    try:
        p = ctx.Process(target=_shm_reader, args=(shm.name, len(numbers), n))
        p.start()
        time.sleep(1.0)
        fmt, seq = struct.Struct(f"<{len(numbers)}d"), struct.Struct("<Q")
        t = time.process_time()
        for i in range(1, n + 1):
            seq.pack_into(shm.buf, 0, 2 * i - 1)
            fmt.pack_into(shm.buf, 8, *[float(v) for v in values.values() if not isinstance(v, str)])
            seq.pack_into(shm.buf, 0, 2 * i)
            time.sleep(PERIOD)
        shm_us = (time.process_time() - t) / n * 1e6
        p.join()
    finally:
        shm.close()
        shm.unlink()
    t = time.process_time()
    for _ in range(n):
        time.sleep(PERIOD)
    idle_us = (time.process_time() - t) / n * 1e6  # the sleep's own cost, taken off both
    return {"signals": len(values), "texts": len(values) - len(numbers), "pipe_us": pipe_us - idle_us,
            "pipe_bytes": size, "shm_us": shm_us - idle_us, "shm_bytes": 8 + 8 * len(numbers)}


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench adapter", description=__doc__.split("\n\n")[0])
    parser.add_argument("--snapshots", type=int, default=3000)
    parser.add_argument("--station", type=Path, default=ROOT / "stations" / "ring_rig")
    args = parser.parse_args(argv)
    r = measure(snapshot_values(args.station), args.snapshots)
    print(f"{args.station.name}: {r['signals']} signals ({r['texts']} text), {args.snapshots} snapshots, "
          "CPU of the sending (simulation's) process per snapshot")
    print(f"{'socket pair (pickled, every value)':40}{r['pipe_us']:>8.1f} us {r['pipe_bytes']:>8} B")
    print(f"{'shared memory + seqlock (numbers only)':40}{r['shm_us']:>8.1f} us {r['shm_bytes']:>8} B")
    return 0
