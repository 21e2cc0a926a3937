"""The evaluator: runs a checked Module as a tree of Python generators, one per running statement.

Nothing here blocks, sleeps or knows the wall clock. A statement that has to wait *yields* a `Wait`
to whoever drives the generator (the Controller) and is resumed on a later tick with the clock
advanced; expressions are evaluated synchronously.

Time-less loops: a loop iteration (WHILE, FOR, a backward GOTO, a RETRY) during which the program
was not suspended costs one unit of the tick's *loop budget* (`loop_budget`, 10 000 by default;
the controller resets `spins` at every tick). While the budget lasts the loop runs on at the same
instant, so `FOR i FROM 1 TO 1000` ends at the time it started; when it is used up the loop yields a
"step" wait and goes on at the next tick. `WHILE TRUE DO ENDWHILE` thus hands control back every
tick instead of hanging the cell. A loop that used up a whole tick's budget is a polling loop: at
the following ticks, until it waits or ends, it gets `POLL_BUDGET` (100) iterations per tick, which
bounds what a busy polling loop costs in wall time per simulated second (`python -m bench rapid`).

Errors and ERROR handlers: every statement runs inside a guard. A runtime error (ExecError) in a
statement of routine R transfers control to R's ERROR handler with ERRNO set; the handler's RETRY
re-runs that statement, TRYNEXT goes on after it, RETURN leaves R, RAISE passes the error to the
caller's handler. A routine without a handler passes the error to its caller. An error with no
handler up the call chain, an error inside a handler, or a handler that reaches its end without
one of those words stops the program (the system error handler).
"""
from __future__ import annotations

import math
from typing import Callable, Generator

from . import builtins as B
from . import nodes as n
from .errors import ExecError, Span
from .host import Host, SignalInfo
from .instructions import InstructionsMixin
from .interrupts import InterruptTable
from .sockets import SocketsMixin
from .system import SystemMixin
from .runtime import (ABSENT, DEFAULT_LOOP_BUDGET, NS, Cell, ExitCycleSignal, ExitSignal, Fatal, Frame, GotoSignal,
                      Propagate, Ref, RetrySignal, ReturnSignal, TryNextSignal, Wait, component_type, to_ns)
from .values import (SIGNAL_KINDS, SIGNAL_TYPES, STRING_MAX, Aggregate, Array, Record, SignalRef, TypeMismatch, a_, array_type,
                     coerce, default_value, describe_type, fmt_num, json_num, new_array, pos, xyz)

GO_MAX = 2.0 ** 32 - 1  # the largest value of a 32-bit group output

__all__ = ["Interpreter", "Wait", "NS", "to_ns", "ExitSignal", "ExitCycleSignal", "Fatal", "Propagate"]


