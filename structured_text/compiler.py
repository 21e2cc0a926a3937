"""Compiler: the checked program to Python source, compiled once; a scan then runs plain Python.

Each FUNCTION_BLOCK and PROGRAM becomes a class (members as `__slots__` attributes `v_<name>`, the
body as `_body()`), each FUNCTION a Python function, each STRUCT a class; globals live on one object
`_G`. Integer results wrap to the type where they are stored (an assignment, a parameter, a
conversion), REAL results are rounded to 32 bits at every operation; integer `/` truncates toward
zero and MOD keeps the dividend's sign. Run-time checks (a zero divisor, an index out of bounds, a
loop past the scan's budget) raise with a site number that names the FILE:LINE:COL.

Why compiled: a scan then costs what the same logic written in Python costs (`python -m bench st`: the ring
rig's gripper PLC in ST scans in 0.85x the time of its Python original), with no interpreter loop per node.
"""
from __future__ import annotations

from . import nodes as n
from . import stdlib_fn
from . import types as ty
from .checker import PouInfo, Program, Symbol, literal_int
from .errors import CheckError
from .rtlib import HELPERS, Budget, Sites, StructBase
from .stdlib_fb import STANDARD_FBS, Clock

def f32(code: str) -> str:
    """Python rounding `code` to a 32-bit float, inline (a function call costs twice as much)."""
    return f"_up(_pk({code}))[0]"


_FITS_STD = {"ABS": False, "MAX": True, "MIN": True, "LIMIT": True, "SEL": True, "MUX": True, "MOVE": True,
             "LEN": True, "FIND": True, "SHL": True, "SHR": True, "ROL": True, "ROR": True, "TIME": True,
             "GT": True, "GE": True, "EQ": True, "LE": True, "LT": True, "NE": True}


class Compiled:
    """The compiled program: its namespace (classes, functions, `_G`, `_clk`, images) and span table."""

    def __init__(self, program: Program, source: str, namespace: dict, sites: Sites, line_spans: list):
        self.program = program
        self.source = source
        self.ns = namespace
        self.sites = sites
        self.line_spans = line_spans  # (line of the generated source, span of the ST statement), ascending

    def span_of_line(self, line: int):
        """The ST statement a line of the generated Python belongs to."""
        import bisect
        k = bisect.bisect_right([ln for ln, _ in self.line_spans], line) - 1
        return self.line_spans[k][1] if k >= 0 else None

    def new_instances(self) -> dict:
        """Fresh globals and program instances (cold start values)."""
        self.ns["_G"] = self.ns["Globals"]()
        return {inst.name.upper(): self.ns["P_" + inst.pou.name.upper()]() for inst in self.program.instances}


def compile_program(program: Program) -> Compiled:
    return Compiler(program).run()


class Emitter:
    def __init__(self):
        self.lines: list[str] = []
        self.level = 0
        self.tmp = 0
        self.spans: list[tuple[int, object]] = []  # (index of the next line, the statement's span)

    def emit(self, line: str) -> None:
        self.lines.append("    " * self.level + line)

    def temp(self, stem: str = "t") -> str:
        self.tmp += 1
        return f"_{stem}{self.tmp}"


