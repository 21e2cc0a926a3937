"""The live view and recording: what they cost the simulation, side by side in one run.

    python -m bench view [--seconds S] [--steps N]

1. Real time (`twin serve stations/ring_rig_plc --realtime`, the robot running its program): late steps
   of the bare server, then of the same server with `--view` and `--record`, with a headless Chromium
   showing the page meanwhile; and how often the page's state line changed per second in the browser
   (the page's update rate). Needs Playwright and Debian's chromium for the browser rows.
2. Lockstep, in process: microseconds per step of the ring rig with and without a recorder attached
   (alternating blocks, so the machine's load hits both alike): the recording's cost per step, as a
   share of the step's own compute time and of the 12 ms real-time step.
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STATION = ROOT / "stations" / "ring_rig_plc"

COUNT_UPDATES = """(seconds) => new Promise(resolve => {
    let last = null, changes = 0;
    const look = () => { const el = document.querySelector('#sim-state'); const t = el ? el.textContent : null;
                         if (t !== null && t !== last) { if (last !== null) changes++; last = t; } };
    const obs = new MutationObserver(look);
    obs.observe(document.body, {subtree: true, childList: true, characterData: true});
    setTimeout(() => { obs.disconnect(); resolve(changes / seconds); }, seconds * 1000);
})"""


WINDOWS = {"bare": lambda browser: (False, None), "record": lambda browser: (False, None, True),
           "view": lambda browser: (True, browser, False), "view+record": lambda browser: (True, browser)}


def realtime_run(seconds: float, view: bool, browser, record: bool | None = None) -> dict:
    from plc_client.testing import twin_server

    record = view if record is None else record
    extra, tmp = [], None
    if view:
        extra += ["--view", "0"]
    if record:
        tmp = tempfile.TemporaryDirectory(prefix="bench-view-")
        extra += ["--record", str(Path(tmp.name) / "run.parquet")]
    try:
        with twin_server(STATION, lockstep=False, extra_args=extra) as server:
            page = None
            fps = None
            url = server.endpoint("view")["url"] if view else None  # the page is up when the server is ready
            if view and browser is not None:
                page = browser.new_page(viewport={"width": 1024, "height": 700})
                page.goto(url)
                page.wait_for_selector("#sim-state", timeout=120000)
                page.wait_for_timeout(2000)
            with server.client() as plc:
                plc.write(fullAutoRun=1)  # the robot program runs its cycle (it waits for the PLC at the grips)
                a = plc.read("sim.step", "sim.late_steps")
                t0 = time.perf_counter()
                if page is not None:
                    fps = page.evaluate(COUNT_UPDATES, seconds)
                else:
                    time.sleep(seconds)
                wall = time.perf_counter() - t0
                b = plc.read("sim.step", "sim.late_steps")
            if page is not None:
                page.close()
        steps = b["sim.step"] - a["sim.step"]
        late = b["sim.late_steps"] - a["sim.late_steps"]
        return {"steps": steps, "late": late, "late_pct": 100.0 * late / max(1, steps), "fps": fps,
                "steps_per_s": steps / wall}
    finally:
        if tmp is not None:
            tmp.cleanup()


def lockstep_cost(steps: int, blocks: int = 6) -> dict:
    """The recorder's cost per lockstep step (`bench.recording`, `python -m bench record`)."""
    from bench.recording import lockstep_cost as cost

    return cost(steps, blocks)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench view", description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=15.0, help="real-time window per run (default 15)")
    parser.add_argument("--steps", type=int, default=300, help="lockstep: steps per block (default 300)")
    parser.add_argument("--no-browser", action="store_true", help="serve the page without opening it in Chromium")
    parser.add_argument("--windows", default=",".join(WINDOWS),
                        help=f"the real-time runs, of {', '.join(WINDOWS)} (default all)")
    args = parser.parse_args(argv)
    windows = [w.strip() for w in args.windows.split(",") if w.strip()]
    if not windows or any(w not in WINDOWS for w in windows):
        parser.error(f"--windows: some of {', '.join(WINDOWS)}")

    browser, pw, why = None, None, ""
    try:
        if args.no_browser:
            raise ImportError("--no-browser")
        from playwright.sync_api import sync_playwright

        from tests.view.conftest import CHROMIUM_ARGS, chromium_path

        exe = chromium_path()
        if exe is None:
            why = "no chromium installed"
        else:
            pw = sync_playwright().start()
            browser = pw.chromium.launch(executable_path=exe, args=CHROMIUM_ARGS)
    except ImportError as exc:
        why = f"no Playwright ({exc})"
    try:
        runs = {("bare server" if w == "bare" else w): realtime_run(args.seconds, *WINDOWS[w](browser))
                for w in windows}
    finally:
        if browser is not None:
            browser.close()
        if pw is not None:
            pw.stop()
    cost = lockstep_cost(args.steps)

    print(f"ring_rig_plc, real time x1 (step 12 ms), {args.seconds:g} s windows"
          + (f"; browser rows skipped: {why}" if why else ""))
    print(f"{'':36}" + "".join(f"{k:>14}" for k in runs))
    print(f"{'steps run':36}" + "".join(f"{r['steps']:>14}" for r in runs.values()))
    print(f"{'late steps':36}" + "".join(f"{r['late']:>14}" for r in runs.values()))
    print(f"{'late steps, %':36}" + "".join(f"{r['late_pct']:>14.2f}" for r in runs.values()))
    print(f"{'page updates per s (browser)':36}"
          + "".join(f"{'-' if r['fps'] is None else format(r['fps'], '.1f'):>14}" for r in runs.values()))
    import os

    print(f"(load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; the browser renders WebGL in software "
          "on the same machine)")
    print()
    print(f"lockstep, in process, median of 6 blocks of {args.steps} steps ({cost['columns']} columns per row)")
    print(f"{'us per step, bare':40}{cost['bare_us']:>14.0f}")
    print(f"{'us per step, recording':40}{cost['rec_us']:>14.0f}")
    print(f"{'recording cost, us per step':40}{cost['cost_us']:>14.0f}")
    print(f"{'file size, bytes per step (Parquet)':40}{cost['bytes_per_row']:>14.0f}")
    print(f"{'  share of the step compute time':40}{100 * cost['cost_us'] / cost['bare_us']:>13.1f}%")
    print(f"{'  share of the 12 ms real-time step':40}{100 * cost['cost_us'] / (cost['dt'] * 1e6):>13.1f}%")
    return 0
