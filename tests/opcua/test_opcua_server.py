"""`twin serve --opcua` as a subprocess, driven by asyncua's client over loopback, beside pymodbus's client:
the address space, reads equal to Modbus at the same lockstep step, writes applied and refused, subscriptions,
Sim.Advance against a Modbus lockstep run, real time."""
from __future__ import annotations

import asyncio
import math
import struct
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import pytest
from asyncua import Client, ua
from pymodbus.client import ModbusTcpClient

from opcua_helpers import FOLDERS, RING_RIG, OpcUaServerProcess, advance, namespace, node, write_status

UNIT = 1


@pytest.fixture(scope="module")
def rmap():
    from twin.frontends.modbus.register_map import build_map

    return build_map(RING_RIG)


@pytest.fixture(scope="module")
def lockstep():
    with OpcUaServerProcess(RING_RIG, "--lockstep") as server:
        yield server


def run(coro):
    return asyncio.run(asyncio.wait_for(coro, 600))


# -- Modbus, as the reference front end ------------------------------------------------------------------
def modbus(server) -> ModbusTcpClient:
    c = ModbusTcpClient("127.0.0.1", port=server.port, timeout=5, retries=0)
    assert c.connect()
    return c


def modbus_read(c: ModbusTcpClient, e):
    """The engineering value of a map entry, read over Modbus."""
    read = {"coil": c.read_coils, "discrete_input": c.read_discrete_inputs,
            "holding_register": c.read_holding_registers, "input_register": c.read_input_registers}[e.table]
    r = read(e.address, count=e.count, device_id=UNIT)
    assert not r.isError(), (e.name, r)
    return e.decode(r.bits[:1] if e.table in ("coil", "discrete_input") else r.registers)


def modbus_advance(c: ModbusTcpClient, rmap, n: int) -> None:
    a = rmap["sim.advance"].address
    assert not c.write_register(a, n, device_id=UNIT).isError()
    for _ in range(20000):
        if c.read_holding_registers(a, count=1, device_id=UNIT).registers == [0]:
            return
    raise AssertionError("sim.advance never came back to 0")


# -- the address space -----------------------------------------------------------------------------------
def urdf_limits(path, joint):
    j = next(j for j in ET.parse(path).getroot().iter("joint") if j.get("name") == joint)
    lim = j.find("limit")
    return float(lim.get("lower")), float(lim.get("upper"))


def test_browse_folders_and_every_signal_is_one_variable_named_by_its_signal(lockstep, rmap):
    async def main():
        async with Client(lockstep.url, timeout=240) as c:
            ns = await namespace(c)
            assert ns >= 2
            children = {(await ch.read_browse_name()).Name: ch for ch in await c.nodes.objects.get_children()}
            assert set(FOLDERS) <= set(children)
            found = {}
            for folder in FOLDERS:
                fnode = children[folder]
                assert await fnode.read_type_definition() == ua.NodeId(ua.ObjectIds.FolderType)
                for ch in await fnode.get_children(nodeclassmask=ua.NodeClass.Variable):
                    assert ch.nodeid.NamespaceIndex == ns and isinstance(ch.nodeid.Identifier, str)
                    assert (await ch.read_browse_name()).Name == ch.nodeid.Identifier
                    found[ch.nodeid.Identifier] = (folder, ch)
            methods = await children["Sim"].get_children(nodeclassmask=ua.NodeClass.Method)
            assert [m.nodeid for m in methods] == [ua.NodeId("Sim.Advance", ns)]
            return ns, {name: (folder, await ch.read_data_type_as_variant_type(), await ch.read_attribute(
                ua.AttributeIds.AccessLevel)) for name, (folder, ch) in found.items()}

    ns, found = run(main())
    # every signal Modbus serves is a variable of that name, the simulator's own too
    for e in rmap:
        assert e.name in found, e.name
        folder, vtype, access = found[e.name]
        expected = {"bool": ua.VariantType.Boolean}.get(e.type, ua.VariantType.String if e.choices else None)
        if expected is not None:
            assert vtype == expected, e.name
        writable = bool(access.Value.Value & ua.AccessLevel.CurrentWrite.mask)
        assert writable == (e.access == "rw"), e.name  # outputs read-only, inputs writable
    assert found["L2"][0] == "Gripper" and found["doGripped"][0] == "Gripper" and found["L2.actual"][0] == "Gripper"
    assert found["L2.force"][0] == "Fingers" and found["L3.contact"][0] == "Fingers"
    assert found["robot.j1"][0] == "Robot" and found["ring.present"][0] == "Targets" and found["ring.x"][0] == "Targets"
    assert found["aoAxis1"][0] == "Controller" and found["rapid.running"][0] == "Controller"
    assert found["sim.step"][0] == "Sim"
    assert found["L2"][1] == ua.VariantType.Double and found["L2.actual"][1] == ua.VariantType.Double
    assert found["rapid.line"][1] == ua.VariantType.Int32


