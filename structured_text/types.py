"""Data types: the elementary types of IEC 61131-3 with their widths and ranges, and the derived ones.

A value at run time is a Python value: BOOL a bool, the integers and bit strings an int kept in
the declared type's range (wrapped where it is stored), REAL and LREAL a float (REAL rounded to
32 bits where it is stored), TIME, DATE, TIME_OF_DAY and DATE_AND_TIME an int of nanoseconds
(DATE and DT since 1970-01-01), STRING a str, an array a flat list, a structure or an FB instance
an object with one attribute per member.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field


class DataType:
    kind = "?"
    name = "?"

    def __str__(self) -> str:
        return self.name


@dataclass(eq=False)
class Elementary(DataType):
    name: str
    kind: str  # bool, int, bits, real, time, date, tod, dt, string
    bits: int = 0
    signed: bool = False

    @property
    def lo(self) -> int:
        return -(1 << (self.bits - 1)) if self.signed else 0

    @property
    def hi(self) -> int:
        return (1 << (self.bits - 1)) - 1 if self.signed else (1 << self.bits) - 1


def _elem(name, kind, bits=0, signed=False):
    return Elementary(name, kind, bits, signed)


ELEMENTARY: dict[str, Elementary] = {}
for _n, _b in (("SINT", 8), ("INT", 16), ("DINT", 32), ("LINT", 64)):
    ELEMENTARY[_n] = _elem(_n, "int", _b, True)
for _n, _b in (("USINT", 8), ("UINT", 16), ("UDINT", 32), ("ULINT", 64)):
    ELEMENTARY[_n] = _elem(_n, "int", _b, False)
for _n, _b in (("BYTE", 8), ("WORD", 16), ("DWORD", 32), ("LWORD", 64)):
    ELEMENTARY[_n] = _elem(_n, "bits", _b, False)
ELEMENTARY["BOOL"] = _elem("BOOL", "bool", 1)
ELEMENTARY["REAL"] = _elem("REAL", "real", 32, True)
ELEMENTARY["LREAL"] = _elem("LREAL", "real", 64, True)
for _n, _k in (("TIME", "time"), ("LTIME", "time"), ("DATE", "date"), ("LDATE", "date"), ("TIME_OF_DAY", "tod"),
               ("LTIME_OF_DAY", "tod"), ("DATE_AND_TIME", "dt"), ("LDATE_AND_TIME", "dt")):
    ELEMENTARY[_n] = _elem(_n, _k, 64, True)
ALIASES = {"TOD": "TIME_OF_DAY", "DT": "DATE_AND_TIME", "LTOD": "LTIME_OF_DAY", "LDT": "LDATE_AND_TIME"}
for _a, _t in ALIASES.items():
    ELEMENTARY[_a] = ELEMENTARY[_t]

BOOL, INT, DINT, LINT, REAL, LREAL, TIME = (ELEMENTARY[k] for k in ("BOOL", "INT", "DINT", "LINT", "REAL", "LREAL", "TIME"))
ULINT, LWORD = ELEMENTARY["ULINT"], ELEMENTARY["LWORD"]

# An untyped literal takes the type its context needs: `x := 5` for any integer or real x.
LIT_INT = _elem("ANY_INT literal", "int", 64, True)
LIT_REAL = _elem("ANY_REAL literal", "real", 64, True)


@dataclass(eq=False)
class StringT(DataType):
    length: int = 254
    wide: bool = False
    kind = "string"

    @property
    def name(self) -> str:
        return ("WSTRING" if self.wide else "STRING") + (f"[{self.length}]" if self.length != 254 else "")


STRING = StringT()


@dataclass(eq=False)
class ArrayT(DataType):
    dims: list[tuple[int, int]]
    elem: DataType
    kind = "array"

    @property
    def name(self) -> str:
        return "ARRAY[" + ", ".join(f"{a}..{b}" for a, b in self.dims) + f"] OF {self.elem}"

    @property
    def size(self) -> int:
        n = 1
        for a, b in self.dims:
            n *= b - a + 1
        return n


@dataclass(eq=False)
class StructT(DataType):
    name: str
    fields: dict[str, tuple[str, DataType, object]] = field(default_factory=dict)  # UPPER -> (name, type, init)
    kind = "struct"


@dataclass(eq=False)
class EnumT(DataType):
    name: str
    values: dict[str, tuple[str, int]] = field(default_factory=dict)  # UPPER -> (name as written, value)
    kind = "enum"

    def text_of(self, value: int) -> str:
        for name, v in self.values.values():
            if v == value:
                return name
        return str(value)


@dataclass(eq=False)
class SubrangeT(DataType):
    base: Elementary
    lo: int
    hi: int
    kind = "int"

    @property
    def name(self) -> str:
        return f"{self.base.name}({self.lo}..{self.hi})"

    @property
    def bits(self) -> int:
        return self.base.bits

    @property
    def signed(self) -> bool:
        return self.base.signed


@dataclass(eq=False)
class FbT(DataType):
    """A function block type: its members (inputs, outputs, in-outs, locals) by upper-case name."""

    name: str
    members: dict = field(default_factory=dict)  # UPPER -> Symbol
    inputs: list = field(default_factory=list)  # Symbols of VAR_INPUT then VAR_IN_OUT, in order
    builtin: object = None  # the Python class of a standard FB
    pou: object = None
    kind = "fb"


@dataclass(eq=False)
class ProgramT(FbT):
    kind = "program"


def is_numeric(t: DataType) -> bool:
    return t.kind in ("int", "real", "bits")


def is_integer(t: DataType) -> bool:
    return t.kind in ("int", "bits")


def is_anyint_like(t: DataType) -> bool:
    return t.kind in ("int", "bits")


def width(t: DataType) -> int:
    return getattr(t, "bits", 64)


def range_of(t: DataType) -> tuple[int, int]:
    if isinstance(t, SubrangeT):
        return t.lo, t.hi
    return t.lo, t.hi


_F32 = struct.Struct("f")


def to_f32(x: float) -> float:
    """Round a Python float to the nearest 32-bit float (a REAL as a PLC stores it)."""
    try:
        return _F32.unpack(_F32.pack(x))[0]
    except OverflowError:
        return float("inf") if x > 0 else float("-inf")


def wrap(t: DataType, v: int) -> int:
    """An integer wrapped into the type's range, as fixed-width arithmetic does."""
    bits = t.bits
    if t.signed:
        half = 1 << (bits - 1)
        return ((v + half) & ((1 << bits) - 1)) - half
    return v & ((1 << bits) - 1)


