"""What compiled Structured Text calls at run time: arithmetic with the standard's rules, checks that
stop the PLC with the place (a site number into the program's span table), string functions.
"""
from __future__ import annotations

import math as _m
import struct

from .errors import PlcFault

_F32 = struct.Struct("<f")
_pack, _unpack = _F32.pack, _F32.unpack


class Sites:
    """The spans of the program's run-time checks, by site number."""

    def __init__(self):
        self.spans: list = []

    def add(self, span) -> int:
        self.spans.append(span)
        return len(self.spans) - 1


class Fault(Exception):
    """Raised by compiled code; the runtime turns it into a PlcFault naming the task."""

    def __init__(self, message: str, site: int):
        super().__init__(message)
        self.message = message
        self.site = site


class Budget:
    """Loop iterations left in this scan: a scan that does not end is stopped, not waited for."""

    __slots__ = ("left",)

    def __init__(self):
        self.left = 0


_pk = _pack
_up = _unpack


def _f32(x):
    try:
        return _unpack(_pack(x))[0]
    except OverflowError:
        return _m.inf if x > 0 else -_m.inf


def _rtoi(x, lo, hi, site, truncate=False):
    """REAL to an integer type: to the nearest (halves to even) or toward zero; out of the type's range
    (or NaN) is a runtime error, not a wrapped number."""
    if x != x or not lo - 1 < x < hi + 1:
        raise Fault(f"{x!r} does not fit the integer type ({lo}..{hi})", site)
    v = int(x) if truncate else round(x)
    if not lo <= v <= hi:
        raise Fault(f"{x!r} does not fit the integer type ({lo}..{hi})", site)
    return v


def _shift(x, n, mask, left, site):
    if n < 0:
        raise Fault(f"{'SHL' if left else 'SHR'} by a negative count ({n})", site)
    return (x << n) & mask if left else (x & mask) >> n


def _round(x):
    """REAL to integer: to the nearest, halves to the even neighbour."""
    if x != x or x in (_m.inf, -_m.inf):
        return 0
    return round(x)


def _trunc(x):
    if x != x or x in (_m.inf, -_m.inf):
        return 0
    return int(x)


def _idiv(a, b, site):
    if b == 0:
        raise Fault("division by zero", site)
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b >= 0) else -q


def _imod(a, b, site):
    if b == 0:
        return 0  # the standard: IF IN2 = 0 THEN OUT := 0
    q = abs(a) // abs(b)
    return a - (q if (a >= 0) == (b >= 0) else -q) * b


def _fdiv(a, b, site):
    if b == 0:
        raise Fault("division by zero", site)
    return a / b


def _tdiv(a, b, site):
    if b == 0:
        raise Fault("division by zero", site)
    if isinstance(b, float):
        return _round(a / b)
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b >= 0) else -q


def _expt(a, b, site):
    try:
        if isinstance(a, int) and isinstance(b, int) and not isinstance(a, bool):
            if b < 0:
                if a == 0:
                    raise Fault("division by zero (0 ** negative)", site)
                return _trunc(a ** b)
            return a ** b
        r = float(a) ** b
        return _m.nan if isinstance(r, complex) else r  # a negative base to a fractional power: invalid
    except OverflowError:
        return _m.inf
    except ZeroDivisionError:
        raise Fault("division by zero (0 ** negative)", site) from None


def _sqrt(x):
    return _m.sqrt(x) if x >= 0 else _m.nan


def _ln(x):
    return _m.log(x) if x > 0 else (-_m.inf if x == 0 else _m.nan)


def _log(x):
    return _m.log10(x) if x > 0 else (-_m.inf if x == 0 else _m.nan)


def _exp(x):
    try:
        return _m.exp(x)
    except OverflowError:
        return _m.inf


def _asin(x):
    return _m.asin(x) if -1 <= x <= 1 else _m.nan


def _acos(x):
    return _m.acos(x) if -1 <= x <= 1 else _m.nan


def _rot(x, n, bits, left):
    mask = (1 << bits) - 1
    x &= mask
    n %= bits
    if not left:
        n = (bits - n) % bits
    return ((x << n) | (x >> (bits - n))) & mask


def _mux(k, values, site):
    if 0 <= k < len(values):
        return values[k]
    raise Fault(f"MUX selector K = {k} is out of 0..{len(values) - 1}", site)


def _ix(i, lo, hi, site):
    if lo <= i <= hi:
        return i - lo
    raise Fault(f"array index {i} is out of bounds {lo}..{hi}", site)


def _subrange(v, lo, hi, site):
    if lo <= v <= hi:
        return v
    raise Fault(f"value {v} is out of the subrange {lo}..{hi}", site)


def _endless(site):
    raise Fault("the scan does not end: the loop ran past the scan's budget of iterations (an endless loop?)", site)


def _bcd_from(v, site):
    """A BCD-coded bit string to its number (16#1234 -> 1234); a nibble above 9 is an error."""
    out, mul = 0, 1
    while v:
        d = v & 15
        if d > 9:
            raise Fault(f"not a BCD value: a digit {d} (16#{d:X})", site)
        out += d * mul
        v >>= 4
        mul *= 10
    return out


def _bcd_to(v, site):
    """A number to its BCD code (1234 -> 16#1234); a negative number is an error."""
    if v < 0:
        raise Fault(f"{v} has no BCD code (negative)", site)
    out, shift = 0, 0
    while v:
        out |= (v % 10) << shift
        v //= 10
        shift += 4
    return out


def _left(s, n):
    return s[:max(0, n)]


def _right(s, n):
    return s[len(s) - n:] if n > 0 else ""


def _mid(s, n, p):
    p = max(1, p)
    return s[p - 1:p - 1 + max(0, n)]


def _insert(s1, s2, p):
    return s1[:max(0, p)] + s2 + s1[max(0, p):]


def _delete(s, n, p):
    p = max(1, p)
    return s[:p - 1] + s[p - 1 + max(0, n):]


def _replace(s1, s2, n, p):
    p = max(1, p)
    return s1[:p - 1] + s2 + s1[p - 1 + max(0, n):]


def _str_to_int(s):
    try:
        return int(s.strip().replace("_", ""), 0) if s.strip()[:2].lower() in ("0x",) else int(float(s.strip()))
    except ValueError:
        return 0


def _to_string(v, kind):
    if kind == "bool":
        return "TRUE" if v else "FALSE"
    if kind == "real32":
        return repr(float(_np_f32_repr(v)))
    if kind == "time":
        from .values import time_text
        return time_text(v)
    return str(v)


def _np_f32_repr(v):
    """The shortest decimal that reads back as the same 32-bit float."""
    for digits in range(1, 10):
        text = f"{v:.{digits}g}"
        if _f32(float(text)) == v:
            return text
    return repr(v)


def _deep(v):
    if isinstance(v, list):
        return [_deep(x) for x in v] if v and isinstance(v[0], (list, StructBase)) else v[:]
    if isinstance(v, StructBase):
        return v._copy()
    return v


class StructBase:
    __slots__ = ()

    def _copy(self):
        new = object.__new__(type(self))
        for k in self.__slots__:
            setattr(new, k, _deep(getattr(self, k)))
        return new


HELPERS = {name: obj for name, obj in globals().items() if name.startswith("_") and callable(obj)
           and not name.startswith("__")}
HELPERS["_pk"], HELPERS["_up"] = _pack, _unpack
HELPERS["_m"] = _m
