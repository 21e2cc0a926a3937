"""Errors of the PLC client. Raised where the problem is found; the CLI shows them once, as one line.

    TwinError (twin.core.errors)       base of everything gripper-twin raises on purpose: catch it for all
    ├── MapError                       the register map cannot be loaded (names the file and the entry), or
    │                                  the server serves another map; defined once, in
    │                                  twin.frontends.modbus.register_map (`twin map`'s and the server's too),
    │                                  re-exported here
    └── PlcClientError                 base of everything else the client raises on purpose
        ├── UnknownSignalError         a name the map does not have ("did you mean ...?")
        ├── SignalValueError           a value a signal cannot take (SignalSpec.check's refusals; SignalError)
        │   ├── ValueTypeError         not a value of the signal's type (also a SignalTypeError)
        │   ├── ValueOutOfRangeError   outside the signal's range (also a SignalRangeError; names the range)
        │   └── NotWritableError       the signal is an output of the twin
        ├── ModbusExceptionError       the server answered with a Modbus exception (code, address, unit)
        ├── ConnectionFailedError      no server at host:port, or the connection broke
        └── OutputRefusedError         a scan cycle's logic set an output the process refused (names it)

`except TwinError` catches both branches (the `plc` command does that: one line, exit status 2, or 1 for
a connection or a Modbus exception); `except PlcClientError` no longer catches a MapError.
"""
from __future__ import annotations

import difflib
from collections.abc import Iterable

from twin.core.errors import SignalError, SignalRangeError, SignalTypeError, TwinError
from twin.frontends.modbus.protocol import EXCEPTION_NAMES
from twin.frontends.modbus.register_map import MapError

__all__ = ["TwinError", "MapError", "PlcClientError", "UnknownSignalError", "SignalValueError", "ValueTypeError",
           "ValueOutOfRangeError",
           "NotWritableError", "ModbusExceptionError", "ConnectionFailedError", "OutputRefusedError", "EXCEPTION_NAMES"]


class PlcClientError(TwinError):
    """Base class of the PLC client's own errors (a MapError is a TwinError beside it: see the tree above)."""


class UnknownSignalError(PlcClientError, SignalError, KeyError):
    """A signal name that is not in the register map (a SignalError, as the twin's own for a name it lacks)."""

    def __init__(self, name: str, known: Iterable[str] = ()):
        self.signal = name
        self.suggestions = tuple(difflib.get_close_matches(name, list(known), n=3, cutoff=0.6))
        hint = f"; did you mean {self.suggestions[0]!r}?" if self.suggestions else \
            " (`plc map` lists the signals)"
        Exception.__init__(self, f"unknown signal {name!r}{hint}")

    def __str__(self) -> str:  # KeyError would quote the message
        return self.args[0]


class SignalValueError(PlcClientError, SignalError, ValueError):
    """A value a signal cannot take: the refusals of the one write validation (`SignalSpec.check`), raised
    before anything is sent. Each kind is also the twin's own error class, so `except SignalRangeError`
    catches the client's range refusal as it catches the twin's, the exchange's and the page's."""

    def __init__(self, name: str, message: str):
        self.signal = name
        Exception.__init__(self, f"signal {name!r}: {message}")


class ValueTypeError(SignalValueError, SignalTypeError):
    """A value of the wrong type (text for a number, 2 for a bit, NaN, a fraction for a whole number)."""


class ValueOutOfRangeError(SignalValueError, SignalRangeError):
    """A value outside the signal's range (never clamped)."""

    def __init__(self, name: str, value: float, lo: float | None, hi: float | None, unit: str = ""):
        self.value, self.min, self.max, self.unit = value, lo, hi, unit
        u = f" {unit}" if unit else ""
        rng = f"{_g(lo)} to {_g(hi)}{u}" if lo is not None and hi is not None else \
            (f"at least {_g(lo)}{u}" if lo is not None else f"at most {_g(hi)}{u}")
        super().__init__(name, f"{_g(value)}{u} is out of range: {rng}")


class NotWritableError(SignalValueError):
    """A write to a signal the twin computes (an output)."""

    def __init__(self, name: str):
        super().__init__(name, "is an output of the twin and cannot be written")


class ModbusExceptionError(PlcClientError):
    """The server answered a request with a Modbus exception."""

    def __init__(self, code: int, function: int, address: int, count: int, unit: int, signals: Iterable[str] = ()):
        self.code, self.function, self.address, self.count, self.unit = code, function, address, count, unit
        self.signals = tuple(signals)
        what = f" ({', '.join(self.signals)})" if self.signals else ""
        super().__init__(f"Modbus exception {code:02d} ({EXCEPTION_NAMES.get(code, 'unknown')}) for function "
                         f"{function:#04x} at address {address}, count {count}, unit {unit}{what}")


class ConnectionFailedError(PlcClientError):
    """No server answered at host:port, or the connection broke."""

    def __init__(self, host: str, port: int, message: str = "no answer"):
        self.host, self.port = host, port
        super().__init__(f"cannot reach a twin server at {host}:{port}: {message}")


class OutputRefusedError(PlcClientError):
    """The logic of a scan cycle set an output that the process refused (a value out of range, an output of
    the twin, a Modbus exception): the scan cycle stops there, nothing of that output image was written by
    the client's checks (a Modbus exception may have come after part of it was sent)."""

    def __init__(self, outputs: dict, cause: PlcClientError, scan: int, time: float):
        self.outputs, self.cause, self.scan, self.time = dict(outputs), cause, scan, time
        name = getattr(cause, "signal", None)
        names = (name,) if name in self.outputs else tuple(n for n in getattr(cause, "signals", ()) if n in self.outputs)
        shown = {n: self.outputs[n] for n in names} or self.outputs
        what = ", ".join(f"{n}={_g(v)}" for n, v in shown.items())
        s = "" if len(shown) == 1 else "s"
        super().__init__(f"the PLC logic's output{s} {what} refused at scan {scan} (t={time:.3f} s): {cause}")


def _g(v) -> str:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return str(v)
    return str(v) if isinstance(v, int) else f"{v:.10g}"
