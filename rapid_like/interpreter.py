"""The evaluator: runs a checked Module as a tree of Python generators, one per running statement.

Nothing here blocks, sleeps or knows the wall clock. A statement that has to wait *yields* a `Wait`
to whoever drives the generator (the Controller) and is resumed on a later tick with the clock
advanced; expressions are evaluated synchronously. Loops that consumed no time during an iteration
yield a "step" wait on their back edge, so `WHILE TRUE DO ENDWHILE` hands control back every tick
instead of hanging the cell.

Errors and ERROR handlers: every statement runs inside a guard. A runtime error (ExecError) in a
statement of routine R transfers control to R's ERROR handler with ERRNO set; the handler's RETRY
re-runs that statement, TRYNEXT goes on after it, RETURN leaves R, RAISE passes the error to the
caller's handler. A routine without a handler passes the error to its caller. An error with no
handler up the call chain, an error inside a handler, or a handler that reaches its end without
one of those words stops the program (the system error handler).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Generator

from . import builtins as B
from . import nodes as n
from .errors import ExecError, Span
from .host import Host, MotionRequest, SignalInfo
from .values import (RECORDS, SIGNAL_TYPES, Aggregate, Record, SignalRef, TypeMismatch, base_type, coerce,
                     default_value, describe_type, fmt_num, format_value, json_num)

NS = 1_000_000_000


def to_ns(seconds: float) -> int:
    return int(round(seconds * NS))


@dataclass
class Wait:
    """What a suspended program waits for.

    kind "time" / "poll": resume at the first tick with now >= at.
    kind "step": a time-less loop iteration; resume at the next tick (or at `at` when set).
    kind "signal" / "motion": re-evaluate on every tick; `at` (a timeout) is only a hint for
    event-driven runners: nothing changes before `at` unless a signal does.
    kind "stop": the program executed Stop; it waits for resume() or start().
    """

    kind: str
    at: int | None = None
    what: str = ""
    span: Span | None = None


# ---- control-flow signals (exceptions that are not errors) ------------------------------------
class ReturnSignal(Exception):
    def __init__(self, value: object = None):
        self.value = value


class ExitSignal(Exception):
    """EXIT: the program ends."""


class RetrySignal(Exception):
    pass


class TryNextSignal(Exception):
    pass


class Propagate(Exception):
    """An error on its way to the caller's ERROR handler (passes through this routine's guards)."""

    def __init__(self, error: ExecError):
        self.error = error


class Fatal(Exception):
    """An error for the system error handler: the program stops with this error."""

    def __init__(self, error: ExecError):
        self.error = error


# ---- storage -----------------------------------------------------------------------------------
class Cell:
    """A variable, persistent, constant or parameter. `value is ABSENT` for a missing optional."""

    __slots__ = ("type", "value", "storage", "name")

    def __init__(self, type_: str, value: object, storage: str = "VAR", name: str = ""):
        self.type, self.value, self.storage, self.name = type_, value, storage, name

    def get(self) -> object:
        return self.value

    def set(self, v: object) -> None:
        self.value = v


ABSENT = object()


class Ref:
    """A reference to a variable or one of its components (an INOUT argument, an assignment target)."""

    __slots__ = ("cell", "path", "type", "name")

    def __init__(self, cell, path: list[str], type_: str, name: str):
        self.cell, self.path, self.type, self.name = cell, path, type_, name

    @property
    def storage(self) -> str:
        return "VAR"

    def get(self) -> object:
        v = self.cell.get()
        for k in self.path:
            v = v.fields[k]  # type: ignore[union-attr]
        return v

    def set(self, v: object) -> None:
        if not self.path:
            self.cell.set(v)
            return
        obj = self.cell.get()
        for k in self.path[:-1]:
            obj = obj.fields[k]  # type: ignore[union-attr]
        obj.fields[self.path[-1]] = v  # type: ignore[union-attr]


@dataclass
class Frame:
    routine: n.Routine
    vars: dict[str, object] = field(default_factory=dict)
    in_handler: bool = False
    error: ExecError | None = None


def _component_type(t: str, path: list[str]) -> str:
    for k in path:
        t = dict(RECORDS[base_type(t)])[k]
    return t


class Interpreter:
    def __init__(self, module: n.Module, host: Host, emit: Callable[[dict], None] | None = None):
        self.module = module
        self.host = host
        self.emit = emit or (lambda ev: None)
        self.signals: dict[str, SignalInfo] = {s.name.lower(): s for s in host.signals()}
        self.routines = {r.key: r for r in module.routines}
        self.predefined = {k: Cell(t, v, "CONST", k) for k, (t, v) in B.predefined_data().items()}
        self.globals: dict[str, Cell] = {}
        self.predefined_vars: dict[str, Cell] = {}
        self.now = 0  # ns, set by the controller before every resume
        self.suspensions = 0  # bumped by the controller each time the program stays suspended over a tick
        self.errno = 0.0
        self.pulses: list[tuple[int, str, float]] = []  # scheduled writes: (due ns, signal, value)
        self.next_user_errno = B.USER_ERRNO_BASE

    # ---- set-up ---------------------------------------------------------------------------------
    def init_data(self, keep_pers: bool = False) -> None:
        """(Re)initialise module data. PERS data keep their values when `keep_pers`."""
        old = self.globals
        self.globals = {}
        self.predefined_vars = {k: Cell(t, default_value(t), "VAR", k) for k, t in B.PREDEFINED_VARS.items()}
        top = Frame(n.Routine(self.module.span, "PROC", "<module>", [], []))
        for d in self.module.data:
            if keep_pers and d.storage == "PERS" and d.key in old:
                self.globals[d.key] = old[d.key]
                continue
            value = self.coerce(self.eval(d.init, top), d.type, d.init.span) if d.init else default_value(d.type)
            self.globals[d.key] = Cell(d.type, value, d.storage, d.name)

    def run(self, entry: str) -> Generator[Wait, None, None]:
        r = self.routines[entry.lower()]
        yield from self.invoke(r, Frame(r))

    # ---- helpers --------------------------------------------------------------------------------
    def fail(self, message: str, span: Span | None, errname: str = "") -> ExecError:
        """A runtime error; with an error name, ERROR handlers see it as ERRNO (e.g. ERR_DIVZERO)."""
        text = f"{message} ({errname})" if errname else message
        return ExecError(text, span, B.ERRORS.get(errname, 0), errname)

    def coerce(self, v: object, t: str, span: Span) -> object:
        try:
            return coerce(v, t)
        except TypeMismatch as e:
            raise self.fail(f"type mismatch: {e}", span) from None

    def write(self, sig: SignalRef, value: float, span: Span | None = None) -> None:
        if sig.kind == "GO" and value != int(value):
            raise self.fail(f"a group output takes whole numbers, not {fmt_num(value)}", span)
        if sig.kind in ("DO",) and value not in (0, 1):
            raise self.fail(f"a digital output is 0 or 1, not {fmt_num(value)}", span)
        self.host.write_signal(sig.name, float(value))
        self.emit({"type": sig.kind, "signal": sig.name, "value": json_num(float(value))})

    def apply_pulses(self) -> None:
        """Write the pulse edges that are due (called by the controller at the start of a tick)."""
        due = [p for p in self.pulses if p[0] <= self.now]
        if not due:
            return
        self.pulses = [p for p in self.pulses if p[0] > self.now]
        for _, name, value in sorted(due):
            info = self.signals[name.lower()]
            self.host.write_signal(info.name, value)
            self.emit({"type": info.kind, "signal": info.name, "value": json_num(value)})

    # ---- routines -------------------------------------------------------------------------------
    def invoke(self, r: n.Routine, frame: Frame):
        """Run a routine body; an error it does not handle is raised again at the call."""
        try:
            yield from self.block(r.body, frame)
        except ReturnSignal as rs:
            return rs.value
        except Propagate as p:
            raise p.error from None
        if r.kind == "FUNC":
            raise self.fail(f"FUNC {r.name} ended without RETURN", r.span, "ERR_FNCNORET")
        return None

    def bind(self, r_name: str, params: list[n.Param], args: list[n.Arg], f: Frame, span: Span,
             frame: Frame) -> None:
        bound, msg, bad = B.match_args(params, args)
        if msg:
            raise self.fail(f"{r_name}: {msg}", bad.span if bad else span)
        for p in params:
            for q in [p, *p.alternatives]:
                a = bound.get(q.key)
                if a is None:
                    frame.vars[q.key] = Cell(q.type, ABSENT if q.optional else None, "VAR", q.name)
                elif q.type == "switch":
                    frame.vars[q.key] = Cell("switch", True, "CONST", q.name)
                elif q.type in SIGNAL_TYPES:
                    frame.vars[q.key] = Cell(q.type, self.signal_arg(a.value, f, SIGNAL_TYPES[q.type]), "CONST",
                                             q.name)
                elif q.mode in ("INOUT", "VAR", "PERS"):
                    frame.vars[q.key] = self.lvalue(a.value, f)
                else:
                    frame.vars[q.key] = Cell(q.type, self.coerce(self.eval(a.value, f), q.type, a.value.span),
                                             "VAR", q.name)

    def call_function(self, e: n.Call, f: Frame) -> object:
        key = e.key
        r = self.routines.get(key)
        if r is not None:
            frame = Frame(r)
            self.bind(r.name, r.params, e.args, f, e.span, frame)
            gen = self.invoke(r, frame)
            try:
                while True:
                    w = next(gen)
                    if w.kind != "step":
                        gen.close()
                        raise self.fail(f"FUNC {r.name} cannot wait ({w.what or w.kind}): only a PROC can",
                                        w.span or e.span)
            except StopIteration as stop:
                return self.coerce(stop.value, r.return_type or "num", e.span)
        return self.builtin_function(e, f)

    # ---- statements -----------------------------------------------------------------------------
    def block(self, stmts: list[n.Stmt], f: Frame):
        for s in stmts:
            yield from self.guarded(s, f)

    def guarded(self, s: n.Stmt, f: Frame):
        quick_retries = 0
        while True:
            mark = self.suspensions
            try:
                yield from self.stmt(s, f)
                return
            except ExecError as err:
                if err.span is None:  # raised by the host (e.g. a setpoint out of range): blame the statement
                    err.span = s.span
                if f.in_handler:
                    raise Fatal(err) from None
                if f.routine.error_handler is None:
                    raise Propagate(err) from None
                action = yield from self.handler(f, err)
                if action == "trynext":
                    return
                if self.suspensions == mark:
                    # RETRY is immediate, but a statement retried again and again without time
                    # passing costs one step per retry, so a RETRY loop cannot hang the cell.
                    quick_retries += 1
                    if quick_retries > 1:
                        yield Wait("step", what="RETRY")
                else:
                    quick_retries = 0

    def handler(self, f: Frame, err: ExecError):
        self.errno = float(err.errno)
        f.in_handler, f.error = True, err
        try:
            yield from self.block(f.routine.error_handler or [], f)
        except RetrySignal:
            return "retry"
        except TryNextSignal:
            return "trynext"
        finally:
            f.in_handler = False
        raise Fatal(err)

    def stmt(self, s: n.Stmt, f: Frame):
        if isinstance(s, n.ProcCall):
            yield from self.proc_call(s, f)
        elif isinstance(s, n.Assign):
            ref = self.lvalue(s.target, f)
            ref.set(self.coerce(self.eval(s.value, f), ref.type, s.value.span))
        elif isinstance(s, n.If):
            for cond, body in s.branches:
                if self.truth(cond, f):
                    yield from self.block(body, f)
                    return
            if s.orelse is not None:
                yield from self.block(s.orelse, f)
        elif isinstance(s, n.While):
            while True:
                mark = self.suspensions
                if not self.truth(s.cond, f):
                    return
                yield from self.block(s.body, f)
                if self.suspensions == mark:
                    yield Wait("step", what="WHILE")
        elif isinstance(s, n.For):
            yield from self.for_loop(s, f)
        elif isinstance(s, n.Test):
            subject = self.eval(s.subject, f)
            for values, body in s.cases:
                for v in values:
                    if self.equal(subject, self.eval(v, f), v.span):
                        yield from self.block(body, f)
                        return
            if s.default is not None:
                yield from self.block(s.default, f)
        elif isinstance(s, n.LocalDecl):
            d = s.decl
            value = self.coerce(self.eval(d.init, f), d.type, d.init.span) if d.init else default_value(d.type)
            f.vars[d.key] = Cell(d.type, value, d.storage, d.name)
        elif isinstance(s, n.Return):
            value = None
            if s.value is not None:
                value = self.coerce(self.eval(s.value, f), f.routine.return_type or "num", s.value.span)
            raise ReturnSignal(value)
        elif isinstance(s, n.Exit):
            raise ExitSignal()
        elif isinstance(s, n.Retry):
            raise RetrySignal()
        elif isinstance(s, n.TryNext):
            raise TryNextSignal()
        elif isinstance(s, n.Raise):
            if s.errno is None:
                raise Propagate(f.error or self.fail("RAISE without an active error", s.span))
            no = self.eval(s.errno, f)
            err = ExecError(f"error {fmt_num(no)} raised", s.span, int(no), B.ERR_NAMES.get(int(no), ""))
            if f.in_handler:
                raise Propagate(err)
            raise err
        if False:  # pragma: no cover - keeps this a generator for every statement
            yield

    def for_loop(self, s: n.For, f: Frame):
        start = self.num(s.start, f)
        stop = self.num(s.stop, f)
        step = self.num(s.step, f) if s.step is not None else (1.0 if start <= stop else -1.0)
        if step == 0:
            raise self.fail("FOR loop STEP is 0", s.step.span if s.step else s.span)
        key = s.var.lower()
        cell = Cell("num", start, "CONST", s.var)
        f.vars[key] = cell
        try:
            i = start
            while (i <= stop) if step > 0 else (i >= stop):
                mark = self.suspensions
                cell.value = i
                yield from self.block(s.body, f)
                if self.suspensions == mark:
                    yield Wait("step", what="FOR")
                i += step
        finally:
            f.vars.pop(key, None)

    # ---- expressions ----------------------------------------------------------------------------
    def truth(self, e: n.Expr, f: Frame) -> bool:
        v = self.eval(e, f)
        if not isinstance(v, bool):
            raise self.fail(f"type mismatch: expected bool, found {describe_type(v)}", e.span)
        return v

    def num(self, e: n.Expr, f: Frame) -> float:
        v = self.eval(e, f)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise self.fail(f"type mismatch: expected num, found {describe_type(v)}", e.span)
        return float(v)

    def lookup(self, name: str, f: Frame, span: Span):
        key = name.lower()
        if key in f.vars:
            return f.vars[key]
        if key in self.globals:
            return self.globals[key]
        if key in self.predefined:
            return self.predefined[key]
        if key in self.predefined_vars:
            return self.predefined_vars[key]
        if key in self.signals:
            s = self.signals[key]
            return Cell(SIGNAL_KINDS_T[s.kind], SignalRef(s.name, s.kind), "CONST", s.name)
        if key == "errno":
            return Cell("errnum", self.errno, "CONST", "ERRNO")
        raise self.fail(f"undefined name '{name}'", span)

    def eval(self, e: n.Expr, f: Frame) -> object:
        if isinstance(e, (n.NumLit, n.StrLit, n.BoolLit)):
            return e.value
        if isinstance(e, n.Name):
            cell = self.lookup(e.name, f, e.span)
            v = cell.get()
            if v is ABSENT:
                raise self.fail(f"optional argument {e.name} is not present (test it with Present({e.name}))",
                                e.span, "ERR_ARGNOTPER")
            if isinstance(v, SignalRef):
                return float(self.host.read_signal(v.name))
            if isinstance(v, Record):
                return v.copy()
            return v
        if isinstance(e, n.Component):
            obj = self.eval(e.obj, f)
            if not isinstance(obj, Record) or e.field.lower() not in obj.fields:
                raise self.fail(f"{describe_type(obj)} has no component '{e.field}'", e.field_span)
            return obj.fields[e.field.lower()]
        if isinstance(e, n.Aggregate):
            return Aggregate(self.eval(i, f) for i in e.items)
        if isinstance(e, n.Unary):
            v = self.eval(e.operand, f)
            if e.op == "NOT":
                if not isinstance(v, bool):
                    raise self.fail(f"type mismatch: NOT needs a bool, found {describe_type(v)}", e.operand.span)
                return not v
            if isinstance(v, Record) and v.type == "pos":
                return _pos(*(-c if e.op == "-" else c for c in _xyz(v)))
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise self.fail(f"type mismatch: unary {e.op} needs a num, found {describe_type(v)}", e.operand.span)
            return -v if e.op == "-" else v
        if isinstance(e, n.Binary):
            return self.binary(e, f)
        if isinstance(e, n.Call):
            return self.call_function(e, f)
        raise self.fail(f"cannot evaluate {type(e).__name__}", e.span)  # pragma: no cover

    def equal(self, a: object, b: object, span: Span) -> bool:
        if isinstance(a, Aggregate) or isinstance(b, Aggregate):
            t = a.type if isinstance(a, Record) else (b.type if isinstance(b, Record) else None)
            if t is None:
                return list(a) == list(b)  # type: ignore[arg-type]
            a, b = self.coerce(a, t, span), self.coerce(b, t, span)
        if isinstance(a, bool) != isinstance(b, bool) or type(a) is str and type(b) is not str:
            raise self.fail(f"type mismatch: cannot compare {describe_type(a)} with {describe_type(b)}", span)
        return a == b

    def binary(self, e: n.Binary, f: Frame) -> object:
        op = e.op
        a = self.eval(e.left, f)
        b = self.eval(e.right, f)
        if op in ("AND", "OR", "XOR"):
            for side, v in ((e.left, a), (e.right, b)):
                if not isinstance(v, bool):
                    raise self.fail(f"type mismatch: {op} needs bool operands, found {describe_type(v)}", side.span)
            return (a and b) if op == "AND" else (a or b) if op == "OR" else (a != b)
        if op == "=":
            return self.equal(a, b, e.op_span)
        if op == "<>":
            return not self.equal(a, b, e.op_span)
        if op == "+" and isinstance(a, str) and isinstance(b, str):
            return a + b
        if isinstance(a, Record) or isinstance(b, Record):
            return self.record_arith(op, a, b, e)
        for side, v in ((e.left, a), (e.right, b)):
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise self.fail(f"type mismatch: {op} needs num operands, found {describe_type(v)}", side.span)
        if op == "+":
            return a + b
        if op == "-":
            return a - b
        if op == "*":
            return a * b
        if op == "/":
            if b == 0:
                raise self.fail("division by zero", e.op_span, "ERR_DIVZERO")
            return a / b
        if op in ("DIV", "MOD"):
            for side, v in ((e.left, a), (e.right, b)):
                if v != int(v):
                    raise self.fail(f"{op} needs whole numbers, found {fmt_num(v)}", side.span)
            if b == 0:
                raise self.fail("division by zero", e.op_span, "ERR_DIVZERO")
            q = math.trunc(a / b)
            return float(q) if op == "DIV" else float(a - q * b)
        if op == "<":
            return a < b
        if op == "<=":
            return a <= b
        if op == ">":
            return a > b
        if op == ">=":
            return a >= b
        raise self.fail(f"unknown operator {op}", e.op_span)  # pragma: no cover

    def record_arith(self, op: str, a: object, b: object, e: n.Binary) -> object:
        ta = a.type if isinstance(a, Record) else describe_type(a)
        tb = b.type if isinstance(b, Record) else describe_type(b)
        if op in ("+", "-") and ta == tb == "pos":
            s = 1 if op == "+" else -1
            return _pos(*(x + s * y for x, y in zip(_xyz(a), _xyz(b))))  # type: ignore[arg-type]
        if op == "*" and ta == "pos" and tb == "num":
            return _pos(*(x * b for x in _xyz(a)))  # type: ignore[arg-type]
        if op == "*" and ta == "num" and tb == "pos":
            return _pos(*(a * y for y in _xyz(b)))  # type: ignore[operator, arg-type]
        if op == "*" and ta == tb == "orient":
            q = B.qmul([a.fields[k] for k in ("q1", "q2", "q3", "q4")],  # type: ignore[union-attr]
                       [b.fields[k] for k in ("q1", "q2", "q3", "q4")])  # type: ignore[union-attr]
            return Record("orient", dict(zip(("q1", "q2", "q3", "q4"), q)))
        raise self.fail(f"type mismatch: {op} is not defined for {ta} and {tb}", e.op_span)

    def lvalue(self, e: n.Expr, f: Frame) -> Ref:
        path: list[str] = []
        root = e
        while isinstance(root, n.Component):
            path.insert(0, root.field.lower())
            root = root.obj
        assert isinstance(root, n.Name)
        cell = self.lookup(root.name, f, root.span)
        if cell.storage == "CONST":
            raise self.fail(f"cannot assign to the constant {root.name}", root.span)
        try:
            t = _component_type(cell.type, path)
        except KeyError:
            raise self.fail(f"{cell.type} has no component '{path[-1]}'", e.span) from None
        return Ref(cell, path, t, e.text)

    def signal_arg(self, e: n.Expr | None, f: Frame, kind: str) -> SignalRef:
        if not isinstance(e, n.Name):
            raise self.fail(f"expected a {kind} signal", e.span if e else None)
        cell = self.lookup(e.name, f, e.span)
        v = cell.get()
        if not isinstance(v, SignalRef):
            raise self.fail(f"{e.name} is not a signal", e.span)
        if v.kind != kind:
            raise self.fail(f"{e.name} is a {v.kind} signal, a {kind} is needed", e.span)
        return v

    # ---- built-in functions ---------------------------------------------------------------------
    def builtin_function(self, e: n.Call, f: Frame) -> object:
        key = e.key
        if key not in B.FUNCTIONS:
            raise self.fail(f"unknown function '{e.name}'", e.span)
        params, rtype = B.FUNCTIONS[key]
        bound, msg, bad = B.match_args(params, e.args)
        if msg:
            raise self.fail(f"{e.name}: {msg}", bad.span if bad else e.span)
        ptypes = {p.key: p.type for p in params}

        def arg(name: str, default: object = None) -> object:
            a = bound.get(name)
            if a is None:
                return default
            if ptypes[name] == "switch":
                return True
            if ptypes[name] in SIGNAL_TYPES:
                return self.signal_arg(a.value, f, SIGNAL_TYPES[ptypes[name]])
            if ptypes[name] == "any":
                return self.eval(a.value, f)  # type: ignore[arg-type]
            return self.coerce(self.eval(a.value, f), ptypes[name], a.value.span)  # type: ignore[union-attr]

        names = [p.key for p in params]
        if key == "present":
            a = bound["optpar"].value
            if not isinstance(a, n.Name) or a.key not in f.vars:
                raise self.fail("Present needs the name of an optional parameter", a.span if a else e.span)
            return f.vars[a.key].get() is not ABSENT
        if key == "crobt":
            return self.host.current_robtarget(arg("tool"), arg("wobj"))
        if key == "cjointt":
            return self.host.current_jointtarget()
        if key in ("doutput", "dinput", "aoutput", "goutput"):
            return float(self.host.read_signal(arg("signal").name))  # type: ignore[union-attr]
        if key == "testdi":
            return self.host.read_signal(arg("signal").name) == 1  # type: ignore[union-attr]
        vals = [arg(k) for k in names]
        x = vals[0] if vals else None
        try:
            if key == "offs":
                return B.offs(*vals)
            if key == "reltool":
                return B.rel_tool(vals[0], vals[1], vals[2], vals[3], *(v or 0.0 for v in vals[4:]))
            if key == "abs":
                return abs(x)
            if key == "round":
                return B.rapid_round(x, arg("dec", 0.0))
            if key == "trunc":
                return B.rapid_trunc(x, arg("dec", 0.0))
            if key == "sqrt":
                if x < 0:
                    raise self.fail(f"Sqrt of a negative number ({fmt_num(x)})", e.span, "ERR_INVALID_VALUE")
                return math.sqrt(x)
            if key == "pow":
                return float(math.pow(vals[0], vals[1]))
            if key == "exp":
                return math.exp(x)
            if key == "sin":
                return _clean(math.sin(math.radians(x)))
            if key == "cos":
                return _clean(math.cos(math.radians(x)))
            if key == "tan":
                return _clean(math.tan(math.radians(x)))
            if key == "atan":
                return math.degrees(math.atan(x))
            if key == "atan2":
                return math.degrees(math.atan2(vals[0], vals[1]))
            if key == "numtostr":
                return B.num_to_str(vals[0], vals[1], bool(vals[2]))
            if key == "valtostr":
                return format_value(x)
            if key == "strlen":
                return float(len(x))
            if key == "strpart":
                s, start, length = vals[0], int(vals[1]), int(vals[2])
                if start < 1 or length < 0 or start - 1 + length > len(s):
                    raise self.fail(f"StrPart: characters {start} to {start + length - 1} are outside the "
                                    f"string of length {len(s)}", e.span, "ERR_OUTOFBND")
                return s[start - 1:start - 1 + length]
            if key == "dist":
                return B.dist(vals[0], vals[1])
            if key == "clkread":
                return x.read(self.now)
        except (ValueError, OverflowError) as exc:
            raise self.fail(f"{e.name}: {exc}", e.span, "ERR_INVALID_VALUE") from None
        raise self.fail(f"function {e.name} is not implemented", e.span)  # pragma: no cover

    # ---- instructions ---------------------------------------------------------------------------
    def proc_call(self, s: n.ProcCall, f: Frame):
        key = s.key
        r = self.routines.get(key)
        if r is not None:
            frame = Frame(r)
            self.bind(r.name, r.params, s.args, f, s.span, frame)
            yield from self.invoke(r, frame)
            return
        if key not in B.INSTRUCTIONS:
            raise self.fail(f"unknown instruction or procedure '{s.name}'", s.span)
        params = B.INSTRUCTIONS[key]
        bound, msg, bad = B.match_args(params, s.args)
        if msg:
            raise self.fail(f"{s.name}: {msg}", bad.span if bad else s.span)
        ptypes = {p.key: p for p in params}

        def arg(name: str, default: object = None) -> object:
            a = bound.get(name)
            if a is None:
                return default
            p = ptypes[name]
            if p.type == "switch":
                return True
            if p.type in SIGNAL_TYPES:
                return self.signal_arg(a.value, f, SIGNAL_TYPES[p.type])
            if p.mode == "INOUT":
                return self.lvalue(a.value, f)  # type: ignore[arg-type]
            return self.coerce(self.eval(a.value, f), p.type, a.value.span)  # type: ignore[union-attr]

        def text(name: str, default: str = "") -> str:
            a = bound.get(name)
            return a.value.text if a is not None and a.value is not None else default

        arg.frame = f  # type: ignore[attr-defined]
        yield from getattr(self, "i_" + key)(s, arg, text, bound)

    # Each i_* is a generator (instructions that wait yield; the others return at once).
    def i_incr(self, s, arg, text, bound):
        ref = arg("name")
        ref.set(ref.get() + 1)
        yield from ()

    def i_decr(self, s, arg, text, bound):
        ref = arg("name")
        ref.set(ref.get() - 1)
        yield from ()

    def i_add(self, s, arg, text, bound):
        ref = arg("name")
        ref.set(ref.get() + arg("addvalue"))
        yield from ()

    def i_bookerrno(self, s, arg, text, bound):
        arg("errorname").set(float(self.next_user_errno))
        self.next_user_errno += 1
        yield from ()

    def i_clkreset(self, s, arg, text, bound):
        clock = arg("clock").get()
        clock.elapsed, clock.started = 0, (self.now if clock.started is not None else None)
        yield from ()

    def i_clkstart(self, s, arg, text, bound):
        clock = arg("clock").get()
        if clock.started is None:
            clock.started = self.now
        yield from ()

    def i_clkstop(self, s, arg, text, bound):
        clock = arg("clock").get()
        if clock.started is not None:
            clock.elapsed += self.now - clock.started
            clock.started = None
        yield from ()

    def i_setdo(self, s, arg, text, bound):
        sig, value, delay = arg("signal"), arg("value"), arg("sdelay")
        if delay:  # \SDelay: the program goes on, the output changes `delay` seconds later
            if value not in (0, 1):
                raise self.fail(f"a digital output is 0 or 1, not {fmt_num(value)}", bound["value"].value.span)
            self.pulses.append((self.now + to_ns(delay), sig.name, float(value)))
        else:
            self.write(sig, value, bound["value"].value.span)
        yield from ()

    def i_setao(self, s, arg, text, bound):
        self.write(arg("signal"), arg("value"), bound["value"].value.span)
        yield from ()

    def i_setgo(self, s, arg, text, bound):
        self.write(arg("signal"), arg("value"), bound["value"].value.span)
        yield from ()

    def i_set(self, s, arg, text, bound):
        self.write(arg("signal"), 1.0)
        yield from ()

    def i_reset(self, s, arg, text, bound):
        self.write(arg("signal"), 0.0)
        yield from ()

    def i_invertdo(self, s, arg, text, bound):
        sig = arg("signal")
        self.write(sig, 0.0 if self.host.read_signal(sig.name) else 1.0)
        yield from ()

    def i_pulsedo(self, s, arg, text, bound):
        sig = arg("signal")
        length = arg("plength", 0.2)
        if not 0.001 <= length <= 2000:
            raise self.fail(f"PulseDO \\PLength must be 0.001 to 2000 s, not {fmt_num(length)}",
                            bound["plength"].value.span, "ERR_INVALID_VALUE")
        current = self.host.read_signal(sig.name)
        high = arg("high", False)
        self.pulses = [p for p in self.pulses if p[1] != sig.name]
        if high or current == 0:  # positive pulse
            self.write(sig, 1.0)
            self.pulses.append((self.now + to_ns(length), sig.name, 0.0))
        else:  # already high without \High: the level is inverted for the pulse length
            self.write(sig, 0.0)
            self.pulses.append((self.now + to_ns(length), sig.name, 1.0))
        yield from ()

    def i_tpwrite(self, s, arg, text, bound):
        out = arg("string")
        for k in ("num", "bool", "pos", "orient"):
            v = arg(k)
            if v is not None:
                out += format_value(v)
        self.host.tp_write(out)
        self.emit({"type": "print", "text": out})
        yield from ()

    def i_tperase(self, s, arg, text, bound):
        yield from ()

    def i_stop(self, s, arg, text, bound):
        yield Wait("stop", what="Stop")

    i_break = i_stop

    def _noop(self, s, arg, text, bound):
        for k in bound:
            arg(k)  # evaluate for errors
        yield from ()

    i_confj = i_confl = i_velset = i_accset = i_waitrob = _noop

    def i_waittime(self, s, arg, text, bound):
        t = arg("time")
        if t < 0:
            raise self.fail(f"WaitTime needs a time >= 0, not {fmt_num(t)}", bound["time"].value.span,
                            "ERR_INVALID_VALUE")
        until = self.now + to_ns(t)
        while self.now < until:
            yield Wait("time", until, f"WaitTime {fmt_num(t)}", s.span)

    def _wait_cond(self, s, arg, bound, test: Callable[[], bool], name: str, poll: int | None):
        maxtime = arg("maxtime")
        flag = arg("timeflag")
        deadline = None if maxtime is None else self.now + to_ns(maxtime)
        start = self.now
        k = 0
        while True:
            if test():
                if flag is not None:
                    flag.set(False)
                return
            if deadline is not None and self.now >= deadline:
                if flag is not None:
                    flag.set(True)
                    return
                raise self.fail(f"{name} timed out: \\MaxTime of {fmt_num(maxtime)} s ran out", s.span,
                                "ERR_WAIT_MAXTIME")
            if poll:
                k += 1
                at = start + k * poll
                while at <= self.now:
                    k += 1
                    at = start + k * poll
                if deadline is not None:
                    at = min(at, deadline)
                yield Wait("poll", at, name, s.span)
            else:
                yield Wait("signal", deadline, name, s.span)

    def i_waituntil(self, s, arg, text, bound):
        cond = bound["cond"].value
        poll = to_ns(arg("pollrate", 0.1))
        if poll <= 0:
            raise self.fail("WaitUntil \\PollRate must be > 0", bound["pollrate"].value.span, "ERR_INVALID_VALUE")
        f = arg.frame
        yield from self._wait_cond(s, arg, bound, lambda: self.truth(cond, f), "WaitUntil", poll)

    def i_waitdi(self, s, arg, text, bound, name="WaitDI"):
        sig, value = arg("signal"), arg("value")
        yield from self._wait_cond(s, arg, bound, lambda: self.host.read_signal(sig.name) == value,
                                   f"{name} {sig.name}", None)

    def i_waitdo(self, s, arg, text, bound):
        yield from self.i_waitdi(s, arg, text, bound, "WaitDO")

    def _move(self, s, arg, text, bound, instr: str):
        target_key = "tojointpos" if instr == "MoveAbsJ" else "topoint"
        target = arg(target_key)
        via = arg("cirpoint") if instr == "MoveC" else None
        req = MotionRequest(
            instr=instr, target=target, via=via, speed=arg("speed"), zone=arg("zone"), tool=arg("tool"),
            wobj=arg("wobj", self.predefined["wobj0"].value), target_name=text(target_key),
            via_name=text("cirpoint"), speed_name=text("speed"), zone_name=text("zone"),
            tool_name=text("tool"), wobj_name=text("wobj", "wobj0"), line=s.span.line)
        ev = {"type": "move", "instr": instr, "to": _target_json(target)}
        if via is not None:
            ev["via"] = _target_json(via)
        ev.update(speed=req.speed_name, zone=req.zone_name, tool=req.tool_name, wobj=req.wobj_name)
        self.emit(ev)
        handle = self.host.start_motion(req)
        while not self.host.motion_done(handle):
            yield Wait("motion", None, f"{instr} {req.target_name}", s.span)

    def i_movej(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveJ")

    def i_movel(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveL")

    def i_movec(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveC")

    def i_moveabsj(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveAbsJ")


SIGNAL_KINDS_T = {v: k for k, v in SIGNAL_TYPES.items()}


def _xyz(p: Record) -> tuple[float, float, float]:
    return p.fields["x"], p.fields["y"], p.fields["z"]  # type: ignore[return-value]


def _pos(x: float, y: float, z: float) -> Record:
    return Record("pos", {"x": x, "y": y, "z": z})


def _clean(x: float) -> float:
    r = round(x, 12)
    return 0.0 if r == 0 else r


def _target_json(t: Record) -> dict:
    if t.type == "jointtarget":
        rob = t.fields["robax"]
        return {"robax": [json_num(v) for v in rob.values()]}  # type: ignore[union-attr]
    trans, rot = t.fields["trans"], t.fields["rot"]
    return {"trans": [json_num(v) for v in trans.values()],  # type: ignore[union-attr]
            "rot": [json_num(v) for v in rot.values()]}  # type: ignore[union-attr]
