"""The runners (twin.runtime.pacing) and the bridge, in process, against a tiny stand-in twin (no physics)."""
from __future__ import annotations

import asyncio
import struct
import time

from twin.core.errors import SignalRangeError
from twin.core.signals import BOOL, FLOAT, INPUT, OUTPUT, SignalSpec
from twin.runtime.exchange import Exchange
from twin.frontends.modbus.bridge import TwinBridge
from twin.frontends.modbus.register_map import build_register_map
from twin.frontends.modbus.server import ModbusServer
from twin.runtime.pacing import LockstepRunner, RealtimeRunner


class StandIn:
    """The Twin contract in memory: `x` follows the input `target`; `broken_at` makes a step fail."""

    signals = (SignalSpec("go", INPUT, BOOL), SignalSpec("target", INPUT, FLOAT, "m", 0.0, 0.1),
               SignalSpec("x", OUTPUT, FLOAT, "m", 0.0, 0.1), SignalSpec("at", OUTPUT, BOOL))

    def __init__(self, broken_at: int | None = None):
        self.values = {"go": False, "target": 0.0, "x": 0.0, "at": True}
        self.step_count, self.dt, self.broken_at = 0, 0.012, broken_at

    @property
    def time(self) -> float:
        return self.step_count * self.dt

    def read(self, name):
        return self.values[name]

    def write(self, name, value):
        if name == "target" and not 0 <= value <= 0.1:
            raise SignalRangeError(name, value, 0, 0.1, "m")
        self.values[name] = value

    def step(self, n: int = 1):
        for _ in range(n):
            if self.step_count == self.broken_at:
                raise RuntimeError("the physics engine gave up")
            self.values["x"] = self.values["target"]
            self.values["at"] = True
            self.step_count += 1


def test_the_realtime_runner_keeps_the_wall_clock_at_the_requested_speed():
    async def run(speed: float) -> int:
        steps = []
        runner = RealtimeRunner(lambda: steps.append(1) or True, 0.01, speed)
        task = asyncio.ensure_future(runner.run())
        await asyncio.sleep(0.3)
        runner.stop()
        await task
        return runner.steps, runner.late_steps

    steps, late = asyncio.run(run(1.0))
    assert 26 <= steps <= 32 and late < steps // 2  # loose: a loaded CI machine wakes sleepers late
    steps, _ = asyncio.run(run(2.0))
    assert 52 <= steps <= 63


def test_a_step_slower_than_real_time_is_counted_late_and_the_runner_resynchronises():
    async def run():
        runner = RealtimeRunner(lambda: time.sleep(0.004) or True, 0.002, max_lag=0.02)
        task = asyncio.ensure_future(runner.run())
        await asyncio.sleep(0.2)
        runner.stop()
        await task
        return runner

    runner = asyncio.run(run())
    assert runner.late_steps >= runner.steps - 1 and runner.resyncs >= 1


def test_the_lockstep_runner_runs_exactly_the_steps_requested():
    async def run():
        count = []
        runner = LockstepRunner(lambda: count.append(1) or True)
        task = asyncio.ensure_future(runner.run())
        await asyncio.sleep(0.05)
        assert count == []
        runner.request(7)
        runner.request(3)
        while runner.remaining:
            await asyncio.sleep(0.001)
        await asyncio.sleep(0.02)
        runner.stop()
        await task
        return len(count)

    assert asyncio.run(run()) == 10


def test_steps_asked_while_the_lockstep_runner_is_held_run_at_its_release_not_before():
    """A server holds the runner while it answers a turn's requests (the watchdog sees them first); the steps
    they asked for run when it lets go, in that same turn, and the answers waiting for them go out then."""
    async def run():
        count, done = [], []
        runner = LockstepRunner(lambda: count.append(1) or True)
        task = asyncio.ensure_future(runner.run())
        await asyncio.sleep(0.01)
        runner.hold()
        runner.request(3)
        runner.when_done(lambda: done.append(len(count)))
        await asyncio.sleep(0.02)  # turns of the loop: nothing runs while held
        held = len(count)
        runner.release()  # runs them now, without a turn of the loop
        released = len(count), list(done)
        runner.release()  # nothing held, nothing asked: nothing runs
        runner.stop()
        await task
        return held, released, len(count)

    assert asyncio.run(run()) == (0, (3, [3]), 3)


