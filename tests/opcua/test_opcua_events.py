"""OPC UA clients in the machine interface (`twin serve --events`, docs/events.md): a session that is opened and
closed (or whose connection drops) is a `client_connected` and a `client_gone` event, with the peer address the
client's own socket has, its account and access, and the step and simulated time of the cell; and the values it
reads are stamped with simulated time."""
from __future__ import annotations

import asyncio
import time
from datetime import timedelta

import pytest
from asyncua import Client, ua

from opcua_helpers import RING_RIG, OpcUaServerProcess, advance, namespace, node


def run(coro):
    return asyncio.run(asyncio.wait_for(coro, 300))


@pytest.fixture(scope="module")
def server():
    args = ("--lockstep", "--no-modbus", "--opcua-security", "none", "--opcua-user", "operator:s3cret",
            "--opcua-reader", "viewer:look")
    with OpcUaServerProcess(RING_RIG, *args) as s:
        yield s


def client(url: str, user: str, password: str) -> Client:
    c = Client(url, timeout=60)
    c.set_user(user)
    c.set_password(password)
    return c


def local_address(c: Client) -> str:
    """HOST:PORT of the client's end of its connection (what the server sees as its peer)."""
    host, port = c.uaclient.protocol.transport.get_extra_info("sockname")[:2]
    return f"{host}:{port}"


def client_events(server, after: int = 0) -> list[dict]:
    server.events.new()
    return [e for e in server.events.seen[after:] if e["event"].startswith("client_")]


def wait_events(server, count: int, after: int = 0, timeout: float = 30.0) -> list[dict]:
    """The first `count` client events after event number `after` (they cross from the OPC UA process)."""
    end = time.monotonic() + timeout
    while len(found := client_events(server, after)) < count:
        if time.monotonic() > end:
            raise AssertionError(f"{count} client events expected, got {found}")
        time.sleep(0.05)
    return found


def test_a_session_opened_and_closed_is_a_connected_and_a_gone_event(server):
    seen_before = len(server.events.seen)

    async def main():
        viewer = client(server.url, "viewer", "look")
        operator = client(server.url, "operator", "s3cret")
        await viewer.connect()
        await operator.connect()
        peers = {"viewer": local_address(viewer), "operator": local_address(operator)}
        ns = await namespace(operator)
        dt_us = await node(operator, ns, "sim.dt_us").read_value()
        start = await node(operator, ns, "sim.step").read_value()
        await advance(operator, ns, 5)
        await operator.disconnect()  # CloseSession at step start + 5
        # the viewer's write is refused by its role, and costs no event
        dv = ua.DataValue(ua.Variant(True, ua.VariantType.Boolean))
        with pytest.raises(ua.uaerrors.BadUserAccessDenied):
            await node(viewer, ns, "Active").write_value(dv)
        await viewer.disconnect()
        return peers, dt_us, start

    peers, dt_us, start = run(main())
    events = wait_events(server, 4, seen_before)
    assert [(e["event"], e["peer"]) for e in events] == [
        ("client_connected", peers["viewer"]), ("client_connected", peers["operator"]),
        ("client_gone", peers["operator"]), ("client_gone", peers["viewer"])]
    assert all(e["front_end"] == "opcua" for e in events)
    viewer_in, operator_in, operator_out, viewer_out = events
    assert (viewer_in["user"], viewer_in["access"], viewer_in["connected"]) == ("viewer", "read", 1)
    assert (operator_in["user"], operator_in["access"], operator_in["connected"]) == ("operator", "read/write", 2)
    assert (operator_out["reason"], operator_out["connected"]) == ("closed by the client", 1)
    assert (viewer_out["reason"], viewer_out["connected"]) == ("closed by the client", 0)
    # the cell's step and simulated time when each happened (lockstep: only Sim.Advance moves them)
    assert [e["step"] for e in events] == [start, start, start + 5, start + 5]
    for e in events:
        assert e["t"] == pytest.approx(e["step"] * dt_us * 1e-6, abs=1e-9)


def test_a_dropped_connection_is_a_gone_event(server):
    seen_before = len(server.events.seen)

    async def main():
        c = client(server.url, "operator", "s3cret")
        await c.connect()
        peer = local_address(c)
        c.uaclient.protocol.transport.abort()  # no CloseSession: the socket just ends
        return peer

    peer = run(main())
    events = wait_events(server, 2, seen_before)
    assert [(e["event"], e["peer"]) for e in events] == [("client_connected", peer), ("client_gone", peer)]
    assert events[1]["reason"] == "connection lost"


def test_values_are_stamped_with_simulated_time(server):
    """In lockstep simulated time stands still between advances, whatever the wall clock does, and moves by
    exactly the steps run: so do the SourceTimestamps of what a client reads."""
    async def main():
        async with client(server.url, "operator", "s3cret") as c:
            ns = await namespace(c)
            step, dt = node(c, ns, "sim.step"), node(c, ns, "sim.dt_us")
            dt_us = await dt.read_value()
            first = await step.read_data_value()
            await asyncio.sleep(0.3)
            again = await step.read_data_value()
            await advance(c, ns, 7)
            later = await step.read_data_value()
            return dt_us, first, again, later

    dt_us, first, again, later = run(main())
    assert again.Value.Value == first.Value.Value and again.SourceTimestamp == first.SourceTimestamp
    assert later.Value.Value == first.Value.Value + 7
    assert later.SourceTimestamp - first.SourceTimestamp == timedelta(microseconds=7 * dt_us)
