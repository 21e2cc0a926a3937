"""Runtime structures shared by the evaluator and the built-in instructions: simulated time in
integer nanoseconds, the `Wait` a suspended program yields, storage cells and references, call
frames, and the exceptions that carry RETURN, EXIT, RETRY, TRYNEXT and errors between frames.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from . import nodes as n
from .errors import ExecError, Span
from .values import RECORDS, array_type, base_type, split_array_type

NS = 1_000_000_000
DEFAULT_LOOP_BUDGET = 10_000  # time-less loop iterations per tick (Controller, Interpreter)
# Iterations per tick for a loop that already used up a whole tick's budget without waiting: a
# polling loop. It bounds the wall time a busy polling loop costs per simulated second.
POLL_BUDGET = 100


def to_ns(seconds: float) -> int:
    return int(round(seconds * NS))


# Kinds of scheduled output writes (`Interpreter.pulses`: (due ns, signal, value, kind)).
PULSE = "pulse"  # the end edge of a PulseDO
SDELAY = "sdelay"  # a SetDO \SDelay


@dataclass
class Wait:
    """What a suspended program waits for.

    kind "time" / "poll": resume at the first tick with now >= at.
    kind "pace": an offline motion in a polling loop takes its time (like "time", and the loop stays a
    polling loop).
    kind "step": a loop used up the tick's loop budget; ready at the next tick, whenever it comes
    (`at`, set for event-driven runners, is when that tick is due at the latest).
    kind "signal" / "motion": re-evaluate on every tick; `at` (a timeout) is only a hint for
    event-driven runners: nothing changes before `at` unless a signal does.
    kind "stop": the program executed Stop; it waits for resume() or start().
    """

    kind: str
    at: int | None = None
    what: str = ""
    span: Span | None = None


# ---- control-flow signals (exceptions that are not errors) ------------------------------------
class ReturnSignal(Exception):
    def __init__(self, value: object = None):
        self.value = value


class ExitSignal(Exception):
    """EXIT: the program ends."""


class ExitCycleSignal(Exception):
    """ExitCycle: the cycle ends; the next one starts from the entry routine (data keep their values)."""


class GotoSignal(Exception):
    """GOTO: caught by the innermost block around it that holds the label."""

    def __init__(self, label: str):
        self.label = label


class RetrySignal(Exception):
    pass


class TryNextSignal(Exception):
    pass


class Propagate(Exception):
    """An error on its way to the caller's ERROR handler (passes through this routine's guards)."""

    def __init__(self, error: ExecError):
        self.error = error


class Fatal(Exception):
    """An error for the system error handler: the program stops with this error."""

    def __init__(self, error: ExecError):
        self.error = error


# ---- storage -----------------------------------------------------------------------------------
class Cell:
    """A variable, persistent, constant or parameter. `value is ABSENT` for a missing optional."""

    __slots__ = ("type", "value", "storage", "name")

    def __init__(self, type_: str, value: object, storage: str = "VAR", name: str = ""):
        self.type, self.value, self.storage, self.name = type_, value, storage, name

    def get(self) -> object:
        return self.value

    def set(self, v: object) -> None:
        self.value = v


ABSENT = object()


class Ref:
    """A reference to a variable or one of its components (an INOUT argument, an assignment target)."""

    __slots__ = ("cell", "path", "type", "name")

    def __init__(self, cell, path: list, type_: str, name: str):
        self.cell, self.path, self.type, self.name = cell, path, type_, name

    @property
    def storage(self) -> str:
        return "VAR"

    def get(self) -> object:
        v = self.cell.get()
        for k in self.path:
            v = v[k] if isinstance(k, int) else v.fields[k]  # type: ignore[union-attr,index]
        return v

    def set(self, v: object) -> None:
        if not self.path:
            self.cell.set(v)
            return
        obj = self.cell.get()
        for k in self.path[:-1]:
            obj = obj[k] if isinstance(k, int) else obj.fields[k]  # type: ignore[union-attr,index]
        last = self.path[-1]
        if isinstance(last, int):
            obj[last] = v  # type: ignore[index]
        else:
            obj.fields[last] = v  # type: ignore[union-attr]


@dataclass
class Frame:
    routine: n.Routine
    vars: dict[str, object] = field(default_factory=dict)
    in_handler: bool = False
    error: ExecError | None = None
    undoing: bool = False


def component_type(t: str, path: list) -> str:
    """The type of `path` (component names, and 0-based indexes as ints) inside a `t`."""
    for k in path:
        if isinstance(k, int):
            elem, ndims = split_array_type(t)  # type: ignore[misc]
            t = elem if ndims == 1 else array_type(elem, ndims - 1)
        else:
            t = dict(RECORDS[base_type(t)])[k]
    return t
