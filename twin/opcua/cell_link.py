"""The OPC UA server's link to a running cell: the same write queue, runner and snapshot as Modbus.

The cell's bridge (`twin.modbus.bridge.TwinBridge`) owns the write queue the runner applies before each
step; OPC UA writes go into that same queue (so writes from both front ends apply in arrival order, at the
next step, and show at once in Modbus's coil and holding-register images too). `step()` is what the runner
calls: the bridge's step, then the new snapshot published to the OPC UA server, then any `Sim.Advance`
whose steps are done is answered.
"""
from __future__ import annotations

import asyncio
from collections.abc import Sequence

from .address_space import Variable
from .errors import AdvanceRefused

# the bridge's Modbus exception codes -> OPC UA status codes
_REFUSED = {0x03: "BadOutOfRange", 0x04: "BadDeviceFailure", 0x02: "BadNodeIdUnknown"}


class CellLink:
    def __init__(self, twin, bridge, runner=None):
        self.twin, self.bridge, self.runner = twin, bridge, runner
        self.server = None  # the OpcUaServer, once attached
        status = set(bridge._status())  # the runner's own values (sim.*, fault, comm.*): published by the bridge
        self._names = tuple(s.name for s in twin.signals if s.name not in status)
        self._waiting: list[tuple[int, asyncio.Future]] = []

    def signals(self) -> tuple:
        """The cell's signal table as OPC UA serves it: the twin's signals, then the simulator's own entries of the
        register map (sim.step, sim.lockstep, fault, ...: what the runner and the server publish)."""
        from twin.core.signals import BOOL, INPUT, INT, OUTPUT, SignalSpec

        own = {s.name for s in self.twin.signals}
        status = tuple(SignalSpec(e.name, INPUT if e.writable else OUTPUT, BOOL if e.type == "bool" else INT, e.unit,
                                  e.min, e.max, e.description, group="sim")
                       for e in self.bridge.map if e.signal is None and e.name not in own)
        return tuple(self.twin.signals) + status

    def attach(self, server) -> None:
        self.server = server
        self.publish()

    # -- the runner's side ----------------------------------------------------------------------------
    def step(self) -> bool:
        ok = self.bridge.step()
        self.publish(in_step=True)
        if not ok:
            self._fail_waiting()
        return ok

    def values(self, in_step: bool = False) -> dict[str, object]:
        read = self.twin.read
        values = {name: read(name) for name in self._names}
        values.update(self.bridge._status())
        runner = self.runner
        # the steps still to run (as Modbus reads it): inside a step, the runner still counts the one running
        remaining = 0 if runner is None else max(0, runner.remaining - (1 if in_step else 0))
        values["sim.advance"] = min(0xFFFF, remaining)
        return values

    def publish(self, in_step: bool = False) -> None:
        if self.server is not None:
            self.server.publish(self.values(in_step))
        if self._waiting:
            step = self.twin.step_count
            done = [(n, f) for n, f in self._waiting if step >= n]
            if done:
                self._waiting = [(n, f) for n, f in self._waiting if step < n]
                for _, fut in done:
                    if not fut.done():
                        fut.set_result(step)

    def _fail_waiting(self) -> None:
        waiting, self._waiting = self._waiting, []
        for _, fut in waiting:
            if not fut.done():
                fut.set_exception(AdvanceRefused("BadDeviceFailure", "the simulation faulted"))

    # -- the server's side ----------------------------------------------------------------------------
    def submit(self, changes: Sequence[tuple[Variable, object]]) -> str | None:
        rmap = self.bridge.map
        entries = []
        for var, value in changes:
            if var.name not in rmap:
                return "BadNotWritable"
            entries.append((rmap[var.name], value))
        code = self.bridge.submit(entries)
        return _REFUSED.get(code, "BadInternalError") if code else None

    async def advance(self, n: int) -> int:
        runner = self.runner
        if runner is None or runner.mode != "lockstep":
            raise AdvanceRefused("BadInvalidState", "Sim.Advance runs only in lockstep (twin serve --lockstep)")
        if self.bridge.fault or getattr(runner, "failed", False):
            raise AdvanceRefused("BadDeviceFailure", "the simulation faulted")
        target = self.twin.step_count + runner.remaining + n  # the step count once these steps are done
        if target <= self.twin.step_count:
            return self.twin.step_count
        fut = asyncio.get_running_loop().create_future()
        self._waiting.append((target, fut))
        runner.request(n)
        self.publish()  # sim.advance shows the steps to run
        return await fut
