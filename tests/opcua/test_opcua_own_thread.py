"""The OPC UA server runs in a thread of its own: a client is answered while the cell's loop is busy (as in a
long simulation step), and what it reads is the cell's last published step. No timing: the cell's loop is
held until the client has its answers, so a server that needed that loop would never answer."""
from __future__ import annotations

import asyncio
import threading

from asyncua import Client, ua

from opcua_helpers import RING_RIG, advance, namespace, node, write_status


def test_reads_and_writes_are_answered_while_the_cells_loop_is_busy():
    from twin.opcua.security import Security
    from twin.opcua.serve import OpcUaFrontEnd
    from twin_app.cell import Cell

    answers: dict[str, object] = {}
    answered = threading.Event()

    def client(url: str) -> None:
        async def session():
            async with Client(url, timeout=20, watchdog_intervall=3600) as c:
                ns = await namespace(c)
                answers["sim.step"] = await node(c, ns, "sim.step").read_value()
                answers["write"] = await write_status(node(c, ns, "L2"), 0.30, ua.VariantType.Double)
                answers["L2 read back"] = await node(c, ns, "L2").read_value()
                answered.set()  # the cell's loop may go on now
                answers["advanced to"] = await advance(c, ns, 3)  # needs the cell's loop: it runs the steps
                answers["L2 after"] = await node(c, ns, "L2").read_value()

        try:
            asyncio.run(session())
        except Exception as exc:  # noqa: BLE001
            answers["error"] = repr(exc)
        finally:
            answered.set()

    async def main():
        with Cell(RING_RIG) as cell:
            front = OpcUaFrontEnd(port=0, security=Security(policies=("none",)))
            cell.add_front_end(front)
            stop = asyncio.Event()
            serving = asyncio.ensure_future(cell.serve(lockstep=True, stop=stop))
            while front.link is None or front.link.server is None:
                await asyncio.sleep(0.05)
            await advance_in_process(cell, 5)
            thread = threading.Thread(target=client, args=(front.server.endpoint,), daemon=True)
            thread.start()
            held = answered.wait(120)  # blocks the cell's event loop, as a long step would
            answers["held until answered"] = held and "error" not in answers
            await asyncio.get_running_loop().run_in_executor(None, thread.join, 120)
            answers["cell L2"] = cell.read("L2")
            stop.set()
            await serving

    asyncio.run(asyncio.wait_for(main(), 300))
    assert answers == {"sim.step": 5, "write": "Good", "L2 read back": 0.30, "held until answered": True,
                       "advanced to": 8, "L2 after": 0.30, "cell L2": 0.30}


async def advance_in_process(cell, n: int) -> None:
    """Run n lockstep steps through the cell's exchange (as a Modbus write of sim.advance does) and wait."""
    done = asyncio.Event()
    cell.exchange.submit([("sim.advance", n)])
    cell.runner.when_done(done.set)
    await done.wait()