class Compiler:
    def __init__(self, program: Program):
        self.p = program
        self.sites = Sites()
        self.out = Emitter()
        self.structs: dict[int, str] = {}
        self.struct_defs: list[str] = []
        self.pou: PouInfo | None = None
        self.loop_vars: dict[int, tuple[str, int | None, int | None]] = {}  # FOR control symbols -> local, range

    def site(self, span) -> int:
        return self.sites.add(span)

    # ---- the module ------------------------------------------------------------------------------
    def run(self) -> Compiled:
        o = self.out
        for info in self.p.pous.values():
            if info.kind == "FUNCTION":
                self.function(info)
        for info in self.p.pous.values():
            if info.kind != "FUNCTION":
                self.block_class(info)
        self.globals_class()
        source = "\n".join(self.struct_defs + o.lines) + "\n"
        base = len(self.struct_defs) + 1
        line_spans = [(base + k, span) for k, span in o.spans]
        ns: dict = dict(HELPERS)
        ns["StructBase"] = StructBase
        ns["_clk"] = Clock()
        ns["_rt"] = Budget()
        ns["_I"], ns["_Q"], ns["_M"] = {}, {}, {}
        for name, cls in STANDARD_FBS.items():
            ns["STD_" + name] = cls
        code = compile(source, "<structured text>", "exec")
        exec(code, ns)
        return Compiled(self.p, source, ns, self.sites, line_spans)

    def globals_class(self) -> None:
        o = self.out
        syms = list(self.p.globals.values())
        o.emit("class Globals:")
        o.level += 1
        o.emit(f"__slots__ = {tuple(s.attr for s in syms)!r}")
        o.emit("def __init__(self):")
        o.level += 1
        for s in syms:
            o.emit(f"self.{s.attr} = {self.initial(s.type, s.init)}")
        o.emit("pass")
        o.level -= 2

    def block_class(self, info: PouInfo) -> None:
        o = self.out
        self.pou = info
        members = [s for s in info.symbols.values() if s.section not in ("VAR_EXTERNAL", "VAR_TEMP")]
        prefix = "P_" if info.kind == "PROGRAM" else "FB_"
        o.emit(f"class {prefix}{info.name.upper()}:")
        o.level += 1
        o.emit(f"__slots__ = {tuple(s.attr for s in members)!r}")
        o.emit("def __init__(self):")
        o.level += 1
        for s in members:
            o.emit(f"self.{s.attr} = {self.initial(s.type, s.init)}")
        o.emit("pass")
        o.level -= 1
        o.emit("def _body(self):")
        o.level += 1
        for s in info.symbols.values():
            if s.section == "VAR_TEMP":
                o.emit(f"{s.attr} = {self.initial(s.type, s.init)}")
        self.block(info.node.body)
        o.emit("return")
        o.level -= 2
        self.pou = None

    def function(self, info: PouInfo) -> None:
        o = self.out
        self.pou = info
        params = [s for s in info.params if s.section in ("VAR_INPUT", "VAR_IN_OUT")]
        o.emit(f"def F_{info.name.upper()}({', '.join(s.attr for s in params)}):")
        o.level += 1
        for s in info.symbols.values():
            if s.section in ("VAR", "VAR_TEMP", "VAR_OUTPUT", "RESULT"):
                o.emit(f"{s.attr} = {self.initial(s.type, s.init)}")
        self.block(info.node.body)
        o.emit(self.function_return(info))
        o.level -= 1
        self.pou = None

    def function_return(self, info: PouInfo) -> str:
        res = info.symbols[info.name.upper()].attr
        extra = [s.attr for s in info.params if s.section in ("VAR_OUTPUT", "VAR_IN_OUT")]
        return f"return ({res}, {', '.join(extra)},)" if extra else f"return {res}"

    # ---- values ----------------------------------------------------------------------------------
    def initial(self, t: ty.DataType, init) -> str:
        """Python that builds a fresh value of type t (initialised with init, a checked Python value)."""
        if init is None:
            init = getattr(t, "default", None)
        if isinstance(t, ty.ArrayT):
            values = list(init or [])
            elem_simple = not isinstance(t.elem, (ty.ArrayT, ty.StructT, ty.FbT))
            if elem_simple:
                d = ty.default_value(t.elem) if getattr(t.elem, "default", None) is None else t.elem.default
                values = values + [d] * (t.size - len(values))
                if all(v == values[0] for v in values):
                    return f"[{values[0]!r}] * {t.size}"
                return repr(values)
            items = [self.initial(t.elem, values[k] if k < len(values) else None) for k in range(t.size)]
            if len(set(items)) == 1:
                return f"[{items[0]} for _ in range({t.size})]"
            return "[" + ", ".join(items) + "]"
        if isinstance(t, ty.StructT):
            cls = self.struct_class(t)
            over = init or {}
            args = ", ".join(f"v_{t.fields[k][0].lower()}={self.initial(t.fields[k][1], v)}" for k, v in over.items())
            return f"{cls}({args})"
        if isinstance(t, ty.FbT):
            if t.builtin is not None:
                return f"STD_{t.name.upper()}(_clk)"
            return f"FB_{t.name.upper()}()"
        if init is None:
            return repr(ty.default_value(t))
        return repr(init)

    def struct_class(self, t: ty.StructT) -> str:
        key = id(t)
        if key in self.structs:
            return self.structs[key]
        name = f"S_{len(self.structs)}_{''.join(ch for ch in t.name if ch.isalnum())}"
        self.structs[key] = name
        fields = list(t.fields.values())
        lines = [f"class {name}(StructBase):", f"    __slots__ = {tuple('v_' + f[0].lower() for f in fields)!r}",
                 f"    def __init__(self, {', '.join('v_' + f[0].lower() + '=None' for f in fields)}):"]
        for fname, ft, finit in fields:
            a = "v_" + fname.lower()
            lines.append(f"        self.{a} = {self.initial(ft, finit)} if {a} is None else {a}")
        lines.append("        pass")
        self.struct_defs.extend(lines)
        return name

    # ---- statements ------------------------------------------------------------------------------
    def block(self, body: list[n.Stmt]) -> None:
        if not body:
            self.out.emit("pass")
            return
        for st in body:
            self.stmt(st)

    def stmt(self, st: n.Stmt) -> None:
        o = self.out
        o.spans.append((len(o.lines), st.span))
        if isinstance(st, n.Assign):
            if isinstance(st.value, n.Call) and st.value.target and st.value.target[0] == "fn" and \
                    self.has_outputs(st.value.target[1]):
                def call():
                    r = self.call_with_outputs(st.value)
                    self.assign(st.target, r, st.value.ty, fits=False)
                self.guarded(st.value, call)
                return
            v = st.value
            if isinstance(v, n.Call) and getattr(v, "eno", None) is not None:  # `y := F(EN := e, ENO => ok)`
                en = o.temp("en")
                o.emit(f"{en} = {self.expr(v.en)[0] if v.en is not None else 'True'}")
                saved, v.en = v.en, None
                code, fits = self.call_expr(v)
                v.en = saved
                self.assign(st.target, f"({code} if {en} else {self.initial(v.ty, None)})", v.ty, fits)
                self.assign(v.eno, en, ty.BOOL, True)
                return
            code, fits = self.expr(st.value)
            self.assign(st.target, code, st.value.ty, fits)
        elif isinstance(st, n.CallStmt):
            c = st.call
            if c.target[0] == "fb":
                self.fb_call(c)
            elif c.target[0] == "fn" and self.has_outputs(c.target[1]):
                self.guarded(c, lambda: self.call_with_outputs(c))
            else:
                en, c.en = c.en, None
                code = self.expr(c)[0]
                c.en = en
                self.guarded(c, lambda: o.emit(code))
        elif isinstance(st, n.If):
            for k, (cond, body) in enumerate(st.branches):
                o.emit(f"{'if' if k == 0 else 'elif'} {self.expr(cond)[0]}:")
                o.level += 1
                self.block(body)
                o.level -= 1
            if st.orelse:
                o.emit("else:")
                o.level += 1
                self.block(st.orelse)
                o.level -= 1
        elif isinstance(st, n.Case):
            sel = o.temp("c")
            o.emit(f"{sel} = {self.expr(st.selector)[0]}")
            first = True
            for item in st.items:
                tests = []
                for lo, hi in item.labels:
                    if hi is None:
                        tests.append(f"{sel} == {lo.const!r}")
                    else:
                        tests.append(f"{lo.const!r} <= {sel} <= {hi.const!r}")
                o.emit(f"{'if' if first else 'elif'} {' or '.join(tests)}:")
                first = False
                o.level += 1
                self.block(item.body)
                o.level -= 1
            if st.orelse:
                if first:
                    self.block(st.orelse)
                else:
                    o.emit("else:")
                    o.level += 1
                    self.block(st.orelse)
                    o.level -= 1
        elif isinstance(st, n.For):
            self.for_stmt(st)
        elif isinstance(st, n.While):
            site = self.site(st.span)
            o.emit(f"while {self.expr(st.cond)[0]}:")
            o.level += 1
            self.budget(site)
            self.block(st.body)
            o.level -= 1
        elif isinstance(st, n.Repeat):
            site = self.site(st.span)
            first = o.temp("first")
            o.emit(f"{first} = True")
            o.emit(f"while {first} or not {self.expr(st.cond)[0]}:")
            o.level += 1
            o.emit(f"{first} = False")
            self.budget(site)
            self.block(st.body)
            o.level -= 1
        elif isinstance(st, n.Exit):
            o.emit("break")
        elif isinstance(st, n.Continue):
            o.emit("continue")
        elif isinstance(st, n.Return):
            if self.pou.kind == "FUNCTION":
                o.emit(self.function_return(self.pou))
            else:
                o.emit("return")
        else:
            raise AssertionError(st)

    def budget(self, site: int) -> None:
        self.out.emit("_rt.left -= 1")
        self.out.emit(f"if _rt.left < 0: _endless({site})")

    def for_stmt(self, st: n.For) -> None:
        o = self.out
        vt = st.var.ty
        site = self.site(st.span)
        start = self.expr(st.start)[0]
        end = self.expr(st.end)[0]
        step_const = 1 if st.step is None else getattr(st.step, "const", None)
        r = o.temp("r")
        if step_const is not None:
            if step_const == 0:
                o.emit(f"_endless({site})")
                return
            step = repr(step_const)
            stop = f"({end}) + {1 if step_const > 0 else -1}"
        else:
            step = o.temp("s")
            o.emit(f"{step} = {self.expr(st.step)[0]}")
            o.emit(f"if {step} == 0: _endless({site})")
            stop = f"({end}) + (1 if {step} > 0 else -1)"
        o.emit(f"{r} = range({start}, {stop}, {step})")
        var = o.temp("i")
        target = self.lvalue_code(st.var)
        o.emit(f"{target} = {start}")
        o.emit(f"for {var} in {r}:")
        o.level += 1
        o.emit(f"{target} = {var}")
        self.budget(site)
        lo, hi = getattr(st.start, "const", None), getattr(st.end, "const", None)
        if lo is None or hi is None or step_const is None:
            lo = hi = None
        elif step_const < 0:
            lo, hi = hi, lo
        sym = st.var.ref
        outer = self.loop_vars.get(id(sym))
        self.loop_vars[id(sym)] = (var, lo, hi)  # the body reads the control variable from the Python local
        self.block(st.body)
        if outer is None:
            del self.loop_vars[id(sym)]
        else:
            self.loop_vars[id(sym)] = outer
        o.level -= 1
        o.emit("else:")
        o.level += 1
        o.emit(f"if {r}: {target} = {self.wrap(vt, f'{r}[-1] + {step}')}")
        o.level -= 1

    # ---- assignment ------------------------------------------------------------------------------
    def assign(self, target: n.Expr, code: str, vtype: ty.DataType, fits: bool) -> None:
        o = self.out
        tt = target.ty
        value = self.store(tt, code, vtype, fits, target.span)
        if isinstance(target, n.BitAccess):
            base = self.lvalue_code(target.base)
            mask = 1 << target.bit
            full = (1 << target.base.ty.bits) - 1
            bt = target.base.ty
            on = f"({base} | {mask})"
            off = f"({base} & {full ^ mask})"
            if getattr(bt, "signed", False):
                on, off = self.wrap(bt, on), self.wrap(bt, off)
            o.emit(f"{base} = {on} if {value} else {off}")
            return
        o.emit(f"{self.lvalue_code(target)} = {value}")

    def lvalue_code(self, e: n.Expr) -> str:
        if isinstance(e, n.Direct):
            return f"_{e.area}[{direct_key(e)!r}]"
        return self.expr(e)[0]

    def store(self, tt: ty.DataType, code: str, vt: ty.DataType, fits: bool, span) -> str:
        """`code` (a value of type vt) converted for storing in a tt: wrapped, rounded, truncated, copied."""
        k = tt.kind
        if isinstance(tt, ty.SubrangeT):
            return f"_subrange({code}, {tt.lo}, {tt.hi}, {self.site(span)})"
        if k in ("int", "bits"):
            if vt is ty.LIT_INT and fits:
                return code  # a literal: the checker found it in range
            if vt.kind in ("int", "bits") and fits and self.within(vt, tt):
                return code
            if vt.kind == "bool":
                return f"int({code})"
            return self.wrap(tt, code)
        if k == "real":
            if vt.kind == "real" and (fits and (vt.bits <= tt.bits) or vt is ty.LIT_REAL and tt.bits == 64):
                return code
            if tt.bits == 32 and not (vt.kind in ("int", "bits") and fits and vt is not ty.LIT_INT
                                      and getattr(vt, "bits", 64) <= 24):
                return f32(code)
            return code if vt.kind == "real" else f"float({code})"
        if k == "string":
            if isinstance(vt, ty.StringT) and vt.length <= tt.length:
                return code
            return f"({code})[:{tt.length}]"
        if k in ("array", "struct"):
            return f"_deep({code})"
        if k == "bool":
            return code
        return code

    def within(self, vt: ty.DataType, tt: ty.DataType) -> bool:
        if vt is ty.LIT_INT:
            return False
        lo, hi = ty.range_of(vt)
        tlo, thi = ty.range_of(tt)
        return tlo <= lo and hi <= thi

    def wrap(self, t: ty.DataType, code: str) -> str:
        if isinstance(t, ty.SubrangeT):
            t = t.base
        return stdlib_fn.wrap_code(t, code)

    # ---- calls -----------------------------------------------------------------------------------
    def has_outputs(self, info: PouInfo) -> bool:
        return any(s.section in ("VAR_OUTPUT", "VAR_IN_OUT") for s in info.params)

    def guarded(self, c: n.Call, emit_call) -> None:
        """The call under its EN (if given), then ENO := EN."""
        o = self.out
        if c.en is None:
            emit_call()
            if c.eno is not None:
                self.assign(c.eno, "True", ty.BOOL, True)
            return
        en = o.temp("en")
        o.emit(f"{en} = {self.expr(c.en)[0]}")
        o.emit(f"if {en}:")
        o.level += 1
        emit_call()
        o.level -= 1
        if c.eno is not None:
            self.assign(c.eno, en, ty.BOOL, True)

    def fb_call(self, c: n.Call) -> None:
        self.guarded(c, lambda: self._fb_call(c))

    def _fb_call(self, c: n.Call) -> None:
        o = self.out
        inst = self.expr(c.instance)[0]
        if not inst.replace(".", "").replace("_", "").isalnum():
            tmp = o.temp("fb")
            o.emit(f"{tmp} = {inst}")
            inst = tmp
        after = []
        for p, a in c.binds:
            if p.section == "VAR_OUTPUT":
                after.append((p, a))
                continue
            if p.section == "VAR_IN_OUT":
                o.emit(f"{inst}.{p.attr} = {self.expr(a.value)[0]}")
                after.append((p, a))
                continue
            code, fits = self.expr(a.value)
            o.emit(f"{inst}.{p.attr} = {self.store(p.type, code, a.value.ty, fits, a.value.span)}")
        o.emit(f"{inst}._body()")
        for p, a in after:
            value = f"{inst}.{p.attr}"
            if a.negated:
                value = f"(not {value})"
            self.assign(a.value, value, p.type, True)

    def call_with_outputs(self, c: n.Call) -> str:
        """A FUNCTION with VAR_OUTPUT or VAR_IN_OUT: called as a statement, its outputs stored after."""
        o = self.out
        info = c.target[1]
        r = o.temp("r")
        o.emit(f"{r} = {self.fn_call_code(c)}")
        extra = [s for s in info.params if s.section in ("VAR_OUTPUT", "VAR_IN_OUT")]
        for p, a in c.binds:
            if p.section in ("VAR_OUTPUT", "VAR_IN_OUT"):
                k = extra.index(p) + 1
                value = f"{r}[{k}]"
                if a.negated:
                    value = f"(not {value})"
                self.assign(a.value, value, p.type, True)
        return f"{r}[0]"

    def fn_call_code(self, c: n.Call) -> str:
        info = c.target[1]
        given = {p.name.upper(): a for p, a in c.binds}
        args = []
        for p in info.params:
            if p.section not in ("VAR_INPUT", "VAR_IN_OUT"):
                continue
            a = given.get(p.name.upper())
            if a is None:
                args.append(self.initial(p.type, p.init))
            else:
                code, fits = self.expr(a.value)
                args.append(self.store(p.type, code, a.value.ty, fits, a.value.span))
        return f"F_{info.name.upper()}({', '.join(args)})"

    # ---- expressions: (python code, whether the value is already in its type's range) -------------
    def expr(self, e: n.Expr) -> tuple[str, bool]:
        if isinstance(e, n.Literal):
            lit = e.lit
            if lit.category == "enum":
                return repr(e.ref_value), True
            v = lit.value
            if e.ty is not None and e.ty.kind == "real":
                return repr(float(v)) if e.ty.bits == 64 else repr(ty.to_f32(float(v))), True
            if e.ty is not None and e.ty.kind == "bool":
                return repr(bool(v)), True
            return repr(v), True
        if isinstance(e, n.Name):
            ref = e.ref
            if isinstance(ref, tuple):  # an enumeration value
                return repr(ref[2]), True
            loop = self.loop_vars.get(id(ref))
            if loop is not None:
                return loop[0], True
            return self.symbol_code(ref), True
        if isinstance(e, n.Member):
            base = self.expr(e.base)[0]
            return f"{base}.v_{e.name.lower()}", True
        if isinstance(e, n.Index):
            base = self.expr(e.base)[0]
            at = e.base.ty
            offset = self.offset(e, at)
            return f"{base}[{offset}]", True
        if isinstance(e, n.BitAccess):
            base = self.expr(e.base)[0]
            return f"((({base}) >> {e.bit}) & 1 != 0)", True
        if isinstance(e, n.Direct):
            default = "False" if e.size == "X" else "0"
            return f"_{e.area}.get({direct_key(e)!r}, {default})", True
        if isinstance(e, n.Unary):
            code, fits = self.expr(e.operand)
            t = e.ty
            if e.op == "NOT":
                if t.kind == "bool":
                    return f"(not {code})", True
                if t is ty.LIT_INT:
                    return f"(~{code})", False
                if getattr(t, "signed", False):
                    return f"(~{code})", fits
                return f"(~{code} & {(1 << t.bits) - 1})", True
            if e.op == "-":
                if t.kind == "real":
                    return f"(-{code})", fits
                return f"(-{code})", False
            return code, fits
        if isinstance(e, n.Binary):
            return self.binary(e)
        if isinstance(e, n.Call):
            return self.call_expr(e)
        raise AssertionError(e)

    def symbol_code(self, s: Symbol) -> str:
        if s.is_global:
            return f"_G.{s.attr}"
        if self.pou is None:
            return f"_G.{s.attr}"
        if self.pou.kind == "FUNCTION" or s.section == "VAR_TEMP":
            return s.attr
        return f"self.{s.attr}"

    def offset(self, e: n.Index, at: ty.ArrayT) -> str:
        parts = []
        stride = 1
        strides = []
        for lo, hi in reversed(at.dims):
            strides.append(stride)
            stride *= hi - lo + 1
        strides.reverse()
        const = 0
        for ix, (lo, hi), s in zip(e.indexes, at.dims, strides):
            v = literal_int(ix)
            if v is not None:
                const += (v - lo) * s
                continue
            code = self.expr(ix)[0]
            loop = self.loop_vars.get(id(ix.ref)) if isinstance(ix, n.Name) else None
            if loop is not None and loop[1] is not None and lo <= loop[1] and loop[2] <= hi:
                term = f"({code} - {lo})" if lo else code  # a FOR variable whose range lies within the bounds
            else:
                term = f"_ix({code}, {lo}, {hi}, {self.site(ix.span)})"
            parts.append(term if s == 1 else f"{term} * {s}")
        if const or not parts:
            parts.append(repr(const))
        return " + ".join(parts)

    def binary(self, e: n.Binary) -> tuple[str, bool]:
        op = e.op
        a, afits = self.expr(e.left)
        b, bfits = self.expr(e.right)
        t = e.ty
        if t.kind == "real" and t.bits == 32 or op in ("=", "<>", "<", "<=", ">", ">=") and \
                ty.REAL in (e.left.ty, e.right.ty):
            # an untyped literal beside a REAL is a REAL (32 bits), as the standard types it
            if e.left.ty is ty.LIT_REAL or e.left.ty is ty.LIT_INT and isinstance(e.left, n.Literal):
                a = repr(ty.to_f32(float(e.left.lit.value))) if isinstance(e.left, n.Literal) else a
            if e.right.ty is ty.LIT_REAL or e.right.ty is ty.LIT_INT and isinstance(e.right, n.Literal):
                b = repr(ty.to_f32(float(e.right.lit.value))) if isinstance(e.right, n.Literal) else b
        lt, rt = e.left.ty, e.right.ty
        if op in ("AND", "OR", "XOR"):
            if t.kind == "bool":
                if op == "XOR":
                    return f"({a} != {b})", True
                return f"({a} {op.lower()} {b})", True
            sym = {"AND": "&", "OR": "|", "XOR": "^"}[op]
            return f"({a} {sym} {b})", afits and bfits
        if op in ("=", "<>", "<", "<=", ">", ">="):
            pyop = {"=": "==", "<>": "!="}.get(op, op)
            return f"({a} {pyop} {b})", True
        if op in ("/", "MOD"):
            code = stdlib_fn.divide(op, a, b, t, self.site(e.op_span))
            if t.kind == "real" and t.bits == 32:
                return f32(code), True
            return code, t.kind in ("time",)
        if op == "**":
            code = f"_expt({a}, {b}, {self.site(e.op_span)})"
            if t.kind == "real":
                return (f32(code), True) if t.bits == 32 else (code, True)
            return code, False
        pyop = op
        if t.kind == "time" and op == "*" and (lt.kind == "real" or rt.kind == "real"):
            return f"_round({a} * {b})", True
        code = f"({a} {pyop} {b})"
        if t.kind == "real":
            if t.bits == 32:
                return f32(code), True
            return code, True
        if t.kind in ("time", "date", "tod", "dt"):
            return code, True
        if t.kind == "string":
            return code, True
        return code, False

    def call_expr(self, c: n.Call) -> tuple[str, bool]:
        if getattr(c, "en", None) is not None:  # EN FALSE: the function does not run, its result is the default
            en = c.en
            c.en = None
            code, fits = self.call_expr(c)
            c.en = en
            return f"({code} if {self.expr(en)[0]} else {self.initial(c.ty, None)})", fits
        kind = c.target[0]
        if kind == "fn":
            info = c.target[1]
            if self.has_outputs(info):
                raise CheckError(f"a call of {info.name}, which has outputs or in-outs, must be a statement "
                                 "or the whole right side of an assignment", c.span)
            code = self.fn_call_code(c)
            return code, True
        if kind == "std":
            up = c.target[1]
            codes, types = [], []
            for v in c.arg_values:
                code, _ = self.expr(v)
                codes.append(code)
                types.append(v.ty)
            code = stdlib_fn.generate(up, codes, types, c.ty, self.site(c.span))
            conv = stdlib_fn.conversion(up)
            if conv is not None:
                return code, True
            if c.ty.kind == "real" and c.ty.bits == 32 and up not in ("MAX", "MIN", "LIMIT", "SEL", "MUX", "MOVE"):
                return f32(code), True
            return code, _FITS_STD.get(up, False)
        raise CheckError("a function block call is a statement", c.span)


def direct_key(e: n.Direct) -> str:
    """The images' key of a direct address (as runtime.address_key: its canonical text)."""
    return f"%{e.area}{e.size}{'.'.join(str(i) for i in e.index)}"
