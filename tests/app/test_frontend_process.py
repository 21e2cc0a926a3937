"""A front end in a process of its own (`twin.frontends.process`) sees every step and writes as one in the
simulation's process would: the same refusals (type and message) and, in lockstep, the same results bit for
bit as the cell stepped in process."""
from __future__ import annotations

import asyncio
import json

from tests.conftest import STATIONS
from twin.frontends.process import FrontEndProcess
from twin_app.cell import Cell

SCRIPT = [("submit", [("L2", 9.0)]),            # out of range
          ("submit", [("ring.present", 2)]),    # not a bool
          ("submit", [("sim.step", 3)]),        # an output
          ("submit", [("L2", 0.2), ("ring.present", True)]),
          ("advance", 5),
          ("submit", [("L3", 0.1)]),
          ("advance", 3)]


def served(tmp_path) -> dict:
    out = tmp_path / "probe.json"
    with Cell(STATIONS / "ring_rig") as cell:
        cell.add_front_end(FrontEndProcess("probe", "tests.app.frontend_probe:probe",
                                           {"out": str(out), "script": SCRIPT}))

        async def main():
            stop = asyncio.Event()

            async def until_done():
                while not out.exists():
                    await asyncio.sleep(0.05)
                stop.set()
            waiter = asyncio.ensure_future(until_done())
            code = await asyncio.wait_for(cell.serve(lockstep=True, stop=stop), 60)
            waiter.cancel()
            return code
        assert asyncio.run(main()) == 0
        final = dict(cell.exchange.snapshot.values)
    return json.loads(out.read_text()) | {"final": final}


def in_process() -> tuple[list, dict, dict]:
    """The same script on a cell stepped in process: the refusals it raises, the values after each advance."""
    refusals, after = [], []
    with Cell(STATIONS / "ring_rig") as cell:
        cell.pace(lockstep=True)
        for kind, arg in SCRIPT:
            if kind == "submit":
                try:
                    cell.exchange.submit(arg)
                except Exception as exc:  # noqa: BLE001
                    refusals.append([type(exc).__module__ + "." + type(exc).__qualname__, str(exc)])
            else:
                cell.step(arg)
                after.append(dict(cell.exchange.publish().values))
    return refusals, after


def test_a_front_end_in_its_own_process_writes_as_one_in_process(tmp_path):
    seen = served(tmp_path)
    refusals, after = in_process()
    results = seen["results"]
    assert [r[1:] for r in results if r[0] == "err"] == refusals and len(refusals) == 3
    advances = [r[1] for r in results if r[0] == "ok" and isinstance(r[1], list) and isinstance(r[1][0], int)]
    assert [a[0] for a in advances] == [5, 8]  # the step count when the steps were done
    # what the process saw after each advance is the in-process cell's state, bit for bit (sim.* aside: the
    # runner's own bookkeeping differs between a served and a stepped cell)
    for (_, step, values), expected in zip(advances, after):
        assert step == expected["sim.step"]
        assert {k: v for k, v in values.items() if not k.startswith("sim.")} == \
               {k: v for k, v in expected.items() if not k.startswith("sim.")}
    # every step reached the process, in order, from step 0 (a process that missed the first ones would not pass)
    steps = seen["steps"]
    assert sorted(set(steps)) == list(range(steps[0], 9)) and steps == sorted(steps), steps
    assert steps[0] == 0  # from the first snapshot on: in lockstep nothing steps before the script asks


def test_bench_adapter_runs_with_tiny_parameters():
    """`python -m bench adapter` (the measurement behind the adapter's choice of channel) cannot rot."""
    import subprocess
    import sys

    from tests.conftest import ROOT

    run = subprocess.run([sys.executable, "-m", "bench", "adapter", "--snapshots", "20"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "socket pair" in run.stdout and "shared memory" in run.stdout
