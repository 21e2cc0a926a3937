"""The `fault` event (docs/events.md): when the simulation stops on an error, the machine interface says so once,
stamped with the simulated time of the last step that completed, and the served cell goes on to its `stopped`.

The cell is served as `twin serve --lockstep --events FILE` serves it (its runner, its events writer), in
process so the test can take the physics engine away between two steps: pybullet's connection closed under a
running simulation, as when a physics server dies. Steps are asked for through `sim.advance`, as a client would."""
from __future__ import annotations

import asyncio
from concurrent.futures import ThreadPoolExecutor

from plc_client.events import EventLog
from tests.conftest import STATIONS
from twin.observe.events import Events
from twin_app.cli import open_served_cell

STEPS = 7


def test_a_failing_step_is_one_fault_event_at_the_last_completed_steps_time(tmp_path):
    path = tmp_path / "events.jsonl"
    events = Events.open(str(path))
    cell = open_served_cell(STATIONS / "smart_gripper", events)
    dt = cell.twin.dt

    async def run() -> None:
        stop = asyncio.Event()
        served = asyncio.ensure_future(cell.serve(lockstep=True, stop=stop))

        async def advance(n: int) -> None:
            cell.exchange.submit([("sim.advance", n)])
            for _ in range(500):
                if cell.exchange.read("sim.advance") == 0 or cell.exchange.fault:
                    return
                await asyncio.sleep(0.01)
            raise AssertionError("the steps did not run")

        try:
            for _ in range(500):  # served once `ready` is out
                if '"ready"' in path.read_text():
                    break
                await asyncio.sleep(0.01)
            await advance(STEPS)
            cell.twin.world.client.disconnect()  # the engine is gone before the next step
            await advance(1)
            assert cell.exchange.fault
        finally:
            stop.set()
            await served

    try:  # in a thread of its own: a loop some other test left running in this one cannot get in the way
        with ThreadPoolExecutor(1) as pool:
            pool.submit(asyncio.run, run()).result()
    finally:
        events.close()
        cell.close()
    log = EventLog(path).new()
    kinds = [e["event"] for e in log]
    assert kinds[0] == "ready" and kinds[-1] == "stopped"
    faults = [e for e in log if e["event"] == "fault"]
    assert len(faults) == 1  # one, although the runner was asked for another step
    fault = faults[0]
    assert fault["step"] == STEPS and fault["t"] == STEPS * dt  # the last step that completed, simulated time
    assert "physics server" in fault["message"]  # pybullet's own words, with the error's type
    assert kinds.index("fault") < kinds.index("stopped")
    assert log[-1]["steps"] == STEPS
