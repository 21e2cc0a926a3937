"""Checker: names, types and calls resolved before anything runs; every error with FILE:LINE:COL.

It builds the program's symbol tables (types, POUs, globals, the configuration's tasks and program
instances), gives every expression its data type (`Expr.ty`) and every name what it refers to
(`Name.ref`), and evaluates what must be constant (array bounds, CASE labels, initial values, task
intervals). Errors are collected, one per statement or declaration, and raised together.

Typing follows IEC 61131-3 3rd edition: an untyped literal takes the type its context needs
(range-checked: `x : SINT := 200` is an error), a value may be stored where its type widens
implicitly (INT into DINT or REAL, BYTE into WORD, REAL into LREAL), any narrowing or a change of
kind (REAL into INT, INT into BOOL, TIME into DINT) needs a conversion function; conditions are BOOL.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from . import nodes as n
from . import stdlib_fn
from . import types as ty
from .errors import CheckError, Span, StaticErrors, StError
from .stdlib_fb import STANDARD_FBS

DEFAULT_TASK = "MAIN_TASK"


@dataclass(eq=False)
class Symbol:
    name: str
    type: ty.DataType
    section: str  # VAR, VAR_INPUT, VAR_OUTPUT, VAR_IN_OUT, VAR_GLOBAL, VAR_EXTERNAL, VAR_TEMP, RESULT
    span: Span
    constant: bool = False
    retain: bool = False
    location: tuple | None = None
    init: object = None  # the initial value (a Python value), None for the type's default
    is_global: bool = False
    target: "Symbol | None" = None  # VAR_EXTERNAL: the global it names

    @property
    def attr(self) -> str:
        return "v_" + self.name.lower()


@dataclass(eq=False)
class PouInfo:
    node: n.Pou
    name: str
    kind: str
    symbols: dict[str, Symbol] = field(default_factory=dict)
    fbtype: ty.FbT | None = None
    result: ty.DataType | None = None
    params: list[Symbol] = field(default_factory=list)  # inputs, in-outs, outputs in declaration order


@dataclass(eq=False)
class TaskInfo:
    name: str
    interval: int  # ns; 0 = every scan
    priority: int
    span: Span
    order: int


@dataclass(eq=False)
class InstanceInfo:
    name: str
    pou: PouInfo
    task: str
    span: Span
    args: list[n.Arg]
    binds: list[tuple[Symbol, n.Arg]] = field(default_factory=list)


@dataclass(eq=False)
class Program:
    files: list[n.SourceFile]
    types: dict[str, ty.DataType]
    pous: dict[str, PouInfo]
    globals: dict[str, Symbol]
    tasks: list[TaskInfo]
    instances: list[InstanceInfo]
    enum_values: dict[str, list[tuple[ty.EnumT, int]]]
    configuration: str | None = None


class _Scope:
    def __init__(self, pou: PouInfo | None, checker: "Checker"):
        self.pou = pou
        self.checker = checker
        self.loops = 0
        self.eno_ok = False  # checking the whole right side of an assignment: ENO may be connected
        self.for_vars: list = []  # the control variables of the FOR loops being checked

    def lookup(self, name: str) -> Symbol | None:
        up = name.upper()
        if self.pou is not None and up in self.pou.symbols:
            s = self.pou.symbols[up]
            return s.target or s if s.section == "VAR_EXTERNAL" else s
        return self.checker.globals.get(up)


class _Quiet(CheckError):
    """A follow-on of an error already reported (a use of a variable whose type was unknown): not reported."""


ERROR_TYPE = ty.Elementary("<error>", "error")


def check(files: list[n.SourceFile]) -> Program:
    return Checker(files).run()


class Checker:
    def __init__(self, files: list[n.SourceFile]):
        self.files = files
        self.errors: list[StError] = []
        self.type_decls: dict[str, n.TypeDecl] = {}
        self.types: dict[str, ty.DataType] = {}
        self.resolving: set[str] = set()
        self.pous: dict[str, PouInfo] = {}
        self.globals: dict[str, Symbol] = {}
        self.enum_values: dict[str, list[tuple[ty.EnumT, int]]] = {}
        self.fb_builtin: dict[str, ty.FbT] = {}

    def fail(self, message: str, span: Span) -> CheckError:
        return CheckError(re.sub(r"\ba (?=[AEIO][A-Z_]*\b)", "an ", message), span)

    def guard(self, fn, *args):
        try:
            return fn(*args)
        except _Quiet:
            return None
        except CheckError as exc:
            self.errors.append(exc)
            return None

    # ---- the whole program -----------------------------------------------------------------------
    def run(self) -> Program:
        for f in self.files:
            for td in f.types:
                up = td.name.upper()
                if up in self.type_decls or up in ty.ELEMENTARY or up in STANDARD_FBS:
                    self.errors.append(self.fail(f"type '{td.name}' is declared twice (or names a standard type)", td.span))
                    continue
                self.type_decls[up] = td
            for p in f.pous:
                up = p.name.upper()
                if up in self.pous or up in STANDARD_FBS or up in ty.ELEMENTARY or up in self.type_decls:
                    self.errors.append(self.fail(f"'{p.name}' is declared twice (or names a standard type or block)",
                                                 p.name_span or p.span))
                    continue
                if p.kind == "FUNCTION" and stdlib_fn.is_standard(up):
                    self.errors.append(self.fail(f"'{p.name}' is the name of a standard function", p.name_span or p.span))
                    continue
                self.pous[up] = PouInfo(p, p.name, p.kind)
        # the order: FB and program types (a TYPE, a global or a member may be an instance of one), the
        # TYPEs, the globals (their constants may size a POU's arrays), then the POUs' variables
        for info in self.pous.values():
            if info.kind != "FUNCTION":
                info.fbtype = (ty.ProgramT if info.kind == "PROGRAM" else ty.FbT)(info.name, pou=info)
        for up in list(self.type_decls):
            self.guard(self.named_type, self.type_decls[up].name, self.type_decls[up].span)
        configs = [c for f in self.files for c in f.configurations]
        for f in self.files:
            for d in f.globals:
                self.guard(self.declare_global, d)
        for c in configs:
            for d in c.globals:
                self.guard(self.declare_global, d)
            for r in c.resources:
                for d in r.globals:
                    self.guard(self.declare_global, d)
        for info in self.pous.values():
            self.declare_pou(info)
        for info in self.pous.values():
            self.resolve_externals(info)
        for info in self.pous.values():
            self.check_body(info)
        tasks, instances, conf_name = self.configuration(configs)
        self.errors = [e for e in self.errors if not isinstance(e, _Quiet)]
        if self.errors:
            self.errors.sort(key=lambda e: (e.span.file, e.span.line, e.span.col) if e.span else ("", 0, 0))
            raise StaticErrors(self.errors)
        return Program(self.files, self.types, self.pous, self.globals, tasks, instances, self.enum_values, conf_name)

    # ---- types -----------------------------------------------------------------------------------
    def named_type(self, name: str, span: Span) -> ty.DataType:
        up = name.upper()
        if up in ty.ELEMENTARY:
            return ty.ELEMENTARY[up]
        if up in ("STRING", "WSTRING"):
            return ty.StringT(wide=up == "WSTRING")
        if up in self.types:
            return self.types[up]
        if up in self.type_decls:
            if up in self.resolving:
                raise self.fail(f"type '{name}' is defined in terms of itself", span)
            self.resolving.add(up)
            try:
                td = self.type_decls[up]
                t = self.type_of(td.spec, _Scope(None, self), type_name=td.name)
                if td.init is not None:
                    t = self.with_default(t, td.init, td.name)
                self.types[up] = t
                return t
            finally:
                self.resolving.discard(up)
        if up in STANDARD_FBS:
            return self.std_fb_type(up)
        if up in self.pous:
            info = self.pous[up]
            if info.kind == "FUNCTION":
                raise self.fail(f"'{name}' is a FUNCTION, not a type", span)
            return info.fbtype
        raise self.fail(f"unknown type '{name}'", span)

    def with_default(self, t: ty.DataType, init: n.Expr, name: str) -> ty.DataType:
        """A TYPE with an initial value: a copy of the type whose default is that value."""
        value = self.init_value(t, init, _Scope(None, self))
        if isinstance(t, ty.EnumT):
            t2 = ty.EnumT(name, t.values)
        elif isinstance(t, ty.Elementary):
            t2 = ty.Elementary(name, t.kind, t.bits, t.signed)
        elif isinstance(t, ty.SubrangeT):
            t2 = ty.SubrangeT(t.base, t.lo, t.hi)
        else:
            t2 = t
        t2.default = value
        return t2

    def std_fb_type(self, up: str) -> ty.FbT:
        if up not in self.fb_builtin:
            cls = STANDARD_FBS[up]
            fbt = ty.FbT(up, builtin=cls)
            for name, t, section in cls.MEMBERS:
                s = Symbol(name, t, section, Span("<standard>", 0, 0))
                fbt.members[name.upper()] = s
                if section in ("VAR_INPUT", "VAR_IN_OUT"):
                    fbt.inputs.append(s)
            self.fb_builtin[up] = fbt
        return self.fb_builtin[up]

    def type_of(self, spec: n.TypeSpec, scope: _Scope, type_name: str | None = None) -> ty.DataType:
        if isinstance(spec, n.NamedType):
            return self.named_type(spec.name, spec.span)
        if isinstance(spec, n.StringType):
            length = 254
            if spec.length is not None:
                length = self.const_int(spec.length, scope)
                if length < 1:
                    raise self.fail("a string's length is at least 1", spec.length.span)
            return ty.StringT(length, spec.wide)
        if isinstance(spec, n.ArraySpec):
            dims = []
            for lo_e, hi_e in spec.ranges:
                lo, hi = self.const_int(lo_e, scope), self.const_int(hi_e, scope)
                if hi < lo:
                    raise self.fail(f"array bounds {lo}..{hi}: the upper bound is below the lower", lo_e.span)
                dims.append((lo, hi))
            return ty.ArrayT(dims, self.type_of(spec.elem, scope))
        if isinstance(spec, n.StructSpec):
            st = ty.StructT(type_name or "STRUCT")
            for d in spec.fields:
                up = d.name.upper()
                if up in st.fields:
                    raise self.fail(f"member '{d.name}' is declared twice", d.span)
                ft = self.type_of(d.spec, scope)
                init = self.init_value(ft, d.init, scope) if d.init is not None else None
                st.fields[up] = (d.name, ft, init)
            return st
        if isinstance(spec, n.EnumSpec):
            et = ty.EnumT(type_name or "enumeration")
            nxt = 0
            for name, span, init in spec.values:
                if init is not None:
                    nxt = self.const_int(init, scope)
                if name.upper() in et.values:
                    raise self.fail(f"enumeration value '{name}' is declared twice", span)
                et.values[name.upper()] = (name, nxt)
                self.enum_values.setdefault(name.upper(), []).append((et, nxt))
                nxt += 1
            return et
        if isinstance(spec, n.SubrangeSpec):
            base = self.named_type(spec.base, spec.span)
            if base.kind not in ("int", "bits"):
                raise self.fail(f"a subrange needs an integer type, not {base}", spec.span)
            lo, hi = self.const_int(spec.lo, scope), self.const_int(spec.hi, scope)
            if hi < lo or lo < base.lo or hi > base.hi:
                raise self.fail(f"subrange {lo}..{hi} does not fit {base}", spec.lo.span)
            return ty.SubrangeT(base, lo, hi)
        raise AssertionError(spec)

    # ---- declarations ----------------------------------------------------------------------------
    def declare_pou(self, info: PouInfo) -> None:
        scope = _Scope(info, self)
        p = info.node
        if p.kind == "FUNCTION":
            rt = self.guard(self.type_of, p.result, scope)
            info.result = rt or ty.INT
            if rt is not None and rt.kind in ("fb", "program"):
                self.errors.append(self.fail("a FUNCTION returns data, not a function block", p.result.span))
            info.symbols[p.name.upper()] = Symbol(p.name, info.result, "RESULT", p.span)
        for d in p.decls:
            self.guard(self.declare_var, info, d, scope)

    def declare_var(self, info: PouInfo, d: n.VarDecl, scope: _Scope) -> None:
        up = d.name.upper()
        if up in info.symbols:
            raise self.fail(f"'{d.name}' is declared twice in {info.name}", d.span)
        if d.section == "VAR_EXTERNAL":
            t = self.type_of(d.spec, scope)
            s = Symbol(d.name, t, d.section, d.span, d.constant)
            info.symbols[up] = s
            s.target = self.globals.get(up)  # checked by resolve_externals; linked now for constant bounds
            return
        try:
            t = self.type_of(d.spec, scope)
        except CheckError:
            info.symbols[up] = Symbol(d.name, ERROR_TYPE, d.section, d.span)  # its uses say nothing more
            raise
        kind = info.kind
        if t.kind in ("fb", "program"):
            if t.kind == "program":
                raise self.fail(f"'{t.name}' is a PROGRAM: programs are instantiated in a CONFIGURATION", d.spec.span)
            if kind == "FUNCTION" and d.section not in ("VAR_IN_OUT",):
                raise self.fail("a FUNCTION cannot hold a function block instance (it keeps no state)", d.spec.span)
            if t.pou is info:
                raise self.fail(f"'{info.name}' cannot contain an instance of itself", d.spec.span)
            if d.init is not None:
                raise self.fail("a function block instance has no initial value here", d.init.span)
        if d.location is not None:
            self.check_location(d, t)
        init = self.init_value(t, d.init, scope) if d.init is not None else None
        s = Symbol(d.name, t, d.section, d.span, d.constant, d.retain, d.location, init)
        info.symbols[up] = s
        if d.section in ("VAR_INPUT", "VAR_IN_OUT", "VAR_OUTPUT"):
            info.params.append(s)
        if info.fbtype is not None:
            info.fbtype.members[up] = s
            if d.section in ("VAR_INPUT", "VAR_IN_OUT"):
                info.fbtype.inputs.append(s)

    def check_location(self, d: n.VarDecl, t: ty.DataType) -> None:
        area, size, _ = d.location
        want = {"X": ("bool",), "B": (8,), "W": (16,), "D": (32,), "L": (64,)}[size]
        if size == "X":
            ok = t.kind == "bool"
        else:
            ok = t.kind in ("int", "bits", "real", "time", "enum") and getattr(t, "bits", 16 if t.kind == "enum" else 0) == want[0]
        if not ok:
            raise self.fail(f"a {t} cannot be located at a {'bit' if size == 'X' else f'{want[0]}-bit'} address "
                            f"(%{area}{size}...)", d.location_span)

    def declare_global(self, d: n.VarDecl) -> None:
        up = d.name.upper()
        if up in self.globals:
            raise self.fail(f"global '{d.name}' is declared twice", d.span)
        scope = _Scope(None, self)
        t = self.type_of(d.spec, scope)
        if t.kind == "program":
            raise self.fail(f"'{t.name}' is a PROGRAM: instantiate it with PROGRAM ... WITH ...", d.spec.span)
        if d.location is not None:
            self.check_location(d, t)
        init = self.init_value(t, d.init, scope) if d.init is not None else None
        self.globals[up] = Symbol(d.name, t, "VAR_GLOBAL", d.span, d.constant, d.retain, d.location, init, True)

    def resolve_externals(self, info: PouInfo) -> None:
        for s in list(info.symbols.values()):
            if s.section != "VAR_EXTERNAL":
                continue
            s.target = None
            g = self.globals.get(s.name.upper())
            if g is None:
                self.errors.append(self.fail(f"VAR_EXTERNAL '{s.name}' names no VAR_GLOBAL", s.span))
                s.target = Symbol(s.name, s.type, "VAR_GLOBAL", s.span, is_global=True)
                continue
            if not ty.same_type(g.type, s.type) and g.type.name != s.type.name:
                self.errors.append(self.fail(f"VAR_EXTERNAL '{s.name}' is a {s.type} but the global is a {g.type}", s.span))
            if g.constant and not s.constant:
                self.errors.append(self.fail(f"global '{s.name}' is CONSTANT: declare it VAR_EXTERNAL CONSTANT", s.span))
            s.target = g

    # ---- constants and initial values ------------------------------------------------------------
    def const_value(self, e: n.Expr, scope: _Scope):
        """The value of a constant expression (literals, CONSTANT variables, enumeration values, arithmetic)."""
        if isinstance(e, n.Literal):
            self.expr(e, scope)
            return e.lit.value if e.lit.category != "enum" else e.ref_value
        if isinstance(e, n.Name):
            s = scope.lookup(e.name)
            if s is not None:
                if s.constant and s.init is not None:
                    return s.init
                raise self.fail(f"'{e.name}' is not a constant", e.span)
            vals = self.enum_values.get(e.name.upper())
            if vals and len(vals) == 1:
                return vals[0][1]
            raise self.fail(f"'{e.name}' is not a constant", e.span)
        if isinstance(e, n.Unary) and e.op in ("-", "+"):
            v = self.const_value(e.operand, scope)
            return -v if e.op == "-" else v
        if isinstance(e, n.Binary) and e.op in ("+", "-", "*", "/", "MOD"):
            a, b = self.const_value(e.left, scope), self.const_value(e.right, scope)
            if e.op in ("/", "MOD") and b == 0:
                raise self.fail("division by zero in a constant expression", e.op_span)
            if e.op == "+":
                return a + b
            if e.op == "-":
                return a - b
            if e.op == "*":
                return a * b
            if isinstance(a, int) and isinstance(b, int):
                q = abs(a) // abs(b) * (1 if (a >= 0) == (b >= 0) else -1)
                return q if e.op == "/" else a - q * b
            return a / b
        raise self.fail("expected a constant expression", e.span)

    def const_int(self, e: n.Expr, scope: _Scope) -> int:
        v = self.const_value(e, scope)
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail("expected an integer constant", e.span)
        return v

    def init_value(self, t: ty.DataType, e: n.Expr | None, scope: _Scope):
        if e is None:
            return None
        if isinstance(t, ty.ArrayT):
            if not isinstance(e, n.ArrayInit):
                raise self.fail(f"an array's initial value is a list in [ ], e.g. [1, 2, 3]", e.span)
            values = []
            for count_e, item in e.items:
                count = 1 if count_e is None else self.const_int(count_e, scope)
                v = ty.default_value(t.elem) if item is None else self.init_value(t.elem, item, scope)
                values.extend([v] * count)
            if len(values) > t.size:
                raise self.fail(f"{len(values)} initial values for an array of {t.size} elements", e.span)
            return values
        if isinstance(t, ty.StructT):
            if not isinstance(e, n.StructInit):
                raise self.fail("a structure's initial value is (member := value, ...)", e.span)
            out = {}
            for name, span, item in e.fields:
                f = t.fields.get(name.upper())
                if f is None:
                    raise self.fail(f"{t.name} has no member '{name}'", span)
                out[name.upper()] = self.init_value(f[1], item, scope)
            return out
        if isinstance(e, (n.ArrayInit, n.StructInit)):
            raise self.fail(f"a {t} takes a single initial value", e.span)
        vt = self.expr(e, scope, t)
        self.need_assignable(t, vt, e, "an initial value")
        v = self.const_value(e, scope)
        if t.kind == "real":
            v = float(v) if t.bits == 64 else ty.to_f32(float(v))
        elif t.kind == "string" and len(v) > t.length:
            v = v[:t.length]
        return v

    # ---- bodies ----------------------------------------------------------------------------------
    def check_body(self, info: PouInfo) -> None:
        scope = _Scope(info, self)
        self.stmts(info.node.body, scope)

    def stmts(self, body: list[n.Stmt], scope: _Scope) -> None:
        for st in body:
            self.guard(self.stmt, st, scope)

    def stmt(self, st: n.Stmt, scope: _Scope) -> None:
        if isinstance(st, n.Assign):
            tt = self.lvalue(st.target, scope)
            self.not_a_for_variable(st.target, scope)
            scope.eno_ok = isinstance(st.value, n.Call)  # `y := F(EN := e, x := 1, ENO => ok)`
            try:
                vt = self.expr(st.value, scope, tt)
            finally:
                scope.eno_ok = False
            self.need_assignable(tt, vt, st.value, "the assignment")
        elif isinstance(st, n.CallStmt):
            self.call(st.call, scope, statement=True)
        elif isinstance(st, n.If):
            for cond, body in st.branches:
                self.guard(self.condition, cond, scope, "IF")
                self.stmts(body, scope)
            if st.orelse is not None:
                self.stmts(st.orelse, scope)
        elif isinstance(st, n.Case):
            self.case(st, scope)
        elif isinstance(st, n.For):
            vt = self.lvalue(st.var, scope)
            self.not_a_for_variable(st.var, scope)
            if vt.kind not in ("int", "bits"):
                raise self.fail(f"a FOR loop counts with an integer variable, not a {vt}", st.var.span)
            for e in (st.start, st.end, st.step):
                if e is not None:
                    et = self.expr(e, scope, vt)
                    self.need_assignable(vt, et, e, "the FOR loop's bound")
                    try:  # a constant bound lets the compiler drop index checks the loop cannot fail
                        e.const = self.const_int(e, scope)
                    except CheckError:
                        e.const = None
            scope.loops += 1
            scope.for_vars.append(st.var.ref)
            self.stmts(st.body, scope)
            scope.for_vars.pop()
            scope.loops -= 1
        elif isinstance(st, n.While):
            self.guard(self.condition, st.cond, scope, "WHILE")
            scope.loops += 1
            self.stmts(st.body, scope)
            scope.loops -= 1
        elif isinstance(st, n.Repeat):
            scope.loops += 1
            self.stmts(st.body, scope)
            scope.loops -= 1
            self.condition(st.cond, scope, "UNTIL")
        elif isinstance(st, (n.Exit, n.Continue)):
            if scope.loops == 0:
                raise self.fail(f"{'EXIT' if isinstance(st, n.Exit) else 'CONTINUE'} outside a loop", st.span)
        elif isinstance(st, n.Return):
            pass
        else:
            raise AssertionError(st)

    def not_a_for_variable(self, e: n.Expr, scope: _Scope) -> None:
        """The standard: a FOR loop's control variable is not altered by the statements it repeats (an
        assignment, an inner FOR, an output or in-out argument)."""
        if isinstance(e, n.Name) and e.ref is not None and e.ref in scope.for_vars:
            raise self.fail(f"'{e.name}' is the control variable of the FOR loop around it: "
                            "the loop alone changes it", e.span)

    def condition(self, e: n.Expr, scope: _Scope, what: str) -> None:
        t = self.expr(e, scope, ty.BOOL)
        if t.kind != "bool":
            raise self.fail(f"the {what} condition is a {t}, not a BOOL", e.span)

    def case(self, st: n.Case, scope: _Scope) -> None:
        sel = self.expr(st.selector, scope)
        if sel.kind not in ("int", "bits", "enum"):
            raise self.fail(f"CASE selects on an integer or enumeration, not a {sel}", st.selector.span)
        seen: dict[int, Span] = {}
        for item in st.items:
            for lo, hi in item.labels:
                for e in (lo, hi):
                    if e is None:
                        continue
                    lt = self.expr(e, scope, sel)
                    if not (ty.assignable(sel, lt) or (sel.kind in ("int", "bits") and lt.kind in ("int", "bits"))):
                        raise self.fail(f"a CASE label of type {lt} for a selector of type {sel}", e.span)
                    e.const = self.const_value(e, scope)
                if hi is None:
                    v = lo.const
                    if v in seen:
                        raise self.fail(f"CASE label {v} appears twice (first on line {seen[v].line})", lo.span)
                    seen[v] = lo.span
                elif hi.const < lo.const:
                    raise self.fail(f"CASE range {lo.const}..{hi.const} is empty", lo.span)
            self.stmts(item.body, scope)
        if st.orelse is not None:
            self.stmts(st.orelse, scope)

    def need_assignable(self, target: ty.DataType, value: ty.DataType, e: n.Expr, what: str) -> None:
        if target.kind in ("fb", "program"):
            raise self.fail("a function block instance cannot be assigned", e.span)
        if not ty.assignable(target, value):
            hint = ""
            if target.kind in ("int", "bits", "real", "bool") and value.kind in ("int", "bits", "real", "bool", "time"):
                hint = f" (convert it: {value.name}_TO_{target.name})" if isinstance(value, ty.Elementary) and \
                    value not in (ty.LIT_INT, ty.LIT_REAL) and isinstance(target, ty.Elementary) else ""
            raise self.fail(f"type mismatch in {what}: a {value} cannot be stored in a {target}{hint}", e.span)
        lit = literal_int(e)
        if lit is not None and target.kind in ("int", "bits"):
            lo, hi = ty.range_of(target)
            if not lo <= lit <= hi:
                raise self.fail(f"constant {lit} is out of the range of {target} ({lo}..{hi})", e.span)

    # ---- expressions -----------------------------------------------------------------------------
    def lvalue(self, e: n.Expr, scope: _Scope) -> ty.DataType:
        """The type of an assignable expression; an error when it cannot be written."""
        if isinstance(e, n.Name):
            t = self.expr(e, scope)
            s = e.ref
            if not isinstance(s, Symbol):
                raise self.fail(f"'{e.name}' cannot be assigned (it is a constant value)", e.span)
            if s.constant:
                raise self.fail(f"'{e.name}' is CONSTANT", e.span)
            if s.location is not None and s.location[0] == "I":
                raise self.fail(f"'{e.name}' is an input (%I): the program cannot write it", e.span)
            return t
        if isinstance(e, n.Member):
            t = self.expr(e, scope)
            bt = e.base.ty
            if bt.kind in ("fb", "program"):
                s = bt.members[e.name.upper()]
                if s.section == "VAR_OUTPUT":
                    raise self.fail(f"'{e.name}' is an output of {bt.name}: only the block writes it", e.span)
            else:
                self.lvalue(e.base, scope)
            return t
        if isinstance(e, (n.Index, n.BitAccess)):
            t = self.expr(e, scope)
            self.lvalue(e.base, scope)
            return t
        if isinstance(e, n.Direct):
            if e.area == "I":
                raise self.fail("an input (%I) cannot be written", e.span)
            return self.expr(e, scope)
        raise self.fail("this cannot be assigned to", e.span)

    def expr(self, e: n.Expr, scope: _Scope, expected: ty.DataType | None = None) -> ty.DataType:
        t = self._expr(e, scope, expected)
        if t is ERROR_TYPE:
            raise _Quiet("", e.span)
        e.ty = t
        return t

    def _expr(self, e: n.Expr, scope: _Scope, expected: ty.DataType | None) -> ty.DataType:
        if isinstance(e, n.Literal):
            return self.literal(e, expected)
        if isinstance(e, n.Name):
            s = scope.lookup(e.name)
            if s is not None:
                e.ref = s
                if s.type.kind == "program":
                    raise self.fail(f"'{e.name}' is a program instance", e.span)
                return s.type
            vals = self.enum_values.get(e.name.upper())
            if vals:
                if len(vals) > 1 and isinstance(expected, ty.EnumT):
                    for et, v in vals:
                        if et is expected:
                            e.ref = ("enum", et, v)
                            return et
                if len(vals) > 1:
                    raise self.fail(f"'{e.name}' is a value of several enumerations: write Type#{e.name}", e.span)
                e.ref = ("enum", vals[0][0], vals[0][1])
                return vals[0][0]
            up = e.name.upper()
            if up in self.pous or up in STANDARD_FBS:
                raise self.fail(f"'{e.name}' is a POU, not a variable", e.span)
            raise self.fail(f"undeclared name '{e.name}'", e.span)
        if isinstance(e, n.Member):
            bt = self.expr(e.base, scope)
            up = e.name.upper()
            if isinstance(bt, ty.StructT):
                f = bt.fields.get(up)
                if f is None:
                    raise self.fail(f"{bt.name} has no member '{e.name}'", e.name_span)
                return f[1]
            if bt.kind in ("fb", "program"):
                s = bt.members.get(up)
                if s is None:
                    raise self.fail(f"{bt.name} has no member '{e.name}'", e.name_span)
                if s.section not in ("VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT") and bt.kind == "fb":
                    raise self.fail(f"'{e.name}' is internal to {bt.name}: only its inputs and outputs are "
                                    "visible outside", e.name_span)
                return s.type
            raise self.fail(f"a {bt} has no members ('.{e.name}')", e.name_span)
        if isinstance(e, n.Index):
            bt = self.expr(e.base, scope)
            if not isinstance(bt, ty.ArrayT):
                raise self.fail(f"a {bt} cannot be indexed", e.indexes[0].span)
            if len(e.indexes) != len(bt.dims):
                raise self.fail(f"the array has {len(bt.dims)} dimension{'s' if len(bt.dims) > 1 else ''}, "
                                f"indexed with {len(e.indexes)}", e.span)
            for ix, (lo, hi) in zip(e.indexes, bt.dims):
                it = self.expr(ix, scope, ty.DINT)
                if it.kind not in ("int", "bits"):
                    raise self.fail(f"an array index is an integer, not a {it}", ix.span)
                v = literal_int(ix)
                if v is not None and not lo <= v <= hi:
                    raise self.fail(f"index {v} is out of the array's bounds {lo}..{hi}", ix.span)
            return bt.elem
        if isinstance(e, n.BitAccess):
            bt = self.expr(e.base, scope)
            if bt.kind not in ("bits", "int") or bt is ty.LIT_INT:
                raise self.fail(f"bit access needs a bit string (BYTE, WORD, ...), not a {bt}", e.span)
            if e.bit >= bt.bits:
                raise self.fail(f"bit {e.bit} of a {bt}: it has bits 0 to {bt.bits - 1}", e.span)
            return ty.BOOL
        if isinstance(e, n.Direct):
            return {"X": ty.BOOL, "B": ty.ELEMENTARY["BYTE"], "W": ty.ELEMENTARY["WORD"],
                    "D": ty.ELEMENTARY["DWORD"], "L": ty.ELEMENTARY["LWORD"]}[e.size]
        if isinstance(e, n.Unary):
            t = self.expr(e.operand, scope, expected)
            if e.op == "NOT":
                if t.kind not in ("bool", "bits", "int") or t is ty.LIT_INT and expected is None:
                    raise self.fail(f"NOT needs a BOOL or a bit string, not a {t}", e.span)
                return t
            if t.kind not in ("int", "real", "time"):
                raise self.fail(f"'{e.op}' needs a number, not a {t}", e.span)
            return t
        if isinstance(e, n.Binary):
            return self.binary(e, scope, expected)
        if isinstance(e, n.Call):
            return self.call(e, scope, statement=False, expected=expected)
        if isinstance(e, (n.ArrayInit, n.StructInit)):
            raise self.fail("a list of values is only an initial value", e.span)
        raise AssertionError(e)

    def literal(self, e: n.Literal, expected: ty.DataType | None) -> ty.DataType:
        lit = e.lit
        c = lit.category
        if lit.type_name is not None and c not in ("time", "date", "tod", "dt", "enum"):
            up = lit.type_name.upper()
            t = ty.ELEMENTARY.get(up)
            if up in ("STRING", "WSTRING"):
                return ty.StringT(max(1, len(lit.value)), up == "WSTRING")
            if t is None:
                raise self.fail(f"unknown type '{lit.type_name}' in a typed literal", e.span)
            if c == "bool" and t.kind == "bool" or c == "int" and t.kind == "bool" and lit.value in (0, 1):
                return t
            if c == "int" and t.kind in ("int", "bits"):
                if not t.lo <= lit.value <= t.hi:
                    raise self.fail(f"{lit.value} is out of the range of {t} ({t.lo}..{t.hi})", e.span)
                return t
            if c in ("int", "real") and t.kind == "real":
                return t
            raise self.fail(f"'{e.lit.value}' is not a {t} literal", e.span)
        if c == "int":
            return ty.LIT_INT
        if c == "real":
            return ty.LIT_REAL
        if c == "bool":
            return ty.BOOL
        if c == "time":
            return ty.ELEMENTARY["LTIME" if lit.type_name.upper() in ("LT", "LTIME") else "TIME"]
        if c == "date":
            return ty.ELEMENTARY["DATE"]
        if c == "tod":
            return ty.ELEMENTARY["TIME_OF_DAY"]
        if c == "dt":
            return ty.ELEMENTARY["DATE_AND_TIME"]
        if c in ("string", "wstring"):
            return ty.StringT(max(1, len(lit.value)), c == "wstring")
        if c == "enum":
            et = self.types.get(lit.type_name.upper())
            if et is None and lit.type_name.upper() in self.type_decls:
                et = self.named_type(lit.type_name, e.span)
            if not isinstance(et, ty.EnumT):
                raise self.fail(f"'{lit.type_name}' is not an enumeration type", e.span)
            v = et.values.get(str(lit.value).upper())
            if v is None:
                raise self.fail(f"{et.name} has no value '{lit.value}'", e.span)
            e.ref_value = v[1]
            return et
        raise AssertionError(c)

    def binary(self, e: n.Binary, scope: _Scope, expected: ty.DataType | None) -> ty.DataType:
        op = e.op
        if op in ("AND", "OR", "XOR"):
            a = self.expr(e.left, scope, expected)
            b = self.expr(e.right, scope, expected if expected is not None else a)
            if a.kind == "bool" and b.kind == "bool":
                return ty.BOOL
            if a.kind in ("bits", "int") and b.kind in ("bits", "int"):
                return ty.common_numeric(a, b)
            raise self.fail(f"{op} needs two BOOLs or two bit strings, not {a} and {b}", e.op_span)
        if op in ("=", "<>", "<", "<=", ">", ">="):
            a = self.expr(e.left, scope)
            b = self.expr(e.right, scope, a)
            if isinstance(a, ty.EnumT) and b is not a and isinstance(e.right, n.Name):
                b = self.expr(e.right, scope, a)
            if a.kind in ("int", "bits", "real") and b.kind in ("int", "bits", "real"):
                return ty.BOOL
            if a.kind == b.kind and a.kind in ("bool", "time", "date", "tod", "dt", "string"):
                return ty.BOOL
            if isinstance(a, ty.EnumT) and a is b:
                return ty.BOOL
            raise self.fail(f"'{op}' compares values of one kind, not {a} and {b}", e.op_span)
        a = self.expr(e.left, scope, expected if expected is not None and expected.kind != "time" else None)
        b = self.expr(e.right, scope, a if a.kind != "time" else None)
        if op == "**":
            if not ty.is_numeric(a) or not ty.is_numeric(b):
                raise self.fail(f"'**' needs numbers, not {a} and {b}", e.op_span)
            if a is ty.LIT_REAL or a is ty.LIT_INT and b is ty.LIT_REAL:
                return ty.LIT_REAL  # a REAL or an LREAL, as the context needs
            if a.kind == "real":
                return a
            return ty.LREAL if b.kind == "real" else (a if a is not ty.LIT_INT else ty.LIT_INT)
        try:
            return ty.arith_type(op, a, b)
        except ty.OperandError as exc:
            raise self.fail(str(exc), e.op_span) from None

    # ---- calls -----------------------------------------------------------------------------------
    def call(self, c: n.Call, scope: _Scope, statement: bool, expected: ty.DataType | None = None) -> ty.DataType:
        if c.instance is not None:
            it = self.expr(c.instance, scope)
            if it.kind != "fb":
                raise self.fail(f"a {it} cannot be called", c.span)
            return self.fb_call(c, it, scope, statement)
        s = scope.lookup(c.name)
        up = c.name.upper()
        if s is not None:
            if s.type is ERROR_TYPE:
                raise _Quiet("", c.span)
            if s.type.kind == "fb":
                inst = n.Name(c.span, c.name)
                self.expr(inst, scope)
                c.instance = inst
                return self.fb_call(c, s.type, scope, statement)
            raise self.fail(f"'{c.name}' is a {s.type}, not a function or function block instance", c.span)
        if up in self.pous:
            info = self.pous[up]
            if info.kind != "FUNCTION":
                raise self.fail(f"'{c.name}' is a {info.kind} type: call an instance of it", c.span)
            c.target = ("fn", info)
            self.en_eno(c, scope, statement)
            self.bind_args(c, info.params, scope, f"function {info.name}")
            return info.result
        if up in STANDARD_FBS:
            raise self.fail(f"'{c.name}' is a function block type: declare an instance (t1 : {up};) and call it", c.span)
        if stdlib_fn.is_standard(up):
            self.en_eno(c, scope, statement)
            if c.eno is not None:
                raise self.fail("ENO of a standard function is not supported", c.eno.span)
            return self.std_call(c, up, scope, expected)
        if up in ("ADR", "REF", "SIZEOF", "ADRINST", "__NEW", "__DELETE"):
            raise self.fail(f"{up}: pointers and references are not supported", c.span)
        raise self.fail(f"unknown function '{c.name}' (undeclared)", c.span)

    def fb_call(self, c: n.Call, fbt: ty.FbT, scope: _Scope, statement: bool) -> ty.DataType:
        if not statement:
            raise self.fail(f"a function block call is a statement, not a value (call it, then read its outputs: "
                            f"{c.name}.Q)", c.span)
        c.target = ("fb", fbt)
        self.en_eno(c, scope, statement)
        params = [s for s in fbt.members.values() if s.section in ("VAR_INPUT", "VAR_IN_OUT", "VAR_OUTPUT")]
        self.bind_args(c, params, scope, f"{fbt.name} instance")
        return ty.BOOL

    def en_eno(self, c: n.Call, scope: _Scope, statement: bool) -> None:
        """The standard's EN input and ENO output of a call: taken out of the arguments (c.en, c.eno).
        EN FALSE: the call does not run (a function gives its type's default), ENO FALSE."""
        c.en = c.eno = None
        eno_allowed, scope.eno_ok = statement or scope.eno_ok, False  # only the outermost call of a right side
        rest = []
        for a in c.args:
            name = (a.name or "").upper()
            if name == "EN" and not a.output:
                if self.expr(a.value, scope, ty.BOOL).kind != "bool":
                    raise self.fail("EN is a BOOL", a.value.span)
                c.en = a.value
            elif name == "ENO" and a.output:
                if not eno_allowed:
                    raise self.fail("ENO of a call inside an expression is not supported: call it as a statement "
                                    "or the whole right side of an assignment", a.span)
                if self.lvalue(a.value, scope).kind != "bool":
                    raise self.fail("ENO is a BOOL", a.value.span)
                c.eno = a.value
            else:
                rest.append(a)
        c.args = rest

    def bind_args(self, c: n.Call, params: list[Symbol], scope: _Scope, what: str) -> None:
        by_name = {p.name.upper(): p for p in params}
        positional = [p for p in params]
        binds: list[tuple[Symbol, n.Arg]] = []
        used: set[str] = set()
        formal_seen = False
        for k, a in enumerate(c.args):
            if a.name is None:
                if formal_seen:
                    raise self.fail("positional arguments come before the formal ones (name := value)", a.span)
                if k >= len(positional):
                    raise self.fail(f"too many arguments for {what}", a.span)
                p = positional[k]
                if p.section == "VAR_OUTPUT":
                    raise self.fail(f"too many arguments for {what}", a.span)
            else:
                formal_seen = True
                p = by_name.get(a.name.upper())
                if p is None:
                    raise self.fail(f"{what} has no parameter '{a.name}'", a.span)
            if p.name.upper() in used:
                raise self.fail(f"parameter '{p.name}' is given twice", a.span)
            used.add(p.name.upper())
            if p.section == "VAR_OUTPUT":
                if not a.output:
                    raise self.fail(f"'{p.name}' is an output: connect it with {p.name} => variable", a.span)
                vt = self.lvalue(a.value, scope)
                self.not_a_for_variable(a.value, scope)
                if not ty.assignable(vt, p.type if not a.negated else ty.BOOL):
                    raise self.fail(f"output '{p.name}' is a {p.type}, it cannot be stored in a {vt}", a.value.span)
            else:
                if a.output:
                    raise self.fail(f"'{p.name}' is an input: give it with {p.name} := value", a.span)
                if p.section == "VAR_IN_OUT":
                    vt = self.lvalue(a.value, scope)
                    self.not_a_for_variable(a.value, scope)
                    if not ty.same_type(vt, p.type) and not ty.assignable(p.type, vt):
                        raise self.fail(f"in-out '{p.name}' is a {p.type}, not a {vt}", a.value.span)
                else:
                    vt = self.expr(a.value, scope, p.type)
                    self.need_assignable(p.type, vt, a.value, f"parameter '{p.name}'")
            binds.append((p, a))
        for p in params:
            if p.section == "VAR_IN_OUT" and p.name.upper() not in used and c.target[0] == "fn":
                raise self.fail(f"in-out '{p.name}' of {what} must be given", c.span)
        c.binds = binds

    def std_call(self, c: n.Call, up: str, scope: _Scope, expected: ty.DataType | None) -> ty.DataType:
        formals = stdlib_fn.FORMALS.get(up, ())
        values: list[n.Expr | None] = []
        for k, a in enumerate(c.args):
            if a.output:
                raise self.fail(f"{up} has no outputs", a.span)
            if a.name is None:
                values.append(a.value)
                continue
            nm = a.name.upper()
            if nm in formals:
                pos = formals.index(nm)
            elif nm == "IN" and not formals:
                pos = 0
            elif nm.startswith("IN") and nm[2:].isdigit():
                pos = int(nm[2:]) - (0 if up in ("SEL", "MUX") else 1) + (1 if up in ("SEL", "MUX") else 0)
            else:
                raise self.fail(f"{up} has no parameter '{a.name}'", a.span)
            while len(values) <= pos:
                values.append(None)
            values[pos] = a.value
        if any(v is None for v in values):
            raise self.fail(f"{up}: a parameter is missing", c.span)
        ts = []
        first = None
        for v in values:
            want = first if first is not None and first.kind not in ("bool",) else expected
            t = self.expr(v, scope, want if up not in ("SEL", "MUX") else None)
            ts.append(t)
            if first is None and t is not ty.LIT_INT and t is not ty.LIT_REAL:
                first = t
        try:
            result = stdlib_fn.signature(up, ts)
        except stdlib_fn.SignatureError as exc:
            raise self.fail(str(exc), c.span) from None
        if result is ty.LIT_INT and expected is not None and expected.kind in ("int", "bits"):
            result = expected
        elif result is ty.LIT_INT:
            result = ty.DINT
        elif result is ty.LIT_REAL:
            result = expected if expected is not None and expected.kind == "real" else ty.LREAL
        c.target = ("std", up)
        c.arg_values = values
        return result

    # ---- configuration ---------------------------------------------------------------------------
    def configuration(self, configs: list[n.Configuration]):
        tasks: list[TaskInfo] = []
        instances: list[InstanceInfo] = []
        if len(configs) > 1:
            self.errors.append(self.fail("a PLC runs one CONFIGURATION; this is a second one", configs[1].span))
        if not configs:
            programs = [p for p in self.pous.values() if p.kind == "PROGRAM"]
            if not programs:
                where = self.files[0].pous[0].span if self.files and self.files[0].pous else Span(
                    self.files[0].file if self.files else "<input>", 1, 1)
                self.errors.append(self.fail("nothing to run: no PROGRAM and no CONFIGURATION", where))
                return tasks, instances, None
            tasks.append(TaskInfo(DEFAULT_TASK, 0, 0, programs[0].node.span, 0))
            for p in programs:
                instances.append(InstanceInfo(p.name, p, DEFAULT_TASK, p.node.span, []))
            return tasks, instances, None
        conf = configs[0]
        scope = _Scope(None, self)
        names: set[str] = set()
        for r in conf.resources:
            for t in r.tasks:
                if t.name.upper() in names:
                    self.errors.append(self.fail(f"task '{t.name}' is declared twice", t.span))
                    continue
                names.add(t.name.upper())
                interval = priority = 0
                if t.single is not None:
                    self.errors.append(self.fail("event tasks (SINGLE) are not supported", t.single.span))
                if t.interval is not None:
                    try:
                        it = self.expr(t.interval, scope)
                        if it.kind != "time":
                            raise self.fail(f"a task's INTERVAL is a TIME (T#10ms), not a {it}", t.interval.span)
                        interval = self.const_value(t.interval, scope)
                        if interval <= 0:
                            raise self.fail("a task's INTERVAL is greater than zero", t.interval.span)
                    except CheckError as exc:
                        self.errors.append(exc)
                if t.priority is not None:
                    try:
                        priority = self.const_int(t.priority, scope)
                    except CheckError as exc:
                        self.errors.append(exc)
                tasks.append(TaskInfo(t.name, interval, priority, t.span, len(tasks)))
        inst_names: set[str] = set()
        for r in conf.resources:
            for pc in r.programs:
                if pc.name.upper() in inst_names:
                    self.errors.append(self.fail(f"program instance '{pc.name}' is declared twice", pc.span))
                    continue
                inst_names.add(pc.name.upper())
                info = self.pous.get(pc.type_name.upper())
                if info is None or info.kind != "PROGRAM":
                    self.errors.append(self.fail(f"'{pc.type_name}' is not a PROGRAM", pc.type_span))
                    continue
                task = pc.task
                if task is None:
                    if DEFAULT_TASK not in names:
                        tasks.append(TaskInfo(DEFAULT_TASK, 0, 0, pc.span, len(tasks)))
                        names.add(DEFAULT_TASK)
                    task = DEFAULT_TASK
                elif task.upper() not in names:
                    self.errors.append(self.fail(f"task '{task}' is not declared", pc.task_span))
                    continue
                task = next(t.name for t in tasks if t.name.upper() == task.upper())
                inst = InstanceInfo(pc.name, info, task, pc.span, pc.args)
                try:
                    call = n.Call(pc.span, pc.name, pc.args)
                    call.target = ("fn", info)
                    self.bind_args(call, info.params, scope, f"program {info.name}")
                    inst.binds = call.binds
                except CheckError as exc:
                    self.errors.append(exc)
                instances.append(inst)
        if not instances:
            self.errors.append(self.fail("the CONFIGURATION runs no PROGRAM", conf.span))
        return tasks, instances, conf.name


def literal_int(e: n.Expr) -> int | None:
    """The value of an integer literal (possibly negated), else None."""
    if isinstance(e, n.Literal) and e.lit.category == "int" and not isinstance(e.lit.value, bool):
        return e.lit.value
    if isinstance(e, n.Unary) and e.op == "-":
        v = literal_int(e.operand)
        return None if v is None else -v
    return None
