"""Everything at once: `twin serve --realtime` quiet, and beside it in the same run under every load together.

    python -m bench load [--seconds S] [--connections 40] [--items 1000] [--station DIR] [--no-browser]

Four runs of the same station in real time (the robot running its program), each measured over S seconds:

1. quiet: `twin serve` and one Modbus poller (one FC 4 read of sim.step every 10 ms, like a PLC scan);
2. everything: the same server with `--opcua 0 --view 0 --record FILE`, and meanwhile `connections`
   connections flooding Modbus with pipelined reads (`bench.flood`, one process), an OPC UA client with
   `items` monitored items at 12 ms (`bench.opcua --subscriber`, a second process), the live page open in a
   headless Chromium (Playwright with Debian's chromium, as tests/view), and the poller;
3. and 4. the same two with a CPU hog (a busy loop pinned to one core) beside them.

Reported: steps run, late steps (the server's own sim.late_steps: steps finished after their wall-clock
deadline), the poller's p50/p99, the flood's answers/s, the OPC UA notifications/s, the page's updates/s.
Targets (issue 21): late steps at most 1 % (percentage points) above the quiet run's, the poller's p99 under
20 ms.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from bench.modbus_latency import Conn, percentile
from bench.view import COUNT_UPDATES

ROOT = Path(__file__).resolve().parent.parent
STATION = ROOT / "stations" / "ring_rig_plc"
POLL_S = 0.010
LATE_TARGET_PCT = 1.0
P99_TARGET_MS = 20.0


def hog() -> subprocess.Popen:
    """A busy loop pinned to the machine's last core (stopped by the caller)."""
    core = max(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 0
    code = f"import os\ntry:\n    os.sched_setaffinity(0, {{{core}}})\nexcept (AttributeError, OSError):\n    pass\nwhile True:\n    pass\n"
    return subprocess.Popen([sys.executable, "-c", code])


class Poller(threading.Thread):
    """One FC 4 read of sim.step..sim.time_ms every POLL_S: its latencies in ms."""

    def __init__(self, port: int):
        super().__init__(daemon=True)
        self.conn, self.stop, self.ms = Conn(port), threading.Event(), []

    def run(self) -> None:
        try:
            while not self.stop.is_set():
                t0 = time.perf_counter()
                self.conn.call(4, 0, 4)
                self.ms.append((time.perf_counter() - t0) * 1e3)
                self.stop.wait(POLL_S)
        finally:
            self.conn.close()


def run(station: Path, seconds: float, *, everything: bool, with_hog: bool, connections: int, items: int,
        browser, rt_priority: bool = True) -> dict:
    from plc_client.testing import twin_server

    tmp = tempfile.TemporaryDirectory(prefix="bench-load-")
    extra = ["--opcua", "0", "--opcua-security", "none", "--view", "0",
             "--record", str(Path(tmp.name) / "run.parquet")] if everything else []
    if not rt_priority:
        extra.append("--no-rt-priority")
    procs: list[subprocess.Popen] = []
    page = None
    result = {"fps": None, "notifications_s": None, "flood_s": None}
    try:
        if with_hog:
            procs.append(hog())
        with twin_server(station, lockstep=False, extra_args=extra) as server:
            port = server.endpoint("modbus")["port"]
            subscriber = flooder = None
            if everything:
                url = server.endpoint("opcua")["url"]
                subscriber = subprocess.Popen([sys.executable, "-m", "bench", "opcua", "--subscriber", url,
                                               _station_name(station), str(items), str(seconds + 1.5)],
                                              stdout=subprocess.PIPE, text=True, cwd=ROOT)
                procs.append(subscriber)
                line = subscriber.stdout.readline()
                if not line.startswith("subscribed"):
                    raise RuntimeError(f"the OPC UA subscriber did not start: {line!r}")
                if browser is not None:
                    page = browser.new_page(viewport={"width": 1024, "height": 700})
                    page.goto(server.endpoint("view")["url"])
                    page.wait_for_selector("#sim-state", timeout=120000)
                flooder = subprocess.Popen([sys.executable, "-m", "bench.flood", str(port), str(connections),
                                            str(seconds + 1.0)], stdout=subprocess.PIPE, text=True, cwd=ROOT)
                procs.append(flooder)
                time.sleep(0.5)
            with server.client() as plc:
                if "fullAutoRun" in server.map:
                    plc.write(fullAutoRun=1)  # the robot program runs its cycle
                poller = Poller(port)
                a = plc.read("sim.step", "sim.late_steps")
                poller.start()
                if page is not None:
                    result["fps"] = page.evaluate(COUNT_UPDATES, seconds)
                else:
                    time.sleep(seconds)
                b = plc.read("sim.step", "sim.late_steps")
                poller.stop.set()
                poller.join(10)
            if flooder is not None:
                result["flood_s"] = int(flooder.communicate(timeout=60)[0] or 0) / (seconds + 1.0)
            if subscriber is not None:
                out = subscriber.communicate(timeout=60)[0]
                counts = [int(w.split()[1]) for w in out.splitlines() if w.startswith("notifications")]
                result["notifications_s"] = counts[0] / (seconds + 1.5) if counts else None
            if page is not None:
                page.close()
                page = None
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait(10)
        tmp.cleanup()
    steps, late = b["sim.step"] - a["sim.step"], b["sim.late_steps"] - a["sim.late_steps"]
    return result | {"steps": steps, "late": late, "late_pct": 100.0 * late / max(1, steps),
                     "p50": percentile(poller.ms, 50) if poller.ms else float("nan"),
                     "p99": percentile(poller.ms, 99) if poller.ms else float("nan"), "polls": len(poller.ms)}


def _station_name(station: Path) -> str:
    from twin.core.station import load_station

    return load_station(station).name


def open_browser():
    """(playwright, browser) or (None, None) and why not."""
    try:
        from playwright.sync_api import sync_playwright

        from tests.view.conftest import CHROMIUM_ARGS, chromium_path
    except ImportError as exc:
        return None, None, f"no Playwright ({exc})"
    exe = chromium_path()
    if exe is None:
        return None, None, "no chromium installed"
    pw = sync_playwright().start()
    return pw, pw.chromium.launch(executable_path=exe, args=CHROMIUM_ARGS), ""


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench load", description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="measured window per run (default 20)")
    parser.add_argument("--connections", type=int, default=40, help="connections flooding Modbus (default 40)")
    parser.add_argument("--items", type=int, default=1000, help="OPC UA monitored items (default 1000)")
    parser.add_argument("--station", type=Path, default=STATION)
    parser.add_argument("--no-browser", action="store_true", help="no Chromium on the page")
    parser.add_argument("--no-hog", action="store_true", help="leave out the two runs beside a CPU hog")
    parser.add_argument("--no-rt-priority", action="store_true",
                        help="twin serve --no-rt-priority: without real-time scheduling (to see what it does)")
    args = parser.parse_args(argv)

    pw, browser, why = (None, None, "--no-browser") if args.no_browser else open_browser()
    runs = {}
    try:
        for hogged in (False,) if args.no_hog else (False, True):
            for everything in (False, True):
                label = ("everything" if everything else "quiet") + (" + hog" if hogged else "")
                runs[label] = run(args.station, args.seconds, everything=everything, with_hog=hogged,
                                  connections=args.connections, items=args.items, browser=browser,
                                  rt_priority=not args.no_rt_priority)
    finally:
        if browser is not None:
            browser.close()
        if pw is not None:
            pw.stop()

    def fmt(v, spec):
        return f"{'-' if v is None else format(v, spec):>18}"

    print(f"{args.station.name}, real time, {args.seconds:g} s windows; everything = {args.connections} connections "
          f"flooding Modbus, OPC UA {args.items} monitored items, the page open"
          + (f" (no browser: {why})" if why else " in Chromium") + ", recording on"
          + ("; twin serve --no-rt-priority" if args.no_rt_priority else ""))
    print(f"{'':30}" + "".join(f"{k:>18}" for k in runs))
    for label, key, spec in (("steps run", "steps", "d"), ("late steps", "late", "d"), ("late steps, %", "late_pct", ".2f"),
                             ("poller p50, ms", "p50", ".2f"), ("poller p99, ms", "p99", ".2f"),
                             ("flood answers/s", "flood_s", ".0f"), ("OPC UA notifications/s", "notifications_s", ".0f"),
                             ("page updates/s", "fps", ".1f")):
        print(f"{label:30}" + "".join(fmt(r[key], spec) for r in runs.values()))
    print(f"(load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")
    for hogged in ("",) if args.no_hog else ("", " + hog"):
        quiet, loaded = runs["quiet" + hogged], runs["everything" + hogged]
        extra = loaded["late_pct"] - quiet["late_pct"]
        ok = extra <= LATE_TARGET_PCT and loaded["p99"] < P99_TARGET_MS
        print(f"everything{hogged}: late steps {extra:+.2f} points above the quiet run's (target at most "
              f"+{LATE_TARGET_PCT:g}), poller p99 {loaded['p99']:.1f} ms (target under {P99_TARGET_MS:g}): "
              + ("met" if ok else "MISSED"))
    return 0
