"""Static check, run before anything executes: every name resolves (declared data, a routine, a
predefined constant or a configured I/O signal), built-in and user routines get the right number
and kinds of arguments, types agree where they can be known, constants and signals are not
assigned, RETRY/TRYNEXT appear only in ERROR handlers, and every FUNC has a RETURN somewhere (one
that can still reach its ENDFUNC is the runtime error ERR_FNCNORET, at the ENDFUNC).

RAPID does not declare signals; the controller's I/O configuration does. The checker gets that
configuration (`signals`: lower-case name -> SignalInfo) so a misspelt signal is an error here, with
its line and column, rather than a surprise in the middle of a cycle. A signal must have a name of
its own: one that is also declared data, a routine, predefined data (reg1, v100, tool0, fine...),
a built-in instruction or function, or a reserved word is an error here too.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass

from . import builtins as B
from . import nodes as n
from . import rapid_names
from .errors import CheckError, Span
from .host import SignalInfo
from .tokens import KEYWORDS
from .values import (BUILTIN_RECORDS, KNOWN_TYPES, RECORDS, SIGNAL_TYPES, a_, array_type, base_type, define_records,
                     split_array_type)

# A name the program uses as a signal without an I/O configuration: its kind from its prefix.
_SIGNAL_PREFIXES = {"di": "DI", "do": "DO", "ai": "AI", "ao": "AO", "gi": "GI", "go": "GO"}


# Instructions accepted whose effect the simulation only approximates (`rapid check` lists each use).
_APPROXIMATE = {
    "singarea": "singularities are not simulated",
    "pathresol": "the path resolution does not change the simulated motion",
    "cirpathmode": "the tool orientation along a circle is not changed by CirPathMode",
    "worldacclim": "acceleration limits are not simulated",
    "storepath": "without a StopMove before it, StorePath stands where the path is at the end of the motion under "
                 "way (on its corner path if it blends)",
    "restopath": "no regain movement: RestoPath needs the robot back within 1 mm of where the stored path stands "
                 "(else ERR_PATHDIST)",
    "pdispset": "program displacement is not applied to the motions",
    "pdispoff": "program displacement is not applied to the motions",
    "eoffsoff": "external axes are not simulated",
    "ierror": "error interrupts never fire in simulation",
    "pdispon": "program displacement is not applied to the motions",
    "eoffson": "external axes are not simulated",
    "eoffsset": "external axes are not simulated",
    "waitsynctask": "one task runs: WaitSyncTask does not wait for the others",
    "searchl": "the search moves to ToPoint; it hits when the signal is 1 at the start or at the end of the "
               "motion (SearchPoint := ToPoint), else ERR_WHLSEARCH",
    "write": "written files go to the trace (type file), not to disk",
    "triggio": "the output is set when the TriggL/TriggJ motion ends, not at its Distance on the path",
    "triggequip": "the output is set when the TriggL/TriggJ motion ends, not at its Distance (EquipLag unused)",
    "triggint": "the interrupt occurs when the TriggL/TriggJ motion ends, not at its Distance on the path",
    "spystart": "no spy log is written",
    "softact": "soft servo is not simulated: the arm keeps its stiffness (noted once in the event log)",
    "softdeact": "soft servo is not simulated (noted once in the event log)",
    "actunit": "the twin has no external mechanical units (noted once in the event log)",
    "deactunit": "the twin has no external mechanical units (noted once in the event log)",
    "waitwobj": "the twin has no conveyor: the work object is connected at once (noted once in the event log)",
    "dropwobj": "the twin has no conveyor (noted once in the event log)",
    "setleadthrough": "lead-through needs the real arm (noted once in the event log)",
    "waitrob": "WaitRob waits for a \\Conc motion, and with \\InPos or \\ZeroSpeed for the robot at rest",
}

# RAPID instructions that are deliberately left out of the subset, with what to do instead.
_UNSUPPORTED = {
    "callbyvar": "it calls a procedure by a name built at run time (late binding); call the "
                 "procedure by its name, e.g. in a TEST on the number",
}


@dataclass
class Sym:
    kind: str  # data, signal, param, loop, switch
    type: str | None
    storage: str = "VAR"  # VAR, PERS, CONST
    signal: SignalInfo | None = None
    name: str = ""  # as declared
    optional: bool = False  # an optional parameter (\\Name) of the routine


def check(program: n.Module | n.Task, signals: dict[str, SignalInfo] | None = None,
          infer_signals: bool = False) -> "Checker":
    """Raise CheckError for the first static error in `program` (a module or a task of modules).
    With `infer_signals` (no I/O configuration given), a name used as a signal is taken as one:
    `checker.inferred` lists them and `checker.warnings` says so, with what else is approximate."""
    c = Checker(program, dict(signals or {}), infer_signals)
    c.run()
    return c


def as_task(program: n.Module | n.Task) -> n.Task:
    return program if isinstance(program, n.Task) else n.Task([program])


class Checker:
    def __init__(self, program: n.Module | n.Task, signals: dict[str, SignalInfo], infer_signals: bool = False):
        self.task = as_task(program)
        self.signals = signals
        self.infer = infer_signals
        self.inferred: list[SignalInfo] = []
        self.warnings: list[tuple[Span, str]] = []
        self.globals: dict[str, Sym] = {}
        self.routines: dict[str, n.Routine] = {}
        self.predefined = {k: Sym("data", t, "CONST") for k, (t, _) in B.predefined_data().items()}
        self.current: n.Routine | None = None

    # ---- names ---------------------------------------------------------------------------------
    def err(self, msg: str, span: Span) -> CheckError:
        return CheckError(msg, span)

    def all_names(self, scope: dict[str, Sym]) -> list[str]:
        return list(scope) + list(self.globals) + list(self.signals) + list(self.routines)

    def spelling(self, key: str, scope: dict[str, Sym]) -> str:
        """A name as it was declared (hints show `Axis1`, not `axis1`)."""
        for table in (scope, self.globals):
            if key in table and table[key].name:
                return table[key].name
        if key in self.signals:
            return self.signals[key].name
        if key in self.routines:
            return self.routines[key].name
        return key

    def undefined(self, name: str, span: Span, scope: dict[str, Sym], what: str = "") -> CheckError:
        if rapid_names.refused(name):
            return self.err(rapid_names.refused(name), span)
        kind = rapid_names.kind_of(name)
        if kind == "data":
            return self.err(f"{name} is RAPID predefined data that rapid_like does not define", span)
        if kind is not None:
            return self.err(f"{name} is a RAPID {kind} that rapid_like does not implement", span)
        close = difflib.get_close_matches(name.lower(), self.all_names(scope), n=1)
        hint = ""
        if close:
            hint = f" (did you mean {self.spelling(close[0], scope)}?)"
        return self.err(f"undefined name '{name}'{what}: it is not declared data, a routine or a configured "
                        f"I/O signal{hint}", span)

    def lookup(self, name: str, scope: dict[str, Sym]) -> Sym | None:
        key = name.lower()
        if key in scope:
            return scope[key]
        if key in self.globals:
            return self.globals[key]
        if key in self.predefined:
            return self.predefined[key]
        if key == "errno":
            return Sym("data", "errnum", "CONST")
        if key in B.PREDEFINED_VARS:
            return Sym("data", B.PREDEFINED_VARS[key], "VAR", name=key)
        if key in self.signals:
            return Sym("signal", "num", "CONST", self.signals[key])
        if self.infer and len(name) > 2 and name[:2].lower() in _SIGNAL_PREFIXES and \
                (name[2] in "_0123456789" or name[2].isupper() or name[:2].isupper()):
            info = self.infer_signal(name, _SIGNAL_PREFIXES[name[:2].lower()])
            return Sym("signal", "num", "CONST", info)
        return None

    def may_be_signal(self, name: str, scope: dict[str, Sym]) -> bool:
        """Without an I/O configuration, may an undeclared name used as a value be a digital input? Not
        when it is a routine, a RAPID name, or a near miss of a declared name (a misspelling)."""
        key = name.lower()
        if key in self.routines or key in B.FUNCTIONS or key in B.INSTRUCTIONS or rapid_names.kind_of(key):
            return False
        declared = [k for k in self.all_names(scope) if k not in self.signals]
        return not difflib.get_close_matches(key, declared, n=1, cutoff=0.75)

    def infer_signal(self, name: str, kind: str, span: Span | None = None) -> SignalInfo:
        info = SignalInfo(name, kind)
        self.signals[name.lower()] = info
        self.inferred.append(info)
        self.warn(span or self.task.span, f"{name} is not a configured I/O signal: taken as {a_(kind)} from its use "
                                          f"(configure the I/O with --io or in the station)")
        return info

    def warn(self, span: Span | None, message: str) -> None:
        if span is not None:
            self.warnings.append((span, message))

    def check_type_name(self, t: str, span: Span, allow_signals: bool = False) -> None:
        if t == "switch":
            return
        arr = split_array_type(t)
        if arr:
            t = arr[0]
        if t not in KNOWN_TYPES and rapid_names.refused(t):
            raise self.err(rapid_names.refused(t), span)
        if t not in KNOWN_TYPES or (t in SIGNAL_TYPES and not allow_signals):
            close = difflib.get_close_matches(t, sorted(KNOWN_TYPES), n=1)
            hint = f" (did you mean {close[0]}?)" if close else ""
            if t in SIGNAL_TYPES:
                raise self.err(f"signals are configured in the controller's I/O, not declared as data: "
                               f"{t} can only be a parameter type", span)
            raise self.err(f"unknown data type '{t}'{hint}", span)

    def decl_type(self, d: n.DataDecl, scope: dict[str, Sym]) -> str:
        """A declaration's type; `num{}` etc. for arrays, whose sizes must be nums."""
        self.check_type_name(d.type, d.type_span)
        for e in d.dims:
            self.expect_type(e, "num", scope, what="an array size")
        return array_type(d.type, len(d.dims)) if d.dims else d.type

    # ---- module --------------------------------------------------------------------------------
    def run(self) -> None:
        self.define_records()
        # Every module's names first (a module may use what a later one declares), each module seeing
        # the task's global names and its own LOCAL ones.
        task_routines: dict[str, n.Routine] = {}
        task_data: dict[str, tuple[Sym, n.DataDecl]] = {}
        local_routines: dict[str, dict[str, n.Routine]] = {m.name: {} for m in self.task.modules}
        local_data: dict[str, dict[str, tuple[Sym, n.DataDecl]]] = {m.name: {} for m in self.task.modules}
        names = [m.name.lower() for m in self.task.modules]
        for m in self.task.modules:
            if names.count(m.name.lower()) > 1 and m.name != "<anonymous>":
                raise self.err(f"module {m.name} is loaded twice", m.span)
            for r in m.routines:
                table = local_routines[m.name] if r.local else task_routines
                first = table.get(r.key) or local_routines[m.name].get(r.key) or \
                    (task_routines.get(r.key) if r.local else None)
                if first is not None and (first.local == r.local or first.module == m.name):
                    where = f"line {first.span.line}" if first.span.file == r.span.file else str(first.span)
                    raise self.err(f"routine {r.name} is declared twice (first on {where})", r.span)
                table[r.key] = r
            for d in m.data:
                self.check_type_name(d.type, d.type_span)
                sym = Sym("data", array_type(d.type, len(d.dims)) if d.dims else d.type, d.storage, name=d.name)
                table = local_data[m.name] if d.local else task_data
                first_d = table.get(d.key) or local_data[m.name].get(d.key)
                if first_d is not None:
                    where = f"line {first_d[1].span.line}" if first_d[1].span.file == d.span.file else \
                        str(first_d[1].span)
                    if d.storage == "PERS" and first_d[1].storage == "PERS" and not d.local and \
                            first_d[1].module != m.name and first_d[0].type == sym.type:
                        continue  # a PERS declared in several modules is one persistent
                    raise self.err(f"{d.name} is declared twice (first on {where})", d.span)
                if d.key in task_routines or d.key in local_routines[m.name]:
                    raise self.err(f"{d.name} is declared twice (also a routine)", d.span)
                if d.key in self.signals:
                    raise self.err(f"{d.name} is already a configured I/O signal", d.span)
                table[d.key] = (sym, d)
        self.routines = dict(task_routines)
        self.infer_signals_from_calls()
        self.check_signal_names()
        for m in self.task.modules:
            self.routines = {**task_routines, **local_routines[m.name]}
            self.globals = {k: v[0] for k, v in {**task_data, **local_data[m.name]}.items()}
            for d in m.data:
                for e in d.dims:
                    self.expect_type(e, "num", {}, what="an array size")
                if d.init is not None:
                    self.expect_type(d.init, self.globals[d.key].type, {})
            for r in m.routines:
                self.routine(r)
        self.routines = dict(task_routines)
        self.globals = {k: v[0] for k, v in task_data.items()}

    def define_records(self) -> None:
        seen: dict[str, n.RecordDecl] = {}
        for rec in self.task.records:
            if rec.key in BUILTIN_RECORDS or rec.key in KNOWN_TYPES - set(seen) and rec.key not in RECORDS:
                raise self.err(f"RECORD {rec.name}: {rec.key} is a RAPID data type already", rec.span)
            if rec.key in seen:
                raise self.err(f"RECORD {rec.name} is declared twice (first on {seen[rec.key].span})", rec.span)
            fields = [f.lower() for f, _, _ in rec.fields]
            for fname, _, fspan in rec.fields:
                if fields.count(fname.lower()) > 1:
                    raise self.err(f"RECORD {rec.name} has two components named {fname}", fspan)
            seen[rec.key] = rec
        define_records([(rec.key, [(f, t) for f, t, _ in rec.fields]) for rec in self.task.records])
        for rec in self.task.records:
            for fname, ftype, fspan in rec.fields:
                self.check_type_name(ftype, fspan)
                if ftype == rec.key:
                    raise self.err(f"RECORD {rec.name} cannot contain itself (component {fname})", fspan)

    def infer_signals_from_calls(self) -> None:
        """Without an I/O configuration, a name passed where a built-in takes a signal (SetDO x, WaitDI x,
        DOutput(x), ...) and declared nowhere is a signal of that kind."""
        if not self.infer:
            return
        declared = {d.key for d in self.task.data} | {r.key for r in self.task.routines}
        for r in self.task.routines:
            declared |= {q.key for p in r.params for q in (p, *p.alternatives)}
            declared |= {s.decl.key for s in _walk_stmts(r.body + (r.error_handler or [])) if isinstance(s, n.LocalDecl)}
        for r in self.task.routines:
            for name, args, params in _builtin_calls(r):
                bound, msg, _ = B.match_args(params, args)
                if msg:
                    continue
                table = B.param_table(params)
                for key, a in bound.items():
                    kind = SIGNAL_TYPES.get(table[key].type)
                    if kind and isinstance(a.value, n.Name) and a.value.key not in declared and \
                            a.value.key not in self.signals and a.value.key not in self.predefined:
                        self.infer_signal(a.value.name, kind, a.value.span)

    def check_signal_names(self) -> None:
        """A configured signal's name must not be taken by anything else the program can name: a
        routine of the program, predefined data (reg1, v100, tool0, fine, ERRNO...), a built-in
        instruction or function, or a reserved word. (Declared data is checked with the data.)"""
        for key, sig in self.signals.items():
            what = f"the configured I/O signal {sig.name} ({sig.kind})"
            if key in self.routines:
                r = self.routines[key]
                raise self.err(f"{r.kind} {r.name} has the name of {what}: rename one of them", r.span)
            if key in self.predefined or key in B.PREDEFINED_VARS or key == "errno":
                raise self.err(f"{what} has the name of the predefined data {_proper_data(key)}: rename the "
                               f"signal", None)
            if key in B.INSTRUCTIONS or key in B.FUNCTIONS:
                kind = "instruction" if key in B.INSTRUCTIONS else "function"
                raise self.err(f"{what} has the name of the built-in {kind} {_proper(key)}: rename the signal",
                               None)
            if key.upper() in KEYWORDS:
                raise self.err(f"{what} is the reserved word {key.upper()}: rename the signal", None)

    def routine(self, r: n.Routine) -> None:
        scope: dict[str, Sym] = {}
        if r.kind == "TRAP" and r.params:
            raise self.err(f"TRAP {r.name} takes no parameters", r.span)
        if r.return_type:
            self.check_type_name(r.return_type, r.span)
        for p in r.params:
            for q in [p, *p.alternatives]:
                self.check_type_name(q.type, q.span, allow_signals=True)
                if q.key in scope:
                    raise self.err(f"parameter {q.name} is declared twice", q.span)
                kind = "switch" if q.type == "switch" else "param"
                if q.type in SIGNAL_TYPES:
                    scope[q.key] = Sym("signal", "num", "CONST", SignalInfo(q.name, SIGNAL_TYPES[q.type]),
                                       optional=q.optional)
                else:
                    scope[q.key] = Sym(kind, q.type, "CONST" if kind == "switch" else "VAR", name=q.name,
                                       optional=q.optional)
        self.current = r
        self.labels: list[dict[str, n.Label]] = []
        self.all_labels = {lab.name.lower() for lab in _walk_labels(r.body)}
        seen: dict[str, n.Label] = {}
        for lab in _walk_labels(r.body + (r.error_handler or [])):
            if lab.name.lower() in seen:
                raise self.err(f"label {lab.name} is declared twice in {r.name}", lab.span)
            seen[lab.name.lower()] = lab
        self.block(r.body, scope, in_handler=False)
        for e in r.error_list or []:
            self.expect_type(e, "errnum", scope, what="an ERROR list")
        if r.error_handler is not None:
            self.block(r.error_handler, scope, in_handler=True)
        if r.undo is not None:
            self.block(r.undo, scope, in_handler=False)
        if r.kind == "FUNC" and not any(isinstance(s, n.Return)
                                        for s in _walk_stmts(r.body + (r.error_handler or []))):
            raise self.err(f"FUNC {r.name} has no RETURN: a function must return its value with "
                           f"RETURN value;", r.span)

    # ---- statements ----------------------------------------------------------------------------
    def block(self, stmts: list[n.Stmt], scope: dict[str, Sym], in_handler: bool) -> None:
        labels = {s.name.lower(): s for s in stmts if isinstance(s, n.Label)}
        self.labels.append(labels)
        try:
            for s in stmts:
                self.stmt(s, scope, in_handler)
        finally:
            self.labels.pop()

    def stmt(self, s: n.Stmt, scope: dict[str, Sym], h: bool) -> None:
        if isinstance(s, n.LocalDecl):
            d = s.decl
            dtype = self.decl_type(d, scope)
            if d.key in scope:
                raise self.err(f"{d.name} is declared twice in {self.current.name}", d.span)
            if d.init is not None:
                self.expect_type(d.init, dtype, scope)
            scope[d.key] = Sym("data", dtype, d.storage, name=d.name)
        elif isinstance(s, n.Assign):
            ttype = self.assign_target(s.target, scope)
            self.expect_type(s.value, ttype, scope)
        elif isinstance(s, n.ProcCall):
            self.proc_call(s, scope)
        elif isinstance(s, n.If):
            for cond, body in s.branches:
                self.expect_type(cond, "bool", scope, what="an IF condition")
                self.block(body, scope, h)
            if s.orelse is not None:
                self.block(s.orelse, scope, h)
        elif isinstance(s, n.While):
            self.expect_type(s.cond, "bool", scope, what="a WHILE condition")
            self.block(s.body, scope, h)
        elif isinstance(s, n.For):
            for e in (s.start, s.stop, s.step):
                if e is not None:
                    self.expect_type(e, "num", scope, what="a FOR bound")
            # the loop variable hides data, a parameter or an outer loop variable of the same name in the loop
            inner = dict(scope)
            inner[s.var.lower()] = Sym("loop", "num", "CONST", name=s.var)
            self.block(s.body, inner, h)
            for k, v in inner.items():  # declarations inside the loop body stay visible after it
                if k != s.var.lower() and k not in scope:
                    scope[k] = v
        elif isinstance(s, n.Test):
            t = self.value_type(s.subject, scope)
            for values, body in s.cases:
                for v in values:
                    self.expect_type(v, t, scope)
                self.block(body, scope, h)
            if s.default is not None:
                self.block(s.default, scope, h)
        elif isinstance(s, n.Return):
            r = self.current
            if r.kind == "PROC" and s.value is not None:
                raise self.err(f"a PROC returns no value: write RETURN; in {r.name}", s.value.span)
            if r.kind == "FUNC":
                if s.value is None:
                    raise self.err(f"RETURN in FUNC {r.name} needs {a_(r.return_type)} value", s.span)
                self.expect_type(s.value, r.return_type, scope)
        elif isinstance(s, (n.Retry, n.TryNext)):
            if not h:
                word = "RETRY" if isinstance(s, n.Retry) else "TRYNEXT"
                raise self.err(f"{word} is only allowed in an ERROR handler", s.span)
        elif isinstance(s, n.Raise):
            if s.errno is None and not h:
                raise self.err("RAISE without an error number is only allowed in an ERROR handler", s.span)
            if s.errno is not None:
                self.expect_type(s.errno, "errnum", scope)
        elif isinstance(s, n.Goto):
            if not any(s.label.lower() in level for level in self.labels):
                inside = s.label.lower() in self.all_labels
                raise self.err(f"GOTO {s.label}: " + ("the label is inside another IF, WHILE, FOR or TEST; GOTO "
                                                      "cannot jump into one" if inside else
                                                      f"no label {s.label}: in {self.current.name}"), s.label_span)
        elif isinstance(s, n.Connect):
            t = self.assign_target(s.target, scope)
            if t is not None and base_type(t) != "num":
                raise self.err(f"CONNECT needs an intnum variable, {s.target.text} is {a_(t)}", s.target.span)
            r = self.routines.get(s.trap.lower())
            if r is None:
                raise self.undefined(s.trap, s.trap_span, scope, " (a TRAP routine)")
            if r.kind != "TRAP":
                raise self.err(f"CONNECT ... WITH {r.name}: {r.name} is a {r.kind}, not a TRAP routine", s.trap_span)
        elif isinstance(s, (n.Exit, n.Label)):
            pass
        else:  # pragma: no cover - the parser makes no other statements
            raise self.err(f"unknown statement {type(s).__name__}", s.span)

    def assign_target(self, target: n.Expr, scope: dict[str, Sym]) -> str | None:
        root = target
        while isinstance(root, (n.Component, n.Index)):
            root = root.obj
        assert isinstance(root, n.Name)
        sym = self.lookup(root.name, scope)
        if sym is None:
            if root.key in self.routines:
                raise self.err(f"{root.name} is a routine, not data", root.span)
            raise self.undefined(root.name, root.span, scope)
        if sym.kind == "signal":
            kind = sym.signal.kind if sym.signal else "signal"
            hint = {"DO": "SetDO", "AO": "SetAO", "GO": "SetGO"}.get(kind)
            raise self.err(f"{root.name} is {a_(kind)} signal and cannot be assigned"
                           + (f": use {hint} {root.name}, value;" if hint else ""), root.span)
        if sym.storage == "CONST":
            what = "the FOR loop variable" if sym.kind == "loop" else "the constant"
            if root.key == "errno":
                what = "the system variable"
            raise self.err(f"cannot assign to {what} {root.name}", root.span)
        return self.value_type(target, scope)

    def proc_call(self, s: n.ProcCall, scope: dict[str, Sym]) -> None:
        key = s.key
        if key in self.routines:
            r = self.routines[key]
            if r.kind == "TRAP":
                raise self.err(f"{r.name} is a TRAP routine: it runs on an interrupt (CONNECT ... WITH {r.name}), "
                               f"it cannot be called", s.span)
            if r.kind != "PROC":
                raise self.err(f"{r.name} is a FUNC: call it in an expression, e.g. x := {r.name}(...);", s.span)
            self.args(s.name, r.params, s.args, s.span, scope)
        elif key in B.INSTRUCTIONS:
            self.args(s.name, B.INSTRUCTIONS[key], s.args, s.span, scope)
            self.approximations(s)
        elif key in B.FUNCTIONS:
            raise self.err(f"{s.name} is a function: use its value, e.g. x := {s.name}(...);", s.span)
        else:
            sym = self.lookup(s.name, scope)
            if sym is not None:
                raise self.err(f"{s.name} is data, not an instruction (did you mean {s.name} := ...;?)", s.span)
            if key in _UNSUPPORTED:
                raise self.err(f"{s.name} is not supported by rapid_like: {_UNSUPPORTED[key]}", s.span)
            if rapid_names.refused(s.name):
                raise self.err(rapid_names.refused(s.name), s.span)
            kind = rapid_names.kind_of(key)
            if kind is not None:
                raise self.err(f"{s.name} is a RAPID {kind} that rapid_like does not implement", s.span)
            close = difflib.get_close_matches(key, list(self.routines) + list(B.INSTRUCTIONS), n=1)
            hint = ""
            if close:
                hint = f" (did you mean {self.routines[close[0]].name if close[0] in self.routines else _proper(close[0])}?)"
            raise self.err(f"unknown instruction or procedure '{s.name}'{hint}", s.span)

    def args(self, name: str, params: list[n.Param], args: list[n.Arg], span: Span,
             scope: dict[str, Sym]) -> None:
        bound, msg, bad = B.match_args(params, args)
        if msg:
            raise self.err(f"{name}: {msg}", bad.span if bad else span)
        every = B.param_table(params)
        for key, a in bound.items():
            p = every[key]
            if a.value is None:
                continue
            if a.conditional:
                self.conditional_arg(name, p, a, scope)
                continue
            if p.type in SIGNAL_TYPES:
                self.signal_arg(name, p, a.value, scope)
            elif p.type == "any":
                if name.lower() == "dim":
                    t = self.value_type(a.value, scope)
                    if t is not None and not split_array_type(t):
                        raise self.err(f"Dim needs an array, {a.value.text} is {a_(t)}", a.value.span)
                elif name.lower() == "present":
                    if not (isinstance(a.value, n.Name) and self.lookup(a.value.name, scope)
                            and self.lookup(a.value.name, scope).kind in ("param", "switch", "signal")
                            and a.value.key in scope):
                        raise self.err("Present needs the name of an optional parameter of this routine",
                                       a.value.span)
                else:
                    self.value_type(a.value, scope)
            elif p.mode in ("INOUT", "VAR", "PERS"):
                if not isinstance(a.value, (n.Name, n.Component, n.Index)):
                    raise self.err(f"{name}: argument {p.name} must be a variable (it is {p.mode})", a.value.span)
                t = self.assign_target(a.value, scope)
                if t is not None and base_type(t) != base_type(p.type):
                    raise self.err(f"type mismatch: {name} argument {p.name} must be {a_(p.type)} variable, "
                                   f"{a.value.text} is {t}", a.value.span)
            else:
                self.expect_type(a.value, p.type, scope, what=f"{name} argument {p.name}")

    def conditional_arg(self, name: str, p: n.Param, a: n.Arg, scope: dict[str, Sym]) -> None:
        """`\\Name?Param`: Param must be an optional parameter of the calling routine, of the type
        that Name takes (any optional parameter for a switch: its presence is passed on)."""
        assert isinstance(a.value, n.Name)
        ref = a.value
        sym = scope.get(ref.key)
        what = f"{name}: \\{a.name}?{ref.name}"
        if sym is None or not sym.optional:
            if sym is None and self.lookup(ref.name, scope) is None:
                raise self.undefined(ref.name, ref.span, scope)
            raise self.err(f"{what}: a conditional argument passes on an optional parameter of "
                           f"{self.current.name}, and {ref.name} is not one", ref.span)
        if p.type == "switch":
            return
        if sym.kind == "switch":
            raise self.err(f"{what}: {ref.name} is a switch, {name}'s \\{p.name} takes {a_(p.type)}", ref.span)
        if p.type in SIGNAL_TYPES:
            if sym.kind != "signal" or sym.signal is None or sym.signal.kind != SIGNAL_TYPES[p.type]:
                raise self.err(f"{what}: {name}'s \\{p.name} takes {a_(SIGNAL_TYPES[p.type])} signal", ref.span)
            return
        if sym.type is not None and p.type != "any" and base_type(sym.type) != base_type(p.type):
            raise self.err(f"type mismatch: {what}: \\{p.name} takes {a_(p.type)}, {ref.name} is {a_(sym.type)}",
                           ref.span)

    def approximations(self, s: n.ProcCall) -> None:
        """Warnings for what an instruction asks of the controller that the simulation only approximates."""
        key = s.key
        word = B.PROPER_NAMES.get(key, s.name)
        if key in _APPROXIMATE:
            self.warn(s.span, f"{word}: {_APPROXIMATE[key]}")
        if key in ("movejsync", "movelsync"):
            proc = next((a.value for a in s.args if a.key == "procname" or (not a.optional and isinstance(
                a.value, n.StrLit) and a is s.args[-1])), None)
            if isinstance(proc, n.StrLit) and not isinstance(self.routines.get(proc.value.lower()), n.Routine):
                raise self.err(f"{s.name}: no PROC named {proc.value!r} to call at the point", proc.span)
            self.warn(s.span, f"{word}: the procedure runs when the robot is at the point (not in the middle "
                              f"of the corner path)")
        if key in ("movej", "movel", "movec", "moveabsj", "movejdo", "moveldo", "movejsync", "movelsync", "triggl",
                   "triggj"):
            zone = next((a for a in s.args if a.value is not None and not a.optional and a.value.text.lower() in
                         B.zone_names()), None)
            if any(a.optional and a.key == "conc" for a in s.args):
                self.warn(s.span, f"{word} \\Conc: the program goes on at once and the next motion waits for "
                                  f"this one; offline without --station every motion ends at once")
            if zone is not None and zone.value.text.lower() != "fine" and key not in ("movej", "movel", "movec",
                                                                                        "moveabsj"):
                self.warn(zone.span, f"{word} with zone {zone.value.text}: the motion stops at its point (the "
                                     f"instruction acts there), as with fine")

    def signal_arg(self, name: str, p: n.Param, e: n.Expr, scope: dict[str, Sym]) -> None:
        want = SIGNAL_TYPES[p.type]
        if not isinstance(e, n.Name):
            raise self.err(f"{name}: argument {p.name} must be {a_(want)} signal, found {e.text}", e.span)
        sym = self.lookup(e.name, scope)
        if sym is None and self.infer and not self.routines.get(e.key):
            self.infer_signal(e.name, want, e.span)
            sym = self.lookup(e.name, scope)
        if sym is None:
            raise self.undefined(e.name, e.span, scope)
        if sym.kind != "signal" or sym.signal is None:
            raise self.err(f"{name}: argument {p.name} must be {a_(want)} signal, {e.name} is "
                           f"{sym.type} data", e.span)
        if sym.signal.kind != want:
            raise self.err(f"{name}: {e.name} is {a_(sym.signal.kind)} signal, {name} needs {a_(want)}", e.span)

    # ---- expressions ---------------------------------------------------------------------------
    def expect_type(self, e: n.Expr, want: str | None, scope: dict[str, Sym], what: str = "") -> None:
        got = self.value_type(e, scope)
        if want is None or got is None:
            return
        if not self.compatible(want, got, e, scope):
            where = f" in {what}" if what else ""
            raise self.err(f"type mismatch{where}: expected {want}, found {got}"
                           + (f" ({e.text})" if len(e.text) <= 40 else ""), e.span)

    def compatible(self, want: str, got: str, e: n.Expr, scope: dict[str, Sym]) -> bool:
        want, got = base_type(want), base_type(got)
        if want == got:
            return True
        if got == "aggregate" and split_array_type(want):
            assert isinstance(e, n.Aggregate)
            elem, ndims = split_array_type(want)  # type: ignore[misc]
            inner = elem if ndims == 1 else array_type(elem, ndims - 1)
            for item in e.items:
                it = "aggregate" if isinstance(item, n.Aggregate) else self.value_type(item, scope)
                if it is not None and not self.compatible(inner, it, item, scope):
                    raise self.err(f"type mismatch in an array element: expected {inner}, found {it}", item.span)
            return True
        if got == "aggregate" and want in RECORDS:
            assert isinstance(e, n.Aggregate)
            spec = RECORDS[want]
            if len(spec) != len(e.items):
                raise self.err(f"type mismatch: {a_(want)} has {len(spec)} components "
                               f"({', '.join(f for f, _ in spec)}), the aggregate has {len(e.items)}", e.span)
            for (fname, ftype), item in zip(spec, e.items):
                it = self.value_type(item, scope) if not isinstance(item, n.Aggregate) else "aggregate"
                if isinstance(item, n.Aggregate):
                    if not self.compatible(ftype, "aggregate", item, scope):
                        return False
                elif it is not None and not self.compatible(ftype, it, item, scope):
                    raise self.err(f"type mismatch in component {fname} of the {want}: expected {ftype}, "
                                   f"found {it}", item.span)
            return True
        return False

    def value_type(self, e: n.Expr, scope: dict[str, Sym]) -> str | None:
        if isinstance(e, n.NumLit):
            return "num"
        if isinstance(e, n.StrLit):
            return "string"
        if isinstance(e, n.BoolLit):
            return "bool"
        if isinstance(e, n.Aggregate):
            for item in e.items:
                if not isinstance(item, n.Aggregate):
                    self.value_type(item, scope)
                else:
                    self.value_type(item, scope)
            return "aggregate"
        if isinstance(e, n.Name):
            sym = self.lookup(e.name, scope)
            if sym is None and self.infer and self.may_be_signal(e.name, scope):
                self.infer_signal(e.name, "DI", e.span)
                sym = self.lookup(e.name, scope)
            if sym is None:
                if e.key in self.routines or e.key in B.FUNCTIONS:
                    raise self.err(f"{e.name} is a routine, not a value (a function call needs "
                                   f"parentheses: {e.name}(...))", e.span)
                raise self.undefined(e.name, e.span, scope)
            if sym.kind == "switch":
                raise self.err(f"{e.name} is a switch: test it with Present({e.name})", e.span)
            return sym.type
        if isinstance(e, n.Index):
            t = self.value_type(e.obj, scope)
            for i in e.indices:
                self.expect_type(i, "num", scope, what="an array index")
            if t is None:
                return None
            arr = split_array_type(t)
            if not arr:
                raise self.err(f"{e.obj.text} is {a_(t)}, not an array: it cannot be indexed", e.indices[0].span)
            elem, ndims = arr
            if len(e.indices) != ndims:
                raise self.err(f"{e.obj.text} has {ndims} dimension{'s' if ndims > 1 else ''}, "
                               f"{len(e.indices)} ind{'ices' if len(e.indices) > 1 else 'ex'} given",
                               e.indices[0].span)
            return elem
        if isinstance(e, (n.Component, n.Index)) and isinstance(e.obj, n.Name) and \
                self.lookup(e.obj.name, scope) is None and e.obj.key not in self.routines:
            raise self.undefined(e.obj.name, e.obj.span, scope)  # a record or an array, never a signal
        if isinstance(e, n.Component):
            t = self.value_type(e.obj, scope)
            if t is None:
                return None
            t = base_type(t)
            if split_array_type(t):
                raise self.err(f"{e.obj.text} is an array: index it first, e.g. {e.obj.text}{{1}}.{e.field}",
                               e.field_span)
            if t not in RECORDS:
                raise self.err(f"{e.obj.text} is {a_(t)} and has no components", e.field_span)
            for fname, ftype in RECORDS[t]:
                if fname == e.field.lower():
                    return ftype
            raise self.err(f"{a_(t)} has no component '{e.field}' (it has "
                           f"{', '.join(f for f, _ in RECORDS[t])})", e.field_span)
        if isinstance(e, n.Unary):
            t = self.value_type(e.operand, scope)
            if e.op == "NOT":
                self.operand(e.operand, t, "bool", "NOT")
                return "bool"
            if t is not None and base_type(t) not in ("num", "pos"):
                raise self.err(f"type mismatch: unary {e.op} needs a num, found {t}", e.operand.span)
            return t and base_type(t)
        if isinstance(e, n.Binary):
            return self.binary_type(e, scope)
        if isinstance(e, n.Call):
            return self.call_type(e, scope)
        raise self.err(f"unknown expression {type(e).__name__}", e.span)  # pragma: no cover

    def operand(self, e: n.Expr, got: str | None, want: str, op: str) -> None:
        if got is not None and base_type(got) != want:
            raise self.err(f"type mismatch: {op} needs {want} operands, found {got}", e.span)

    def binary_type(self, e: n.Binary, scope: dict[str, Sym]) -> str | None:
        lt = self.value_type(e.left, scope)
        rt = self.value_type(e.right, scope)
        lb, rb = (base_type(lt) if lt else None), (base_type(rt) if rt else None)
        op = e.op
        if op in ("AND", "OR", "XOR"):
            self.operand(e.left, lt, "bool", op)
            self.operand(e.right, rt, "bool", op)
            return "bool"
        if op in ("=", "<>"):
            if lb and rb and lb != rb and "aggregate" not in (lb, rb):
                raise self.err(f"type mismatch: cannot compare {lt} with {rt} using {op}", e.op_span)
            return "bool"
        if op in ("<", "<=", ">", ">="):
            self.operand(e.left, lt, "num", op)
            self.operand(e.right, rt, "num", op)
            return "bool"
        if op == "+" and (lb == "string" or rb == "string"):
            self.operand(e.left, lt, "string", "string +")
            self.operand(e.right, rt, "string", "string +")
            return "string"
        if op in ("+", "-") and (lb == "pos" or rb == "pos"):
            for side, t in ((e.left, lt), (e.right, rt)):
                if t == "aggregate":
                    self.expect_type(side, "pos", scope)  # `p + [0, 0, 100]`: the aggregate is a pos
                else:
                    self.operand(side, t, "pos", f"pos {op}")
            return "pos"
        if op == "*" and (lb in ("pos", "orient") or rb in ("pos", "orient")):
            if lb == "orient" or rb == "orient":
                self.operand(e.left, lt, "orient", "orient *")
                self.operand(e.right, rt, "orient", "orient *")
                return "orient"
            if lb == "pos" and rb == "pos":
                return "pos"
            return "pos"
        self.operand(e.left, lt, "num", op)
        self.operand(e.right, rt, "num", op)
        return "num"

    def call_type(self, e: n.Call, scope: dict[str, Sym]) -> str | None:
        key = e.key
        if key in self.routines:
            r = self.routines[key]
            if r.kind != "FUNC":
                raise self.err(f"{r.name} is a PROC and returns no value: call it as an instruction", e.span)
            self.args(e.name, r.params, e.args, e.span, scope)
            return r.return_type
        if key in B.FUNCTIONS:
            params, rtype = B.FUNCTIONS[key]
            self.args(e.name, params, e.args, e.span, scope)
            if key in ("calcjointt", "calcrobt"):
                self.warn(e.span, f"{B.PROPER_NAMES[key]}: there is no kinematics model here: it returns the robot's "
                                  f"present {'joints' if key == 'calcjointt' else 'position'}")
            return rtype
        if key in B.INSTRUCTIONS:
            raise self.err(f"{e.name} is an instruction and returns no value", e.span)
        if rapid_names.refused(e.name):
            raise self.err(rapid_names.refused(e.name), e.span)
        kind = rapid_names.kind_of(key)
        if kind is not None:
            raise self.err(f"{e.name} is a RAPID {kind} that rapid_like does not implement", e.span)
        close = difflib.get_close_matches(key, list(self.routines) + list(B.FUNCTIONS), n=1)
        hint = ""
        if close:
            hint = f" (did you mean {self.routines[close[0]].name if close[0] in self.routines else _proper(close[0])}?)"
        raise self.err(f"unknown function '{e.name}'{hint}", e.span)


