"""The OPC UA server runs in a process of its own (`twin.frontends.process`): a client's reads are answered while
the cell's loop is busy (as in a long simulation step), and what it reads is the cell's last published step; a
write is answered once the simulation's process has validated it, and reads back as written. No timing: the
cell's loop is held until the client has its read answers, so a server that needed that loop would never answer.
The simulation's process keeps its interpreter-wide settings and its own threads only."""
from __future__ import annotations

import asyncio
import threading

from asyncua import Client, ua

from opcua_helpers import RING_RIG, advance, namespace, node, write_status


def test_reads_are_answered_while_the_cells_loop_is_busy_and_the_simulations_process_is_left_alone():
    import gc
    import sys

    from twin.frontends.opcua.security import Security
    from twin.frontends.opcua.serve import OpcUaFrontEnd
    from twin_app.cell import Cell

    answers: dict[str, object] = {}
    answered = threading.Event()

    def client(url: str) -> None:
        async def session():
            async with Client(url, timeout=20, watchdog_intervall=3600) as c:
                ns = await namespace(c)
                answers["sim.step"] = await node(c, ns, "sim.step").read_value()
                answers["L2 before"] = await node(c, ns, "L2").read_value()
                answered.set()  # the cell's loop may go on now: a write needs it (validated there)
                answers["write"] = await write_status(node(c, ns, "L2"), 0.30, ua.VariantType.Double)
                answers["L2 read back"] = await node(c, ns, "L2").read_value()
                answers["advanced to"] = await advance(c, ns, 3)  # needs the cell's loop: it runs the steps
                answers["L2 after"] = await node(c, ns, "L2").read_value()

        try:
            asyncio.run(session())
        except Exception as exc:  # noqa: BLE001
            answers["error"] = repr(exc)
        finally:
            answered.set()

    def mine() -> list[str]:  # the threads of this process (the log's writer aside: it comes with the log)
        return sorted(t.name for t in threading.enumerate() if t.name != "twin-serve-log")

    switch, threads = sys.getswitchinterval(), mine()

    async def main():
        with Cell(RING_RIG) as cell:
            front = OpcUaFrontEnd(port=0, security=Security(policies=("none",)))
            cell.add_front_end(front)
            stop = asyncio.Event()
            serving = asyncio.ensure_future(cell.serve(lockstep=True, stop=stop))
            while not front.endpoints():
                await asyncio.sleep(0.05)
            # no thread of its own in this process (threads of earlier tests may have ended meanwhile)
            answers["settings"] = (sys.getswitchinterval() == switch, gc.get_freeze_count() == 0,
                                   not set(mine()) - set(threads))
            await advance_in_process(cell, 5)
            answers["L2 in process"] = cell.read("L2")
            thread = threading.Thread(target=client, args=(front.endpoints()[0]["url"],), daemon=True)
            thread.start()
            held = answered.wait(120)  # blocks the cell's event loop, as a long step would
            answers["held until answered"] = held and "error" not in answers
            await asyncio.get_running_loop().run_in_executor(None, thread.join, 120)
            answers["cell L2"] = cell.read("L2")
            stop.set()
            await serving

    asyncio.run(asyncio.wait_for(main(), 300))
    assert answers == {"settings": (True, True, True), "sim.step": 5, "L2 before": answers["L2 in process"], "L2 in process": answers["L2 in process"], "held until answered": True,
                       "write": "Good", "L2 read back": 0.30, "advanced to": 8, "L2 after": 0.30, "cell L2": 0.30}


async def advance_in_process(cell, n: int) -> None:
    """Run n lockstep steps through the cell's exchange (as a Modbus write of sim.advance does) and wait."""
    done = asyncio.Event()
    cell.exchange.submit([("sim.advance", n)])
    cell.runner.when_done(done.set)
    await done.wait()
