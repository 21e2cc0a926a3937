"""The signal table: every value the twin exchanges with the outside world, described as data.

A signal is an *input* (written by a PLC, a robot controller or a test) or an *output* (computed by the
twin each step). Values are in SI units (m, rad, N, N*m, s). The table's order is the station's
declaration order and is stable from run to run, so anything derived from it (the Modbus register map)
is stable too.
"""
from __future__ import annotations

from dataclasses import dataclass, field

INPUT = "input"
OUTPUT = "output"

BOOL = "bool"    # True/False
FLOAT = "float"  # a physical quantity in `unit`
INT = "int"      # a count (steps, ...)
ENUM = "enum"    # one of `choices`; read as the choice's text, index 0 means "none"


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

    @property
    def writable(self) -> bool:
        return self.direction == INPUT