async def _rpc(reader, writer, pdu: bytes) -> bytes:
    writer.write(struct.pack(">HHHB", 1, 0, len(pdu) + 1, 1) + pdu)
    head = await reader.readexactly(7)
    return await reader.readexactly(struct.unpack_from(">H", head, 4)[0] - 1)


def test_a_failing_step_sets_the_fault_bit_freezes_the_outputs_and_writes_get_exception_04():
    async def run():
        twin = StandIn(broken_at=2)
        rmap = build_register_map(twin.signals, "stand-in")
        logs = []
        exchange = Exchange(twin, log=logs.append)
        bridge = TwinBridge(exchange, rmap)
        runner = LockstepRunner(exchange.step)
        exchange.runner = runner
        server = ModbusServer(rmap, bridge, log=logs.append)
        _, port = await server.start("127.0.0.1", 0)
        task = asyncio.ensure_future(runner.run())
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        try:
            target = rmap["target"].address
            assert await _rpc(reader, writer, struct.pack(">BHH", 6, target, 5000)) == struct.pack(">BHH", 6, target, 5000)
            assert await _rpc(reader, writer, struct.pack(">BHH", 6, 0, 5)) == struct.pack(">BHH", 6, 0, 5)
            for _ in range(100):
                if await _rpc(reader, writer, struct.pack(">BHH", 3, 0, 1)) == b"\x03\x02\x00\x00":
                    break
                await asyncio.sleep(0.01)
            fault = await _rpc(reader, writer, struct.pack(">BHH", 2, rmap["fault"].address, 1))
            step = await _rpc(reader, writer, struct.pack(">BHH", 4, rmap["sim.step"].address, 2))
            x = await _rpc(reader, writer, struct.pack(">BHH", 4, rmap["x"].address, 1))
            refused = await _rpc(reader, writer, struct.pack(">BHH", 6, target, 100))
            return fault, step, x, refused, logs
        finally:
            writer.close()
            runner.stop()
            await server.close()
            await asyncio.gather(task, return_exceptions=True)

    fault, step, x, refused, logs = asyncio.run(run())
    assert fault == b"\x02\x01\x01"
    assert step == b"\x04\x04" + struct.pack(">I", 2)  # two steps done, the third failed
    assert x == b"\x04\x02" + struct.pack(">H", 5000)  # 50.00 mm: the last completed step
    assert refused == b"\x86\x04"
    assert any("simulation fault at step 2" in line and "gave up" in line for line in logs)


def test_a_write_reads_back_at_once_and_no_publish_undoes_it_before_it_is_applied():
    twin = StandIn()
    rmap = build_register_map(twin.signals, "stand-in")
    exchange = Exchange(twin)
    bridge = TwinBridge(exchange, rmap)
    target, go = rmap["target"], rmap["go"]

    def holding(entry) -> int:
        return struct.unpack_from(">H", bridge.images.holding, 2 * entry.address)[0]

    assert bridge.submit([(target, 0.05), (go, True)]) == 0
    assert holding(target) == 5000 and bridge.images.coils[go.address] == 1  # at once
    assert twin.values["target"] == 0.0  # not applied yet: that is the next step's job
    exchange.publish()  # a publish before the step (whoever calls it) keeps what was written
    assert holding(target) == 5000 and bridge.images.coils[go.address] == 1
    x = rmap["x"]
    assert struct.unpack_from(">H", bridge.images.input_registers, 2 * x.address)[0] == 0  # outputs: last step
    assert exchange.step()
    assert twin.values["target"] == 0.05 and holding(target) == 5000
    assert struct.unpack_from(">H", bridge.images.input_registers, 2 * x.address)[0] == 5000


