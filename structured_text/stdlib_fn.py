"""The standard functions (IEC 61131-3 3rd ed., 6.6.2.5): their typing and the Python each compiles to.

`signature(NAME, arg_types) -> result type` (or a message why the arguments do not fit) is used by
the checker; `generate(NAME, codes, arg_types, result)` by the compiler. One table, both stages.
Conversions `A_TO_B` (and `TO_B`): REAL to an integer rounds to the nearest, halves to even (as
matiec's and the standard's examples do), TRUNC cuts toward zero; integer to integer wraps; TIME (DATE,
TOD, DT) to and from numbers counts seconds, as matiec's library does (the standard leaves the unit to the
implementation): TIME_TO_DINT(T#1500ms) = 1, TIME_TO_REAL(T#1500ms) = 1.5, DINT_TO_TIME(2) = T#2s;
numbers to STRING print as ST literals would.
"""
from __future__ import annotations

import math

from . import types as ty

# formal parameter names, for calls written `LIMIT(MN := 0, IN := x, MX := 10)`
FORMALS = {
    "SEL": ("G", "IN0", "IN1"), "LIMIT": ("MN", "IN", "MX"), "MUX": ("K",), "SHL": ("IN", "N"), "SHR": ("IN", "N"),
    "ROL": ("IN", "N"), "ROR": ("IN", "N"), "LEFT": ("IN", "L"), "RIGHT": ("IN", "L"), "MID": ("IN", "L", "P"),
    "INSERT": ("IN1", "IN2", "P"), "DELETE": ("IN", "L", "P"), "REPLACE": ("IN1", "IN2", "L", "P"),
    "FIND": ("IN1", "IN2"), "EXPT": ("IN1", "IN2"),
}
_LOGIC = {"AND": "&", "OR": "|", "XOR": "^"}
# the 2nd edition's named time functions (still in the 3rd): name -> (operator, argument kinds)
_TIME_FUNCS = {"ADD_TIME": ("+", "time", "time"), "ADD_TOD_TIME": ("+", "tod", "time"), "ADD_DT_TIME": ("+", "dt", "time"),
               "SUB_TIME": ("-", "time", "time"), "SUB_DATE_DATE": ("-", "date", "date"),
               "SUB_TOD_TIME": ("-", "tod", "time"), "SUB_TOD_TOD": ("-", "tod", "tod"),
               "SUB_DT_TIME": ("-", "dt", "time"), "SUB_DT_DT": ("-", "dt", "dt"),
               "MULTIME": ("*", "time", "num"), "DIVTIME": ("/", "time", "num"), "MUL_TIME": ("*", "time", "num"),
               "DIV_TIME": ("/", "time", "num"), "CONCAT_DATE_TOD": ("+", "date", "tod")}
EXTENSIBLE = {"ADD", "MUL", "MAX", "MIN", "CONCAT", "MUX", "GT", "GE", "EQ", "LE", "LT", "AND", "OR", "XOR"}
_MATH1 = {"SQRT": "_sqrt", "LN": "_ln", "LOG": "_log", "EXP": "_exp", "SIN": "_m.sin", "COS": "_m.cos",
          "TAN": "_m.tan", "ASIN": "_asin", "ACOS": "_acos", "ATAN": "_m.atan"}
NAMES = {"ABS", "EXPT", "ADD", "SUB", "MUL", "DIV", "MOD", "MOVE", "SHL", "SHR", "ROL", "ROR", "SEL", "MAX", "MIN",
         "LIMIT", "MUX", "GT", "GE", "EQ", "LE", "LT", "NE", "LEN", "LEFT", "RIGHT", "MID", "CONCAT", "INSERT",
         "DELETE", "REPLACE", "FIND", "TRUNC", "TIME", "ATAN2", "AND", "OR", "XOR"} | set(_TIME_FUNCS) | set(_MATH1)
_DT_KINDS = ("time", "date", "tod", "dt")


class SignatureError(Exception):
    pass