def test_engineering_units_and_ranges_follow_the_urdf_and_unece(lockstep):
    async def main():
        async with Client(lockstep.url, timeout=240) as c:
            ns = await namespace(c)
            out = {}
            for name in ("L2", "L5", "L2.force", "robot.j1"):
                n = node(c, ns, name)
                assert await n.read_type_definition() == ua.NodeId(ua.ObjectIds.AnalogItemType)
                out[name] = (await (await n.get_child("0:EngineeringUnits")).read_value(),
                             await (await n.get_child("0:EURange")).read_value())
            return out

    out = run(main())
    urdf = RING_RIG / "gripper3.urdf"
    for name, joint_name in (("L2", None), ("L5", None)):
        eu, rng = out[name]
        assert eu.NamespaceUri == "http://www.opcfoundation.org/UA/units/un/cefact"
        assert eu.UnitId == 0x4D5452  # UNECE "MTR", metre (OPC UA Part 8: one byte per character)
    joints = {j.get("name"): j for j in ET.parse(urdf).getroot().iter("joint") if j.get("type") == "prismatic"}
    lows_highs = sorted((float(j.find("limit").get("lower")), float(j.find("limit").get("upper"))) for j in joints.values())
    assert (out["L2"][1].Low, out["L2"][1].High) in lows_highs and (out["L5"][1].Low, out["L5"][1].High) in lows_highs
    assert out["L2.force"][0].UnitId == 0x4E4557  # "NEW", newton
    assert out["L2.force"][1].Low == 0.0 and out["L2.force"][1].High == math.inf
    assert out["robot.j1"][0].UnitId == 0x433831  # "C81", radian


# -- reads and writes, against Modbus ------------------------------------------------------------------
def test_every_signal_reads_as_over_modbus_at_the_same_lockstep_step(lockstep, rmap):
    with modbus(lockstep) as mb:
        assert not mb.write_registers(rmap["L2"].address, [31000, 31000, 31000], device_id=UNIT).isError()  # 310 mm
        modbus_advance(mb, rmap, 20)  # mid-way from 350 to 310 mm at 0.1 m/s: the fingers move (at 60 steps they
        # stand on the ring at 320 mm, stalled: neither moving nor any longer flickering between moving and still)
        over_modbus = {e.name: modbus_read(mb, e) for e in rmap}

        async def main():
            async with Client(lockstep.url, timeout=240) as c:
                ns = await namespace(c)
                names = [e.name for e in rmap]
                values = await c.read_values([node(c, ns, n) for n in names])
                return dict(zip(names, values))

        over_opcua = run(main())
        assert over_modbus == {e.name: modbus_read(mb, e) for e in rmap}  # nothing moved meanwhile
    assert over_opcua["sim.step"] == over_modbus["sim.step"] > 0
    moving = 0
    for e in rmap:
        if e.name not in over_opcua:
            continue
        got, ref = over_opcua[e.name], over_modbus[e.name]
        if e.type == "bool":
            assert got is ref, e.name
        elif e.choices:
            assert got == ref, e.name
        elif e.type == "float32":
            assert struct.unpack(">f", struct.pack(">f", got * e.factor))[0] == pytest.approx(ref, rel=1e-6, abs=1e-6), e.name
        else:  # scaled integers: the OPC UA Double, in the map's unit and rounded to a count, is the Modbus value
            lo, hi = e.count_range
            counts = min(max(round(got * e.factor / e.scale), lo), hi)
            assert counts * e.scale == pytest.approx(ref, abs=1e-9), e.name
        moving += e.name.endswith(".moving") and bool(ref)
    assert moving, "nothing was moving: the comparison saw a static cell"


