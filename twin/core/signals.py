"""The signal table: every value the twin exchanges with the outside world, described as data.

A signal is an *input* (written by a PLC, a robot controller or a test) or an *output* (computed by the
twin each step). Values are in SI units (m, rad, N, N*m, s). The table's order is the station's
declaration order and is stable from run to run, so anything derived from it (the Modbus register map)
is stable too.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from numbers import Integral, Real

from .errors import SignalError, SignalRangeError, SignalTypeError

INPUT = "input"
OUTPUT = "output"

BOOL = "bool"    # True/False
FLOAT = "float"  # a physical quantity in `unit`
INT = "int"      # a count (steps, ...)
ENUM = "enum"    # one of `choices`; read as the choice's text, index 0 means "none"

# Who a signal belongs to (`SignalSpec.owner`): for an input, who writes it in the real cell; for an output, who
# produces it. A Modbus master PLC is configured to write exactly the PLC's inputs (the register map's PLC layout).
PLC, ROBOT, OPERATOR, SIMULATOR = "plc", "robot", "operator", "simulator"
OWNERS = (PLC, ROBOT, OPERATOR, SIMULATOR)

#: The units a PLC, the register map, a plot and the live page show instead of an SI unit: SI unit ->
#: (engineering unit, factor), SI value * factor = the value shown. Other units are shown as they are.
ENGINEERING_UNITS = {"m": ("mm", 1000.0), "rad": ("deg", 180.0 / math.pi)}


def engineering_unit(unit: str) -> tuple[str, float]:
    """(the unit shown, factor from SI) for a signal's SI unit: mm for m, deg for rad, else the unit itself."""
    return ENGINEERING_UNITS.get(unit, (unit, 1.0))


@dataclass(frozen=True)
class SignalSpec:
    """Description of one signal (not its value)."""

    name: str
    direction: str  # INPUT or OUTPUT
    type: str  # BOOL, FLOAT, INT or ENUM
    unit: str = ""
    min: float | None = None
    max: float | None = None
    description: str = ""
    group: str = "gripper"  # gripper, robot, controller or sim: where the signal belongs
    choices: tuple[str, ...] = field(default=())  # ENUM only; choices[0] == "" (none)
    # PLC, ROBOT, OPERATOR or SIMULATOR ("": an input is the operator's, an output the simulator's). Not compared:
    # the station's wiring decides it (an input a robot signal drives is the robot's), the twin's own table cannot.
    owner: str = field(default="", compare=False)

    @property
    def owned_by(self) -> str:
        return self.owner or (OPERATOR if self.direction == INPUT else SIMULATOR)

    @property
    def writable(self) -> bool:
        return self.direction == INPUT

    def check(self, value):
        """A value written to this signal, normalised (bool, float, int or the enumeration's text), or the error
        every front end reports for it: SignalError for an output, SignalTypeError for a value of the wrong
        type (a number for a bool, text for a number, NaN), SignalRangeError outside min..max (never clamped).
        The one validation of writes: the twin, Modbus, OPC UA and the view all go through it."""
        if self.direction != INPUT:
            raise SignalError(self.name, "is an output of the twin and cannot be written")
        if self.type == BOOL:
            if isinstance(value, (bool, Integral)) and value in (0, 1):
                return bool(value)
            raise SignalTypeError(self.name, value, "a bool (True/False, 1/0)")
        if self.type == ENUM:
            if isinstance(value, str) and value in self.choices:
                return value
            if isinstance(value, Integral) and not isinstance(value, bool) and 0 <= value < len(self.choices):
                return self.choices[value]
            raise SignalTypeError(self.name, value, "one of " + ", ".join(repr(c) for c in self.choices))
        if isinstance(value, bool) or not isinstance(value, Real):
            raise SignalTypeError(self.name, value, "a number")
        if not math.isfinite(value):
            raise SignalTypeError(self.name, value, "a finite number")
        if self.type == INT:
            if value != int(value):
                raise SignalTypeError(self.name, value, "a whole number")
            value = int(value)
        else:
            value = float(value)
        lo = -math.inf if self.min is None else self.min
        hi = math.inf if self.max is None else self.max
        # a range end sent in other units (deg, mm) and converted back is the end, within a rounding's width
        # (a whole number is exact: no slack)
        slack = 0 if self.type == INT else 1e-9 * max(1.0, *(abs(v) for v in (self.min, self.max) if v is not None))
        if hi < value <= hi + slack:
            value = type(value)(hi)
        elif lo - slack <= value < lo:
            value = type(value)(lo)
        if not lo <= value <= hi:
            raise SignalRangeError(self.name, value, lo, hi, self.unit)
        return value
