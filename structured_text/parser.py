"""Parser: tokens to a SourceFile, by hand-written recursive descent.

Hand-written rather than blark/lark (docs/plc-st.md says why): blark's Earley parse takes seconds
for a few hundred lines and its errors list terminals rather than saying what is missing. Here the
first error stops the parse, at the token where something else was expected ("expected ';' after
the statement, found 'b'", "expected END_IF to close the IF on line 4, found END_PROGRAM").

Operator precedence is the standard's (IEC 61131-3 3rd ed., table 71, and its grammar), tightest first:
    ( )  >  function call  >  unary - + NOT  >  **  >  * / MOD  >  + -  >  < > <= >=  >  = <>
    >  AND &  >  XOR  >  OR
Operators of one level associate to the left (`2 ** 3 ** 2` is `(2 ** 3) ** 2`); a unary operator
binds tighter than `**` (`-2 ** 2` is 4) and NOT than AND (`NOT a AND b` is `(NOT a) AND b`).
"""
from __future__ import annotations

from . import nodes as n
from .errors import ParseError, Span
from .lexer import lex
from .tokens import UNSUPPORTED, Kind, Lit, Token

_VAR_SECTIONS = ("VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR_GLOBAL", "VAR_EXTERNAL", "VAR_TEMP")
_STMT_END = ("END_IF", "ELSIF", "ELSE", "END_CASE", "END_FOR", "END_WHILE", "UNTIL", "END_REPEAT",
             "END_PROGRAM", "END_FUNCTION", "END_FUNCTION_BLOCK")
_IL_OPERATORS = {"LD", "LDN", "ST", "STN", "S", "R", "ANDN", "ORN", "XORN", "ADD", "SUB", "MUL", "DIV", "GT", "GE",
                 "EQ", "NE", "LE", "LT", "JMPC", "JMPCN", "CAL", "CALC", "CALCN", "RET", "RETC", "RETCN"}
_POU_END = {"PROGRAM": "END_PROGRAM", "FUNCTION": "END_FUNCTION", "FUNCTION_BLOCK": "END_FUNCTION_BLOCK"}


def parse(source: str, file: str = "<input>") -> n.SourceFile:
    """Parse one source file: POUs, TYPE blocks, global variables and configurations, in any order."""
    return Parser(lex(source, file), file).source_file()