def test_written_setpoints_are_applied_and_grip_the_ring(lockstep, rmap):
    async def main():
        async with Client(lockstep.url, timeout=240) as c:
            ns = await namespace(c)
            for name in ("L2", "L3", "L4"):
                assert await write_status(node(c, ns, name), 0.30, ua.VariantType.Double) == "Good"
            assert await node(c, ns, "L3").read_value() == 0.30  # reads back as written, before any step
            before = await node(c, ns, "sim.step").read_value()
            after = await advance(c, ns, 200)
            assert after == before + 200 == await node(c, ns, "sim.step").read_value()
            return {n: await node(c, ns, n).read_value() for n in ("doGripped", "GrippedPart", "L2.actual", "L2.force")}

    with modbus(lockstep) as mb:
        values = run(main())
        assert modbus_read(mb, rmap["L3"]) == pytest.approx(300.0)  # the write shows on Modbus too
        assert modbus_read(mb, rmap["doGripped"]) is True
    assert values["doGripped"] is True and values["GrippedPart"] == "ring"
    assert values["L2.actual"] == pytest.approx(0.32, abs=0.002)  # stopped on the ring's 640 mm outer diameter
    assert values["L2.force"] > 1.0
    # open again for the other tests
    async def reopen():
        async with Client(lockstep.url, timeout=240) as c:
            ns = await namespace(c)
            for name in ("L2", "L3", "L4"):
                assert await write_status(node(c, ns, name), 0.35, ua.VariantType.Double) == "Good"
            await advance(c, ns, 100)
            assert await node(c, ns, "doGripped").read_value() is False
    run(reopen())


def test_out_of_range_and_wrong_typed_writes_are_refused_and_change_nothing(lockstep, rmap):
    async def main():
        async with Client(lockstep.url, timeout=240) as c:
            ns = await namespace(c)
            L2, active, gripped, present = (node(c, ns, n) for n in ("L2", "Active", "doGripped", "ring.present"))
            before = await L2.read_value()
            answers = {
                "over the URDF limit": await write_status(L2, 0.5, ua.VariantType.Double),
                "below": await write_status(L2, -0.001, ua.VariantType.Double),
                "NaN": await write_status(L2, math.nan, ua.VariantType.Double),
                "text for a number": await write_status(L2, "0.3", ua.VariantType.String),
                "Float for a Double": await write_status(L2, 0.3, ua.VariantType.Float),
                "integer for a Double": await write_status(L2, 0, ua.VariantType.Int32),
                "integer for a Boolean": await write_status(active, 1, ua.VariantType.Int64),
                "an output": await write_status(gripped, True, ua.VariantType.Boolean),
                "array": await write_status(L2, [0.3], ua.VariantType.Double),
            }
            await advance(c, ns, 5)
            return before, answers, await L2.read_value(), await present.read_value()

    with modbus(lockstep) as mb:
        l2_modbus = modbus_read(mb, rmap["L2"])
        before, answers, after, present = run(main())
        assert modbus_read(mb, rmap["L2"]) == l2_modbus
    assert answers == {
        "over the URDF limit": "BadOutOfRange", "below": "BadOutOfRange", "NaN": "BadOutOfRange",
        "text for a number": "BadTypeMismatch", "Float for a Double": "BadTypeMismatch",
        "integer for a Double": "BadTypeMismatch", "integer for a Boolean": "BadTypeMismatch",
        "an output": "BadNotWritable", "array": "BadTypeMismatch"}
    assert after == before and present is True


# -- Sim.Advance against a Modbus lockstep run -------------------------------------------------------------
def grip_run(via_opcua: bool, rmap) -> list[tuple]:
    """The outside grip, closing 1 mm every 17 steps until gripped, then opening. Setpoints go in as Modbus
    counts (over Modbus, or as the very SI value those counts mean over OPC UA); steps by sim.advance or
    Sim.Advance. Returns every output as both front ends read it after each move."""
    seen = []
    with OpcUaServerProcess(RING_RIG, "--lockstep") as server, modbus(server) as mb:
        async def main():
            async with Client(server.url, timeout=240) as c:
                ns = await namespace(c)
                outputs = [e for e in rmap if e.access == "r" and e.name != "sim.map_crc"]
                nodes = [node(c, ns, e.name) for e in outputs]

                async def move(mm: float, steps: int):
                    counts = round(mm * 100)
                    if via_opcua:
                        for name in ("L2", "L3", "L4"):
                            value = rmap[name].si_of_words([counts])
                            assert await write_status(node(c, ns, name), value, ua.VariantType.Double) == "Good"
                        await advance(c, ns, steps)
                    else:
                        assert not mb.write_registers(rmap["L2"].address, [counts] * 3, device_id=UNIT).isError()
                        modbus_advance(mb, rmap, steps)
                    seen.append((tuple(await c.read_values(nodes)), tuple(modbus_read(mb, e) for e in outputs)))

                await move(330.0, 100)
                mm = 330.0
                while not await node(c, ns, "doGripped").read_value() and mm > 300:
                    mm -= 1.0
                    await move(mm, 17)
                assert await node(c, ns, "doGripped").read_value(), f"no grip down to {mm} mm"
                await move(340.0, 100)
        run(main())
    return seen


