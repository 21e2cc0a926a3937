"""The fair share, deterministically: a `ModbusServer` in process with real loopback connections and a
frozen clock (one step period never ends until the test moves the clock)."""
from __future__ import annotations

import asyncio
import struct

from twin.runtime.exchange import Exchange
from twin.frontends.modbus.bridge import TwinBridge
from twin.frontends.modbus.register_map import build_register_map
from twin.frontends.modbus.server import ModbusServer
from twin.runtime.pacing import LockstepRunner

from test_pacing_and_bridge import StandIn

FRAME = struct.pack(">HHHBBHH", 1, 0, 6, 1, 4, 0, 2)  # FC 4, sim.step
ANSWER = 7 + 2 + 4


class Clock:
    t = 100.0

    def __call__(self) -> float:
        return self.t


async def count_answers(reader, counts, i):
    while True:
        data = await reader.read(1 << 16)
        if not data:
            return
        counts[i] += len(data)


def test_all_connections_share_one_budget_per_step_period_evenly_and_an_idle_one_goes_first():
    async def run():
        twin = StandIn()
        rmap = build_register_map(twin.signals, "stand-in")
        exchange = Exchange(twin, log=lambda text: None)
        bridge = TwinBridge(exchange, rmap)
        exchange.runner = LockstepRunner(exchange.step)
        clock = Clock()
        server = ModbusServer(rmap, bridge, requests_per_step=120, step_period=0.02, clock=clock, log=lambda t: None)
        _, port = await server.start("127.0.0.1", 0)
        n = 40
        conns = [await asyncio.open_connection("127.0.0.1", port) for _ in range(n)]
        counts = [0] * (n + 1)
        readers = [asyncio.ensure_future(count_answers(r, counts, i)) for i, (r, _) in enumerate(conns)]
        for _, w in conns:
            w.write(FRAME * 300)  # 300 pipelined requests each: 12000 in all
        await asyncio.sleep(0.3)  # many loop turns, but the clock stands: one step period
        assert sum(counts[:n]) // ANSWER == 120  # the budget, over all connections (all were idle: no reserve)
        for _ in range(9):  # nine more periods
            clock.t += 0.02
            await asyncio.sleep(0.1)
        first = [c // ANSWER for c in counts[:n]]
        assert sum(first) == 120 + 9 * 108, first  # then the budget less the reserve (a tenth) for the idle
        assert max(first) - min(first) <= 4, first  # about 27 each: split evenly (arrival order aside)
        # an idle client asks: answered at once from the reserve, though the backlog used its share
        for _ in range(5):
            pr, pw = await asyncio.open_connection("127.0.0.1", port)
            pw.write(FRAME)
            head = await asyncio.wait_for(pr.readexactly(ANSWER), 2.0)
            assert head[7] == 4
            pw.close()
        await asyncio.sleep(0.05)
        assert [c // ANSWER for c in counts[:n]] == first  # still the same period: the backlog waits
        clock.t += 0.02
        await asyncio.sleep(0.1)
        second = [c // ANSWER - f for c, f in zip(counts[:n], first)]
        assert sum(second) == 108, second
        assert max(second) - min(second) <= 1, second
        for _, w in conns:
            w.close()
        await server.close()
        for r in readers:
            r.cancel()

    asyncio.run(run())
