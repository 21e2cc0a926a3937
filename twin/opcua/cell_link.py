"""The OPC UA server's link to a running cell: the cell's exchange (`twin.exchange`), like every front end,
and its comm-loss watchdog (`twin.watchdog`), fed by every request of an OPC UA session.

Writes go through `exchange.submit` (the same validation and queue as Modbus and the view: writes from all
front ends apply in arrival order, at the next step, and show at once in Modbus's images too). After each
step the exchange hands its snapshot to `_on_snapshot`, which publishes it to the OPC UA server and answers
any `Sim.Advance` whose steps are done.
"""
from __future__ import annotations

import asyncio
from collections.abc import Sequence

from twin.core.errors import SignalError, SignalRangeError, SignalTypeError, TwinError
from twin.exchange import SimulationFault

from .address_space import Variable
from .errors import AdvanceRefused


def status_of(exc: TwinError) -> str:
    """The OPC UA status code for a write the exchange refused."""
    if isinstance(exc, SimulationFault):
        return "BadDeviceFailure"
    if isinstance(exc, SignalRangeError):
        return "BadOutOfRange"
    if isinstance(exc, SignalTypeError):
        return "BadTypeMismatch"
    if isinstance(exc, SignalError):
        return "BadNotWritable"
    return "BadInternalError"


class CellLink:
    def __init__(self, exchange, runner=None, watchdog=None):
        """`watchdog`: the cell's comm-loss watchdog (`twin.watchdog`), fed by every request of a session."""
        self.exchange, self.runner, self.watchdog = exchange, runner, watchdog
        self.twin = exchange.twin  # the station's name and step length
        self.server = None  # the OpcUaServer, once attached
        self._waiting: list[tuple[int, asyncio.Future]] = []
        self._unsubscribe = None

    def signals(self) -> tuple:
        """The cell's signal table as OPC UA serves it: the static table, the simulator's `sim.*` included."""
        return self.exchange.signals

    def attach(self, server) -> None:
        self.server = server
        self._unsubscribe = self.exchange.subscribe(on_snapshot=self._on_snapshot)
        self._on_snapshot(self.exchange.snapshot)

    def detach(self) -> None:
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None

    def values(self) -> dict[str, object]:
        return dict(self.exchange.snapshot.values)

    # -- the exchange's side --------------------------------------------------------------------------
    def _on_snapshot(self, snapshot) -> None:
        if self.server is not None:
            self.server.publish(snapshot.values)
        if self.exchange.fault:
            self._fail_waiting()
            return
        if self._waiting:
            step = snapshot.step
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
    @property
    def lockstep(self) -> bool:
        return self.runner is not None and self.runner.mode == "lockstep"

    def feed(self, source: str, clock_only: bool = False) -> None:
        """A session's request came (see `twin.watchdog`): in lockstep, one that only drives simulated time
        (`clock_only`) arms the watchdog without feeding it, as on Modbus."""
        self.watchdog.feed(source, clock_only=self.lockstep and clock_only)

    def submit(self, changes: Sequence[tuple[Variable, object]]) -> str | None:
        try:
            self.exchange.submit([(var.name, value) for var, value in changes])
        except TwinError as exc:
            return status_of(exc)
        return None

    async def advance(self, n: int) -> int:
        runner = self.runner
        if runner is None or runner.mode != "lockstep":
            raise AdvanceRefused("BadInvalidState", "Sim.Advance runs only in lockstep (twin serve --lockstep)")
        if self.exchange.fault or getattr(runner, "failed", False):
            raise AdvanceRefused("BadDeviceFailure", "the simulation faulted")
        step_count = self.twin.step_count
        target = step_count + runner.remaining + n  # the step count once these steps are done
        if target <= step_count:
            return step_count
        fut = asyncio.get_running_loop().create_future()
        self._waiting.append((target, fut))
        runner.request(n)
        self.exchange.publish()  # sim.advance shows the steps to run
        return await fut
