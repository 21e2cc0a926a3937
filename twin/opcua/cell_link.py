"""The OPC UA server's link to a running cell: the cell's exchange (`twin.exchange`), like every front end,
and its comm-loss watchdog (`twin.watchdog`), fed by every request of an OPC UA session.

The asyncua server runs in a thread of its own, with its own event loop (`ServerThread`), so a client's
request never waits behind a simulation step, and a step never waits behind asyncua's work (encoding the
notifications of a thousand monitored items). The two sides only hand each other messages:

- cell -> server: after each step the exchange calls `_on_snapshot` (the runner's thread), which queues the
  snapshot's values for the server thread; the server publishes every queued snapshot, in order (a value
  that lasts one step still reaches every subscription). Reads answer from what was last published.
- server -> cell: a write is checked in the server thread with the exchange's own validation
  (`Exchange.check`: the same rules and status codes as Modbus), answered at once, and handed to the cell's
  loop, which submits it to the exchange (applied at the next step, in arrival order with every other front
  end's writes). `Sim.Advance` runs in the cell's loop and its answer comes back when its steps are done. A
  session's request feeds the watchdog in the cell's loop.

Order is kept across the two loops (both hand over with `call_soon_threadsafe`, which is first in, first
out): a write answered before a `Sim.Advance` is applied in the advance's first step, and the values a
client reads after an advance are those of its last step, as in one loop: lockstep runs stay bit for bit.
"""
from __future__ import annotations

import asyncio
import logging
import threading
from collections import deque
from collections.abc import Sequence

from twin.core.errors import TwinError
from twin.exchange import SimulationFault

from .address_space import Variable
from .errors import AdvanceRefused, status_of  # status_of: the one mapping of a refused write to a status code

log = logging.getLogger("twin.opcua")




class ServerThread:
    """An asyncio event loop running in a daemon thread of its own (the OPC UA server's)."""

    def __init__(self, name: str = "opcua-server"):
        self.loop = asyncio.new_event_loop()
        self.loop.set_exception_handler(lambda _loop, ctx: log.debug("OPC UA event loop: %s: %r",
                                                                     ctx.get("message"), ctx.get("exception")))
        self.thread = threading.Thread(target=self._run, name=name, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        asyncio.set_event_loop(self.loop)
        try:
            self.loop.run_forever()
            tasks = asyncio.all_tasks(self.loop)
            for t in tasks:
                t.cancel()
            self.loop.run_until_complete(asyncio.gather(*tasks, return_exceptions=True))
        finally:
            self.loop.close()

    async def run(self, coro):
        """Run `coro` in the thread's loop and wait for its result (from another loop)."""
        return await asyncio.wrap_future(asyncio.run_coroutine_threadsafe(coro, self.loop))

    def stop(self, timeout: float = 10.0) -> None:
        if self.thread.is_alive():
            try:
                self.loop.call_soon_threadsafe(self.loop.stop)
            except RuntimeError:  # already closed
                pass
            self.thread.join(timeout)


class CellLink:
    """Between the cell's loop (the runner, the exchange, the watchdog) and the OPC UA server's thread."""

    def __init__(self, exchange, runner=None, watchdog=None, *, cell_loop: asyncio.AbstractEventLoop | None = None,
                 server_loop: asyncio.AbstractEventLoop | None = None):
        """`watchdog`: the cell's comm-loss watchdog (`twin.watchdog`), fed by every request of a session.
        `cell_loop`/`server_loop`: the loops of the two sides (default: the running loop, for both)."""
        self.exchange, self.runner, self.watchdog = exchange, runner, watchdog
        self.twin = exchange.twin  # the station's name and step length
        self.cell_loop = cell_loop or asyncio.get_event_loop()
        self.server_loop = server_loop or self.cell_loop
        self.server = None  # the OpcUaServer, once attached
        self._waiting: list[tuple[int, asyncio.Future]] = []  # Sim.Advance: (step count, future) in the cell's loop
        self._unsubscribe = None
        self._snapshots: deque = deque()  # (values, write batches applied) for the server thread
        self._drain_scheduled = False
        self._applied = 0  # write batches handed to the exchange (the cell's loop)

    def signals(self) -> tuple:
        """The cell's signal table as OPC UA serves it: the static table, the simulator's `sim.*` included."""
        return self.exchange.signals

    def attach(self, server) -> None:
        """Publish every step to `server` from now on (call in the cell's loop)."""
        self.server = server
        self._unsubscribe = self.exchange.subscribe(on_snapshot=self._on_snapshot)
        self._on_snapshot(self.exchange.snapshot)

    def detach(self) -> None:
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
        self.server = None

    # -- the cell's side (its loop) -------------------------------------------------------------------
    def _on_snapshot(self, snapshot) -> None:
        if self.server is not None:
            self._snapshots.append((snapshot.values, self._applied))
            if not self._drain_scheduled:
                self._drain_scheduled = True
                self._to_server(self._drain)
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

    def _submit_now(self, batch) -> None:
        self._applied += 1
        try:
            self.exchange.submit(batch)
        except TwinError as exc:  # the simulation faulted between the check and now
            log.warning("OPC UA write of %s dropped: %s", ", ".join(n for n, _ in batch), exc)

    async def _advance_now(self, n: int) -> int:
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

    def _to_server(self, fn, *args) -> None:
        try:
            self.server_loop.call_soon_threadsafe(fn, *args)
        except RuntimeError:  # the server's loop is closed: it has stopped
            pass

    def _to_cell(self, fn, *args) -> None:
        try:
            self.cell_loop.call_soon_threadsafe(fn, *args)
        except RuntimeError:  # the cell's loop is closed: it has stopped
            pass

    # -- the server's side (its thread) ---------------------------------------------------------------
    @property
    def lockstep(self) -> bool:
        return self.runner is not None and self.runner.mode == "lockstep"

    def _drain(self) -> None:
        self._drain_scheduled = False
        server, queue = self.server, self._snapshots
        while queue:
            values, applied = queue.popleft()
            if server is not None:
                server.publish(values, applied)
        if server is not None:
            server.send_due()

    def feed(self, source: str, clock_only: bool = False) -> None:
        """A session's request came (see `twin.watchdog`): in lockstep, one that only drives simulated time
        (`clock_only`) arms the watchdog without feeding it, as on Modbus. Nothing to do while it is off."""
        if self.watchdog.timeout:
            self._to_cell(self.watchdog.feed, source, self.lockstep and clock_only)

    def submit(self, changes: Sequence[tuple[Variable, object]]) -> str | None:
        """Check writes as the exchange does and hand them to the cell (applied at its next step). Returns
        None, or the name of the Bad status code refusing them all (nothing is handed over then). The
        accepted batches are counted by both sides in the same order: `publish(values, applied)` tells the
        server how many of them a snapshot already shows."""
        exchange = self.exchange
        try:
            if exchange.fault:
                raise SimulationFault(self.twin.step_count)
            batch = [(var.name, exchange.check(var.name, value)) for var, value in changes]
        except TwinError as exc:
            return status_of(exc)
        self._to_cell(self._submit_now, batch)
        return None

    async def advance(self, n: int) -> int:
        """Sim.Advance(n) from the server's loop: run n lockstep steps in the cell's, return the step count."""
        if self.cell_loop is self.server_loop:
            return await self._advance_now(n)
        return await asyncio.wrap_future(asyncio.run_coroutine_threadsafe(self._advance_now(n), self.cell_loop))
