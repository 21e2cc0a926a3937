"""The PLC: a compiled program, its process images, its tasks and its clock, scanned in lockstep.

    plc = load(["main.st"])                  # check + compile (StError with FILE:LINE:COL on error)
    plc.write_located("%IX100.0", True)      # the input image, by address
    plc.scan(0.0)                            # one scan at simulated time 0 s
    plc.read_located("%QW100"); plc.get("main.cnt"); plc.set("cnt", 5)

A scan reads the input image into the located input variables, runs the tasks that are due at
`now` (a task of INTERVAL i is due at every multiple of i; higher priority, i.e. lower PRIORITY
number, first; equal priorities in declaration order), then writes the located output and memory
variables to the output and memory images. Time is only ever what the caller passes: the same
inputs at the same times give the same run, bit for bit.

Process images follow OpenPLC's layout: one table per area and size, `%IX100.0` (byte 100, bit 0),
`%IW100` (word 100), `%QD2`, ... A word address is not a byte offset, so %IW0 and %IX0.0 do not overlap.
The images are dicts keyed by the address's canonical text (`address_key`: '%IX100.0'), so a fieldbus
binding may write `plc.inputs` directly; `plc.located()` lists what the program locates. Image words are unsigned
(0..65535); a located signed integer (`AT %IW100 : INT`) takes its word's bits as two's complement.

A run-time error puts the PLC in STOP: `scan` raises PlcFault (FILE:LINE:COL, the task and program
instance) and every later scan raises it again until `cold_restart()` or `warm_restart()`.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Callable

from . import nodes as n
from . import types as ty
from .checker import Program, Symbol, check
from .compiler import Compiled, compile_program
from .errors import PlcFault, StError
from .parser import parse
from .rtlib import Fault
from .values import json_value

DEFAULT_LOOP_BUDGET = 1_000_000  # loop iterations per scan before the scan is called endless
_ADDR = re.compile(r"%([IQM])([XBWDL]?)(\d+(?:\.\d+)*)$", re.I)


def parse_address(text: str) -> tuple[str, str, tuple[int, ...]]:
    m = _ADDR.match(text.strip())
    if not m:
        raise ValueError(f"{text!r} is not a direct address (e.g. %IX0.0, %QW100, %MD4)")
    size = (m.group(2) or "X").upper()
    idx = tuple(int(p) for p in m.group(3).split("."))
    if (size == "X") != (len(idx) == 2) or len(idx) > 2:
        raise ValueError(f"{text!r}: a bit address is %IXbyte.bit, a word address %IWn")
    return m.group(1).upper(), size, idx


def address_key(area: str, size: str, idx: tuple[int, ...]) -> str:
    """The images' key of an address: its canonical text, `%IX100.0`, `%QW2` (a str: its hash is kept)."""
    return f"%{area}{size}{'.'.join(str(i) for i in idx)}"


def read_source(path: str | Path) -> str:
    return Path(path).read_text(encoding="utf-8")


def compile_files(paths: list[str | Path], sources: dict[str, str] | None = None) -> Compiled:
    """Parse, check and compile the files of one PLC program (StError on the first stage that fails; the
    syntax errors of every file together)."""
    from .errors import StaticErrors
    files, errors = [], []
    for p in paths:
        text = sources[str(p)] if sources and str(p) in sources else read_source(p)
        try:
            files.append(parse(text, str(p)))
        except StError as exc:
            errors.append(exc)
    if errors:
        raise errors[0] if len(errors) == 1 else StaticErrors(errors)
    program = check(files)
    return compile_program(program)


def load(paths: list[str | Path], loop_budget: int = DEFAULT_LOOP_BUDGET) -> "Plc":
    return Plc(compile_files(paths), loop_budget)


class Task:
    def __init__(self, name: str, interval: int, priority: int, order: int):
        self.name = name
        self.interval = interval  # ns, 0: every scan
        self.priority = priority
        self.order = order
        self.programs: list[tuple[str, Callable[[], None]]] = []
        self.next_due = 0


