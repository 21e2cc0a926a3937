"""Errors raised by the twin core.

    TwinError                 base of everything the core raises on purpose
    ├── StationError          a station file or a model it names is wrong (names file and key)
    ├── MechanismError        a gripper URDF cannot be turned into a mechanism
    ├── SignalError           unknown signal name, or a write to an output
    │   ├── SignalTypeError   a value of the wrong type for the signal (text for a number, NaN, ...)
    │   └── SignalRangeError  a value outside the signal's range (never clamped)
    └── MotionError           the robot cannot reach a target (names the target)

Above the core, `twin.modbus.register_map.MapError` and `plc_client.errors.PlcClientError` derive from
`TwinError` too: `except TwinError` catches everything gripper-twin raises on purpose.
"""
from __future__ import annotations


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
