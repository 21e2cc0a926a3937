"""The client's checks before the wire: names and values against the register map, in engineering units.

The map itself is the one `twin.modbus.register_map.RegisterMap`; what the client adds is how it refuses:
an unknown name gets suggestions (`UnknownSignalError`), a value is checked against the entry's range, or
for an entry without one against its type's (whole numbers for integer types of scale 1, finite float32),
and an output of the twin is not writable. Nothing is clamped or rounded into range.

    signal = lookup(rmap, "axis1.actual")       # the entry, or UnknownSignalError ("did you mean ...?")
    value = check_value(rmap, "axis1", 320.0)   # 320.0, or a SignalValueError naming signal, value and range
"""
from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from twin.modbus.register_map import TYPE_LIMITS, Entry, RegisterMap

from .errors import NotWritableError, SignalValueError, UnknownSignalError, ValueOutOfRangeError

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
    """`check_value` for an entry already looked up (its access not checked)."""
    if s.type == "bool":
        if isinstance(value, bool) or value in (0, 1):
            return bool(value)
        raise SignalValueError(s.name, f"needs true or false (1 or 0), not {value!r}")
    if s.choices and isinstance(value, str):
        if value not in s.choices:
            raise SignalValueError(s.name, f"{value!r} is not one of {', '.join(repr(c) for c in s.choices)}")
        return s.choices.index(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
        raise SignalValueError(s.name, f"needs a number, not {value!r}")
    slack = 1e-9 * max(1.0, abs(s.min or 0.0), abs(s.max or 0.0))  # the map's limits carry 9 decimals: an exact end passes
    if (s.min is not None and value < s.min - slack) or (s.max is not None and value > s.max + slack):
        raise ValueOutOfRangeError(s.name, value, s.min, s.max, s.unit)
    if s.type == "float32":
        if math.isinf(value) or abs(value) > FLOAT32_MAX:
            raise ValueOutOfRangeError(s.name, value, -FLOAT32_MAX if s.min is None else s.min,
                                       FLOAT32_MAX if s.max is None else s.max, s.unit)
        return value
    limits = TYPE_LIMITS.get(s.type)
    if limits is not None:  # the type's own range, for entries without min or max
        if math.isinf(value):
            raise SignalValueError(s.name, f"needs a finite number, not {value!r}")
        counts = value / s.scale
        if s.scale == 1.0 and counts != int(counts):
            raise SignalValueError(s.name, f"needs a whole number ({s.type}), not {value!r}")
        lo_c, hi_c = limits
        if not lo_c <= round(counts) <= hi_c:
            lo = s.min if s.min is not None else _eng(lo_c * s.scale)
            hi = s.max if s.max is not None else _eng(hi_c * s.scale)
            raise ValueOutOfRangeError(s.name, value, lo, hi, s.unit)
    return value


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