def default_value(t: DataType):
    """The standard's initial value of a type (0, FALSE, T#0s, '', the first enumeration value)."""
    if t.kind == "bool":
        return False
    if t.kind == "real":
        return 0.0
    if t.kind == "string":
        return ""
    if isinstance(t, EnumT):
        return next(iter(t.values.values()))[1] if t.values else 0
    if isinstance(t, SubrangeT):
        return t.lo  # the standard: a subrange starts at its lower limit
    return 0


def assignable(target: DataType, value: DataType) -> bool:
    """Whether a value of type `value` may be stored in `target` without an explicit conversion:
    the same type, an untyped literal of the right kind, or a widening (INT into DINT or REAL,
    BYTE into WORD, REAL into LREAL) as IEC 61131-3 3rd edition's implicit conversions allow."""
    if target is value:
        return True
    tk, vk = target.kind, value.kind
    if isinstance(target, SubrangeT):
        return value.kind in ("int", "bits")
    if isinstance(value, SubrangeT):
        value = value.base
        vk = value.kind
    if value is LIT_INT:
        return tk in ("int", "bits", "real")
    if value is LIT_REAL:
        return tk == "real"
    if tk == "bool" or vk == "bool":
        return tk == vk
    if tk in ("int", "bits") and vk in ("int", "bits"):
        if vk == "bits" and tk == "int" or vk == "int" and tk == "bits":
            return target.bits >= value.bits
        if value.signed and not target.signed:
            return False
        return target.bits > value.bits or (target.bits == value.bits and target.signed == value.signed)
    if tk == "real" and vk in ("int", "bits"):
        return True
    if tk == "real" and vk == "real":
        return target.bits >= value.bits
    if tk in ("time", "date", "tod", "dt"):
        return tk == vk
    if tk == "string":
        return vk == "string" and target.wide == value.wide
    if isinstance(target, EnumT):
        return target is value
    if isinstance(target, ArrayT) and isinstance(value, ArrayT):
        return target.dims == value.dims and (target.elem is value.elem or same_type(target.elem, value.elem))
    if isinstance(target, StructT):
        return target is value
    return False


