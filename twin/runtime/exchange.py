"""The front-end contract: published snapshots out, queued writes in, one validation for all.

A running cell (see `twin_app.cell`) has one `Exchange` between its stepped twin and every front end
(Modbus/TCP, OPC UA, the web view, a recorder). A front end never touches the twin itself:

- **Read** `exchange.snapshot`: a frozen `Snapshot(step, time, values)` with the value of every signal of
  `exchange.signals` (the station's static table, `twin.core.signal_table`, the simulator's `sim.*`
  included) in SI units, as of the last completed step. It is replaced, never changed, after each step,
  so a reader never sees half a step. To see every step (an OPC UA subscription, a recorder), subscribe:
  `exchange.subscribe(on_snapshot=f)` calls `f(snapshot)` right after each step, in the runner's task:
  take what you need and return (no blocking I/O there).
- **Write** `exchange.submit([(name, value), ...])`: every value is checked first, by the signal's own
  `SignalSpec.check` (an output: `SignalError`; a wrong type or NaN: `SignalTypeError`; out of range:
  `SignalRangeError`, never clamped) and, when the simulation has stopped on an error, `SimulationFault`:
  on any error nothing of the batch is queued. Accepted batches take effect together, in arrival order,
  at the start of the next step. `exchange.written(name)` is an input as last written (queued or
  applied), so a front end can read a write back at once; `subscribe(on_writes=g)` calls `g(batch)`
  for every accepted batch (from any front end).
- **Time** belongs to the runner (`twin.runtime.pacing`), which calls `exchange.step()` once per step. A write of
  N to `sim.advance` asks a lockstep runner for N more steps (real time: only 0 is accepted); the value
  of `sim.advance` is the steps still to run. `exchange.runner` is set by whoever assembles the cell.

The exchange imports no front end, no socket and no clock; the twin is anything with the
`twin.core.Twin` signal contract (`signals`, `read`, `write`, `step`, `step_count`, `time`, `dt`).
"""
from __future__ import annotations

import sys
import traceback
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

from twin.core.errors import SignalError, SignalRangeError, TwinError
from twin.core.signal_table import (SIM_ADVANCE, SIM_DT_US, SIM_FAULT, SIM_LATE, SIM_LATE_STEPS, SIM_LOCKSTEP,
                                SIM_MAP_CRC, SIM_MODE, SIM_NAMES, SIM_SIGNALS, SIM_SPEED_PCT, SIM_STEP, SIM_TIME_MS, WATCHDOG_MS)
from twin.core.signals import SignalSpec

Write = tuple[str, object]


class SimulationFault(TwinError):
    """The simulation stopped on an error: outputs are frozen at the last completed step, writes are refused."""

    def __init__(self, step: int):
        self.step = step
        super().__init__(f"the simulation stopped on an error at step {step}: writes are refused")


@dataclass(frozen=True)
class Snapshot:
    """Every signal's value after one completed step (SI units; enumerations as their text)."""

    step: int
    time: float  # s, step * dt
    values: Mapping[str, object]

    def __getitem__(self, name: str):
        return self.values[name]