def test_sim_advance_reproduces_a_modbus_lockstep_run_bit_for_bit(rmap):
    by_modbus = grip_run(False, rmap)
    by_opcua = grip_run(True, rmap)
    assert len(by_modbus) > 3
    assert by_opcua == by_modbus  # Doubles compared exactly, Modbus registers too


def cpu_hogs(n: int = 2) -> list[subprocess.Popen]:
    """Busy loops beside the server, one a core of this 2-core machine (a loaded machine, on purpose): the OPC UA
    process falls behind the simulation's, as it does under load."""
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]


def test_writes_and_advances_over_either_front_end_keep_their_order_under_load(rmap):
    """The lockstep contract across the two front ends, with CPU hogs beside them: a write answered Good (or
    acknowledged over Modbus) before an advance asked on the other protocol is applied at the advance's first
    step, and a read over OPC UA after an advance done over Modbus shows that advance's last step (the OPC UA
    process publishes what the simulation's process stepped; a read there must not answer from a step
    earlier). Checked against the same writes and steps on a cell stepped in process, bit for bit."""
    from twin_app.cell import Cell

    # (mm, steps, advanced over Modbus): one step right after a write, and runs long enough for the OPC UA
    # process to fall behind the simulation's (30 steps: about 0.4 s of simulated time each)
    schedule = [(345.0 - 1.0 * i, (1, 30, 3)[i % 3], i % 3 != 2) for i in range(15)]
    outputs = [e.name for e in rmap if e.access == "r" and (e.name == "sim.step" or not e.name.startswith("sim."))]
    seen = []
    hogs = cpu_hogs()
    try:
        with OpcUaServerProcess(RING_RIG, "--lockstep") as server, modbus(server) as mb:
            async def main():
                async with Client(server.url, timeout=240) as c:
                    ns = await namespace(c)
                    nodes = [node(c, ns, n) for n in outputs]
                    for mm, steps, over_modbus in schedule:
                        counts = round(mm * 100)
                        if over_modbus:  # written over OPC UA, stepped over Modbus, read over OPC UA
                            for name in ("L2", "L3", "L4"):
                                value = rmap[name].si_of_words([counts])
                                assert await write_status(node(c, ns, name), value, ua.VariantType.Double) == "Good"
                            modbus_advance(mb, rmap, steps)
                        else:  # written over Modbus, stepped over OPC UA
                            assert not mb.write_registers(rmap["L2"].address, [counts] * 3, device_id=UNIT).isError()
                            await advance(c, ns, steps)
                        seen.append(dict(zip(outputs, await c.read_values(nodes))))
            run(main())
    finally:
        for hog in hogs:
            hog.kill()
            hog.wait()
    with Cell(RING_RIG) as cell:
        cell.pace(lockstep=True)
        expected = []
        for mm, steps, _ in schedule:
            value = rmap["L2"].si_of_words([round(mm * 100)])
            cell.exchange.submit([("L2", value), ("L3", value), ("L4", value)])
            cell.step(steps)
            expected.append({n: cell.exchange.snapshot.values[n] for n in outputs})
    assert [s["sim.step"] for s in seen] == [e["sim.step"] for e in expected]
    assert any(s["L2.moving"] for s in seen), "nothing moved: the comparison saw a static cell"
    assert seen == expected  # doubles compared exactly


# -- subscriptions -------------------------------------------------------------------------------------
class Collector:
    def __init__(self):
        self.changes: list[tuple[float, str, object]] = []
        self.stamps: list[tuple[object, object]] = []  # (value, SourceTimestamp)

    def datachange_notification(self, n, val, data):
        self.changes.append((time.monotonic(), n.nodeid.Identifier, val))
        self.stamps.append((val, data.monitored_item.Value.SourceTimestamp))