def same_type(a: DataType, b: DataType) -> bool:
    if a is b:
        return True
    if isinstance(a, ArrayT) and isinstance(b, ArrayT):
        return a.dims == b.dims and same_type(a.elem, b.elem)
    if isinstance(a, StringT) and isinstance(b, StringT):
        return a.wide == b.wide
    return False


def common_numeric(a: DataType, b: DataType) -> DataType:
    """The type of `a op b` for numbers: the wider of the two (a literal takes the other's type)."""
    if isinstance(a, SubrangeT):
        a = a.base
    if isinstance(b, SubrangeT):
        b = b.base
    if a is LIT_INT or a is LIT_REAL:
        if b is LIT_INT or b is LIT_REAL:
            return LIT_REAL if LIT_REAL in (a, b) else LIT_INT
        if a is LIT_REAL and b.kind != "real":
            return LREAL
        return b
    if b is LIT_INT or b is LIT_REAL:
        if b is LIT_REAL and a.kind != "real":
            return LREAL
        return a
    if a.kind == "real" or b.kind == "real":
        if a.kind == "real" and b.kind == "real":
            return a if a.bits >= b.bits else b
        return a if a.kind == "real" else b
    if a.bits != b.bits:
        return a if a.bits > b.bits else b
    if a.kind == "bits" or b.kind == "bits":
        return a if a.kind == "bits" else b
    return a if a.signed or not b.signed else b


class OperandError(Exception):
    """The operands do not fit the operator (the checker turns this into an error at the operator)."""


_TIME_ARITH = {
    ("+", "time", "time"): "time", ("-", "time", "time"): "time",
    ("+", "tod", "time"): "tod", ("-", "tod", "time"): "tod", ("-", "tod", "tod"): "time",
    ("+", "dt", "time"): "dt", ("-", "dt", "time"): "dt", ("-", "dt", "dt"): "time",
    ("-", "date", "date"): "time",
}
_BY_KIND = {"time": "TIME", "tod": "TIME_OF_DAY", "dt": "DATE_AND_TIME", "date": "DATE"}


def arith_type(op: str, a: DataType, b: DataType) -> DataType:
    """The type of `a op b` for + - * / MOD **: numbers (the wider type), and the standard's time
    arithmetic (TIME + TIME, TOD - TOD, DT + TIME, TIME * number, TIME / number, ...)."""
    ak, bk = a.kind, b.kind
    times = ("time", "tod", "dt", "date")
    if ak in times or bk in times:
        if (op, ak, bk) in _TIME_ARITH:
            k = _TIME_ARITH[(op, ak, bk)]
            return a if ak == k else ELEMENTARY[_BY_KIND[k]]
        if op in ("*", "/") and ak == "time" and bk in ("int", "real", "bits"):
            return a
        if op == "*" and bk == "time" and ak in ("int", "real", "bits"):
            return b
        raise OperandError(f"'{op}' does not apply to {a} and {b}")
    if not is_numeric(a) or not is_numeric(b):
        raise OperandError(f"'{op}' needs numbers, not {a} and {b}")
    t = common_numeric(a, b)
    if op == "MOD" and t.kind == "real":
        raise OperandError(f"MOD needs integers, not {a} and {b}")
    return t