class Plc:
    def __init__(self, compiled: Compiled, loop_budget: int = DEFAULT_LOOP_BUDGET):
        self.compiled = compiled
        self.program: Program = compiled.program
        self.ns = compiled.ns
        self.loop_budget = loop_budget
        self.inputs: dict = self.ns["_I"]
        self.outputs: dict = self.ns["_Q"]
        self.memory: dict = self.ns["_M"]
        self.clock = self.ns["_clk"]
        self.budget = self.ns["_rt"]
        self.fault: PlcFault | None = None
        self.scans = 0
        self._slots: dict = {}
        self.trace_hooks: list[Callable[["Plc", float], None]] = []
        self.cold_restart()

    # ---- lifecycle -------------------------------------------------------------------------------
    def cold_restart(self) -> None:
        """Every variable to its initial value (also RETAIN ones); the images cleared; RUN."""
        self.instances = self.compiled.new_instances()
        self.inputs.clear()
        self.outputs.clear()
        self.memory.clear()
        self._build()

    def warm_restart(self) -> None:
        """A power cycle: RETAIN variables keep their values, the others start again from their
        initial values; the tasks start again; the input image is kept (the field still drives it)."""
        kept = self._retained()
        self.instances = self.compiled.new_instances()
        for setter, value in kept:
            setter(value)
        self.outputs.clear()
        self._build()

    def _retained(self) -> list:
        out = []
        G = self.ns["_G"]
        for s in self.program.globals.values():
            if s.retain:
                out.append((lambda v, a=s.attr: setattr(self.ns["_G"], a, v), getattr(G, s.attr)))
        for inst in self.program.instances:
            obj = self.instances[inst.name.upper()]
            self._retained_in(obj, inst.pou.fbtype, out, [inst.name.upper()])
        return out

    def _retained_in(self, obj, fbt: ty.FbT, out: list, path: list[str]) -> None:
        for s in fbt.members.values():
            if s.section in ("VAR_EXTERNAL", "VAR_TEMP", "RESULT"):
                continue
            value = getattr(obj, s.attr)
            if s.retain:
                out.append((self._path_setter(path, s.attr), value))
            elif s.type.kind == "fb" and s.type.pou is not None:
                self._retained_in(value, s.type, out, path + [s.attr])

    def _path_setter(self, path: list[str], attr: str):
        def setter(v):
            obj = self.instances[path[0]]
            for a in path[1:]:
                obj = getattr(obj, a)
            setattr(obj, attr, v)
        return setter

    def _build(self) -> None:
        self.fault = None
        self.scans = 0
        tasks = {t.name.upper(): Task(t.name, t.interval, t.priority, t.order) for t in self.program.tasks}
        self._located_in: list = []
        self._located_out: list = []
        G = self.ns["_G"]
        for s in self.program.globals.values():
            self._locate(G, s)
        for inst in self.program.instances:
            obj = self.instances[inst.name.upper()]
            for s in inst.pou.symbols.values():
                self._locate(obj, s)
            tasks[inst.task.upper()].programs.append((inst.name, self._runner(inst, obj)))
        self.tasks = sorted((t for t in tasks.values() if t.programs), key=lambda t: (t.priority, t.order))
        self._io_in, self._io_out = self._io_code()

    def _io_code(self):
        """Straight-line Python that copies the input and memory images into the located variables, and the
        output and memory variables back: compiled at every (re)start, a few microseconds per scan."""
        env: dict = {"I": self.inputs, "Q": self.outputs, "M": self.memory}
        names: dict[int, str] = {}

        def name(obj) -> str:
            if id(obj) not in names:
                names[id(obj)] = f"o{len(names)}"
                env[names[id(obj)]] = obj
            return names[id(obj)]
        images = {id(self.inputs): "I", id(self.outputs): "Q", id(self.memory): "M"}
        lines_in = [f"    {name(o)}.{a} = {_as_typed(f'{images[id(img)]}[{key!r}]', t)}" for o, a, img, key, t in self._located_in]
        lines_out = [f"    {images[id(img)]}[{key!r}] = {_as_word(f'{name(o)}.{a}', t)}" for o, a, img, key, t in self._located_out]
        src = "def _io_in():\n" + "\n".join(lines_in or ["    pass"]) + "\n" + \
              "def _io_out():\n" + "\n".join(lines_out or ["    pass"]) + "\n"
        exec(compile(src, "<located variables>", "exec"), env)
        return env["_io_in"], env["_io_out"]

    def _locate(self, obj, s: Symbol) -> None:
        if s.location is None:
            return
        area, size, idx = s.location
        key = address_key(area, size, idx)
        image = {"I": self.inputs, "Q": self.outputs, "M": self.memory}[area]
        if area in ("I", "M"):
            self._located_in.append((obj, s.attr, image, key, s.type))
            image.setdefault(key, getattr(obj, s.attr))  # an input never written reads as the initial value
        if area in ("Q", "M"):
            self._located_out.append((obj, s.attr, image, key, s.type))

    def _runner(self, inst, obj) -> Callable[[], None]:
        body = obj._body
        if not inst.binds:
            return body
        G = self.ns["_G"]
        ins = [(p.attr, a.value.ref.attr) for p, a in inst.binds if p.section != "VAR_OUTPUT" and isinstance(a.value, n.Name)]
        outs = [(p.attr, a.value.ref.attr) for p, a in inst.binds if p.section == "VAR_OUTPUT" and isinstance(a.value, n.Name)]

        def run():
            for pa, ga in ins:
                setattr(obj, pa, getattr(G, ga))
            body()
            for pa, ga in outs:
                setattr(G, ga, getattr(obj, pa))
        return run

    # ---- the scan --------------------------------------------------------------------------------
    def scan(self, now: float) -> None:
        """One scan at simulated time `now` (seconds): read inputs, run the due tasks, write outputs."""
        self.scan_ns(round(now * 1e9))

    def scan_ns(self, now_ns: int) -> None:
        if self.fault is not None:
            raise self.fault
        self.clock.now = now_ns
        self._io_in()
        budget = self.budget
        for task in self.tasks:
            if task.interval and now_ns < task.next_due:
                continue
            if task.interval:
                task.next_due = (now_ns // task.interval + 1) * task.interval
            for name, run in task.programs:
                budget.left = self.loop_budget
                try:
                    run()
                except Fault as f:
                    self.fault = PlcFault(f.message, self.compiled.sites.spans[f.site], task.name, name)
                except RecursionError:
                    self.fault = PlcFault("calls nested too deeply (recursion)", None, task.name, name)
                except (OverflowError, ValueError, TypeError, ZeroDivisionError, IndexError, KeyError,
                        AttributeError) as exc:
                    self.fault = PlcFault(_describe(exc), self._where(exc), task.name, name)
                if self.fault is not None:
                    raise self.fault
        self._io_out()
        self.scans += 1
        for hook in self.trace_hooks:
            hook(self, now_ns / 1e9)

    def _where(self, exc: BaseException):
        """The ST statement that was running when Python raised `exc`: its span, from the generated code's line."""
        tb, line = exc.__traceback__, None
        while tb is not None:
            if tb.tb_frame.f_code.co_filename == "<structured text>":
                line = tb.tb_lineno
            tb = tb.tb_next
        return None if line is None else self.compiled.span_of_line(line)

    def base_cycle(self) -> int | None:
        """The greatest common divisor of the task intervals (ns), None when a task runs every scan."""
        from math import gcd
        g = 0
        for t in self.tasks:
            if not t.interval:
                return None
            g = gcd(g, t.interval)
        return g or None

    # ---- images ----------------------------------------------------------------------------------
    def located(self) -> list[tuple[str, str, str]]:
        """(address, variable, type) of every located variable, e.g. ("%IX100.0", "main.start", "BOOL"):
        what a binding to a fieldbus (a Modbus map) maps, checked once before the first scan."""
        out = []

        def text(loc):
            area, size, idx = loc
            return f"%{area}{size}{'.'.join(str(i) for i in idx)}"
        for s in self.program.globals.values():
            if s.location is not None:
                out.append((text(s.location), s.name, s.type.name))
        single = len(self.program.instances) == 1
        for inst in self.program.instances:
            for s in inst.pou.symbols.values():
                if s.location is not None and s.section != "VAR_EXTERNAL":
                    out.append((text(s.location), s.name if single else f"{inst.name}.{s.name}", s.type.name))
        return out

    def _slot(self, address: str):
        """(image, key, mask) of an address, parsed once (a fieldbus binding calls this every scan)."""
        slot = self._slots.get(address)
        if slot is None:
            area, size, idx = parse_address(address)
            image = {"I": self.inputs, "Q": self.outputs, "M": self.memory}[area]
            mask = None if size == "X" else (1 << {"B": 8, "W": 16, "D": 32, "L": 64}[size]) - 1
            slot = self._slots[address] = (image, address_key(area, size, idx), mask)
        return slot

    def read_located(self, address: str):
        image, key, mask = self._slot(address)
        return image.get(key, False if mask is None else 0)

    def write_located(self, address: str, value) -> None:
        image, key, mask = self._slot(address)
        image[key] = bool(value) if mask is None else int(value) & mask

    # ---- variables by name -----------------------------------------------------------------------
    def resolve(self, name: str) -> "VarRef | LocatedRef":
        """`cnt` (the single program's), `main.cnt`, `fb.Q`, `main.arr[2]`, a global, or an address `%IX0.0`."""
        if name.strip().startswith("%"):
            return LocatedRef(self, name.strip())
        return VarRef(self, name)

    def get(self, name: str):
        return self.resolve(name).get()

    def set(self, name: str, value) -> None:
        self.resolve(name).set(value)


class VarRef:
    """A variable of the running PLC by its path; `get()`/`set()` read and write it, `json()` for traces."""

    _PART = re.compile(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*((?:\[[^\]]*\])*)\s*")

    def __init__(self, plc: Plc, name: str):
        self.plc = plc
        self.name = name
        parts = [p for p in re.split(r"\.(?![0-9]+$)|\.(?=[0-9]+$)", name)]
        self.steps: list = []  # ("inst", NAME) | ("global", attr) | ("attr", attr) | ("index", offset) | ("bit", n)
        prog = plc.program
        first, rest = self._split(parts[0])
        up = first.upper()
        t = None
        inst_names = {i.name.upper(): i for i in prog.instances}
        if up in inst_names and (len(parts) > 1 or rest):
            self.steps.append(("inst", up))
            t = inst_names[up].pou.fbtype
            parts = parts[1:]
        elif len(inst_names) >= 1:
            owner = [i for i in prog.instances if up in i.pou.symbols and i.pou.symbols[up].section != "VAR_EXTERNAL"]
            if up in prog.globals and not owner:
                s = prog.globals[up]
                self.steps.append(("global", s.attr))
                t = s.type
                parts = [rest] + parts[1:] if rest else parts[1:]
                self._walk(t, parts, first_done=True)
                return
            if len(owner) == 1 or (owner and len(prog.instances) == 1):
                self.steps.append(("inst", owner[0].name.upper()))
                t = owner[0].pou.fbtype
            else:
                raise KeyError(f"{name!r}: no such variable" if not owner else
                               f"{name!r}: several program instances have it; write INSTANCE.{first}")
        self._walk(t, parts, first_done=False)

    def _split(self, part: str):
        m = self._PART.fullmatch(part)
        if not m:
            raise KeyError(f"{self.name!r}: cannot read this name")
        return m.group(1), m.group(2)

    def _walk(self, t, parts: list[str], first_done: bool) -> None:
        for part in parts:
            if part.strip().isdigit():
                if t.kind not in ("bits", "int"):
                    raise KeyError(f"{self.name!r}: bit access on a {t}")
                self.steps.append(("bit", int(part)))
                t = ty.BOOL
                continue
            if first_done and part.startswith("["):
                field_name, idx = None, part
            else:
                field_name, idx = self._split(part)
            if field_name is not None:
                up = field_name.upper()
                if isinstance(t, ty.StructT) and up in t.fields:
                    self.steps.append(("attr", "v_" + t.fields[up][0].lower()))
                    t = t.fields[up][1]
                elif isinstance(t, ty.FbT) and up in t.members:
                    s = t.members[up]
                    if s.section == "VAR_EXTERNAL":
                        s = s.target
                        self.steps = [("global", s.attr)]
                    else:
                        self.steps.append(("attr", s.attr))
                    t = s.type
                else:
                    raise KeyError(f"{self.name!r}: {t} has no member {field_name!r}")
            for ix in re.findall(r"\[([^\]]*)\]", idx):
                if not isinstance(t, ty.ArrayT):
                    raise KeyError(f"{self.name!r}: a {t} is not an array")
                values = [int(v) for v in ix.split(",")]
                if len(values) != len(t.dims):
                    raise KeyError(f"{self.name!r}: the array has {len(t.dims)} dimensions")
                off, stride = 0, 1
                for v, (lo, hi) in reversed(list(zip(values, t.dims))):
                    if not lo <= v <= hi:
                        raise KeyError(f"{self.name!r}: index {v} out of {lo}..{hi}")
                    off += (v - lo) * stride
                    stride *= hi - lo + 1
                self.steps.append(("index", off))
                t = t.elem
        self.type = t

    def _owner(self):
        obj = None
        for kind, arg in self.steps[:-1]:
            obj = self._step(obj, kind, arg)
        return obj

    def _step(self, obj, kind, arg):
        if kind == "inst":
            return self.plc.instances[arg]
        if kind == "global":
            return getattr(self.plc.ns["_G"], arg)
        if kind == "attr":
            return getattr(obj, arg)
        if kind == "index":
            return obj[arg]
        if kind == "bit":
            return (obj >> arg) & 1 != 0
        raise AssertionError(kind)

    def get(self):
        obj = None
        for kind, arg in self.steps:
            obj = self._step(obj, kind, arg)
        return obj

    def json(self):
        return json_value(self.type, self.get())

    def set(self, value) -> None:
        value = coerce(self.type, value)
        kind, arg = self.steps[-1]
        if kind == "bit":
            parent_steps = self.steps[:-1]
            holder = VarRef.__new__(VarRef)
            holder.plc, holder.steps, holder.name = self.plc, parent_steps, self.name
            word = holder.get()
            word = (word | (1 << arg)) if value else (word & ~(1 << arg))
            holder._set_raw(word)
            return
        self._set_raw(value)

    def _set_raw(self, value) -> None:
        kind, arg = self.steps[-1]
        if kind == "global":
            setattr(self.plc.ns["_G"], arg, value)
            self._sync_located(None, arg, value)
            return
        obj = self._owner()
        if kind == "attr":
            setattr(obj, arg, value)
            self._sync_located(obj, arg, value)
        elif kind == "index":
            obj[arg] = value
        else:
            raise KeyError(f"{self.name!r} cannot be set")

    def _sync_located(self, obj, attr, value) -> None:
        """Setting a located input variable sets its input image too (the next scan reads it from there)."""
        target = obj if obj is not None else self.plc.ns["_G"]
        for o, a, image, key, _ in self.plc._located_in:
            if o is target and a == attr:
                image[key] = value


def _as_typed(word: str, t) -> str:
    """The expression a located input variable reads its image word through: a signed integer (SINT, INT,
    DINT, LINT) takes the word's bits as two's complement, as a PLC's `AT %IW : INT` does (an image holds
    16-bit words 0..65535: 65535 is -1, not 65535, in an INT); every other type takes the word as it is."""
    if getattr(t, "kind", None) != "int" or not t.signed:
        return word
    half = 1 << (t.bits - 1)
    return f"((({word}) + {half}) & {2 * half - 1}) - {half}"


def _as_word(value: str, t) -> str:
    """The expression a located output variable writes its image word through: a signed integer's bits as
    the unsigned word a fieldbus sends (an `AT %QW : INT` holding -1 puts 16#FFFF on the wire), the mirror
    of `_as_typed`; every other type is written as it is."""
    if getattr(t, "kind", None) != "int" or not t.signed:
        return value
    return f"(({value}) & {(1 << t.bits) - 1})"


class LocatedRef:
    """A direct address of the process images (`%IX100.0`, `%QW3`) by its text; `set` on an input address
    writes the input image, which the next scan reads."""

    _TYPES = {"X": "BOOL", "B": "BYTE", "W": "WORD", "D": "DWORD", "L": "LWORD"}

    def __init__(self, plc: Plc, address: str):
        try:
            _, size, _ = parse_address(address)
        except ValueError as exc:
            raise KeyError(str(exc)) from None
        self.plc, self.name = plc, address
        self.type = ty.ELEMENTARY[self._TYPES[size]]

    def get(self):
        return self.plc.read_located(self.name)

    def set(self, value) -> None:
        self.plc.write_located(self.name, coerce(self.type, value))

    def json(self):
        return json_value(self.type, self.get())


def _describe(exc: BaseException) -> str:
    if isinstance(exc, OverflowError):
        return "arithmetic overflow: a REAL beyond +-3.4E38 (or a number too large to convert)"
    if isinstance(exc, ZeroDivisionError):
        return "division by zero"
    return f"a value this runtime cannot compute ({type(exc).__name__}: {exc})"


def coerce(t: ty.DataType, value):
    """A value from outside as a value of type t: text (the command line) must be a literal the type holds
    (ValueError naming what it needs, never a silent wrap); Python values (a binding) are converted."""
    k = t.kind
    if isinstance(value, str):
        return _from_text(t, value)
    if k == "bool":
        return bool(value)
    if k in ("int", "bits"):
        if isinstance(value, float):
            value = round(value)
        if isinstance(t, ty.SubrangeT):
            return int(value)
        return ty.wrap(t, int(value))
    if k == "real":
        return ty.to_f32(float(value)) if t.bits == 32 else float(value)
    if k in ("time", "date", "tod", "dt"):
        return int(value)
    if k == "string":
        return str(value)
    return value


def _from_text(t: ty.DataType, value: str):
    """A literal from the command line as a value of type t (ValueError saying what it needs)."""
    from .lexer import lex
    k = t.kind
    text = value.strip()
    up = text.upper()
    if k == "bool":
        if up.removeprefix("BOOL#") in ("TRUE", "FALSE", "1", "0"):
            return up.removeprefix("BOOL#") in ("TRUE", "1")
        raise ValueError(f"{text!r} is not a BOOL: give TRUE or FALSE")
    if k == "string":
        return text[1:-1] if len(text) >= 2 and text[0] == text[-1] == "'" else text
    if k == "enum":
        v = t.values.get(up.split("#")[-1])
        if v is None:
            raise ValueError(f"{text!r} is not a value of {t.name}")
        return v[1]
    try:
        toks = lex(text, "<value>")
    except StError as exc:
        raise ValueError(f"{text!r}: {exc.message}") from None
    neg = False
    if len(toks) == 3 and toks[0].is_op("-", "+"):
        neg = toks[0].text == "-"
        toks = toks[1:]
    if len(toks) != 2 or toks[0].value is None:
        raise ValueError(f"{text!r} is not a value")
    lit = toks[0].value
    value = -lit.value if neg else lit.value
    cat = lit.category
    if k in ("int", "bits"):
        if cat != "int":
            raise ValueError(f"{text!r} is not an integer ({t} needs one)")
        lo, hi = ty.range_of(t)
        if not lo <= value <= hi:
            raise ValueError(f"{text} is out of the range of {t} ({lo}..{hi})")
        return value
    if k == "real":
        if cat not in ("int", "real"):
            raise ValueError(f"{text!r} is not a number ({t} needs one)")
        return ty.to_f32(float(value)) if t.bits == 32 else float(value)
    if k in ("time", "date", "tod", "dt"):
        if cat != k:
            raise ValueError(f"{text!r} is not a {t} literal (e.g. T#200ms, D#2024-01-31, TOD#12:00:00)")
        return value
    raise ValueError(f"{text!r} cannot be given to a {t}")
