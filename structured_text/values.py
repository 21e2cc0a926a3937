"""Values as a PLC programmer reads them: the trace's JSON values and the texts of typed literals."""
from __future__ import annotations

import datetime as _dt

from . import types as ty
from .rtlib import _np_f32_repr


def time_text(ns: int) -> str:
    """T#1s500ms style."""
    sign = "-" if ns < 0 else ""
    ns = abs(ns)
    parts = []
    for unit, size in (("d", 86_400 * 10**9), ("h", 3_600 * 10**9), ("m", 60 * 10**9), ("s", 10**9),
                       ("ms", 10**6), ("us", 10**3), ("ns", 1)):
        if ns >= size:
            parts.append(f"{ns // size}{unit}")
            ns %= size
    return f"T#{sign}{''.join(parts) or '0s'}"


def json_value(t: ty.DataType, v):
    """A variable's value for the trace: BOOL true/false, integers, REAL as floats, TIME in ms,
    STRING as a string, enumerations by name, DATE/TOD/DT as their literals."""
    k = t.kind
    if k == "bool":
        return bool(v)
    if k in ("int", "bits"):
        return int(v)
    if k == "real":
        if v != v or v in (float("inf"), float("-inf")):
            return "NaN" if v != v else ("Infinity" if v > 0 else "-Infinity")  # JSON has no such numbers
        if t.bits == 32:
            return float(_np_f32_repr(v))
        return float(v)
    if k == "time":
        return v // 10**6 if v % 10**6 == 0 else v / 10**6
    if k == "enum":
        return t.text_of(v)
    if k == "string":
        return v
    epoch = _dt.datetime(1970, 1, 1)
    if k == "date":
        return "D#" + (epoch + _dt.timedelta(microseconds=v // 1000)).strftime("%Y-%m-%d")
    if k == "tod":
        s = (epoch + _dt.timedelta(microseconds=v // 1000)).strftime("%H:%M:%S.%f").rstrip("0").rstrip(".")
        return "TOD#" + s
    if k == "dt":
        s = (epoch + _dt.timedelta(microseconds=v // 1000)).strftime("%Y-%m-%d-%H:%M:%S.%f").rstrip("0").rstrip(".")
        return "DT#" + s
    if k == "array":
        return [json_value(t.elem, x) for x in v]
    if k == "struct":
        return {name: json_value(ft, getattr(v, "v_" + name.lower())) for name, ft, _ in t.fields.values()}
    return repr(v)
