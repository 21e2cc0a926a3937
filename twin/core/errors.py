"""The project's one error tree: everything gripper-twin raises for a user's mistake or a plant condition.

    TwinError                     base: `except TwinError` catches all of them (and nothing else)
    ├── UsageError                a command line that cannot work (the `twin`, `rapid`, `plc` commands)
    ├── StationError              a station file or a model it names is wrong (names file and key)
    ├── MechanismError            a gripper URDF cannot be turned into a mechanism
    ├── SignalError               unknown signal name, or a write to an output
    │   ├── SignalTypeError       a value of the wrong type for the signal (text for a number, NaN, ...)
    │   └── SignalRangeError      a value outside the signal's range (never clamped)
    ├── ObjectError               no such object (target, fixture, body) in the station
    └── MotionError               the robot cannot reach a target (names the target)

Defined above the core, where they are found, and deriving from `TwinError` (the core imports none of them):
`twin.runtime.exchange.SimulationFault` (the simulation stopped on an error), `twin.runtime.faults.FaultError` (a plant fault
that cannot act), `twin_app.plugins.LoadError` (a station's plug-in), `twin.observe.recording.RecordingError`,
`twin.frontends.modbus.register_map.MapError`, `twin.frontends.opcua.security.SecurityError`, `twin.frontends.opcua.address_space.
AddressSpaceError`, `twin.frontends.opcua.errors.AdvanceRefused`, `twin_app.campaign.spec.SpecError` (and its
`ExpressionError`), `twin_app.campaign.scenario.ScenarioError`, `rapid_like.errors.RapidError` (FILE:LINE:COL),
`structured_text.errors.StError` (FILE:LINE:COL), `plc_client.errors.PlcClientError`.

The commands print one line for any of them (`one_line`) and exit 2 (a RAPID or ST program: its
`headline()`, FILE:LINE:COL: error: ...). Argument checks of the programming interfaces (a negative drive
limit, a scan cycle of 0 s) stay Python's ValueError, as Python's own functions do.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Span:
    """A position in a user's source file (a RAPID module, a Structured Text program): 1-based line and column.
    Both interpreters' errors carry one and print it as FILE:LINE:COL."""

    file: str
    line: int
    col: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"


class TwinError(Exception):
    """Base class of the twin core's errors."""


class StationError(TwinError):
    """A station file is wrong. The message names the file and the key."""

    def __init__(self, file: str, key: str, message: str):
        self.file, self.key = str(file), key
        super().__init__(f"{file}: {key}: {message}" if key else f"{file}: {message}")


class MechanismError(TwinError):
    """A gripper URDF has no usable mechanism."""


class SignalError(TwinError):
    """A signal name is unknown, or an output was written."""

    def __init__(self, name: str, message: str):
        self.signal = name
        super().__init__(f"signal {name!r}: {message}")


class SignalTypeError(SignalError):
    """A value of the wrong type for a signal (a number for a bool, text for a number, NaN). Rejected."""

    def __init__(self, name: str, value, expected: str):
        self.value, self.expected = value, expected
        super().__init__(name, f"needs {expected}, not {value!r}")


class SignalRangeError(SignalError):
    """A value outside a signal's range. It is rejected, never clamped."""

    def __init__(self, name: str, value: float, lo: float, hi: float, unit: str):
        self.value, self.min, self.max, self.unit = value, lo, hi, unit
        super().__init__(name, f"value {value:g} {unit} is outside the range {lo:g} to {hi:g} {unit}".replace("  ", " "))


class MotionError(TwinError):
    """The robot cannot perform a motion (e.g. an unreachable target)."""

    def __init__(self, target: str, message: str):
        self.target = target
        super().__init__(f"target {target!r}: {message}")


class UsageError(TwinError):
    """A command line that cannot work: the command prints it as one line and exits with status 2."""


class ObjectError(TwinError, KeyError):
    """No such object (target, fixture, body) in a station. Also a KeyError: `Twin.object_pose` raised one
    before it raised this, and a caller may still catch that."""

    def __init__(self, name: str, message: str):
        self.object = name
        super().__init__(f"object {name!r}: {message}")

    def __str__(self) -> str:  # KeyError's would quote the message
        return self.args[0]


def one_line(exc: BaseException) -> str:
    """What a command prints for an error it stops on: one line (a program's error: FILE:LINE:COL: error: ...)."""
    headline = getattr(exc, "headline", None)
    text = headline() if callable(headline) else f"error: {exc}"
    return text.strip().splitlines()[0] if text.strip() else "error"