class Interpreter(InstructionsMixin, SystemMixin, SocketsMixin):
    """Runs one module against a host; the Controller drives `run()` and sets `now` before each resume."""

    def __init__(self, program: n.Module | n.Task, host: Host, emit: Callable[[dict], None] | None = None,
                 loop_budget: int = DEFAULT_LOOP_BUDGET, answers: list[str] | None = None):
        self.task = program if isinstance(program, n.Task) else n.Task([program])
        self.module = self.task.modules[0]
        self.host = host
        self._sink = emit or (lambda ev: None)
        self.signals: dict[str, SignalInfo] = {s.name.lower(): s for s in host.signals()}
        self.signal_cells = {k: Cell(SIGNAL_KINDS[s.kind], SignalRef(s.name, s.kind), "CONST", s.name)
                             for k, s in self.signals.items()}
        # routines as each module sees them: the task's global ones and its own LOCAL ones
        glob = {r.key: r for r in self.task.routines if not r.local}
        self.routine_scopes = {m.name: {**glob, **{r.key: r for r in m.routines if r.local}}
                               for m in self.task.modules}
        self.routines = glob
        self.scopes: dict[str, dict[str, Cell]] = {m.name: {} for m in self.task.modules}
        self.answers = list(answers or [])  # --answer values for FlexPendant dialogs, in order
        self.interrupts = InterruptTable(self)
        self.sockets: list = []
        self.stop_move = False
        self.stored_paths: list[bool] = []  # StorePath levels: the stop_move of each stored path
        self.files: dict[str, str] = {}  # files the program wrote (Open ... \\Write; Write), by path
        self.concurrent = None  # the handle of a \\Conc motion still running
        self.last_position: tuple | None = None  # the last Cartesian target (mm), for offline motion times
        # motion settings (docs/rapid.md): AccSet (acc %, ramp %), VelSet (override %, max mm/s), ConfJ/ConfL
        # monitoring, the GripLoad mass (kg), PathAccLim (m/s^2 or None), CornerPathWarning
        self.accset = (100.0, 100.0)
        self.velset = (100.0, 5000.0)
        # ConfJ\On and ConfL\On, as a controller starts (the manual's default), unless the host's arm says otherwise
        on = bool(getattr(host, "conf_monitoring", True))
        self.conf = {"j": on, "l": on}
        self.gripload = 0.0
        self.path_acc: float | None = None
        self.corner_warning = True
        self.last_motion = None  # the handle of the last motion handed to the host (its corner may fail)
        self.hardware_noted: set[str] = set()  # hardware-only instructions already noted in the log
        self.predefined = {k: Cell(t, v, "CONST", k) for k, (t, v) in B.predefined_data().items()}
        self.active_tool = self.predefined["tool0"].value
        self.active_wobj = self.predefined["wobj0"].value
        self.globals: dict[str, Cell] = {}
        self.predefined_vars: dict[str, Cell] = {}
        self.now = 0  # ns, set by the controller before every resume
        self.suspensions = 0  # bumped by the controller each time the program stays suspended over a tick
        self.loop_budget = max(1, int(loop_budget))  # time-less loop iterations per tick
        self.spins = 0  # time-less loop iterations in this tick (reset by the controller every tick)
        self.tick_budget = self.loop_budget  # this tick's: POLL_BUDGET for a loop that used up a whole tick
        self.polling = False  # this tick goes on with a loop that used up a whole tick (a polling loop)
        # Bumped by everything that changes the program's state or the world (assignments, loop
        # variables, INOUT arguments, ERRNO, events) or depends on the time (ClkRead): a tick that
        # leaves it unchanged and ends at the same loop would do the same again at the next tick.
        self.changes = 0
        self.errno = 0.0
        # scheduled output writes: (due ns, signal, value, PULSE | SDELAY)
        self.pulses: list[tuple[int, str, float, str]] = []
        self.next_user_errno = B.USER_ERRNO_BASE

    # ---- set-up ---------------------------------------------------------------------------------
    def init_data(self, keep_pers: bool = False) -> None:
        """(Re)initialise module data. PERS data keep their values when `keep_pers`. A declaration may use
        constants of a module loaded after its own, so declarations whose initial value names data not
        made yet wait for a later round."""
        old = self.globals
        old_scopes = self.scopes
        self.globals = {}
        self.scopes = {m.name: {} for m in self.task.modules}
        self.predefined_vars = {k: Cell(t, default_value(t), "VAR", k) for k, t in B.PREDEFINED_VARS.items()}
        pending = [(m, d) for m in self.task.modules for d in m.data]
        while pending:
            later = []
            failure = None
            for m, d in pending:
                scope = self.scopes[m.name]
                if d.storage == "PERS" and not d.local and d.key in self.globals:
                    scope[d.key] = self.globals[d.key]  # a PERS declared in several modules is one persistent
                    continue
                previous = (old_scopes.get(m.name) or {}).get(d.key) if d.local else old.get(d.key)
                if keep_pers and d.storage == "PERS" and previous is not None:
                    cell = previous
                else:
                    top = Frame(n.Routine(m.span, "PROC", "<module>", [], [], module=m.name))
                    try:
                        cell = self.declare(d, top)
                    except ExecError as err:
                        if err.errname != "ERR_REFUNKDAT":
                            raise
                        later.append((m, d))
                        failure = failure or err
                        continue
                scope[d.key] = cell
                if not d.local:
                    self.globals[d.key] = cell
                    for other in self.task.modules:
                        self.scopes[other.name].setdefault(d.key, cell)
            if len(later) == len(pending):
                raise failure  # type: ignore[misc]
            pending = later

    def declare(self, d: n.DataDecl, f: Frame) -> Cell:
        """A new cell for a declaration, with its initial value (arrays get their declared sizes)."""
        if not d.dims:
            value = self.coerce(self.eval(d.init, f), d.type, d.init.span) if d.init else default_value(d.type)
            return Cell(d.type, value, d.storage, d.name)
        sizes = []
        for e in d.dims:
            size = self.num(e, f)
            if size != int(size) or size < 1:
                raise self.fail(f"an array size must be a whole number >= 1, not {fmt_num(size)}", e.span,
                                "ERR_ILLDIM")
            sizes.append(int(size))
        t = array_type(d.type, len(sizes))
        if d.init is None:
            return Cell(t, new_array(d.type, sizes), d.storage, d.name)
        value = self.coerce(self.eval(d.init, f), t, d.init.span)
        if value.sizes() != sizes:  # type: ignore[union-attr]
            raise self.fail(f"{d.name} is declared with {{{', '.join(map(str, sizes))}}} elements, the "
                            f"initial value has {{{', '.join(map(str, value.sizes()))}}}",  # type: ignore[union-attr]
                            d.init.span, "ERR_ILLDIM")
        return Cell(t, value, d.storage, d.name)

    def run(self, entry: str) -> Generator[Wait, None, None]:
        r = self.routines[entry.lower()]
        yield from self.invoke(r, Frame(r))

    def routine_for(self, key: str, f: Frame) -> n.Routine | None:
        """The routine `key` as the module of the running routine sees it."""
        scope = self.routine_scopes.get(f.routine.module)
        return (scope or self.routines).get(key)

    def pause(self, w: Wait, f: Frame | None = None):
        """Yield a wait; when resumed, run the TRAP routines of the interrupts that came meanwhile."""
        yield w
        if self.interrupts.pending:
            yield from self.interrupts.service()

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
        """Write an output (SetDO, Set, Reset, SetAO, SetGO, PulseDO) and trace it.

        A group output takes a whole number from 0 to its range, else ERR_GO_LIM; offline a group's
        width is not configured, so its range is that of RAPID's widest group, 32 bits (0 to
        4294967295). An analog output has no limits offline (a station's signals have their own,
        reported by the host as ERR_AO_LIM); only a value that is not a finite number is
        ERR_AO_LIM."""
        if sig.kind == "GO" and (not math.isfinite(value) or value != int(value) or not 0 <= value <= GO_MAX):
            raise self.fail(f"SetGO {sig.name}: a group output takes a whole number from 0 to {GO_MAX:.0f}, "
                            f"not {fmt_num(value)}", span, "ERR_GO_LIM")
        if sig.kind == "AO" and not math.isfinite(value):
            raise self.fail(f"SetAO {sig.name}: {fmt_num(value)} is not a finite value", span, "ERR_AO_LIM")
        self.host.write_signal(sig.name, float(value))
        self.emit({"type": sig.kind, "signal": sig.name, "value": json_num(float(value))})
        self.interrupts.poll()

    def apply_pulses(self) -> None:
        """Write the pulse edges that are due (called by the controller at the start of a tick)."""
        due = [p for p in self.pulses if p[0] <= self.now]
        if not due:
            return
        self.pulses = [p for p in self.pulses if p[0] > self.now]
        for _, name, value, _kind in sorted(due):
            info = self.signals[name.lower()]
            self.host.write_signal(info.name, value)
            self.emit({"type": info.kind, "signal": info.name, "value": json_num(value)})

    def string(self, text: str, span: Span | None) -> str:
        """A string value made at run time (by `+`, NumToStr, ValToStr, ...): RAPID strings hold at
        most 80 characters, a longer one is the runtime error ERR_STRTOOLNG."""
        if len(text) > STRING_MAX:
            raise self.fail(f"the string would be {len(text)} characters long: a RAPID string holds at most "
                            f"{STRING_MAX}", span, "ERR_STRTOOLNG")
        return text

    def emit(self, event: dict) -> None:
        self.changes += 1
        self._sink(event)

    def spin(self, what: str, span: Span):
        """A loop iteration that consumed no time: one unit of the tick's loop budget; when the
        budget is used up, wait for the next tick (`span` names the loop)."""
        self.spins += 1
        if self.spins >= self.tick_budget:
            yield Wait("step", what=what, span=span)

    # ---- routines -------------------------------------------------------------------------------
    def invoke(self, r: n.Routine, frame: Frame):
        """Run a routine body; an error it does not handle is raised again at the call. When the
        routine is left by an error raised on to its caller, ExitCycle or EXIT, its UNDO runs first."""
        try:
            yield from self.block(r.body, frame)
        except ReturnSignal as rs:
            return rs.value
        except Propagate as p:
            yield from self.undo(r, frame)
            raise p.error from None
        except ExecError:
            yield from self.undo(r, frame)
            raise
        except (ExitCycleSignal, ExitSignal, Fatal):
            yield from self.undo(r, frame)
            raise
        if r.kind == "FUNC":  # reached its ENDFUNC: the error is there, where the RETURN is missing
            raise self.fail(f"FUNC {r.name} reached ENDFUNC without RETURN", r.end_span or r.span, "ERR_FNCNORET")
        return None

    def match(self, r_name: str, params: list[n.Param], args: list[n.Arg], f: Frame, span: Span) -> dict[str, n.Arg]:
        """Arguments matched to parameters ({param key: arg}); a conditional argument `\\A?B` whose
        parameter B is absent in the caller `f` is left out, as if it had not been written."""
        bound, msg, bad = B.match_args(params, args)
        if msg:
            raise self.fail(f"{r_name}: {msg}", bad.span if bad else span)
        if any(a.conditional for a in args):
            for key, a in list(bound.items()):
                if a.conditional:
                    cell = f.vars.get(a.value.key)  # type: ignore[union-attr]
                    if cell is None or cell.get() is ABSENT:
                        del bound[key]
        return bound

    def bind(self, r_name: str, params: list[n.Param], args: list[n.Arg], f: Frame, span: Span,
             frame: Frame) -> None:
        bound = self.match(r_name, params, args, f, span)
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

    def undo(self, r: n.Routine, frame: Frame):
        if r.undo is None or frame.undoing:
            return
        frame.undoing = True
        try:
            yield from self.block(r.undo, frame)
        except ReturnSignal:
            pass

    def call_function(self, e: n.Call, f: Frame) -> object:
        key = e.key
        r = self.routine_for(key, f)
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
        i = 0
        mark = self.suspensions
        while i < len(stmts):
            if self.interrupts.pending:
                yield from self.interrupts.service()
            if type(stmts[i]) is n.Label:  # a backward GOTO's loop turn starts at its label
                mark = self.suspensions
            try:
                yield from self.guarded(stmts[i], f)
            except GotoSignal as g:
                target = next((k for k, s in enumerate(stmts) if isinstance(s, n.Label) and s.name.lower() == g.label),
                              None)
                if target is None:
                    raise
                if target <= i and self.suspensions == mark:  # a backward jump is a loop
                    yield from self.spin(f"GOTO {g.label}", stmts[target].span)
                mark = self.suspensions
                i = target + 1
                continue
            i += 1

    def guarded(self, s: n.Stmt, f: Frame):
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
                if f.routine.error_handler is None or not self.handles(f, err):
                    raise Propagate(err) from None
                action = yield from self.handler(f, err)
                if action == "trynext":
                    return
                if self.suspensions == mark:
                    # RETRY is immediate, but a retry without time passing is a loop iteration
                    # like any other: it uses the loop budget, so a RETRY loop cannot hang the cell.
                    yield from self.spin("RETRY", s.span)

    def handles(self, f: Frame, err: ExecError) -> bool:
        """Does the routine's ERROR handler take this error? `ERROR (ERR_A, ERR_B)` takes only those
        (LONG_JMP_ALL_ERR: every error raised to it); a handler without a list takes every error."""
        if f.routine.error_list is None:
            return True
        for e in f.routine.error_list:
            no = self.num(e, f)
            if no == B.LONG_JMP_ALL_ERR or int(no) == err.errno:
                return True
        return False

    def handler(self, f: Frame, err: ExecError):
        self.errno = float(err.errno)
        self.changes += 1
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
            value = self.coerce(self.eval(s.value, f), ref.type, s.value.span)
            if isinstance(value, Array):
                old = ref.get()
                if isinstance(old, Array) and old.sizes() != value.sizes():
                    raise self.fail(f"type mismatch: {s.target.text} has {{{', '.join(map(str, old.sizes()))}}} "
                                    f"elements, the value {{{', '.join(map(str, value.sizes()))}}}", s.value.span,
                                    "ERR_ILLDIM")
            ref.set(value)
            self.changes += 1
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
                    yield from self.spin("WHILE", s.span)
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
            f.vars[s.decl.key] = self.declare(s.decl, f)
            self.changes += 1
        elif isinstance(s, n.Return):
            value = None
            if s.value is not None:
                value = self.coerce(self.eval(s.value, f), f.routine.return_type or "num", s.value.span)
            raise ReturnSignal(value)
        elif isinstance(s, n.Exit):
            raise ExitSignal()
        elif isinstance(s, n.Connect):
            ref = self.lvalue(s.target, f)
            trap = self.routine_for(s.trap.lower(), f)
            self.interrupts.connect(ref, trap, s.span)  # type: ignore[arg-type]
            self.changes += 1
        elif isinstance(s, n.Goto):
            raise GotoSignal(s.label.lower())
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
        hidden = f.vars.get(key)  # a routine variable or parameter of the same name, hidden in the loop
        f.vars[key] = cell
        try:
            i = start
            while (i <= stop) if step > 0 else (i >= stop):
                mark = self.suspensions
                cell.value = i
                self.changes += 1
                yield from self.block(s.body, f)
                if self.suspensions == mark:
                    yield from self.spin("FOR", s.span)
                i += step
        finally:
            if hidden is not None:
                f.vars[key] = hidden
            else:
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
        scope = self.scopes.get(f.routine.module)
        if scope is not None and key in scope:
            return scope[key]
        if key in self.globals:
            return self.globals[key]
        if key in self.predefined:
            return self.predefined[key]
        if key in self.predefined_vars:
            return self.predefined_vars[key]
        if key in self.signal_cells:
            return self.signal_cells[key]
        if key == "errno":
            return Cell("errnum", self.errno, "CONST", "ERRNO")
        raise self.fail(f"undefined name '{name}'", span, "ERR_REFUNKDAT")

    def eval(self, e: n.Expr, f: Frame) -> object:
        t = type(e)  # the node classes have no subclasses: `type(e) is` is an exact, fast test
        if t is n.NumLit or t is n.StrLit or t is n.BoolLit:
            return e.value  # type: ignore[attr-defined]
        if t is n.Binary:
            return self.binary(e, f)  # type: ignore[arg-type]
        if t is n.Name:
            cell = self.lookup(e.name, f, e.span)
            v = cell.get()
            if v is ABSENT:
                raise self.fail(f"optional argument {e.name} is not present (test it with Present({e.name}))",
                                e.span, "ERR_NOTPRES")
            if isinstance(v, SignalRef):
                return float(self.host.read_signal(v.name))
            if isinstance(v, (Record, Array)):
                return v.copy()
            return v
        if isinstance(e, n.Index):
            arr = self.eval(e.obj, f)
            for k in self.indexes(e, arr, f):
                arr = arr[k]  # type: ignore[index]
            return arr
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
                return pos(*(-c if e.op == "-" else c for c in xyz(v)))
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise self.fail(f"type mismatch: unary {e.op} needs a num, found {describe_type(v)}", e.operand.span)
            return -v if e.op == "-" else v
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
            return self.string(a + b, e.op_span)
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
        if isinstance(a, Aggregate) and isinstance(b, Record) and b.type == "pos":
            a = self.coerce(a, "pos", e.left.span)
        if isinstance(b, Aggregate) and isinstance(a, Record) and a.type == "pos":
            b = self.coerce(b, "pos", e.right.span)
        ta = a.type if isinstance(a, Record) else describe_type(a)
        tb = b.type if isinstance(b, Record) else describe_type(b)
        if op in ("+", "-") and ta == tb == "pos":
            s = 1 if op == "+" else -1
            return pos(*(x + s * y for x, y in zip(xyz(a), xyz(b))))  # type: ignore[arg-type]
        if op == "*" and ta == "pos" and tb == "num":
            return pos(*(x * b for x in xyz(a)))  # type: ignore[arg-type]
        if op == "*" and ta == "num" and tb == "pos":
            return pos(*(a * y for y in xyz(b)))  # type: ignore[operator, arg-type]
        if op == "*" and ta == tb == "orient":
            q = B.qmul([a.fields[k] for k in ("q1", "q2", "q3", "q4")],  # type: ignore[union-attr]
                       [b.fields[k] for k in ("q1", "q2", "q3", "q4")])  # type: ignore[union-attr]
            return Record("orient", dict(zip(("q1", "q2", "q3", "q4"), q)))
        raise self.fail(f"type mismatch: {op} is not defined for {ta} and {tb}", e.op_span)

    def lvalue(self, e: n.Expr, f: Frame) -> Ref:
        steps: list[n.Expr] = []
        root = e
        while isinstance(root, (n.Component, n.Index)):
            steps.insert(0, root)
            root = root.obj
        assert isinstance(root, n.Name)
        cell = self.lookup(root.name, f, root.span)
        if cell.storage == "CONST":
            raise self.fail(f"cannot assign to the constant {root.name}", root.span)
        path: list = []
        value = cell.get()
        for step in steps:
            if isinstance(step, n.Component):
                path.append(step.field.lower())
                value = value.fields[path[-1]] if isinstance(value, Record) else None
            else:
                for k in self.indexes(step, value, f):
                    path.append(k)
                    value = value[k]  # type: ignore[index]
        try:
            t = component_type(cell.type, path)
        except (KeyError, TypeError):
            raise self.fail(f"{cell.type} has no component '{path[-1]}'", e.span) from None
        return Ref(cell, path, t, e.text)

    def indexes(self, e: n.Index, arr: object, f: Frame) -> list[int]:
        """0-based indexes of `e` into `arr`, checked against its bounds (ERR_OUTOFBND)."""
        out = []
        for i in e.indices:
            if not isinstance(arr, Array):
                raise self.fail(f"{e.obj.text} has fewer dimensions than indices", i.span, "ERR_ILLDIM")
            k = self.num(i, f)
            if k != int(k) or not 1 <= k <= len(arr):
                raise self.fail(f"index {fmt_num(k)} is outside {e.obj.text}{{1..{len(arr)}}}", i.span,
                                "ERR_OUTOFBND")
            out.append(int(k) - 1)
            arr = arr[int(k) - 1]
        return out

    def signal_arg(self, e: n.Expr | None, f: Frame, kind: str) -> SignalRef:
        if not isinstance(e, n.Name):
            raise self.fail(f"expected {a_(kind)} signal", e.span if e else None)
        cell = self.lookup(e.name, f, e.span)
        v = cell.get()
        if not isinstance(v, SignalRef):
            raise self.fail(f"{e.name} is not a signal", e.span)
        if v.kind != kind:
            raise self.fail(f"{e.name} is {a_(v.kind)} signal, {a_(kind)} is needed", e.span)
        return v

    def proc_call(self, s: n.ProcCall, f: Frame):
        r = self.routine_for(s.key, f)
        if r is not None:
            frame = Frame(r)
            self.bind(r.name, r.params, s.args, f, s.span, frame)
            yield from self.invoke(r, frame)
        else:
            yield from self.builtin_instruction(s, f)

