"""The OPC UA address space of a station: derived from its signal table, never written by hand.

`build_address_space(signals, station)` is a pure function (no asyncua, no sockets), like the Modbus
register map: the server builds its nodes from what it returns, and tests can check the layout without
starting anything.

Layout, in the namespace `urn:gripper-twin:station:NAME` (NAME: the station's name):

    Objects/
      Gripper/     Active, the joint setpoints (one per input), doGripped, GrippedPart, NAME.actual, .in_position, .moving
      Fingers/     per finger NAME.contact, NAME.force
      Robot/       robot.busy, robot.j1 ..
      Targets/     per target NAME.present, NAME.x, NAME.y, NAME.z
      Controller/  the robot controller's I/O and rapid.*
      Sim/         the simulator's own signals (sim.step, sim.lockstep, fault, ...) and the method Advance

Every signal is one variable whose NodeId is the string `ns=<ns>;s=<signal name>` (BrowseName the same
name in that namespace). Folders are `s=Gripper`, `s=Fingers`, ...; the method is `s=Sim.Advance`.
Data types: Boolean (bool), Double (float, in the signal's own unit: SI for the twin's signals), Int32 for
counts that fit it (UInt32 for the 32-bit counters), String for enumerations (the choice's text, "" for none).
Numbers are AnalogItemType variables with `EngineeringUnits` (UNECE codes, see `units`) and `EURange` (the
signal's min..max; an open end is +-infinity). Inputs are readable and writable; outputs read-only.
"""
from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from twin.core.errors import TwinError
from twin.core.signals import BOOL, ENUM, FLOAT, INPUT, INT, SignalSpec

from .units import Unit, unit_of

NAMESPACE_PREFIX = "urn:gripper-twin:station:"
FOLDERS = ("Gripper", "Fingers", "Robot", "Targets", "Controller", "Sim")
SIM_FOLDER = "Sim"
ADVANCE_METHOD = "Sim.Advance"  # NodeId of the lockstep method (BrowseName "Advance", on the Sim folder)

# signal group -> folder ("cell" is the name targets had before the static signal table)
GROUP_FOLDER = {"gripper": "Gripper", "fingers": "Fingers", "robot": "Robot", "targets": "Targets", "cell": "Targets",
                "controller": "Controller", "sim": "Sim"}

BOOLEAN, DOUBLE, INT32, UINT32, INT64, STRING = "Boolean", "Double", "Int32", "UInt32", "Int64", "String"
_INT32 = (-2**31, 2**31 - 1)
_UINT32 = (0, 2**32 - 1)


class AddressSpaceError(TwinError):
    """The signal table cannot be served as an OPC UA address space (a name clash)."""


@dataclass(frozen=True)
class Variable:
    """One signal as an OPC UA variable."""

    name: str  # the signal's name: the NodeId's string and the BrowseName
    folder: str
    data_type: str  # Boolean, Double, Int32, UInt32, Int64 or String
    writable: bool
    unit: Unit | None
    low: float | None  # EURange (numbers only); None: no EURange
    high: float | None
    description: str
    spec: SignalSpec

    @property
    def numeric(self) -> bool:
        return self.data_type not in (BOOLEAN, STRING)


@dataclass(frozen=True)
class AddressSpace:
    station: str
    namespace_uri: str
    folders: tuple[str, ...]
    variables: tuple[Variable, ...]

    def __iter__(self):
        return iter(self.variables)

    def __len__(self) -> int:
        return len(self.variables)

    def in_folder(self, folder: str) -> tuple[Variable, ...]:
        return tuple(v for v in self.variables if v.folder == folder)


def namespace_uri(station: str) -> str:
    return NAMESPACE_PREFIX + station


def folder_of(spec: SignalSpec) -> str:
    group = spec.group or "gripper"
    if group == "gripper" and (spec.name.endswith(".contact") or spec.name.endswith(".force")):
        return "Fingers"  # tables from before the static signal table have no fingers group
    return GROUP_FOLDER.get(group, group[:1].upper() + group[1:])


def data_type_of(spec: SignalSpec) -> str:
    if spec.type == BOOL:
        return BOOLEAN
    if spec.type == FLOAT:
        return DOUBLE
    if spec.type == ENUM:
        return STRING
    if spec.type == INT:
        lo = -math.inf if spec.min is None else spec.min
        hi = math.inf if spec.max is None else spec.max
        if (spec.min is None or spec.min >= _INT32[0]) and (spec.max is None or spec.max <= _INT32[1]):
            return INT32
        if _UINT32[0] <= lo and hi <= _UINT32[1]:
            return UINT32
        return INT64
    raise AddressSpaceError(f"signal {spec.name!r}: type {spec.type!r} has no OPC UA data type")


def variable_of(spec: SignalSpec) -> Variable:
    dtype = data_type_of(spec)
    numeric = dtype not in (BOOLEAN, STRING)
    low = (-math.inf if spec.min is None else float(spec.min)) if numeric else None
    high = (math.inf if spec.max is None else float(spec.max)) if numeric else None
    return Variable(spec.name, folder_of(spec), dtype, spec.direction == INPUT, unit_of(spec.unit) if numeric else None,
                    low, high, spec.description, spec)


def build_address_space(signals: Iterable[SignalSpec], station: str) -> AddressSpace:
    """The address space serving `signals`: the cell's whole table, the simulator's own signals included."""
    reserved = set(FOLDERS) | {ADVANCE_METHOD}
    seen: set[str] = set()
    variables = []
    for spec in signals:
        if spec.name in reserved:
            raise AddressSpaceError(f"signal {spec.name!r}: its name is taken by the OPC UA folder or method of that "
                                    "NodeId; rename it")
        if spec.name in seen:
            raise AddressSpaceError(f"signal {spec.name!r} appears twice")
        seen.add(spec.name)
        variables.append(variable_of(spec))
    used = {v.folder for v in variables}
    folders = tuple(f for f in FOLDERS) + tuple(sorted(used - set(FOLDERS)))
    return AddressSpace(station, namespace_uri(station), folders, tuple(variables))
