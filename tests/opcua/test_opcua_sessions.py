"""OPC UA sessions as the cell sees them: every request of a session feeds the comm-loss watchdog (in lockstep
on simulated time, so nothing here depends on the wall clock), and a read-only account sees its inputs as
not writable (UserAccessLevel per session)."""
from __future__ import annotations

import asyncio
import re

from asyncua import Client, ua

from opcua_helpers import RING_RIG, OpcUaServerProcess, advance, namespace, node

TIMEOUT = 0.1  # s of simulated time: 9 steps of 12 ms without a request
CHUNK = 5  # steps per Sim.Advance of an active client: 60 ms, well inside the timeout
CHUNKS = 30  # 150 steps, 1.8 s: 18 timeouts long


def run(coro):
    return asyncio.run(asyncio.wait_for(coro, 600))


def quiet_client(url: str, name: str) -> Client:
    """A client that sends nothing on its own: asyncua's keep-alive probe (a read every second) is off."""
    c = Client(url, timeout=30, watchdog_intervall=3600)
    c.description = name
    return c


def comm_lost_lines(server) -> list[str]:
    return [line for line in server.lines if "comm lost" in line]


def test_opcua_sessions_feed_the_watchdog_and_a_silent_one_lets_comm_lost_rise():
    with OpcUaServerProcess(RING_RIG, "--lockstep", "--no-modbus", "--watchdog", str(TIMEOUT)) as server:
        server.wait_for(r"feeds the watchdog \(0\.1 s\)")

        async def reading_client():
            """Active by reads: advance 60 ms, read, ... (Sim.Advance alone does not count: it is the clock)."""
            async with quiet_client(server.url, "reader-plc") as c:
                ns = await namespace(c)
                lost, actual = node(c, ns, "comm.lost"), node(c, ns, "L2.actual")
                seen = []
                for _ in range(CHUNKS):
                    await advance(c, ns, CHUNK)
                    seen.append(await lost.read_value())
                    await actual.read_value()
                return seen

        async def subscribed_client():
            """Active by a subscription only: its publish requests are all it sends besides Sim.Advance."""
            async with quiet_client(server.url, "subscriber-plc") as c:
                ns = await namespace(c)
                steps, lost = asyncio.Queue(), []

                class Handler:
                    def datachange_notification(self, n, value, data):
                        if n.nodeid.Identifier == "sim.step":
                            steps.put_nowait(value)
                        else:
                            lost.append(value)

                sub = await c.create_subscription(12, Handler())
                await sub.subscribe_data_change([node(c, ns, "sim.step"), node(c, ns, "comm.lost")])
                for _ in range(CHUNKS):
                    target = await advance(c, ns, CHUNK)
                    while await asyncio.wait_for(steps.get(), 30) < target:  # this chunk's last step delivered
                        pass
                await sub.delete()
                return lost

        async def silent_client():
            """Connects, reads once, then only advances: the watchdog fires after 0.1 s of simulated time."""
            async with quiet_client(server.url, "silent-plc") as c:
                ns = await namespace(c)
                start = await node(c, ns, "sim.step").read_value()  # its last request before the silence
                await advance(c, ns, 40)
                first = await node(c, ns, "comm.lost").read_value()  # the state of the last step; this read clears it
                await advance(c, ns, 1)
                after = await node(c, ns, "comm.lost").read_value()
                return start, first, after

        assert run(reading_client()) == [False] * CHUNKS
        assert run(subscribed_client()) == [False]  # comm.lost's initial value, and no change after it
        assert comm_lost_lines(server) == []  # 3.6 s of simulated time, never 0.1 s without a request
        start, first, after = run(silent_client())
        assert (first, after) == (True, False)
        line = server.wait_for(r"comm lost: no request for (\S+) s .*last from (.*)\); comm\.lost raised")
        assert line.group(1) == "0.108"  # fired at the first step 0.1 s after the read: 9 steps of 12 ms
        assert re.fullmatch(r"opcua 127\.0\.0\.1:\d+", line.group(2))  # the silent client's address (anonymous)
        server.wait_for(rf"comm restored: request from {re.escape(line.group(2))}")
        assert len(comm_lost_lines(server)) == 1
        assert start == 2 * CHUNKS * CHUNK  # the silent client came after both active ones


def directions() -> tuple[list[str], list[str]]:
    """The cell's inputs and outputs by the Modbus map (an input is a coil or a holding register)."""
    from twin.frontends.modbus.register_map import build_map

    rmap = build_map(RING_RIG)
    inputs = [e.name for e in rmap if e.table in ("coil", "holding_register")]
    return inputs, [e.name for e in rmap if e.name not in inputs]


def test_a_read_only_user_sees_inputs_not_writable_and_a_read_write_user_sees_them_writable():
    inputs, outputs = directions()
    args = ("--lockstep", "--no-modbus", "--opcua-user", "operator:s3cret", "--opcua-reader", "viewer:look")
    with OpcUaServerProcess(RING_RIG, *args) as server:
        async def levels(user: str, password: str) -> dict[str, tuple[int, int]]:
            c = Client(server.url, timeout=30)
            c.set_user(user)
            c.set_password(password)
            async with c:
                ns = await namespace(c)
                names = inputs + outputs
                nodes = [ua.NodeId(n, ns) for n in names]
                out = {}
                for attr in (ua.AttributeIds.AccessLevel, ua.AttributeIds.UserAccessLevel):
                    params = ua.ReadParameters(NodesToRead=[ua.ReadValueId(NodeId=n, AttributeId=attr) for n in nodes])
                    for name, dv in zip(names, await c.uaclient.read(params)):
                        assert dv.StatusCode.is_good(), (name, dv.StatusCode)
                        out.setdefault(name, []).append(dv.Value.Value)
                # one node the asyncua way too
                l2 = node(c, ns, "L2")
                out["L2 (node API)"] = [await l2.get_access_level(), await l2.get_user_access_level()]
                return {k: tuple(v) for k, v in out.items()}

        reader, operator = run(levels("viewer", "look")), run(levels("operator", "s3cret"))
    read, write = ua.AccessLevel.CurrentRead, ua.AccessLevel.CurrentWrite
    assert len(inputs) > 10 and len(outputs) > 30
    for name in inputs:
        for who in (reader, operator):
            assert who[name][0] == read.mask | write.mask, name  # AccessLevel: by direction, whoever asks
        assert reader[name][1] == read.mask, name  # UserAccessLevel: the reader may only read
        assert operator[name][1] == read.mask | write.mask, name
    for name in outputs:
        for who in (reader, operator):
            assert who[name] == (read.mask, read.mask), name
    assert reader["L2 (node API)"] == ({read, write}, {read})
    assert operator["L2 (node API)"] == ({read, write}, {read, write})