def conversion(name: str) -> tuple[ty.DataType | None, ty.DataType] | None:
    """`INT_TO_REAL` -> (INT, REAL); `TO_REAL` -> (None, REAL); TRUNC_INT / REAL_TRUNC_DINT too."""
    up = name.upper()
    if "BCD" in up:
        return None
    for sep in ("_TO_", "_TRUNC_"):
        if sep in up:
            a, _, b = up.partition(sep)
            src = ty.ELEMENTARY.get(a) or (ty.STRING if a in ("STRING", "WSTRING") else None)
            dst = ty.ELEMENTARY.get(b) or (ty.STRING if b in ("STRING", "WSTRING") else None)
            if src is not None and dst is not None:
                return src, dst
    for prefix in ("TO_", "TRUNC_"):
        if up.startswith(prefix):
            b = up[len(prefix):]
            dst = ty.ELEMENTARY.get(b) or (ty.STRING if b in ("STRING", "WSTRING") else None)
            if dst is not None:
                return None, dst
    return None


def bcd(name: str) -> tuple[str, ty.DataType, ty.DataType | None] | None:
    """`WORD_BCD_TO_INT` / `BCD_TO_INT` -> ("from", WORD|None, INT); `INT_TO_BCD_WORD` / `INT_TO_BCD` -> ("to", ...)."""
    up = name.upper()
    for a, sep, b in (up.partition("_BCD_TO_"), up.partition("_TO_BCD_")):
        if sep and a in ty.ELEMENTARY and b in ty.ELEMENTARY:
            return ("from", ty.ELEMENTARY[a], ty.ELEMENTARY[b]) if sep == "_BCD_TO_" else \
                ("to", ty.ELEMENTARY[a], ty.ELEMENTARY[b])
    if up.startswith("BCD_TO_") and up[7:] in ty.ELEMENTARY:
        return "from", None, ty.ELEMENTARY[up[7:]]
    if up.endswith("_TO_BCD") and up[:-7] in ty.ELEMENTARY:
        return "to", ty.ELEMENTARY[up[:-7]], None
    return None


def is_standard(name: str) -> bool:
    up = name.upper()
    return up in NAMES or conversion(up) is not None or bcd(up) is not None


def _num(t: ty.DataType, what: str) -> None:
    if not ty.is_numeric(t):
        raise SignatureError(f"{what} needs a number, not {t}")


def _common(ts: list[ty.DataType], name: str) -> ty.DataType:
    out = ts[0]
    for t in ts[1:]:
        if out.kind in _DT_KINDS or t.kind in _DT_KINDS or out.kind in ("string", "bool", "enum") or \
                t.kind in ("string", "bool", "enum"):
            if out.kind != t.kind:
                raise SignatureError(f"{name}: arguments of types {out} and {t} do not go together")
            continue
        out = ty.common_numeric(out, t)
    return out