def _walk_stmts(stmts: list[n.Stmt]):
    """Every statement of `stmts`, with those nested in IF, WHILE, FOR and TEST."""
    for s in stmts:
        yield s
        if isinstance(s, n.If):
            for _, body in s.branches:
                yield from _walk_stmts(body)
            yield from _walk_stmts(s.orelse or [])
        elif isinstance(s, (n.While, n.For)):
            yield from _walk_stmts(s.body)
        elif isinstance(s, n.Test):
            for _, body in s.cases:
                yield from _walk_stmts(body)
            yield from _walk_stmts(s.default or [])


def _builtin_calls(r: n.Routine):
    """(name, args, signature) of every built-in instruction and function call in a routine."""
    body = r.body + (r.error_handler or []) + (r.undo or [])
    for s in _walk_stmts(body):
        if isinstance(s, n.ProcCall) and s.key in B.INSTRUCTIONS:
            yield s.name, s.args, B.INSTRUCTIONS[s.key]
        for e in _stmt_exprs(s):
            for c in _walk_exprs(e):
                if isinstance(c, n.Call) and c.key in B.FUNCTIONS:
                    yield c.name, c.args, B.FUNCTIONS[c.key][0]


def _stmt_exprs(s: n.Stmt):
    if isinstance(s, n.ProcCall):
        return [a.value for a in s.args if a.value is not None]
    if isinstance(s, n.Assign):
        return [s.target, s.value]
    if isinstance(s, n.If):
        return [c for c, _ in s.branches]
    if isinstance(s, n.While):
        return [s.cond]
    if isinstance(s, n.For):
        return [e for e in (s.start, s.stop, s.step) if e is not None]
    if isinstance(s, n.Test):
        return [s.subject] + [v for vs, _ in s.cases for v in vs]
    if isinstance(s, n.Return) and s.value is not None:
        return [s.value]
    if isinstance(s, n.LocalDecl) and s.decl.init is not None:
        return [s.decl.init]
    return []


def _walk_exprs(e: n.Expr):
    yield e
    if isinstance(e, (n.Component,)):
        yield from _walk_exprs(e.obj)
    elif isinstance(e, n.Index):
        yield from _walk_exprs(e.obj)
        for i in e.indices:
            yield from _walk_exprs(i)
    elif isinstance(e, n.Unary):
        yield from _walk_exprs(e.operand)
    elif isinstance(e, n.Binary):
        yield from _walk_exprs(e.left)
        yield from _walk_exprs(e.right)
    elif isinstance(e, n.Aggregate):
        for i in e.items:
            yield from _walk_exprs(i)
    elif isinstance(e, n.Call):
        for a in e.args:
            if a.value is not None:
                yield from _walk_exprs(a.value)


def _walk_labels(stmts: list[n.Stmt]):
    """Every label of `stmts`, nested ones included."""
    return (s for s in _walk_stmts(stmts) if isinstance(s, n.Label))


def _proper(key: str) -> str:
    return B.PROPER_NAMES.get(key, key)


def _proper_data(key: str) -> str:
    """A predefined data name as the manual writes it: `reg1`, `v100`, `ERR_DIVZERO`, `ERRNO`, `pi`."""
    return key.upper() if key.startswith("err") else key
