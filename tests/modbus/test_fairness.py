"""One client flooding `twin serve` with pipelined requests must not take the event loop from the
simulation runner and the other clients (a real `twin serve` in real time, over loopback)."""
from __future__ import annotations

import os
import statistics
import struct
import subprocess
import sys
import threading
import time

from modbus_helpers import RING_BENCH, Raw, ServerProcess, pdu

FLOOD = 20000  # pipelined reads per send: more than one read() of the server's socket holds
ANSWER = 7 + 2 + 2 * 17  # bytes of one answer to the flood's read of 17 input registers


def flood(port: int, seconds: float) -> None:
    """Send FLOOD pipelined reads at a time for `seconds`, reading the answers in another thread (so TCP
    flow control does not stop the flood); print how many answers came back. Runs in its own process,
    so its threads do not take the measuring client's interpreter lock."""
    with Raw(port, timeout=5) as flooder:
        answered = [0]

        def drain():
            while True:
                try:
                    data = flooder.sock.recv(1 << 20)
                except OSError:
                    return
                if not data:
                    return
                answered[0] += len(data)

        threading.Thread(target=drain, daemon=True).start()
        blob = b"".join(flooder.frame(pdu(4, 16, 17), tid=i & 0xFFFF) for i in range(FLOOD))
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            flooder.send(blob)
        print(answered[0] // ANSWER, flush=True)


def counters(raw: Raw) -> tuple[int, int]:
    """(sim.step, sim.late_steps)."""
    words = struct.unpack(">6H", raw.request(pdu(4, 0, 6))[2:])
    return words[0] << 16 | words[1], words[4] << 16 | words[5]


def measure(server: ServerProcess, other: Raw, flood_cmd: list[str]) -> dict:
    """Run `flood_cmd` (niced: what is measured is the server's own fairness, not the OS giving the
    flooder the server's core) while `other` polls every 5 ms: its latency, the steps and late steps."""
    from modbus_helpers import ROOT

    flooder = subprocess.Popen(flood_cmd, stdout=subprocess.PIPE, text=True, cwd=ROOT, preexec_fn=lambda: os.nice(10))
    try:
        time.sleep(0.6)  # the flood is on
        step0, late0 = counters(other)
        t0 = time.monotonic()
        latencies = []
        while time.monotonic() - t0 < 2.5:
            t1 = time.perf_counter()
            assert other.request(pdu(3, 16, 1))[:2] == b"\x03\x02"
            latencies.append(time.perf_counter() - t1)
            time.sleep(0.005)
        step1, late1 = counters(other)
        wall = time.monotonic() - t0
        out, _ = flooder.communicate(timeout=30)
    finally:
        if flooder.poll() is None:
            flooder.kill()
            flooder.wait()
    assert flooder.returncode == 0
    latencies.sort()
    r = {"answered": int(out), "p50": statistics.median(latencies), "p99": latencies[int(0.99 * (len(latencies) - 1))],
         "steps": step1 - step0, "late": late1 - late0, "wall": wall}
    r["report"] = (f"{r['answered']} flood requests answered; the poller: p50 {r['p50'] * 1e3:.1f} ms, "
                   f"p99 {r['p99'] * 1e3:.1f} ms; {r['steps']} steps in {wall:.2f} s ({r['late']} late)")
    return r


def twice(flood_cmd: list[str], ok) -> None:
    """Measure; on a shared machine whose load spoiled the first try, once more (both reports if both fail)."""
    reports = []
    with ServerProcess(RING_BENCH) as server, Raw(server.port) as other:
        for _ in range(2):
            r = measure(server, other, [c.replace("PORT", str(server.port)) for c in flood_cmd])
            reports.append(r["report"])
            if ok(r):
                return
    raise AssertionError("; ".join(reports))


def test_a_flooding_client_leaves_the_simulation_and_the_other_clients_their_turn():
    # Unfair (a whole socket read answered in one callback): p50 ~130 ms, 15 % of the steps, all late.
    twice([sys.executable, __file__, "PORT", "3.5"],
          lambda r: (r["answered"] > 2000  # the flood itself was served (less while the simulation runs late)
                     and r["p50"] < 0.030 and r["p99"] < 0.200 and r["steps"] > 0.5 * r["wall"] / 0.012))


def test_forty_flooding_connections_leave_the_simulation_its_steps_and_a_poller_its_latency():
    """The issue's case: 40 connections pipelining flat out (in one other process) while one client polls.
    Before the global budget: 81 % of the steps late on a quiet machine, all of them on a busy one. The
    benchmark (`python -m bench modbus`) reports the figures and `test_fair_share.py` checks the sharing
    itself, deterministically; a loaded machine makes some steps late whatever the server does (the process
    waits for a core), so here the margins are wide: the simulation keeps real time on average (it catches
    up) and the poller is answered."""
    twice([sys.executable, "-m", "bench.flood", "PORT", "40", "3.5"],
          lambda r: (r["answered"] > 2000 and r["late"] <= 0.6 * r["steps"]
                     and r["steps"] > 0.75 * r["wall"] / 0.012 and r["p99"] < 0.200))


if __name__ == "__main__":
    flood(int(sys.argv[1]), float(sys.argv[2]))