def signature(name: str, ts: list[ty.DataType]) -> ty.DataType:
    up = name.upper()
    b = bcd(up)
    if b:
        if len(ts) != 1 or ts[0].kind not in ("int", "bits"):
            raise SignatureError(f"{name} converts one integer or bit string")
        way, src, dst = b
        if dst is None:  # INT_TO_BCD: the bit string of the same width
            bits = max(8, ts[0].bits if ts[0] is not ty.LIT_INT else 16)
            dst = ty.ELEMENTARY[{8: "BYTE", 16: "WORD", 32: "DWORD", 64: "LWORD"}[bits]]
        return dst
    conv = conversion(up)
    if conv:
        src, dst = conv
        if len(ts) != 1:
            raise SignatureError(f"{name} takes one argument, not {len(ts)}")
        a = ts[0]
        if src is not None and not (ty.assignable(src, a) or a.kind == src.kind or
                                    (a.kind in ("int", "bits") and src.kind in ("int", "bits"))):
            raise SignatureError(f"{name} converts a {src}, not a {a}")
        if "_TRUNC_" in up or up.startswith("TRUNC_"):
            if a.kind != "real":
                raise SignatureError(f"{name} truncates a REAL or LREAL, not a {a}")
        return dst
    n = len(ts)

    def arity(k: int) -> None:
        if n != k:
            raise SignatureError(f"{name} takes {k} argument{'s' if k != 1 else ''}, not {n}")

    if up == "TIME":
        arity(0)
        return ty.TIME
    if up == "TRUNC":
        arity(1)
        if ts[0].kind != "real":
            raise SignatureError(f"TRUNC truncates a REAL or LREAL, not a {ts[0]}")
        return ty.DINT
    if up == "ABS":
        arity(1)
        _num(ts[0], "ABS")
        return ts[0]
    if up in _MATH1:
        arity(1)
        _num(ts[0], up)
        if ts[0] in (ty.LIT_INT, ty.LIT_REAL):
            return ty.LIT_REAL
        return ts[0] if ts[0].kind == "real" else ty.LREAL
    if up == "ATAN2":
        arity(2)
        return ty.LREAL
    if up == "EXPT":
        arity(2)
        _num(ts[0], "EXPT")
        _num(ts[1], "EXPT")
        return ts[0] if ts[0] is not ty.LIT_INT else ty.LREAL if ts[0].kind == "real" else ty.DINT
    if up in ("ADD", "MUL", "SUB", "DIV", "MOD"):
        if up in ("SUB", "DIV", "MOD"):
            arity(2)
        elif n < 2:
            raise SignatureError(f"{up} takes at least two arguments")
        if any(t.kind in _DT_KINDS for t in ts):
            out = ts[0]
            for t in ts[1:]:
                out = ty.arith_type({"ADD": "+", "SUB": "-", "MUL": "*", "DIV": "/", "MOD": "MOD"}[up], out, t)
            return out
        for t in ts:
            _num(t, up)
        out = _common(ts, up)
        if up == "MOD" and out.kind == "real":
            raise SignatureError("MOD needs integers")
        return out
    if up == "MOVE":
        arity(1)
        return ts[0]
    if up in _TIME_FUNCS:
        arity(2)
        op, ka, kb = _TIME_FUNCS[up]
        for t, k in zip(ts, (ka, kb)):
            if (t.kind != k) if k != "num" else not ty.is_numeric(t):
                raise SignatureError(f"{up} takes ({ka.upper()}, {kb.upper()}), not ({ts[0]}, {ts[1]})")
        if up == "CONCAT_DATE_TOD":
            return ty.ELEMENTARY["DATE_AND_TIME"]
        return ty.arith_type(op, ts[0], ts[1])
    if up in _LOGIC:
        if n < 2:
            raise SignatureError(f"{up} takes at least two arguments")
        if all(t.kind == "bool" for t in ts):
            return ty.BOOL
        if all(t.kind in ("bits", "int") for t in ts):
            return _common(ts, up)
        raise SignatureError(f"{up} needs BOOLs or bit strings")
    if up in ("SHL", "SHR", "ROL", "ROR"):
        arity(2)
        if ts[0].kind not in ("bits", "int"):
            raise SignatureError(f"{up} shifts a bit string (BYTE, WORD, DWORD, LWORD), not a {ts[0]}")
        if ts[1].kind not in ("int", "bits"):
            raise SignatureError(f"{up}'s N is an integer, not a {ts[1]}")
        return ts[0] if ts[0] is not ty.LIT_INT else ty.LWORD
    if up == "SEL":
        arity(3)
        if ts[0].kind != "bool":
            raise SignatureError(f"SEL's G is a BOOL, not a {ts[0]}")
        return _common(ts[1:], up)
    if up in ("MAX", "MIN"):
        if n < 2:
            raise SignatureError(f"{up} takes at least two arguments")
        return _common(ts, up)
    if up == "LIMIT":
        arity(3)
        return _common(ts, up)
    if up == "MUX":
        if n < 2:
            raise SignatureError("MUX takes K and at least one input")
        if ts[0].kind not in ("int", "bits"):
            raise SignatureError(f"MUX's K is an integer, not a {ts[0]}")
        return _common(ts[1:], up)
    if up in ("GT", "GE", "EQ", "LE", "LT", "NE"):
        if up == "NE":
            arity(2)
        elif n < 2:
            raise SignatureError(f"{up} takes at least two arguments")
        _common(ts, up)
        return ty.BOOL
    strings = {"LEN": ("s",), "LEFT": ("s", "i"), "RIGHT": ("s", "i"), "MID": ("s", "i", "i"),
               "INSERT": ("s", "s", "i"), "DELETE": ("s", "i", "i"), "REPLACE": ("s", "s", "i", "i"),
               "FIND": ("s", "s")}
    if up in strings:
        want = strings[up]
        arity(len(want))
        for w, t, k in zip(want, ts, range(n)):
            if w == "s" and t.kind != "string":
                raise SignatureError(f"{up}'s argument {k + 1} is a STRING, not a {t}")
            if w == "i" and t.kind not in ("int", "bits"):
                raise SignatureError(f"{up}'s argument {k + 1} is an integer, not a {t}")
        return ty.INT if up in ("LEN", "FIND") else ty.STRING
    if up == "CONCAT":
        if n < 2:
            raise SignatureError("CONCAT takes at least two arguments")
        for t in ts:
            if t.kind != "string":
                raise SignatureError(f"CONCAT joins STRINGs, not a {t}")
        return ty.STRING
    raise SignatureError(f"'{name}' is not a standard function")