def _rr_allowed() -> bool:
    """Whether this machine lets a process take SCHED_RR (asked of a separate process, not the runner's code)."""
    import subprocess
    import sys

    probe = "import os; os.sched_setscheduler(0, os.SCHED_RR, os.sched_param(1))"
    return subprocess.run([sys.executable, "-c", probe], capture_output=True).returncode == 0


def test_real_time_scheduling_only_while_a_realtime_runner_runs_and_not_for_the_processes_it_starts():
    import os
    import subprocess
    import sys

    if not hasattr(os, "sched_getscheduler"):
        import pytest
        pytest.skip("no POSIX scheduling on this OS")
    flag = getattr(os, "SCHED_RESET_ON_FORK", 0)
    before = os.sched_getscheduler(0) & ~flag
    seen, child = [], []

    def step():
        seen.append(os.sched_getscheduler(0) & ~flag)
        if not child:  # a process started by the simulation's thread runs as an ordinary process
            child.append(int(subprocess.run([sys.executable, "-c", "import os; print(os.sched_getscheduler(0))"],
                                            capture_output=True, text=True).stdout))
        return len(seen) < 3

    asyncio.run(RealtimeRunner(step, 0.001, priority=True).run())
    assert seen == [os.SCHED_RR if _rr_allowed() else before] * 3  # granted, or quietly as before
    assert child == [os.SCHED_OTHER]
    assert os.sched_getscheduler(0) & ~flag == before  # put back when it stops
    seen.clear()
    runner = LockstepRunner(step)  # lockstep: never real-time scheduling
    runner.request(3)
    asyncio.run(_lockstep(runner))
    assert seen and set(seen) == {before}


async def _lockstep(runner) -> None:
    task = asyncio.ensure_future(runner.run())
    while runner.remaining > 0 and not runner.failed:
        await asyncio.sleep(0.001)
    runner.stop()
    await task


def test_an_output_window_written_back_as_it_reads_changes_nothing_and_a_changed_word_writes():
    """A PLC writes its whole output image every scan (OpenPLC does): the words it reads back are no write, so an
    input another front end set finer than the map's 0.01 mm keeps its value; a word that differs is a write."""
    from twin.frontends.modbus.pdu import IMAGE_OUT, PduHandler

    twin = StandIn()
    rmap = build_register_map(twin.signals, "stand-in")
    exchange = Exchange(twin, log=lambda text: None)
    bridge = TwinBridge(exchange, rmap)
    pdus = PduHandler(rmap, bridge)
    exchange.submit([("target", 0.0123456789)])  # e.g. through OPC UA, in full precision
    exchange.step()
    assert twin.read("target") == 0.0123456789
    lay, hr = pdus.layout, rmap["target"]
    window = struct.unpack(f">{lay.out_size}H", pdus.registers("holding_register", IMAGE_OUT, lay.out_size))
    k = lay.out_words(hr)[0]
    assert window[k:k + hr.count] == tuple(hr.encode(0.0123456789))  # 1234.57 counts of 0.01 mm, rounded
    written = []
    exchange.subscribe(on_writes=written.append)
    request = struct.pack(f">BHHB{lay.out_size}H", 16, IMAGE_OUT, lay.out_size, 2 * lay.out_size, *window)
    assert pdus.handle(request)[0] == 16
    exchange.step()
    assert written == [] and twin.read("target") == 0.0123456789  # not rounded to the map's resolution
    changed = list(window)
    changed[k:k + hr.count] = hr.encode(0.02)
    assert pdus.handle(struct.pack(f">BHHB{lay.out_size}H", 16, IMAGE_OUT, lay.out_size, 2 * lay.out_size,
                                   *changed))[0] == 16
    exchange.step()
    assert written == [[("target", 0.02)]] and twin.read("target") == 0.02