def _stderr(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


class Exchange:
    """Publishes a twin's signals as snapshots and queues validated writes for the next step."""

    def __init__(self, twin, *, constants: Mapping[str, object] | None = None,
                 log: Callable[[str], None] = _stderr):
        """`constants`: values of `sim.*` signals only the assembler knows (e.g. `sim.map_crc`)."""
        self.twin, self.log = twin, log
        own = tuple(twin.signals)
        names = {s.name for s in own}
        self.signals: tuple[SignalSpec, ...] = own + tuple(s for s in SIM_SIGNALS if s.name not in names)
        self._spec = {s.name: s for s in self.signals}
        self._sim_names = tuple(s.name for s in self.signals if s.name in SIM_NAMES)  # the runner's state
        self._twin_names = tuple(s.name for s in self.signals if s.name not in SIM_NAMES)
        self.constants = dict(constants or {})
        self.runner = None  # mode ("realtime"/"lockstep"), speed, late_steps, last_late, remaining, request(n)
        self.fault = False
        self.on_fault: Callable[[str], None] | None = None  # told the fault's one-line message (the event stream)
        self._in_step = False
        self.pending: list[Sequence[Write]] = []  # accepted batches, not yet applied
        self._written: dict[str, object] = {}
        self._on_snapshot: list[Callable[[Snapshot], None]] = []
        self._on_writes: list[Callable[[Sequence[Write]], None]] = []
        self.snapshot: Snapshot = self._take()

    # -- front ends' side -----------------------------------------------------------------------------
    def spec(self, name: str) -> SignalSpec:
        try:
            return self._spec[name]
        except KeyError:
            raise SignalError(name, "no such signal") from None

    def subscribe(self, on_snapshot: Callable[[Snapshot], None] | None = None,
                  on_writes: Callable[[Sequence[Write]], None] | None = None) -> Callable[[], None]:
        """Call `on_snapshot(snapshot)` after every step and `on_writes(batch)` for every accepted batch.
        Returns a function that unsubscribes."""
        if on_snapshot is not None:
            self._on_snapshot.append(on_snapshot)
        if on_writes is not None:
            self._on_writes.append(on_writes)

        def unsubscribe() -> None:
            for lst, f in ((self._on_snapshot, on_snapshot), (self._on_writes, on_writes)):
                if f in lst:
                    lst.remove(f)
        return unsubscribe

    def check(self, name: str, value):
        """A write's value, normalised, or the error every front end reports (see the module docstring)."""
        spec = self.spec(name)
        value = spec.check(value)
        if name == SIM_ADVANCE:
            runner = self.runner
            if runner is None or runner.mode != "lockstep":
                if value != 0:
                    raise SignalRangeError(name, value, 0, 0, spec.unit)
            elif runner.remaining + value > spec.max:
                raise SignalRangeError(name, value, 0, spec.max - runner.remaining, spec.unit)
        return value

    def submit(self, writes: Iterable[Write]) -> list[Write]:
        """Check every write, then queue them together for the next step (a sim.advance acts at once).
        Returns the batch as queued (values normalised). On any error nothing is queued."""
        if self.fault:
            raise SimulationFault(self.twin.step_count)
        check = self.check
        batch, signals, advance = [], [], 0
        for name, value in writes:
            value = check(name, value)
            batch.append((name, value))
            if name not in SIM_NAMES:
                signals.append((name, value))
            elif name == SIM_ADVANCE:
                advance += int(value)
        if signals:
            self.pending.append(signals)
            self._written.update(signals)
            for f in tuple(self._on_writes):
                f(signals)
        if advance and self.runner is not None and self.runner.mode == "lockstep":
            self.runner.request(advance)
        return batch

    def written(self, name: str):
        """An input as last written by a front end (queued or applied), else as the twin reads it."""
        if name in self._written:
            return self._written[name]
        return self.read(name)

    def read(self, name: str):
        """A signal's live value (the twin's read, or the simulator's status): for in-process use; front ends
        read `snapshot`."""
        if name in self._sim_names:
            return self._status()[name]
        self.spec(name)
        return self.twin.read(name)

    # -- the runner's side ----------------------------------------------------------------------------
    def step(self, *, reraise: bool = False, publish: bool = True) -> bool:
        """Apply the queued writes, run one step, publish. False (and `fault`) if the twin failed; with
        `reraise` (stepping in process), the error is raised instead. `publish=False` (a cell stepped in
        process with nothing subscribed): no snapshot of this step; `publish()` takes one when wanted."""
        if self.fault:
            return False
        queue, self.pending = self.pending, []
        try:
            for batch in queue:
                for name, value in batch:
                    self.twin.write(name, value)
            self.twin.step()
        except Exception as exc:  # a physics or device error: keep publishing the last state, flag it
            if reraise:
                raise
            self.fault = True
            self.log(f"simulation fault at step {self.twin.step_count}: {type(exc).__name__}: {exc}; gave up\n"
                     + traceback.format_exc().rstrip())
            if self.on_fault is not None:
                self.on_fault(f"{type(exc).__name__}: {exc}")
            self.publish()
            return False
        if not publish:
            return True
        self._in_step = True  # a lockstep runner counts this step as still to run until it returns
        try:
            self.publish()
        finally:
            self._in_step = False
        return True

    def publish(self) -> Snapshot:
        """Take a new snapshot and hand it to the subscribers."""
        self.snapshot = self._take()
        for f in tuple(self._on_snapshot):
            f(self.snapshot)
        return self.snapshot

    def _status(self) -> dict:
        twin, runner = self.twin, self.runner
        lockstep = runner is not None and runner.mode == "lockstep"
        status = {
            SIM_FAULT: self.fault, SIM_LOCKSTEP: lockstep, SIM_LATE: bool(runner is not None and runner.last_late),
            SIM_STEP: twin.step_count, SIM_TIME_MS: round(twin.time * 1000), SIM_DT_US: round(twin.dt * 1e6),
            SIM_LATE_STEPS: 0 if runner is None else runner.late_steps, SIM_MODE: 0 if lockstep else 1,
            SIM_SPEED_PCT: 0 if runner is None or lockstep else round(runner.speed * 100),
            # the steps still to run; inside a step the runner still counts the one running
            SIM_ADVANCE: 0 if runner is None else min(0xFFFF, max(0, runner.remaining - self._in_step)), SIM_MAP_CRC: 0, WATCHDOG_MS: 0,
        }
        status.update(self.constants)
        return status

    def _take(self) -> Snapshot:
        read = self.twin.read
        values = {name: read(name) for name in self._twin_names}
        status = self._status()
        for name in self._sim_names:
            values[name] = status[name]
        return Snapshot(self.twin.step_count, self.twin.time, MappingProxyType(values))