class Parser:
    def __init__(self, tokens: list[Token], file: str):
        self.toks = tokens
        self.pos = 0
        self.file = file

    # ---- helpers -------------------------------------------------------------------------------
    @property
    def tok(self) -> Token:
        return self.toks[self.pos]

    def peek(self, k: int = 1) -> Token:
        return self.toks[min(self.pos + k, len(self.toks) - 1)]

    def advance(self) -> Token:
        t = self.toks[self.pos]
        if t.kind is not Kind.EOF:
            self.pos += 1
        return t

    def error(self, message: str, tok: Token | None = None) -> ParseError:
        return ParseError(message, (tok or self.tok).span)

    def unsupported_check(self, tok: Token) -> None:
        if tok.kind is Kind.KEYWORD and tok.upper in UNSUPPORTED:
            raise self.error(f"{tok.upper}: {UNSUPPORTED[tok.upper]} is not supported", tok)

    def expect_op(self, op: str, where: str = "") -> Token:
        if self.tok.is_op(op):
            return self.advance()
        self.unsupported_check(self.tok)
        raise self.error(f"expected '{op}'{where}, found {self.tok.describe()}")

    def expect_kw(self, word: str, where: str = "") -> Token:
        if self.tok.is_kw(word):
            return self.advance()
        self.unsupported_check(self.tok)
        raise self.error(f"expected {word}{where}, found {self.tok.describe()}")

    def ident(self, what: str = "a name") -> Token:
        if self.tok.kind is Kind.IDENT:
            return self.advance()
        self.unsupported_check(self.tok)
        if self.tok.kind is Kind.KEYWORD:
            raise self.error(f"expected {what}, found the keyword {self.tok.upper} (a reserved word)")
        raise self.error(f"expected {what}, found {self.tok.describe()}")

    def closing(self, word: str, opener: Token) -> Token:
        if self.tok.is_kw(word):
            return self.advance()
        self.unsupported_check(self.tok)
        raise self.error(f"expected {word} to close the {opener.upper} on line {opener.span.line}, "
                         f"found {self.tok.describe()}")

    def semicolon(self, after: str) -> None:
        if self.tok.is_op(";"):
            self.advance()
            return
        raise self.error(f"expected ';' after {after}, found {self.tok.describe()}")

    # ---- top level -------------------------------------------------------------------------------
    def source_file(self) -> n.SourceFile:
        sf = n.SourceFile(self.file)
        while self.tok.kind is not Kind.EOF:
            t = self.tok
            if t.is_kw("PROGRAM", "FUNCTION", "FUNCTION_BLOCK"):
                sf.pous.append(self.pou())
            elif t.is_kw("TYPE"):
                sf.types.extend(self.type_block())
            elif t.is_kw("VAR_GLOBAL"):
                sf.globals.extend(self.var_block())
            elif t.is_kw("CONFIGURATION"):
                sf.configurations.append(self.configuration())
            else:
                self.unsupported_check(t)
                raise self.error("expected PROGRAM, FUNCTION_BLOCK, FUNCTION, TYPE or CONFIGURATION, "
                                 f"found {t.describe()}")
        return sf

    def pou(self) -> n.Pou:
        kw = self.advance()
        kind = kw.upper
        name = self.ident(f"the {kind}'s name")
        result = None
        if kind == "FUNCTION":
            self.expect_op(":", " and the result type after the FUNCTION's name")
            result = self.type_spec()
        elif self.tok.is_kw("EXTENDS", "IMPLEMENTS"):
            self.unsupported_check(self.tok)
        decls: list[n.VarDecl] = []
        while self.tok.kind is Kind.KEYWORD and self.tok.upper in _VAR_SECTIONS + ("VAR_ACCESS", "VAR_CONFIG"):
            self.unsupported_check(self.tok)
            decls.extend(self.var_block())
        body = self.statements()
        end = self.closing(_POU_END[kind], kw)
        if self.tok.is_op(";"):  # tolerated: `END_PROGRAM;`
            self.advance()
        return n.Pou(kw.span, kind, name.text, decls, body, result, end.span, name.span)

    def var_block(self) -> list[n.VarDecl]:
        head = self.advance()
        section = head.upper
        constant = retain = False
        while self.tok.is_kw("CONSTANT", "RETAIN", "NON_RETAIN"):
            w = self.advance().upper
            constant |= w == "CONSTANT"
            retain |= w == "RETAIN"
        out: list[n.VarDecl] = []
        while not self.tok.is_kw("END_VAR"):
            if self.tok.kind is Kind.EOF or (self.tok.kind is Kind.KEYWORD and self.tok.kind is not Kind.IDENT
                                              and not self.tok.is_kw(*UNSUPPORTED)):
                raise self.error(f"expected END_VAR to close the {section} on line {head.span.line}, "
                                 f"found {self.tok.describe()}")
            out.extend(self.var_decl(section, constant, retain))
        self.advance()
        return out

    def var_decl(self, section: str, constant: bool, retain: bool) -> list[n.VarDecl]:
        names = [self.ident("a variable name")]
        while self.tok.is_op(","):
            self.advance()
            names.append(self.ident("a variable name"))
        location = loc_span = None
        if self.tok.is_kw("AT"):
            self.advance()
            if self.tok.kind is not Kind.DIRECT:
                raise self.error(f"expected a direct address after AT (e.g. %IX0.0), found {self.tok.describe()}")
            loc_tok = self.advance()
            location, loc_span = loc_tok.value, loc_tok.span
            if len(names) > 1:
                raise self.error("one located variable per declaration", names[1])
        self.expect_op(":", " and a type after the variable name")
        spec = self.type_spec()
        init = None
        if self.tok.is_op(":="):
            self.advance()
            init = self.initializer()
        self.semicolon("the declaration")
        return [n.VarDecl(t.span, t.text, spec, init, section, constant, retain, location, loc_span) for t in names]

    def initializer(self) -> n.Expr:
        t = self.tok
        if t.is_op("["):
            self.advance()
            items: list[tuple[n.Expr | None, n.Expr]] = []
            while True:
                if self.tok.kind is Kind.LITERAL and isinstance(self.tok.value, Lit) and \
                        self.tok.value.category == "int" and self.peek().is_op("("):
                    count = self.primary()
                    self.advance()
                    value = None if self.tok.is_op(")") else self.initializer()
                    self.expect_op(")", " to close the repeated initial value")
                    items.append((count, value))
                else:
                    items.append((None, self.initializer()))
                if not self.tok.is_op(","):
                    break
                self.advance()
            self.expect_op("]", " to close the array's initial values")
            return n.ArrayInit(t.span, items)
        if t.is_op("(") and self.peek().kind is Kind.IDENT and self.peek(2).is_op(":="):
            self.advance()
            fields = []
            while True:
                name = self.ident("a structure member's name")
                self.expect_op(":=")
                fields.append((name.text, name.span, self.initializer()))
                if not self.tok.is_op(","):
                    break
                self.advance()
            self.expect_op(")", " to close the structure's initial values")
            return n.StructInit(t.span, fields)
        return self.expression()

    def type_spec(self) -> n.TypeSpec:
        t = self.tok
        self.unsupported_check(t)
        if t.is_kw("ARRAY"):
            self.advance()
            self.expect_op("[", " after ARRAY")
            ranges = []
            while True:
                if self.tok.is_op("*"):
                    raise self.error("variable-length arrays (ARRAY[*]) are not supported")
                lo = self.expression()
                self.expect_op("..", " between the array's bounds")
                hi = self.expression()
                ranges.append((lo, hi))
                if not self.tok.is_op(","):
                    break
                self.advance()
            self.expect_op("]", " to close the array's bounds")
            self.expect_kw("OF", " after the array's bounds")
            return n.ArraySpec(t.span, ranges, self.type_spec())
        if t.is_kw("STRUCT"):
            self.advance()
            fields: list[n.VarDecl] = []
            while not self.tok.is_kw("END_STRUCT"):
                if self.tok.kind is Kind.EOF or self.tok.kind is Kind.KEYWORD:
                    raise self.error(f"expected END_STRUCT to close the STRUCT on line {t.span.line}, "
                                     f"found {self.tok.describe()}")
                fields.extend(self.var_decl("FIELD", False, False))
            self.advance()
            return n.StructSpec(t.span, fields)
        if t.is_op("("):
            return self.enum_spec(None)
        name = self.ident("a type")
        up = name.upper
        if up in ("STRING", "WSTRING"):
            length = None
            if self.tok.is_op("[", "("):
                close = "]" if self.advance().text == "[" else ")"
                length = self.expression()
                self.expect_op(close, " after the string's length")
            return n.StringType(name.span, up == "WSTRING", length)
        if self.tok.is_op("("):
            if self.peek().kind is Kind.IDENT and (self.peek(2).is_op(",", ":=", ")")):
                return self.enum_spec(up)  # a typed enumeration, `INT (a := 1, b := 2)`
            self.advance()
            lo = self.expression()
            self.expect_op("..", " in the subrange")
            hi = self.expression()
            self.expect_op(")", " to close the subrange")
            return n.SubrangeSpec(name.span, up, lo, hi)
        return n.NamedType(name.span, name.text)

    def enum_spec(self, base: str | None) -> n.EnumSpec:
        t = self.expect_op("(")
        values = []
        while True:
            v = self.ident("an enumeration value")
            init = None
            if self.tok.is_op(":="):
                self.advance()
                init = self.expression()
            values.append((v.text, v.span, init))
            if not self.tok.is_op(","):
                break
            self.advance()
        self.expect_op(")", " to close the enumeration")
        return n.EnumSpec(t.span, values, base)

    def type_block(self) -> list[n.TypeDecl]:
        head = self.advance()
        out = []
        while not self.tok.is_kw("END_TYPE"):
            if self.tok.kind is not Kind.IDENT:
                self.unsupported_check(self.tok)
                raise self.error(f"expected END_TYPE to close the TYPE on line {head.span.line}, "
                                 f"found {self.tok.describe()}")
            name = self.advance()
            self.expect_op(":", " after the type's name")
            spec = self.type_spec()
            init = None
            if self.tok.is_op(":="):
                self.advance()
                init = self.initializer()
            self.semicolon("the type declaration")
            out.append(n.TypeDecl(name.span, name.text, spec, init))
        self.advance()
        return out

    def configuration(self) -> n.Configuration:
        kw = self.advance()
        name = self.ident("the configuration's name")
        conf = n.Configuration(kw.span, name.text, [], [])
        loose: n.Resource | None = None
        while not self.tok.is_kw("END_CONFIGURATION"):
            t = self.tok
            if t.is_kw("VAR_GLOBAL"):
                conf.globals.extend(self.var_block())
            elif t.is_kw("RESOURCE"):
                conf.resources.append(self.resource())
            elif t.is_kw("TASK", "PROGRAM"):
                if loose is None:
                    loose = n.Resource(t.span, "", [], [], [])
                    conf.resources.append(loose)
                self.resource_item(loose)
            else:
                self.unsupported_check(t)
                raise self.error(f"expected RESOURCE, TASK, PROGRAM, VAR_GLOBAL or END_CONFIGURATION to close "
                                 f"the CONFIGURATION on line {kw.span.line}, found {t.describe()}")
        self.advance()
        return conf

    def resource(self) -> n.Resource:
        kw = self.advance()
        name = self.ident("the resource's name")
        if self.tok.is_kw("ON"):
            self.advance()
            self.ident("the resource's processor type")
        res = n.Resource(kw.span, name.text, [], [], [])
        while not self.tok.is_kw("END_RESOURCE"):
            t = self.tok
            if t.is_kw("VAR_GLOBAL"):
                res.globals.extend(self.var_block())
            elif t.is_kw("TASK", "PROGRAM"):
                self.resource_item(res)
            else:
                self.unsupported_check(t)
                raise self.error(f"expected TASK, PROGRAM, VAR_GLOBAL or END_RESOURCE to close the RESOURCE on "
                                 f"line {kw.span.line}, found {t.describe()}")
        self.advance()
        return res

    def resource_item(self, res: n.Resource) -> None:
        kw = self.advance()
        if kw.upper == "TASK":
            name = self.ident("the task's name")
            task = n.TaskDecl(name.span, name.text, None, None)
            self.expect_op("(", " and the task's INTERVAL/PRIORITY")
            while not self.tok.is_op(")"):
                key = self.ident("INTERVAL, PRIORITY or SINGLE")
                self.expect_op(":=")
                value = self.expression()
                k = key.upper
                if k == "INTERVAL":
                    task.interval = value
                elif k == "PRIORITY":
                    task.priority = value
                elif k == "SINGLE":
                    task.single = value
                else:
                    raise self.error(f"a TASK takes INTERVAL, PRIORITY and SINGLE, not {key.text}", key)
                if not self.tok.is_op(","):
                    break
                self.advance()
            self.expect_op(")", " to close the task's parameters")
            self.semicolon("the TASK")
            res.tasks.append(task)
            return
        retain = False
        if self.tok.is_kw("RETAIN", "NON_RETAIN"):
            retain = self.advance().upper == "RETAIN"
        name = self.ident("the program instance's name")
        task = task_span = None
        if self.tok.is_kw("WITH"):
            self.advance()
            tt = self.ident("a task name")
            task, task_span = tt.text, tt.span
        self.expect_op(":", " and the program type after the instance name")
        ty = self.ident("a PROGRAM type")
        args = self.call_args() if self.tok.is_op("(") else []
        self.semicolon("the PROGRAM instance")
        res.programs.append(n.ProgramConf(name.span, name.text, task, task_span, ty.text, ty.span, args, retain))

    # ---- statements ------------------------------------------------------------------------------
    def statements(self) -> list[n.Stmt]:
        """Statements up to the END word (or ELSIF, ELSE, UNTIL) of the block around them."""
        out: list[n.Stmt] = []
        while True:
            t = self.tok
            if t.kind is Kind.EOF or (t.kind is Kind.KEYWORD and t.upper in _STMT_END):
                return out
            if t.is_op(";"):  # an empty statement
                self.advance()
                continue
            out.append(self.statement())

    def statement(self) -> n.Stmt:
        t = self.tok
        if t.kind is Kind.KEYWORD:
            w = t.upper
            if w == "IF":
                return self.if_stmt()
            if w == "CASE":
                return self.case_stmt()
            if w == "FOR":
                return self.for_stmt()
            if w == "WHILE":
                return self.while_stmt()
            if w == "REPEAT":
                return self.repeat_stmt()
            if w in ("EXIT", "CONTINUE", "RETURN"):
                self.advance()
                self.semicolon(w)
                return {"EXIT": n.Exit, "CONTINUE": n.Continue, "RETURN": n.Return}[w](t.span)
            self.unsupported_check(t)
            raise self.error(f"expected a statement, found {t.describe()}")
        if t.kind not in (Kind.IDENT, Kind.DIRECT):
            raise self.error(f"expected a statement, found {t.describe()}")
        if t.upper in ("STEP", "TRANSITION", "ACTION") and self.peek().kind is Kind.IDENT:
            raise self.error(f"{t.upper}: SFC (sequential function charts) is not supported")
        nxt = self.peek()
        if t.upper in _IL_OPERATORS and nxt.span.line == t.span.line and (
                nxt.kind in (Kind.IDENT, Kind.LITERAL, Kind.DIRECT) or nxt.is_op("%")):
            raise self.error(f"{t.upper} {nxt.text}: Instruction List (IL) is not supported; write Structured Text")
        target = self.postfix(self.primary())
        if self.tok.is_op(":="):
            self.advance()
            if isinstance(target, n.Call):
                raise self.error("a call's result cannot be assigned to", t)
            value = self.expression()
            self.semicolon("the assignment")
            return n.Assign(t.span, target, value)
        if self.tok.is_op("=") and not isinstance(target, n.Call):
            raise self.error("expected ':=' (assignment), found '=' (comparison)")
        if isinstance(target, n.Call):
            self.semicolon("the call")
            return n.CallStmt(t.span, target)
        raise self.error(f"expected ':=' or a call after {target_text(target)}, found {self.tok.describe()}")

    def if_stmt(self) -> n.If:
        kw = self.advance()
        branches = []
        cond = self.expression()
        self.expect_kw("THEN", " after the IF's condition")
        branches.append((cond, self.statements()))
        orelse = None
        while self.tok.is_kw("ELSIF"):
            self.advance()
            c = self.expression()
            self.expect_kw("THEN", " after the ELSIF's condition")
            branches.append((c, self.statements()))
        if self.tok.is_kw("ELSE"):
            self.advance()
            orelse = self.statements()
        self.closing("END_IF", kw)
        self.semicolon("END_IF")
        return n.If(kw.span, branches, orelse)

    def case_stmt(self) -> n.Case:
        kw = self.advance()
        selector = self.expression()
        self.expect_kw("OF", " after the CASE's selector")
        items: list[n.CaseItem] = []
        orelse = None
        while not self.tok.is_kw("END_CASE", "ELSE"):
            if self.tok.kind is Kind.EOF or (self.tok.kind is Kind.KEYWORD and self.tok.upper in _STMT_END):
                self.closing("END_CASE", kw)
            labels = []
            while True:
                lo = self.expression()
                hi = None
                if self.tok.is_op(".."):
                    self.advance()
                    hi = self.expression()
                labels.append((lo, hi))
                if not self.tok.is_op(","):
                    break
                self.advance()
            self.expect_op(":", " after the CASE label")
            items.append(n.CaseItem(labels, self.case_body()))
        if self.tok.is_kw("ELSE"):
            self.advance()
            if self.tok.is_op(":"):
                self.advance()
            orelse = self.statements()
        self.closing("END_CASE", kw)
        self.semicolon("END_CASE")
        return n.Case(kw.span, selector, items, orelse)

    def case_body(self) -> list[n.Stmt]:
        """Statements up to the next CASE label (a value or range followed by ':' or ','), ELSE or END_CASE."""
        out: list[n.Stmt] = []
        while True:
            t = self.tok
            if t.kind is Kind.EOF or (t.kind is Kind.KEYWORD and t.upper in _STMT_END):
                return out
            if t.is_op(";"):
                self.advance()
                continue
            if self.at_case_label():
                return out
            out.append(self.statement())

    def at_case_label(self) -> bool:
        save = self.pos
        try:
            if self.tok.kind not in (Kind.LITERAL, Kind.IDENT) and not self.tok.is_op("-", "+"):
                return False
            try:
                self.expression()
                if self.tok.is_op(".."):
                    self.advance()
                    self.expression()
            except ParseError:
                return False
            return self.tok.is_op(":", ",")
        finally:
            self.pos = save

    def for_stmt(self) -> n.For:
        kw = self.advance()
        v = self.ident("the FOR loop's control variable")
        self.expect_op(":=", " after the FOR's control variable")
        start = self.expression()
        self.expect_kw("TO", " after the FOR's start value")
        end = self.expression()
        step = None
        if self.tok.is_kw("BY"):
            self.advance()
            step = self.expression()
        self.expect_kw("DO", " after the FOR's end value")
        body = self.statements()
        self.closing("END_FOR", kw)
        self.semicolon("END_FOR")
        return n.For(kw.span, n.Name(v.span, v.text), start, end, step, body)

    def while_stmt(self) -> n.While:
        kw = self.advance()
        cond = self.expression()
        self.expect_kw("DO", " after the WHILE's condition")
        body = self.statements()
        self.closing("END_WHILE", kw)
        self.semicolon("END_WHILE")
        return n.While(kw.span, cond, body)

    def repeat_stmt(self) -> n.Repeat:
        kw = self.advance()
        body = self.statements()
        self.expect_kw("UNTIL", f" to end the REPEAT on line {kw.span.line}")
        cond = self.expression()
        self.closing("END_REPEAT", kw)
        self.semicolon("END_REPEAT")
        return n.Repeat(kw.span, body, cond)

    # ---- expressions -----------------------------------------------------------------------------
    def expression(self) -> n.Expr:
        return self.binary_level(0)

    _LEVELS = (("OR",), ("XOR",), ("AND", "&"), ("=", "<>"), ("<", ">", "<=", ">="), ("+", "-"),
               ("*", "/", "MOD"), ("**",))

    def binary_level(self, level: int) -> n.Expr:
        if level == len(self._LEVELS):
            return self.unary()
        ops = self._LEVELS[level]
        left = self.binary_level(level + 1)
        while True:
            t = self.tok
            if t.kind is Kind.OP and t.text in ops:
                op = t.text
            elif t.kind is Kind.KEYWORD and t.upper in ops:
                op = t.upper
            else:
                return left
            self.advance()
            right = self.binary_level(level + 1)
            left = n.Binary(left.span, "AND" if op == "&" else op, left, right, t.span)

    def unary(self) -> n.Expr:
        t = self.tok
        if t.is_op("-", "+") or t.is_kw("NOT"):
            self.advance()
            operand = self.unary()
            op = t.upper if t.kind is Kind.KEYWORD else t.text
            if op == "-" and isinstance(operand, n.Literal) and operand.lit.category in ("int", "real") \
                    and operand.span == self._after(t):
                lit = operand.lit
                return n.Literal(t.span, Lit(lit.category, -lit.value, lit.type_name))
            return n.Unary(t.span, op, operand)
        return self.postfix(self.primary())

    def _after(self, t: Token) -> Span:
        return Span(t.span.file, t.span.line, t.span.col + len(t.text))

    def primary(self) -> n.Expr:
        t = self.tok
        if t.kind is Kind.LITERAL:
            self.advance()
            return n.Literal(t.span, t.value)
        if t.kind is Kind.DIRECT:
            self.advance()
            area, size, idx = t.value
            return n.Direct(t.span, area, size, idx)
        if t.is_op("("):
            self.advance()
            e = self.expression()
            self.expect_op(")", " to close the parenthesis")
            return e
        if t.kind is Kind.IDENT or (t.is_kw("MOD", "AND", "OR", "XOR") and self.peek().is_op("(")):
            self.advance()  # `MOD(a, b)`, `AND(a, b, c)`: the operators' function forms
            if self.tok.is_op("("):
                return n.Call(t.span, t.upper if t.kind is Kind.KEYWORD else t.text, self.call_args())
            return n.Name(t.span, t.text)
        self.unsupported_check(t)
        if t.is_op("^"):
            raise self.error("pointer dereference '^' is not supported")
        raise self.error(f"expected an expression, found {t.describe()}")

    def postfix(self, e: n.Expr) -> n.Expr:
        while True:
            t = self.tok
            if t.is_op("."):
                self.advance()
                m = self.tok
                if m.kind is Kind.LITERAL and m.value.category == "int" and m.value.type_name is None:
                    self.advance()
                    e = n.BitAccess(e.span, e, m.value.value)
                    continue
                if m.kind is Kind.DIRECT or (m.is_op("%")):
                    raise self.error("partial access with '%X' is not supported; write the bit number (w.3)")
                name = self.ident("a member name after '.'")
                e = n.Member(e.span, e, name.text, name.span)
                continue
            if t.is_op("["):
                self.advance()
                idx = [self.expression()]
                while self.tok.is_op(","):
                    self.advance()
                    idx.append(self.expression())
                self.expect_op("]", " to close the index")
                e = n.Index(e.span, e, idx)
                continue
            if t.is_op("(") and isinstance(e, (n.Member, n.Index)):  # `s.fb(...)`, `fbs[i](...)`: an FB instance
                call = n.Call(e.span, e.name if isinstance(e, n.Member) else "", self.call_args())
                call.instance = e
                e = call
                continue
            if t.is_op("^"):
                raise self.error("pointer dereference '^' is not supported")
            return e

    def call_args(self) -> list[n.Arg]:
        self.expect_op("(")
        args: list[n.Arg] = []
        if self.tok.is_op(")"):
            self.advance()
            return args
        while True:
            t = self.tok
            negated = False
            if t.is_kw("NOT") and self.peek().kind is Kind.IDENT and self.peek(2).is_op("=>"):
                self.advance()
                negated = True
            if self.tok.kind is Kind.IDENT and self.peek().is_op(":=", "=>"):
                name = self.advance()
                out = self.advance().text == "=>"
                value = self.expression()
                args.append(n.Arg(name.span, name.text, value, out, negated))
            else:
                value = self.expression()
                args.append(n.Arg(value.span, None, value))
            if not self.tok.is_op(","):
                break
            self.advance()
        self.expect_op(")", " to close the call's arguments")
        return args


def target_text(e: n.Expr) -> str:
    if isinstance(e, n.Name):
        return f"'{e.name}'"
    return "the expression"
