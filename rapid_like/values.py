"""Values and data types: atomic num/bool/string, records (robtarget, tooldata, ...) and signals.

A num is a Python float, a bool a bool, a string a str. A record is a `Record`: a type name and its
components in declaration order. RAPID data has value semantics, so a record is copied whenever it
is assigned or passed by value (`Record.copy`). An aggregate literal `[...]` has no type of its own;
`coerce` gives it the type of the place it goes to.

A signal used in an expression reads as its present value (a num); passed to a `signaldo` (etc.)
parameter it is a `SignalRef`, so SetDO writes the signal itself.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

NUM, BOOL, STRING = "num", "bool", "string"
STRING_MAX = 80  # characters in a RAPID string (longer: a static error in a literal, else ERR_STRTOOLNG)
# Types whose values are nums (RAPID's aliases of num and dnum, and the enumerations it keeps in them).
NUMERIC = {"num", "dnum", "errnum", "intnum", "dionum", "byte", "errdomain", "errtype", "opnum", "socketstatus",
           "tpnum", "btnres", "icondata", "buttondata", "listitem_type", "event_type", "handler_type", "iounit_state",
           "signalorigin", "sensorstate", "paridnum", "paridvalidnum", "opcalc", "symnum", "uishownum"}
# Types whose values the program can only hold and pass on (no components, no literals); their
# default value is an `Opaque` the instructions that use them fill in.
OPAQUE_TYPES = {"socketdev", "rawbytes", "iodev", "triggdata", "wzstationary", "wztemporary", "shapedata",
                "mecunit", "restartdata", "syncident", "dir", "datapos", "pathrecid", "btnvalue"}
ATOMIC = NUMERIC | {BOOL, STRING}
SIGNAL_TYPES = {"signaldi": "DI", "signaldo": "DO", "signalai": "AI", "signalao": "AO",
                "signalgi": "GI", "signalgo": "GO"}
SIGNAL_KINDS = {v: k for k, v in SIGNAL_TYPES.items()}

_N = NUM
# Record types: component names and types, in order (as in the RAPID manual).
RECORDS: dict[str, list[tuple[str, str]]] = {
    "pos": [("x", _N), ("y", _N), ("z", _N)],
    "orient": [("q1", _N), ("q2", _N), ("q3", _N), ("q4", _N)],
    "pose": [("trans", "pos"), ("rot", "orient")],
    "confdata": [("cf1", _N), ("cf4", _N), ("cf6", _N), ("cfx", _N)],
    "extjoint": [(f"eax_{c}", _N) for c in "abcdef"],
    "robjoint": [(f"rax_{i}", _N) for i in range(1, 7)],
    "robtarget": [("trans", "pos"), ("rot", "orient"), ("robconf", "confdata"), ("extax", "extjoint")],
    "jointtarget": [("robax", "robjoint"), ("extax", "extjoint")],
    "speeddata": [("v_tcp", _N), ("v_ori", _N), ("v_leax", _N), ("v_reax", _N)],
    "zonedata": [("finep", BOOL), ("pzone_tcp", _N), ("pzone_ori", _N), ("pzone_eax", _N),
                 ("zone_ori", _N), ("zone_leax", _N), ("zone_reax", _N)],
    "loaddata": [("mass", _N), ("cog", "pos"), ("aom", "orient"), ("ix", _N), ("iy", _N), ("iz", _N)],
    "tooldata": [("robhold", BOOL), ("tframe", "pose"), ("tload", "loaddata")],
    "inposdata": [("position", _N), ("speed", _N), ("mintime", _N), ("maxtime", _N)],
    # `type` is a stoppoint (inpos 1, stoptime 2, fllwtime 3) and `relation` an opnum: nums here
    "stoppointdata": [("type", _N), ("progsynch", BOOL), ("inpos", "inposdata"), ("stoptime", _N),
                      ("followtime", _N), ("signal", STRING), ("relation", _N), ("checkvalue", _N)],
    "wobjdata": [("robhold", BOOL), ("ufprog", BOOL), ("ufmec", STRING), ("uframe", "pose"),
                 ("oframe", "pose")],
    "tasks": [("taskname", STRING)],
    "listitem": [("image", STRING), ("text", STRING)],
}
BUILTIN_RECORDS = frozenset(RECORDS)
KNOWN_TYPES = ATOMIC | set(RECORDS) | set(SIGNAL_TYPES) | {"clock"} | OPAQUE_TYPES | {"errstr", "stringdig"}


def define_records(decls: list[tuple[str, list[tuple[str, str]]]]) -> None:
    """Make user RECORD types known (lower-case name, [(component, type)]). A program's records replace
    those of a program loaded before it; RAPID's own record types cannot be redefined (the checker
    reports that)."""
    for name, fields in decls:
        if name in BUILTIN_RECORDS:
            continue
        RECORDS[name] = [(f.lower(), t) for f, t in fields]
        KNOWN_TYPES.add(name)


class Opaque:
    """A value of a type the program cannot look into (socketdev, rawbytes, iodev, ...); `state` is
    whatever the instructions that use it keep there. Copies share the state, like a RAPID
    reference to a device."""

    __slots__ = ("type", "state")

    def __init__(self, type_: str, state: object = None):
        self.type, self.state = type_, state

    def copy(self) -> "Opaque":
        """rawbytes are data (copied); devices (socketdev, iodev, ...) are references (shared)."""
        if isinstance(self.state, RawBytes):
            c = RawBytes()
            c.data = bytearray(self.state.data)
            return Opaque(self.type, c)
        return self

    def __eq__(self, other: object) -> bool:
        return self is other

    def __hash__(self) -> int:
        return id(self)


class Record:
    """A value of a record type; components are kept by lower-case name, in declaration order."""

    __slots__ = ("type", "fields")

    def __init__(self, type_: str, fields: dict[str, object]):
        self.type = type_
        self.fields = fields

    def copy(self) -> "Record":
        return Record(self.type, {k: (v.copy() if isinstance(v, (Record, Opaque, Array)) else v)
                                  for k, v in self.fields.items()})

    def values(self) -> list[object]:
        return list(self.fields.values())

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Record) and self.type == other.type and self.fields == other.fields

    def __repr__(self) -> str:
        return format_value(self)


class Clock:
    """A RAPID clock (ClkReset/ClkStart/ClkStop/ClkRead) measuring simulated time, in ns."""

    __slots__ = ("started", "elapsed")

    def __init__(self) -> None:
        self.started: int | None = None
        self.elapsed = 0

    def read(self, now: int) -> float:
        running = now - self.started if self.started is not None else 0
        return (self.elapsed + running) / 1e9

    def copy(self) -> "Clock":
        c = Clock()
        c.started, c.elapsed = self.started, self.elapsed
        return c


class Array(list):
    """An array value: `elem` is the element type; a 2- or 3-dimensional array nests Arrays."""

    def __init__(self, elem: str, items=()):
        super().__init__(items)
        self.elem = elem

    def copy(self) -> "Array":  # type: ignore[override]
        return Array(self.elem, (x.copy() if isinstance(x, (Record, Array, Clock)) else x for x in self))

    @property
    def ndims(self) -> int:
        return 1 + (self[0].ndims if self and isinstance(self[0], Array) else 0)

    def sizes(self) -> list[int]:
        return [len(self)] + (self[0].sizes() if self and isinstance(self[0], Array) else [])


def array_type(elem: str, ndims: int) -> str:
    """The type name of an array: `num{}`, `num{,}`, `num{,,}`."""
    return f"{elem}{{{',' * (ndims - 1)}}}"


def split_array_type(t: str) -> tuple[str, int] | None:
    """(element type, dimensions) of an array type name, None for any other type."""
    if t.endswith("}") and "{" in t:
        elem, dims = t[:-1].split("{", 1)
        return elem, dims.count(",") + 1
    return None


def new_array(elem: str, sizes: list[int]) -> Array:
    if len(sizes) == 1:
        return Array(elem, (default_value(elem) for _ in range(sizes[0])))
    return Array(elem, (new_array(elem, sizes[1:]) for _ in range(sizes[0])))


class Aggregate(list):
    """An untyped aggregate `[...]` before it is given a type."""


@dataclass(frozen=True)
class SignalRef:
    """A configured I/O signal passed as an argument (not its value)."""

    name: str  # as configured
    kind: str  # DI, DO, AI, AO, GI, GO


class TypeMismatch(Exception):
    """Raised by `coerce`; the caller turns it into a positioned CheckError or ExecError."""


def base_type(t: str) -> str:
    if t.endswith("}") and "{" in t:
        elem, dims = t[:-1].split("{", 1)
        return f"{base_type(elem)}{{{dims}}}"
    if t in NUMERIC:
        return NUM
    if t in ("errstr", "stringdig"):
        return STRING
    return t


def default_value(t: str) -> object:
    t = base_type(t)
    if t == NUM:
        return 0.0
    if t == BOOL:
        return False
    if t == STRING:
        return ""
    if t in RECORDS:
        return Record(t, {name: default_value(ft) for name, ft in RECORDS[t]})
    if t == "clock":
        return Clock()
    if t in OPAQUE_TYPES:
        return Opaque(t, RawBytes() if t == "rawbytes" else None)
    raise TypeMismatch(f"no default value for type {t}")


class RawBytes:
    """The contents of a rawbytes: up to 1024 bytes (PackRawBytes, SocketReceive \\RawData ...)."""

    __slots__ = ("data",)

    def __init__(self) -> None:
        self.data = bytearray()


def type_of(v: object) -> str:
    if isinstance(v, bool):
        return BOOL
    if isinstance(v, (int, float)):
        return NUM
    if isinstance(v, str):
        return STRING
    if isinstance(v, Record):
        return v.type
    if isinstance(v, SignalRef):
        return SIGNAL_KINDS[v.kind]
    if isinstance(v, Clock):
        return "clock"
    if isinstance(v, Array):
        return array_type(v.elem, v.ndims)
    if isinstance(v, Aggregate):
        return "aggregate"
    if isinstance(v, Opaque):
        return v.type
    return type(v).__name__


def coerce(v: object, t: str) -> object:
    """`v` as a value of type `t` (aggregates become records); raises TypeMismatch."""
    t = base_type(t)
    if t == NUM:
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            return float(v)
    elif t == BOOL:
        if isinstance(v, bool):
            return v
    elif t == STRING:
        if isinstance(v, str):
            return v
    elif t in RECORDS:
        spec = RECORDS[t]
        if isinstance(v, Record):
            if v.type == t:
                return v.copy()
        elif isinstance(v, Aggregate):
            if len(v) != len(spec):
                raise TypeMismatch(f"{a_(t)} has {len(spec)} components, the aggregate has {len(v)}")
            out = {}
            for (name, ft), item in zip(spec, v):
                try:
                    out[name] = coerce(item, ft)
                except TypeMismatch as e:
                    raise TypeMismatch(f"component {name} of the {t}: {e}") from None
            return Record(t, out)
    elif t == "clock":
        if isinstance(v, Clock):
            return v
    elif t in OPAQUE_TYPES:
        if isinstance(v, Opaque) and v.type == t:
            return v
    elif t in SIGNAL_TYPES:
        if isinstance(v, SignalRef) and v.kind == SIGNAL_TYPES[t]:
            return v
    elif split_array_type(t):
        elem, ndims = split_array_type(t)  # type: ignore[misc]
        if isinstance(v, Array):
            if base_type(v.elem) == base_type(elem) and v.ndims == ndims:
                return v.copy()
        elif isinstance(v, Aggregate):
            inner = elem if ndims == 1 else array_type(elem, ndims - 1)
            out = []
            for i, item in enumerate(v, 1):
                try:
                    out.append(coerce(item, inner))
                except TypeMismatch as e:
                    raise TypeMismatch(f"element {i}: {e}") from None
            return Array(elem, out)
    raise TypeMismatch(f"expected {t}, found {describe_type(v)}")


def describe_type(v: object) -> str:
    if isinstance(v, Aggregate):
        return f"an aggregate of {len(v)} items"
    return type_of(v)


def a_(word: str) -> str:
    """`word` with its indefinite article: "a num", "an orient", "a DO", "an AO"."""
    if not word:
        return word
    if word.isupper() and len(word) <= 3:  # an acronym is read letter by letter: "an AO", "an SI", "a DI"
        return ("an " if word[0] in "AEFHILMNORSX" else "a ") + word
    return ("an " if word[0].lower() in "aeiou" else "a ") + word


def fmt_num(x: float, digits: int = 6) -> str:
    """A num as TPWrite \\Num, ValToStr and messages show it, RAPID's standard format: 6 significant
    digits, a number within 0.000005 of an integer shown as that integer, an exponent when the
    digits do not reach the decimal point (`1.23457E+06`, `9E+09`, `1.5E-05`), never `-0`."""
    if isinstance(x, bool):
        return "TRUE" if x else "FALSE"
    if not math.isfinite(x):
        return "-inf" if x < 0 else "inf" if x > 0 else "nan"
    r = round(x)
    if abs(x - r) < 0.000005:
        x = float(r)
    if x == 0:
        return "0"
    s = f"{x:.{digits}g}"
    if "e" in s:
        mant, exp = s.split("e")
        s = f"{mant}E{int(exp):+03d}"
    return s


def format_value(v: object) -> str:
    """A value as TPWrite / ValToStr show it."""
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, (int, float)):
        return fmt_num(v)
    if isinstance(v, str):
        return v
    if isinstance(v, Record):
        return "[" + ",".join(format_value(x) for x in v.values()) + "]"
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(format_value(x) for x in v) + "]"
    if isinstance(v, SignalRef):
        return v.name
    return str(v)


def json_num(x: float) -> int | float:
    """A num for JSON: integral values as integers (330, not 330.0)."""
    if isinstance(x, bool):
        return int(x)
    if math.isfinite(x) and x == int(x) and abs(x) < 2 ** 53:
        return int(x)
    return round(float(x), 9)


def to_plain(v: object) -> object:
    """A value as plain JSON-able Python data (records as nested lists)."""
    if isinstance(v, bool):
        return v
    if isinstance(v, (int, float)):
        return json_num(v)
    if isinstance(v, Record):
        return [to_plain(x) for x in v.values()]
    return v


def xyz(p: Record) -> tuple[float, float, float]:
    """The components of a pos."""
    return p.fields["x"], p.fields["y"], p.fields["z"]  # type: ignore[return-value]


def pos(x: float, y: float, z: float) -> Record:
    return Record("pos", {"x": x, "y": y, "z": z})


def record(t: str, *items: object) -> Record:
    """Build a record from nested Python lists, e.g. record("pos", 1, 2, 3)."""
    return coerce(Aggregate(_agg(x) for x in items), t)  # type: ignore[return-value]


def _agg(x: object) -> object:
    if isinstance(x, (list, tuple)):
        return Aggregate(_agg(i) for i in x)
    if isinstance(x, int) and not isinstance(x, bool):
        return float(x)
    return x