def generate(name: str, codes: list[str], ts: list[ty.DataType], result: ty.DataType, site: int) -> str:
    """Python for a call of the standard function `name` on argument code `codes` (already typed)."""
    up = name.upper()
    b = bcd(up)
    if b:
        return stdlib_wrap(result, f"_bcd_{b[0]}({codes[0]}, {site})")
    conv = conversion(up)
    if conv:
        return convert(codes[0], ts[0], result, truncate="TRUNC" in up, site=site)
    c = codes
    if up == "TIME":
        return "_clk.now"
    if up == "TRUNC":
        return f"_rtoi({c[0]}, {-(1 << 31)}, {(1 << 31) - 1}, {site}, True)"
    if up == "ABS":
        return f"abs({c[0]})"
    if up in _MATH1:
        return f"{_MATH1[up]}({c[0]})"
    if up == "ATAN2":
        return f"_m.atan2({c[0]}, {c[1]})"
    if up == "EXPT":
        return f"_expt({c[0]}, {c[1]}, {site})"
    if up == "ADD":
        return "(" + " + ".join(c) + ")"
    if up == "MUL":
        return "(" + " * ".join(c) + ")"
    if up == "SUB":
        return f"({c[0]} - {c[1]})"
    if up in ("DIV", "MOD"):
        return divide(up, c[0], c[1], result, site)
    if up == "MOVE":
        return c[0]
    if up in _TIME_FUNCS:
        op = _TIME_FUNCS[up][0]
        if op == "/":
            return f"_tdiv({c[0]}, {c[1]}, {site})"
        if op == "*" and ts[1].kind == "real":
            return f"_round({c[0]} * {c[1]})"
        return f"({c[0]} {op} {c[1]})"
    if up in _LOGIC:
        if result.kind == "bool":
            if up == "XOR":
                out = c[0]
                for x in c[1:]:
                    out = f"({out} != {x})"
                return out
            return "(" + f" {up.lower()} ".join(c) + ")"
        return "(" + f" {_LOGIC[up]} ".join(c) + ")"
    bits = result.bits if hasattr(result, "bits") and result.kind in ("bits", "int") else 64
    mask = (1 << bits) - 1
    if up in ("SHL", "SHR"):
        return f"_shift({c[0]}, {c[1]}, {mask}, {up == 'SHL'}, {site})"
    if up in ("ROL", "ROR"):
        return f"_rot({c[0]}, {c[1]}, {bits}, {up == 'ROL'})"
    if up == "SEL":
        return f"({c[2]} if {c[0]} else {c[1]})"
    if up == "MAX":
        return f"max({', '.join(c)})"
    if up == "MIN":
        return f"min({', '.join(c)})"
    if up == "LIMIT":
        return f"min(max({c[1]}, {c[0]}), {c[2]})"
    if up == "MUX":
        return f"_mux({c[0]}, ({', '.join(c[1:])},), {site})"
    ops = {"GT": ">", "GE": ">=", "EQ": "==", "LE": "<=", "LT": "<", "NE": "!="}
    if up in ops:
        return "(" + " and ".join(f"({a} {ops[up]} {b})" for a, b in zip(c, c[1:])) + ")"
    if up == "LEN":
        return f"len({c[0]})"
    if up == "LEFT":
        return f"_left({c[0]}, {c[1]})"
    if up == "RIGHT":
        return f"_right({c[0]}, {c[1]})"
    if up == "MID":
        return f"_mid({c[0]}, {c[1]}, {c[2]})"
    if up == "CONCAT":
        return "(" + " + ".join(c) + ")"
    if up == "INSERT":
        return f"_insert({c[0]}, {c[1]}, {c[2]})"
    if up == "DELETE":
        return f"_delete({c[0]}, {c[1]}, {c[2]})"
    if up == "REPLACE":
        return f"_replace({c[0]}, {c[1]}, {c[2]}, {c[3]})"
    if up == "FIND":
        return f"({c[0]}.find({c[1]}) + 1)"
    raise AssertionError(up)


