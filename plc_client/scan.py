"""The scan-cycle virtual PLC: read the input image, run the logic, write the output image, every cycle.

    plc = ScanCycle(io, logic, cycle=0.010)
    plc.run(seconds=2.0)                       # or plc.run(scans=200), plc.run_until(pred, timeout=5.0)

`logic(inputs, state) -> outputs` is a plain function of the input image (a read-only mapping of signal
names to values, with `.time` in s since the PLC started, `.cycle` and `.scan`) and of its own state (any
object the logic owns: no globals). It returns the outputs it wants set; the scan writes the ones that
changed since the last scan (a PLC's output update) in one go. An output the process refuses (a value
out of range, ...) stops the scan cycle with an `OutputRefusedError` that names it: a PLC program that
commands what the process cannot do is a bug to fix, not a condition to ride over.

The I/O (`ProcessIO`) is either the network client (`ClientIO`, in `plc_client.client`) or, for fast tests,
a twin in the same process (`TwinIO`). A lockstep I/O moves the process by exactly one cycle per scan
(the twin is stepped `cycle / dt` steps, carried over so the average matches); otherwise the scan is paced
against the wall clock, in `ScanCycle._pace`, the one place here that knows the wall clock.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Mapping
from types import SimpleNamespace
from typing import Any, Protocol

from .errors import ConnectionFailedError, OutputRefusedError, PlcClientError

DEFAULT_CYCLE = 0.010  # s


class ProcessIO(Protocol):
    """What a scan cycle needs from the process it controls."""

    lockstep: bool  # True: `advance` moves the process; False: it runs on its own (wall) clock

    def read_image(self, names: Iterable[str]) -> dict[str, Any]: ...

    def write_image(self, values: Mapping[str, Any]) -> None: ...

    def advance(self, seconds: float) -> None: ...


class InputImage(Mapping):
    """The input image of one scan: signal values by name, plus the scan's time, cycle and number."""

    __slots__ = ("_values", "time", "cycle", "scan")

    def __init__(self, values: Mapping[str, Any], time: float, cycle: float, scan: int):
        self._values, self.time, self.cycle, self.scan = dict(values), time, cycle, scan

    def __getitem__(self, name: str) -> Any:
        try:
            return self._values[name]
        except KeyError:
            raise KeyError(f"{name!r} is not in the input image (read: {', '.join(self._values) or 'nothing'})") from None

    def __iter__(self):
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __repr__(self) -> str:
        return f"InputImage(scan={self.scan}, time={self.time:.3f}, {self._values!r})"


Logic = Callable[[InputImage, Any], Mapping[str, Any]]


def plc_logic(inputs: Iterable[str], state: Callable[[], Any] | None = None):
    """Declare what a plain logic function reads (and how its state starts), for `ScanCycle` and `plc run`:

        @plc_logic(inputs=["start", "axis1.force"])
        def press(inputs, state):
            return {"axis1": 300.0 if inputs["start"] else 330.0}
    """
    def mark(fn):
        fn.inputs = tuple(inputs)
        if state is not None:
            fn.initial_state = state
        return fn
    return mark


def _initial_state(logic) -> Any:
    make = getattr(logic, "initial_state", None)
    return make() if make is not None else SimpleNamespace()


class Combined:
    """Several logics in one PLC program, run in order every scan on the same input image, each with its own
    state; their outputs merge (a later logic wins a shared output). E.g. a cell sequencer beside the grip
    sequence: `ScanCycle(io, Combined(grip_sequence, operator))`."""

    def __init__(self, *logics: Logic):
        if not logics:
            raise ValueError("Combined needs at least one logic")
        for logic in logics:
            if getattr(logic, "inputs", None) is None:
                raise ValueError(f"{logic!r} does not say what it reads (.inputs; see plc_logic)")
        self.logics = logics
        self.inputs = tuple(dict.fromkeys(n for logic in logics for n in logic.inputs))
        self.outputs = tuple(dict.fromkeys(n for logic in logics for n in getattr(logic, "outputs", ())))

    def initial_state(self) -> list:
        return [_initial_state(logic) for logic in self.logics]

    def __call__(self, inputs: InputImage, state: list) -> dict:
        out: dict = {}
        for logic, own in zip(self.logics, state):
            out.update(logic(inputs, own) or {})
        return out