def test_a_subscription_sees_every_step_even_when_it_publishes_slower(lockstep):
    """sim.step changes every step: each value lasts one step. A 100 ms publishing interval with a queue of
    the server's maximum (QueueSize 0, asyncua's 10000) gets every one of them, each stamped with its step's
    simulated time."""
    async def main():
        async with Client(lockstep.url, timeout=240) as c:
            ns = await namespace(c)
            col = Collector()
            sub = await c.create_subscription(ua.CreateSubscriptionParameters(
                RequestedPublishingInterval=100, RequestedLifetimeCount=1000, RequestedMaxKeepAliveCount=10,
                PublishingEnabled=True), col)
            step_node = node(c, ns, "sim.step")
            params = ua.MonitoringParameters(ClientHandle=1, SamplingInterval=0, QueueSize=0, DiscardOldest=True)
            await sub.create_monitored_items([ua.MonitoredItemCreateRequest(
                ItemToMonitor=ua.ReadValueId(NodeId=step_node.nodeid, AttributeId=ua.AttributeIds.Value),
                MonitoringMode=ua.MonitoringMode.Reporting, RequestedParameters=params)])
            first = await step_node.read_value()
            await advance(c, ns, 60)
            await asyncio.sleep(0.5)
            await sub.delete()
            dt_us = await node(c, ns, "sim.dt_us").read_value()
            return first, col.changes, col.stamps, dt_us

    first, changes, stamps, dt_us = run(main())
    values = [v for _, _, v in changes]
    assert values[-61:] == list(range(first, first + 61))  # the initial value, then every step's
    # SourceTimestamps in simulated time: step k is k steps of the station's dt after step `first`, to the
    # microsecond (OPC UA's DateTime counts 100 ns), however long the 60 steps took on the wall clock
    t0 = dict(stamps)[first]
    assert all(round((ts - t0).total_seconds() * 1e6) == (step - first) * dt_us for step, ts in stamps[-61:])


def test_sampling_intervals_below_the_step_are_revised_to_the_step(lockstep):
    """Values change once a step, so no item samples faster (the publishing interval is the client's own: asyncua
    revises it only to its own limits)."""
    async def main():
        async with Client(lockstep.url, timeout=240) as c:
            ns = await namespace(c)
            result = await c.uaclient.create_subscription(ua.CreateSubscriptionParameters(
                RequestedPublishingInterval=1, RequestedLifetimeCount=1000, RequestedMaxKeepAliveCount=10,
                PublishingEnabled=True), lambda *a: None)
            items = [ua.MonitoredItemCreateRequest(
                ItemToMonitor=ua.ReadValueId(NodeId=node(c, ns, "doGripped").nodeid, AttributeId=ua.AttributeIds.Value),
                MonitoringMode=ua.MonitoringMode.Reporting,
                RequestedParameters=ua.MonitoringParameters(ClientHandle=7, SamplingInterval=interval, QueueSize=1))
                for interval in (0, 5, 12, 50, -1)]
            created = await c.uaclient.create_monitored_items(ua.CreateMonitoredItemsParameters(
                SubscriptionId=result.SubscriptionId, ItemsToCreate=items))
            await c.uaclient.delete_subscriptions([result.SubscriptionId])
            return [r.RevisedSamplingInterval for r in created]

    sampling = run(main())
    assert sampling == [12.0, 12.0, 12.0, 50.0, 12.0]  # -1: the publishing interval (1 ms), revised to the step


def test_a_subscription_sees_doGripped_rise_during_a_grip_in_real_time():
    with OpcUaServerProcess(RING_RIG) as server:
        async def main():
            async with Client(server.url, timeout=240) as c:
                ns = await namespace(c)
                col = Collector()
                sub = await c.create_subscription(12, col)
                await sub.subscribe_data_change([node(c, ns, n) for n in ("doGripped", "GrippedPart", "sim.step")],
                                                sampling_interval=12)
                t0 = time.monotonic()
                for name in ("L2", "L3", "L4"):
                    assert await write_status(node(c, ns, name), 0.30, ua.VariantType.Double) == "Good"
                while time.monotonic() - t0 < 15:
                    if any(n == "doGripped" and v is True for _, n, v in col.changes):
                        break
                    await asyncio.sleep(0.05)
                await asyncio.sleep(0.3)
                await sub.delete()
                return col.changes

        changes = run(main())
    gripped = [v for _, n, v in changes if n == "doGripped"]
    assert gripped[0] is False and True in gripped, gripped
    assert "ring" in [v for _, n, v in changes if n == "GrippedPart"]
    steps = [v for _, n, v in changes if n == "sim.step"]
    assert steps[1:] == list(range(steps[1], steps[1] + len(steps) - 1)), "a step was lost"  # every step, in order


def test_sim_advance_is_refused_in_real_time():
    with OpcUaServerProcess(RING_RIG, "--no-modbus") as server:
        assert server.port is None and not any("listening on 127" in line for line in server.lines)

        async def main():
            async with Client(server.url, timeout=240) as c:
                ns = await namespace(c)
                with pytest.raises(ua.uaerrors.BadInvalidState):
                    await advance(c, ns, 10)
                return await node(c, ns, "sim.lockstep").read_value(), await node(c, ns, "sim.mode").read_value()

        assert run(main()) == (False, 1)