def convert(code: str, src: ty.DataType, dst: ty.DataType, truncate: bool = False, site: int | None = None) -> str:
    """Python converting a value of type src to type dst (`site`: where a REAL out of an integer's range stops)."""
    sk, dk = src.kind, dst.kind
    if dk == "bool":
        return f"({code} != 0)" if sk != "string" else f"({code}.upper() == 'TRUE')"
    if dk in ("int", "bits"):
        if sk == "real":
            if site is not None:
                lo, hi = ty.range_of(dst)
                return f"_rtoi({code}, {lo}, {hi}, {site}, {truncate})"
            inner = f"_trunc({code})" if truncate else f"_round({code})"
        elif sk == "bool":
            return f"int({code})"
        elif sk in _DT_KINDS:
            inner = f"(({code}) // 1000000000)"  # whole seconds (matiec's tv_sec)
        elif sk == "string":
            inner = f"_str_to_int({code})"
        else:
            if src.kind in ("int", "bits") and src is not ty.LIT_INT and ty.range_of(dst)[0] <= ty.range_of(src)[0] \
                    and ty.range_of(src)[1] <= ty.range_of(dst)[1]:
                return code  # a widening: nothing to wrap
            inner = code
        return wrap_code(dst, inner)
    if dk == "real":
        if sk == "string":
            inner = f"float({code})"
        elif sk in _DT_KINDS:
            inner = f"({code} / 1e9)"  # seconds
        else:
            inner = f"float({code})"
            if sk in ("int", "bits", "bool") and src is not ty.LIT_INT and getattr(src, "bits", 64) <= 24:
                return inner  # a REAL holds every value of a 24-bit integer exactly
        return f"_up(_pk({inner}))[0]" if dst.bits == 32 else inner
    if dk in _DT_KINDS:
        if sk == "dt" and dk == "tod":
            return f"(({code}) % 86400000000000)"
        if sk == "dt" and dk == "date":
            return f"(({code}) - ({code}) % 86400000000000)"
        if sk in _DT_KINDS:
            return code
        if sk == "real":
            return f"_round({code} * 1e9)"  # seconds
        return f"({code} * 1000000000)"
    if dk == "string":
        if sk == "string":
            return code
        return f"_to_string({code}, {_kind_tag(src)!r})"
    return code


def _kind_tag(t: ty.DataType) -> str:
    return t.kind if t.kind != "real" else ("real32" if t.bits == 32 else "real")


def wrap_code(t: ty.DataType, code: str) -> str:
    bits = t.bits
    if getattr(t, "signed", False):
        half = 1 << (bits - 1)
        return f"(((({code}) + {half}) & {(1 << bits) - 1}) - {half})"
    return f"(({code}) & {(1 << bits) - 1})"


def divide(op: str, a: str, b: str, result: ty.DataType, site: int) -> str:
    """`a / b` or `a MOD b`: integers truncate toward zero (C's and the standard's rule, not Python's
    floor), MOD takes the dividend's sign; a zero divisor is a runtime error at `site`."""
    if op == "MOD":
        return f"_imod({a}, {b}, {site})"
    if result.kind == "real":
        return f"_fdiv({a}, {b}, {site})"
    if result.kind == "time":
        return f"_tdiv({a}, {b}, {site})"
    return f"_idiv({a}, {b}, {site})"


def stdlib_wrap(t: ty.DataType, code: str) -> str:
    return wrap_code(t, code) if t.kind in ("int", "bits") else code
