"""The client's checks before the wire: names and values against the register map, in engineering units.

The map itself is the one `twin.frontends.modbus.register_map.RegisterMap`; a value is checked by the one write
validation, `SignalSpec.check`, on the entry as a signal in engineering units (its range, or for an entry
without one its type's: whole numbers for integer types of scale 1, finite float32). What the client adds
is how it refuses: an unknown name gets suggestions (`UnknownSignalError`), a refusal names the signal and
the range in the map's units (`ValueOutOfRangeError`, `ValueTypeError`: the twin's SignalRangeError and
SignalTypeError), an output of the twin is not writable. Nothing is clamped or rounded into range.

    signal = lookup(rmap, "axis1.actual")       # the entry, or UnknownSignalError ("did you mean ...?")
    value = check_value(rmap, "axis1", 320.0)   # 320.0, or a SignalValueError naming signal, value and range
"""
from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from twin.core.errors import SignalRangeError, SignalTypeError
from twin.core.signals import BOOL, ENUM, FLOAT, INPUT, INT, SignalSpec
from twin.frontends.modbus.register_map import TYPE_LIMITS, Entry, RegisterMap

from .errors import NotWritableError, UnknownSignalError, ValueOutOfRangeError, ValueTypeError

FLOAT32_MAX = 3.4028234663852886e38  # the largest finite IEEE 754 single


def lookup(rmap: RegisterMap, name: str) -> Entry:
    """The map's entry for `name`; UnknownSignalError (with the closest names) when it has none."""
    try:
        return rmap[name]
    except KeyError:
        raise UnknownSignalError(name, rmap.by_name) from None


def check_names(rmap: RegisterMap, names: Iterable[str]) -> list[Entry]:
    """The entries of `names`, in order; the first unknown one raises."""
    return [lookup(rmap, n) for n in names]


def check_value(rmap: RegisterMap, name: str, value: Any) -> Any:
    """`value` for the input `name`, in engineering units, checked against the map (not yet encoded): a
    bool for a bit, the index for an enumeration's text, else the number as given."""
    s = lookup(rmap, name)
    if not s.writable:
        raise NotWritableError(name)
    return check_entry_value(s, value)


def check_entry_value(s: Entry, value: Any) -> Any:
    """`check_value` for an entry already looked up (its access not checked): the one write validation,
    `SignalSpec.check`, on the entry as a signal in engineering units (a bool for a bit, the index for an
    enumeration's text, else the number as checked)."""
    try:
        checked = entry_spec(s).check(value)
    except SignalRangeError as exc:
        raise ValueOutOfRangeError(s.name, value, exc.min if math.isfinite(exc.min) else None,
                                   exc.max if math.isfinite(exc.max) else None, s.unit) from None
    except SignalTypeError as exc:
        raise ValueTypeError(s.name, f"needs {exc.expected}, not {value!r}") from None
    if s.choices:
        return s.choices.index(checked)
    return checked


def entry_spec(s: Entry) -> SignalSpec:
    """A map entry as the signal it carries, in the map's engineering units: its range, else its type's
    (whole numbers for integer types of scale 1, a finite float32)."""
    if s.type == "bool":
        return SignalSpec(s.name, INPUT, BOOL)
    if s.choices:
        return SignalSpec(s.name, INPUT, ENUM, choices=tuple(s.choices))
    lo, hi = s.min, s.max
    limits = TYPE_LIMITS.get(s.type)
    if s.type == "float32":
        lo = -FLOAT32_MAX if lo is None else lo
        hi = FLOAT32_MAX if hi is None else hi
    elif limits is not None:
        lo = _eng(limits[0] * s.scale) if lo is None else lo
        hi = _eng(limits[1] * s.scale) if hi is None else hi
    kind = INT if limits is not None and s.scale == 1.0 else FLOAT
    return SignalSpec(s.name, INPUT, kind, s.unit, lo, hi)


def range_text(s: Entry) -> str:
    """The range as `plc map` prints it: 0/1 for a bit, the choices, or lo..hi in engineering units."""
    if s.type == "bool":
        return "0/1"
    if s.choices:
        return "|".join(c or '""' for c in s.choices)
    lo = "" if s.min is None else f"{s.min:.10g}"
    hi = "" if s.max is None else f"{s.max:.10g}"
    return f"{lo}..{hi}" if (lo or hi) else ""


def _eng(v: float) -> float | int:
    return int(v) if float(v).is_integer() else v