class ScanCycle:
    """A virtual PLC: `io` is the process, `logic(inputs, state)` the program, `cycle` the scan time (s).

    `inputs`: the names read each scan (default: `logic.inputs`). `state`: the logic's memory (default:
    `logic.initial_state()`, else an empty namespace). `realtime`: pace against the wall clock (default:
    when the I/O is not lockstep). `speed`: real time only, the PLC's clock runs X times the wall clock,
    to match a twin served at `--speed X`.
    """

    def __init__(self, io: ProcessIO, logic: Logic, cycle: float = DEFAULT_CYCLE, *,
                 inputs: Iterable[str] | None = None, state: Any = None, realtime: bool | None = None,
                 speed: float = 1.0):
        if not cycle > 0:
            raise ValueError(f"the cycle must be greater than 0 s, not {cycle!r}")
        if not speed > 0:
            raise ValueError(f"the speed must be greater than 0, not {speed!r}")
        self.io, self.logic, self.cycle, self.speed = io, logic, float(cycle), float(speed)
        names = inputs if inputs is not None else getattr(logic, "inputs", None)
        if names is None:
            raise ValueError("say which signals the logic reads: ScanCycle(io, logic, inputs=[...])")
        self.inputs = tuple(names)
        self.state = _initial_state(logic) if state is None else state
        self.realtime = (not getattr(io, "lockstep", True)) if realtime is None else realtime
        self.scans = 0
        self.time = 0.0  # s since the first scan: scan count x cycle in lockstep, wall time in real time
        self.image: InputImage | None = None  # the last input image
        self.written: dict[str, Any] = {}  # the output image as last written
        self.overruns = 0  # real time: scans that took longer than the cycle
        self._t0: float | None = None

    def scan(self) -> InputImage:
        """One scan: input image, logic, output image, then one cycle of time. Returns the input image."""
        if self.realtime and self._t0 is None:
            self._t0 = time.monotonic()
        image = InputImage(self.io.read_image(self.inputs), self.time, self.cycle, self.scans)
        self.image = image
        outputs = self.logic(image, self.state) or {}
        changed = {k: v for k, v in outputs.items() if k not in self.written or self.written[k] != v}
        if changed:
            try:
                self.io.write_image(changed)
            except ConnectionFailedError:
                raise
            except PlcClientError as exc:  # e.g. a setpoint out of range: name it, do not just die
                raise OutputRefusedError(changed, exc, self.scans, self.time) from exc
            self.written.update(changed)
        self.scans += 1
        self._pace()
        return image

    def _pace(self) -> None:
        """The cycle's pacing: lockstep advances the process one cycle; real time waits for the deadline."""
        if not self.realtime:
            self.io.advance(self.cycle)
            self.time = self.scans * self.cycle
            return
        period = self.cycle / self.speed  # wall seconds per scan
        deadline = self._t0 + self.scans * period
        now = time.monotonic()
        if now < deadline:
            time.sleep(deadline - now)
        else:
            self.overruns += 1
            if now - deadline > period:  # far behind: skip the lost cycles instead of bursting
                self._t0 += math.floor((now - deadline) / period) * period
        self.time = (time.monotonic() - self._t0) * self.speed

    def run(self, scans: int | None = None, *, seconds: float | None = None) -> None:
        """Run a number of scans, or for `seconds` of PLC time."""
        if scans is None and seconds is None:
            raise ValueError("run(scans=N) or run(seconds=S): a PLC run here is always bounded")
        end = None if seconds is None else self.time + seconds - 1e-9
        n = 0
        while (scans is None or n < scans) and (end is None or self.time < end):
            self.scan()
            n += 1

    def run_until(self, condition: Callable[[InputImage, Any], bool], timeout: float) -> InputImage:
        """Scan until `condition(inputs, state)` holds after a scan; TimeoutError after `timeout` s of PLC time."""
        end = self.time + timeout
        while True:
            image = self.scan()
            if condition(image, self.state):
                return image
            if self.time >= end:
                raise TimeoutError(f"no result after {timeout:g} s ({self.scans} scans); last inputs: {dict(image)}")


class LocalSignals:
    """Signals the PLC holds itself, next to the process's (e.g. the robot's handshake bits when a test
    plays the robot): `io.set(name, value)` and `io.get(name)` reach them and the process alike."""

    def __init__(self, local: Mapping[str, Any] | None = None):
        self.local: dict[str, Any] = dict(local or {})

    def set(self, name: str, value: Any) -> None:
        if name in self.local:
            self.local[name] = value
        else:
            self.write_image({name: value})

    def get(self, name: str) -> Any:
        return self.read_image([name])[name]

    def read_image(self, names: Iterable[str]) -> dict[str, Any]:
        names = list(names)
        remote = self._read([n for n in names if n not in self.local])
        return {n: self.local[n] if n in self.local else remote[n] for n in names}

    def write_image(self, values: Mapping[str, Any]) -> None:
        for n, v in values.items():
            if n in self.local:
                self.local[n] = v
        remote = {n: v for n, v in values.items() if n not in self.local}
        if remote:
            self._write(remote)

    def _read(self, names: list[str]) -> dict[str, Any]:
        raise NotImplementedError

    def _write(self, values: dict[str, Any]) -> None:
        raise NotImplementedError


class TwinIO(LocalSignals):
    """A twin in the same process as the PLC (tests, quick trials): lockstep, no network.

    Values are published in the register map's engineering units (metres as mm) so the same logic runs
    here and over the network. `local`: signals the PLC holds itself (see `LocalSignals`). `wire`: a register
    map (the one a server of this twin serves, `twin.frontends.modbus.register_map.RegisterMap`) whose resolution the
    values take both ways, encoded and decoded as on the wire: the logic reads and writes exactly what it
    would over Modbus, so the run is the same, bit for bit, as against `twin serve` (plain engineering values
    in full precision otherwise).
    """

    lockstep = True
    SCALE = {"m": 1000.0}  # SI unit -> factor to the map's unit (m -> mm)

    def __init__(self, twin, local: Mapping[str, Any] | None = None, *, wire=None):
        super().__init__(local)
        self.twin = twin
        self._scale = {s.name: self.SCALE.get(s.unit, 1.0) for s in twin.signals}
        self._wire, self._entries = wire, None
        if wire is not None:
            from .checks import check_value  # plc_client.client imports this module: these come in here
            from .client import decode, encode

            self._entries = {e.name: e for e in wire if e.signal is not None}
            self._decode, self._encode, self._check = decode, encode, check_value
        self._time = 0.0  # s the PLC asked to advance, carried over to whole steps
        self._steps = 0

    def _read(self, names: list[str]) -> dict[str, Any]:
        out = {}
        read, entries = self.twin.read, self._entries
        for n in names:
            v = read(n)
            entry = entries.get(n) if entries is not None else None
            if entry is not None:  # what a read over Modbus gives: the server's words, the client's decoding
                out[n] = self._decode(entry, entry.encode(v))
            else:
                out[n] = v * self._scale[n] if isinstance(v, float) else v
        return out

    def _write(self, values: dict[str, Any]) -> None:
        entries = self._entries
        for n, v in values.items():
            entry = entries.get(n) if entries is not None else None
            if entry is not None:  # the words a write over Modbus sends, taken as the server takes them
                self.twin.write(n, entry.si_of_words(self._encode(entry, self._check(self._wire, n, v))))
                continue
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                self.twin.write(n, v / self._scale[n])
            else:
                self.twin.write(n, v)

    def advance(self, seconds: float) -> None:
        self._time += seconds
        target = math.floor(self._time / self.twin.dt + 1e-9)
        if target > self._steps:
            self.twin.step(target - self._steps)
            self._steps = target
