"""Parser: tokens to a Module, by hand-written recursive descent.

Hand-written rather than lark because the messages matter more than the grammar's size: a block
that is not closed is reported at the token where its END word was expected, naming the opener
("expected ENDIF to close the IF on line 4, found ENDPROC"), also when another END word stands
there ("... found ENDWHILE") or a misspelt one ("... found 'ENDFI'"). A closing word with no
block open to take it is "ENDIF without IF". An IF whose THEN is missing reads as a compact IF
(`IF cond instruction;`, valid on any lines); when that reading leads to an error and the reading
with THEN does not, the error is the missing THEN, on the IF's line. The first error stops the parse.

Operator precedence follows the RAPID manual, highest first:
    * / DIV MOD  >  + -  >  = <> < <= > >=  >  AND  >  OR XOR NOT
A leading sign applies to the first term (`-a * b` is `-(a * b)`), a relation takes one
comparison (`a < b < c` is an error) and NOT, the loosest, negates a whole AND-chain
(`NOT a AND b` is `NOT (a AND b)`).
"""
from __future__ import annotations

import difflib

from . import nodes as n
from .errors import ParseError, Span
from .lexer import lex
from .tokens import Kind, Token
from .values import array_type

# Words that close a block; a statement never starts with one of them.
_CLOSERS = {"ENDMODULE", "ENDPROC", "ENDFUNC", "ENDTRAP", "ENDIF", "ELSE", "ELSEIF", "ENDWHILE",
            "ENDFOR", "ENDTEST", "CASE", "DEFAULT", "ERROR", "UNDO", "ENDRECORD"}
_RELOPS = ("=", "<>", "<", "<=", ">", ">=")
# The structure each closing word belongs to, for "ENDIF without IF" messages.
_OWNER = {"ENDIF": "IF", "ELSE": "IF", "ELSEIF": "IF", "ENDWHILE": "WHILE", "ENDFOR": "FOR",
          "ENDTEST": "TEST", "CASE": "TEST", "DEFAULT": "TEST", "ENDPROC": "PROC", "ENDFUNC": "FUNC",
          "ERROR": "PROC, FUNC or TRAP", "UNDO": "PROC, FUNC or TRAP", "ENDMODULE": "MODULE", "ENDTRAP": "TRAP",
          "ENDRECORD": "RECORD"}
# Words that end a routine or the module: in a routine body, they are a wrong END word, not a stray one.
_ROUTINE_ENDS = {"ENDPROC", "ENDFUNC", "ENDTRAP", "ENDMODULE"}
# The END words an identifier may be a misspelling of ("ENDFI", "END_IF", "EndWhile1").
_END_WORDS = ("ENDIF", "ENDWHILE", "ENDFOR", "ENDTEST", "ENDPROC", "ENDFUNC", "ENDTRAP", "ENDMODULE")


def _looks_like_end_word(word: str) -> bool:
    w = word.upper()
    return w in ("END", "END_") or w.startswith("END_") or \
        bool(difflib.get_close_matches(w, _END_WORDS, n=1, cutoff=0.75))


def parse(source: str, file: str = "<input>") -> n.Module:
    """Parse one RAPID module (a file with or without the MODULE ... ENDMODULE wrapper)."""
    return Parser(lex(source, file), source, file).module()


# RobotStudio's and the FlexPendant's placeholders for a slot still to be filled in, by what the slot holds
_PLACEHOLDERS = {"SMT": "statement", "EXP": "expression", "ARG": "argument", "ID": "name", "VAR": "variable",
                 "DN": "data name", "TDN": "data type", "CSE": "CASE", "PAR": "parameter", "DIM": "dimension"}


class Parser:
    def __init__(self, tokens: list[Token], source: str, file: str):
        self.toks = tokens
        self.pos = 0
        self.source = source
        self.file = file
        self.open_closers: list[tuple[str, ...]] = []  # closing words of the blocks being parsed
        self.assume_then: set[int] = set()  # IF tokens (indexes) to read as if THEN followed the condition
        self.compact_ifs: list[tuple[int, int]] = []  # (IF token index, index after its condition)
        self.line_starts = [0]
        for i, ch in enumerate(source):
            if ch == "\n":
                self.line_starts.append(i + 1)

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

    def error(self, message: str, span: Span | None = None) -> ParseError:
        placeholder = self.placeholder() if span is None else None
        if placeholder:
            message = (f"{placeholder} is a placeholder RobotStudio's editor left in the program (an empty "
                       f"{_PLACEHOLDERS[placeholder[1:-1].upper()]} slot): write what belongs there, or delete it")
        return ParseError(message, span or self.tok.span)

    def placeholder(self) -> str | None:
        """`<SMT>`, `<EXP>`, ... at the current token: an editor's empty slot, never valid RAPID."""
        t, word, close = self.tok, self.peek(1), self.peek(2)
        if t.is_op("<") and word.kind in (Kind.IDENT, Kind.KEYWORD) and word.upper in _PLACEHOLDERS and close.is_op(">"):
            return f"<{word.text}>"
        return None

    def after_previous(self) -> Span:
        """The position just after the previous token (where a missing ';' belongs)."""
        prev = self.toks[self.pos - 1] if self.pos else self.tok
        return Span(self.file, prev.span.line, prev.span.col + (prev.end - prev.offset))

    def found(self) -> str:
        return self.tok.describe()

    def expect_kw(self, word: str, what: str = "") -> Token:
        if self.tok.is_kw(word):
            return self.advance()
        raise self.missing_word(word, what, self.pos)

    def expect_op(self, op: str, what: str = "", at_previous: bool = False) -> Token:
        if self.tok.is_op(op):
            return self.advance()
        span = self.after_previous() if at_previous else None
        raise self.error(f"expected '{op}'{what}, found {self.found()}", span)

    def expect_ident(self, what: str) -> Token:
        if self.tok.kind is Kind.IDENT:
            return self.advance()
        if self.tok.kind is Kind.KEYWORD:
            raise self.error(f"expected {what}, found the reserved word {self.tok.upper}")
        raise self.error(f"expected {what}, found {self.found()}")

    def end_of_instruction(self) -> None:
        self.expect_op(";", " at the end of the instruction", at_previous=True)

    def text(self, start: Token) -> str:
        prev = self.toks[self.pos - 1]
        return self.source[start.offset:prev.end]

    # ---- module and declarations -----------------------------------------------------------------
    def module(self) -> n.Module:
        start = self.tok
        attributes: list[str] = []
        self.records: list[n.RecordDecl] = []
        if self.tok.is_kw("MODULE"):
            self.advance()
            name = self.expect_ident("a module name after MODULE").text
            self.module_name = name
            if self.tok.is_op("("):  # module attributes: (SYSMODULE, NOSTEPIN, ...)
                self.advance()
                while not self.tok.is_op(")"):
                    if self.tok.kind is Kind.EOF:
                        raise self.error("expected ')' to close the module attributes")
                    t = self.advance()
                    if t.kind is Kind.IDENT:
                        attributes.append(t.text.upper())
                self.advance()
            data, routines = self.module_items(("ENDMODULE",), f" to close the MODULE on line {start.span.line}")
            self.expect_kw("ENDMODULE")
            if self.tok.kind is not Kind.EOF:
                raise self.error(f"unexpected {self.found()} after ENDMODULE")
        else:
            name = "<anonymous>"
            self.module_name = name
            data, routines = self.module_items((), "")
        for d in data:
            d.module = name
        for r in routines:
            r.module = name
        for rec in self.records:
            rec.module = name
        return n.Module(start.span, name, data, routines, self.file, self.source, self.records, attributes)

    def module_items(self, closers: tuple[str, ...], what: str):
        data: list[n.DataDecl] = []
        routines: list[n.Routine] = []
        while True:
            t = self.tok
            if t.kind is Kind.EOF:
                if closers:
                    raise self.error(f"expected {closers[0]}{what}, found end of file")
                return data, routines
            if closers and t.is_kw(*closers):
                return data, routines
            local = False
            if t.is_kw("LOCAL", "TASK"):  # TASK data are global in the task, as the task is all there is
                local = t.is_kw("LOCAL")
                self.advance()
            if self.tok.is_kw("VAR", "PERS", "CONST"):
                data.append(self.data_decl(local))
            elif self.tok.is_kw("PROC", "FUNC", "TRAP"):
                routines.append(self.routine(local))
            elif self.tok.is_kw("RECORD"):
                self.records.append(self.record_decl(local))
            elif self.tok.is_kw("ALIAS"):
                raise self.error("ALIAS data types are not supported by rapid_like: declare the data with the "
                                 "type itself")
            elif self.tok.is_kw("ENDMODULE") and not closers:
                raise self.error("ENDMODULE without MODULE")
            else:
                raise self.error(f"expected a data declaration (VAR, PERS, CONST) or a routine (PROC, FUNC)"
                                 f"{what and ' in the module'}, found {self.found()}")

    def record_decl(self, local: bool) -> n.RecordDecl:
        kw = self.advance()
        name = self.expect_ident("a record type name after RECORD")
        fields: list[tuple[str, str, Span]] = []
        while not self.tok.is_kw("ENDRECORD"):
            if self.tok.kind is Kind.EOF or self.tok.is_kw("PROC", "FUNC", "TRAP", "ENDMODULE", "RECORD"):
                raise self.error(f"expected ENDRECORD to close the RECORD {name.text} on line {kw.span.line}, "
                                 f"found {self.found()}")
            ftype = self.expect_ident(f"a component type in the RECORD {name.text}")
            fname = self.expect_ident(f"a component name after {ftype.text}")
            self.expect_op(";", " after the record component", at_previous=True)
            fields.append((fname.text, ftype.text.lower(), fname.span))
        self.advance()
        if not fields:
            raise self.error(f"the RECORD {name.text} has no components", kw.span)
        return n.RecordDecl(kw.span, name.text, fields, local)

    def data_decl(self, local: bool = False) -> n.DataDecl:
        kw = self.advance()
        storage = kw.upper
        ttok = self.expect_ident(f"a data type after {storage}")
        name = self.expect_ident(f"a name for the {ttok.text} {storage.lower()}iable" if storage == "VAR"
                                 else f"a name for the {ttok.text} {storage}")
        dims: list[n.Expr] = []
        if self.tok.is_op("{"):
            brace = self.advance()
            dims.append(self.expression())
            while self.tok.is_op(","):
                self.advance()
                dims.append(self.expression())
            self.expect_op("}", f" to close the array size on line {brace.span.line} col {brace.span.col}")
            if len(dims) > 3:
                raise self.error("an array has at most 3 dimensions", brace.span)
        init = None
        if self.tok.is_op(":="):
            self.advance()
            init = self.expression()
        elif self.tok.is_op("="):
            raise self.error("expected ':=' to give an initial value ('=' compares)")
        elif storage == "CONST":
            raise self.error(f"expected ':=' and a value for the constant {name.text}", self.after_previous())
        self.expect_op(";", " at the end of the declaration", at_previous=True)
        return n.DataDecl(kw.span, storage, ttok.text.lower(), ttok.span, name.text, init, local, dims)

    def routine(self, local: bool) -> n.Routine:
        """A PROC or FUNC. When it does not parse and one of its compact IFs would parse further as
        an IF ... THEN, the error is that IF's missing THEN."""
        start, compact = self.pos, len(self.compact_ifs)
        try:
            return self.routine_body(local)
        except ParseError as err:
            candidates = [c for c in self.compact_ifs[compact:] if self.toks[c[0]].offset < self._offset(err)]
            del self.compact_ifs[compact:]
            for if_index, after_cond in reversed(candidates):
                if self._parses_further_with_then(start, if_index, local, err):
                    raise self.missing_then(after_cond) from None
            raise

    def missing_then(self, after_cond: int) -> ParseError:
        """THEN is missing before token `after_cond` (reported on the IF's line)."""
        return self.missing_word("THEN", " after the IF condition", after_cond)

    def missing_word(self, word: str, what: str, at: int) -> ParseError:
        """`word` expected before token `at`. When that token starts a later line, the error is
        reported just after the previous token, where the word belongs (`IF cond` / `WHILE cond`
        with THEN / DO forgotten at the end of the line), naming the line of what was found."""
        prev, nxt = self.toks[at - 1], self.toks[at]
        if at > 0 and nxt.span.line > prev.span.line:
            return ParseError(f"expected {word}{what}, found {nxt.describe()} on line {nxt.span.line}",
                              Span(self.file, prev.span.line, prev.span.col + (prev.end - prev.offset)))
        return ParseError(f"expected {word}{what}, found {nxt.describe()}", nxt.span)

    def _offset(self, err: ParseError) -> int:
        span = err.span
        if span is None or span.line > len(self.line_starts):
            return len(self.source)
        return self.line_starts[span.line - 1] + span.col - 1

    def _parses_further_with_then(self, start: int, if_index: int, local: bool, err: ParseError) -> bool:
        """Does the routine at token `start` parse (or fail later than `err`) with a THEN assumed
        after the condition of the IF at token `if_index`?"""
        saved = (self.pos, len(self.compact_ifs))
        self.pos = start
        self.assume_then.add(if_index)
        try:
            self.routine_body(local)
            return True
        except ParseError as again:
            return self._offset(again) > self._offset(err)
        finally:
            self.assume_then.discard(if_index)
            self.pos = saved[0]
            del self.compact_ifs[saved[1]:]

    def routine_body(self, local: bool) -> n.Routine:
        kw = self.advance()
        kind = kw.upper
        rtype = None
        if kind == "FUNC":
            rtype = self.expect_ident("a return type after FUNC").text.lower()
        name = self.expect_ident(f"a name after {kind}")
        if kind == "TRAP":
            params: list[n.Param] = []
            if self.tok.is_op("("):
                raise self.error(f"a TRAP routine takes no parameters: write TRAP {name.text} without '('")
        else:
            self.expect_op("(", f" after the {kind} name {name.text}")
            params = self.params()
        end = {"PROC": "ENDPROC", "FUNC": "ENDFUNC", "TRAP": "ENDTRAP"}[kind]
        opener = f"{kind} {name.text} on line {kw.span.line}"
        body = self.block((end, "ERROR", "UNDO", "BACKWARD"), end, opener)
        handler = error_list = undo = None
        if self.tok.is_kw("BACKWARD"):
            raise self.error("BACKWARD handlers are not supported by rapid_like (the program never runs backwards)")
        if self.tok.is_kw("ERROR"):
            self.advance()
            if self.tok.is_op("("):  # ERROR (ERR_A, ERR_B): the error numbers this handler takes
                paren = self.advance()
                error_list = [self.expression()]
                while self.tok.is_op(","):
                    self.advance()
                    error_list.append(self.expression())
                self.expect_op(")", f" to close the error list on line {paren.span.line}")
            handler = self.block((end, "UNDO"), end, opener)
        if self.tok.is_kw("UNDO"):
            self.advance()
            undo = self.block((end,), end, opener)
        closing = self.expect_kw(end)
        return n.Routine(kw.span, kind, name.text, params, body, handler, rtype, local, closing.span,
                         error_list, undo)

    def params(self) -> list[n.Param]:
        params: list[n.Param] = []
        if self.tok.is_op(")"):
            self.advance()
            return params
        while True:
            if self.tok.is_op("\\"):
                self.advance()
                p = self.one_param(optional=True)
                while self.tok.is_op("|"):
                    self.advance()
                    p.alternatives.append(self.one_param(optional=True))
                params.append(p)
            else:
                params.append(self.one_param(optional=False))
            if self.tok.is_op(")"):
                self.advance()
                return params
            if self.tok.is_op(","):
                self.advance()
                continue
            if self.tok.is_op("\\"):
                continue
            raise self.error(f"expected ',' or ')' in the parameter list, found {self.found()}")

    def one_param(self, optional: bool) -> n.Param:
        start = self.tok
        mode = "IN"
        if self.tok.is_kw("VAR", "PERS", "INOUT"):
            mode = self.advance().upper
        ttok = self.expect_ident("a parameter type")
        if ttok.text.lower() == "switch":
            name = self.expect_ident("a switch name")
            return n.Param(start.span, name.text, "switch", mode, True)
        name = self.expect_ident(f"a parameter name after the type {ttok.text}")
        ptype = ttok.text.lower()
        if self.tok.is_op("{"):  # an array parameter: {*}, {*,*} or {*,*,*}
            self.advance()
            ndims = 0
            while True:
                self.expect_op("*", " in an array parameter's dimensions ({*})")
                ndims += 1
                if not self.tok.is_op(","):
                    break
                self.advance()
            self.expect_op("}", " to close the array parameter's dimensions")
            ptype = array_type(ptype, ndims)
        return n.Param(start.span, name.text, ptype, mode, optional)

    # ---- statements ------------------------------------------------------------------------------
    def block(self, closers: tuple[str, ...], expected: str, opener: str) -> list[n.Stmt]:
        """Statements up to (not including) one of `closers`. Anything else that closes a block is
        reported as the missing `expected` word of `opener`."""
        stmts: list[n.Stmt] = []
        self.open_closers.append(closers)
        in_routine = expected in ("ENDPROC", "ENDFUNC", "ENDTRAP")  # the body (or ERROR handler) of a routine
        try:
            while True:
                t = self.tok
                if t.kind is Kind.KEYWORD and t.upper in closers:
                    return stmts
                if in_routine and t.is_kw("ERROR") and "ERROR" not in closers:
                    raise self.error(f"a second ERROR in the {opener}: a routine has one ERROR handler"
                                     + (", before its UNDO" if "UNDO" in closers else ""))
                if in_routine and t.is_kw("UNDO") and "UNDO" not in closers:
                    raise self.error(f"a second UNDO in the {opener}: a routine has one UNDO section, at its end")
                if in_routine and t.kind is Kind.KEYWORD and t.upper in _CLOSERS and \
                        t.upper not in _ROUTINE_ENDS and not any(t.upper in c for c in self.open_closers):
                    raise self.error(f"{t.upper} without {_OWNER[t.upper]}: no {_OWNER[t.upper]} is open here")
                if t.kind is Kind.EOF or (t.kind is Kind.KEYWORD and t.upper in _CLOSERS) or \
                        t.is_kw("PROC", "FUNC", "TRAP", "ENDMODULE", "ENDTRAP"):
                    hint = ""
                    last = stmts[-1] if stmts else None
                    if isinstance(last, n.ProcCall) and not last.args and _looks_like_end_word(last.name):
                        hint = f" (is '{last.name}' on line {last.span.line} meant to be {expected}?)"
                    raise self.error(f"expected {expected} to close the {opener}, found {self.found()}{hint}")
                if t.kind is Kind.IDENT and _looks_like_end_word(t.text):
                    # `ENDFI`, `END IF`, `ENDWHILE1`...: if it is no instruction, it is the missing END word
                    at = self.pos
                    try:
                        stmts.append(self.statement())
                    except ParseError:
                        self.pos = at
                        raise self.error(f"expected {expected} to close the {opener}, found '{t.text}'") from None
                    continue
                stmts.append(self.statement())
        finally:
            self.open_closers.pop()

    def statement(self) -> n.Stmt:
        t = self.tok
        if t.kind is Kind.IDENT:
            return self.simple_ident_statement()
        if t.kind is Kind.KEYWORD:
            w = t.upper
            if w == "IF":
                return self.if_stmt()
            if w == "WHILE":
                return self.while_stmt()
            if w == "FOR":
                return self.for_stmt()
            if w == "TEST":
                return self.test_stmt()
            if w == "PERS":
                raise self.error("PERS data cannot be declared in a routine: declare it in the module")
            if w in ("VAR", "CONST"):
                decl = self.data_decl()
                return n.LocalDecl(decl.span, decl)
            if w in ("RETURN", "EXIT", "RETRY", "TRYNEXT", "RAISE"):
                return self.keyword_instruction()
            if w == "CONNECT":
                self.advance()
                target = self.postfix(self.name_expr()) if self.tok.kind is Kind.IDENT else None
                if target is None:
                    raise self.error(f"expected an interrupt variable (intnum) after CONNECT, found {self.found()}")
                self.expect_kw("WITH", f" after CONNECT {target.text} (CONNECT intno WITH trap_routine;)")
                trap = self.expect_ident("the name of a TRAP routine after WITH")
                self.end_of_instruction()
                return n.Connect(t.span, target, trap.text, trap.span)
            if w == "GOTO":
                self.advance()
                label = self.expect_ident("a label after GOTO")
                self.end_of_instruction()
                return n.Goto(t.span, label.text, label.span)
        if t.is_op("%"):  # `%"proc" + NumToStr(n, 0)%;` calls the procedure a string names
            raise self.error("late binding (%...%) is not supported by rapid_like: call the procedure by its "
                             "name, e.g. in a TEST on the value")
        prev = self.toks[self.pos - 1] if self.pos else None
        if t.is_op(";") and prev is not None and prev.kind is Kind.KEYWORD and prev.upper in _CLOSERS | _ROUTINE_ENDS:
            raise self.error(f"unexpected ';' after {prev.upper}: a closing word takes no ';'")
        raise self.error(f"expected an instruction, found {self.found()}")

    def keyword_instruction(self) -> n.Stmt:
        t = self.advance()
        w = t.upper
        if w == "RETURN":
            value = None if self.tok.is_op(";") else self.expression()
            self.end_of_instruction()
            return n.Return(t.span, value)
        if w == "RAISE":
            value = None if self.tok.is_op(";") else self.expression()
            self.end_of_instruction()
            return n.Raise(t.span, value)
        self.end_of_instruction()
        return {"EXIT": n.Exit, "RETRY": n.Retry, "TRYNEXT": n.TryNext}[w](t.span)

    def simple_ident_statement(self) -> n.Stmt:
        start = self.tok
        if self.peek().is_op(":"):  # a label: `next:`
            self.advance()
            self.advance()
            return n.Label(start.span, start.text)
        if self.peek().is_op(":=", ".", "{"):
            target = self.postfix(self.name_expr())
            if not self.tok.is_op(":="):
                if self.tok.is_op("="):
                    raise self.error("expected ':=' for an assignment ('=' compares)")
                raise self.error(f"expected ':=' after {target.text}, found {self.found()}")
            self.advance()
            value = self.expression()
            self.end_of_instruction()
            return n.Assign(start.span, target, value)
        if self.peek().is_op("=") and not self.peek(2).is_op("="):
            raise self.error(f"expected ':=' to assign to {start.text} ('=' compares)", self.peek().span)
        name = self.advance()
        args = self.arguments(";", f"the {name.text} instruction")
        self.end_of_instruction()
        return n.ProcCall(name.span, name.text, args)

    def arguments(self, closer: str, what: str) -> list[n.Arg]:
        """Arguments up to `closer` (not consumed). Required arguments are separated by commas;
        an optional `\\Name[:=value]` may follow with or without a comma."""
        args: list[n.Arg] = []
        need_comma = False
        while not self.tok.is_op(closer):
            t = self.tok
            if t.kind is Kind.EOF or (t.kind is Kind.KEYWORD and t.upper in _CLOSERS):
                break
            if t.is_op(","):
                if not args:
                    raise self.error(f"expected an argument of {what} before ','")
                self.advance()
                need_comma = False
                if self.tok.is_op(closer, ","):
                    raise self.error(f"expected an argument of {what} after ','")
                continue
            if t.is_op("\\"):
                self.advance()
                name = self.expect_ident(f"an optional argument name after '\\' in {what}")
                value = None
                conditional = False
                if self.tok.is_op(":="):
                    self.advance()
                    value = self.expression()
                elif self.tok.is_op("?"):  # a conditional argument: \Speed?Speed
                    self.advance()
                    param = self.expect_ident(f"the name of an optional parameter after '\\{name.text}?'")
                    value = n.Name(param.span, param.text, param.text)
                    conditional = True
                args.append(n.Arg(t.span, value, name.text, True, conditional))
                need_comma = True
                continue
            if need_comma and args and not args[-1].optional:
                prev = self.toks[self.pos - 1]
                if closer == ";" and t.span.line == prev.span.line:
                    raise self.error(f"expected ',' between the arguments of {what}, found {self.found()}",
                                     self.after_previous())
                if closer == ";":
                    raise self.error(f"expected ';' at the end of the instruction, found {self.found()}",
                                     self.after_previous())
                raise self.error(f"expected ',' between the arguments of {what}, found {self.found()}")
            aname = None
            if t.kind is Kind.IDENT and self.peek().is_op(":="):
                aname = self.advance().text
                self.advance()
            value = self.expression()
            args.append(n.Arg(t.span, value, aname, False))
            need_comma = True
        return args

    def if_stmt(self) -> n.Stmt:
        if_index = self.pos
        kw = self.advance()
        cond = self.expression()
        if not self.tok.is_kw("THEN") and if_index not in self.assume_then:
            # compact IF: IF cond instruction;
            if self.tok.kind is Kind.IDENT or self.tok.is_kw("RETURN", "EXIT", "RETRY", "TRYNEXT", "RAISE", "GOTO"):
                self.compact_ifs.append((if_index, self.pos))
                body = [self.statement()]
                return n.If(kw.span, [(cond, body)], None, compact=True)
            raise self.missing_then(self.pos)
        if self.tok.is_kw("THEN"):
            self.advance()
        opener = f"IF on line {kw.span.line}"
        branches = [(cond, self.block(("ELSEIF", "ELSE", "ENDIF"), "ENDIF", opener))]
        orelse = None
        while self.tok.is_kw("ELSEIF"):
            self.advance()
            c = self.expression()
            self.expect_kw("THEN", " after the ELSEIF condition")
            branches.append((c, self.block(("ELSEIF", "ELSE", "ENDIF"), "ENDIF", opener)))
        if self.tok.is_kw("ELSE"):
            else_line = self.advance().span.line
            orelse = self.block(("ENDIF", "ELSEIF", "ELSE"), "ENDIF", opener)
            if self.tok.is_kw("ELSEIF", "ELSE"):
                raise self.error(f"{self.tok.upper} after ELSE in the {opener}: ELSE (line {else_line}) must be "
                                 f"its last branch")
        self.expect_kw("ENDIF")
        return n.If(kw.span, branches, orelse)

    def while_stmt(self) -> n.Stmt:
        kw = self.advance()
        cond = self.expression()
        self.expect_kw("DO", " after the WHILE condition")
        body = self.block(("ENDWHILE",), "ENDWHILE", f"WHILE on line {kw.span.line}")
        self.advance()
        return n.While(kw.span, cond, body)

    def for_stmt(self) -> n.Stmt:
        kw = self.advance()
        var = self.expect_ident("a loop variable after FOR")
        self.expect_kw("FROM", f" after FOR {var.text}")
        start = self.expression()
        self.expect_kw("TO", " after the FROM value")
        stop = self.expression()
        step = None
        if self.tok.is_kw("STEP"):
            self.advance()
            step = self.expression()
        self.expect_kw("DO", " after the FOR range")
        body = self.block(("ENDFOR",), "ENDFOR", f"FOR on line {kw.span.line}")
        self.advance()
        return n.For(kw.span, var.text, var.span, start, stop, step, body)

    def test_stmt(self) -> n.Stmt:
        kw = self.advance()
        subject = self.expression()
        opener = f"TEST on line {kw.span.line}"
        cases: list[tuple[list[n.Expr], list[n.Stmt]]] = []
        default = None
        if not self.tok.is_kw("CASE", "DEFAULT"):
            raise self.error(f"expected CASE or DEFAULT after the TEST value, found {self.found()}")
        while self.tok.is_kw("CASE"):
            self.advance()
            values = [self.expression()]
            while self.tok.is_op(","):
                self.advance()
                values.append(self.expression())
            self.expect_op(":", " after the CASE values")
            cases.append((values, self.block(("CASE", "DEFAULT", "ENDTEST"), "ENDTEST", opener)))
        if self.tok.is_kw("DEFAULT"):
            self.advance()
            self.expect_op(":", " after DEFAULT")
            default = self.block(("ENDTEST", "CASE", "DEFAULT"), "ENDTEST", opener)
        if self.tok.is_kw("CASE", "DEFAULT"):
            raise self.error(f"{self.tok.upper} after DEFAULT in the {opener}: DEFAULT must be its last branch")
        self.expect_kw("ENDTEST", f" to close the {opener}")
        return n.Test(kw.span, subject, cases, default)

    # ---- expressions -----------------------------------------------------------------------------
    def expression(self) -> n.Expr:
        start = self.tok
        left = self.not_expr()
        while self.tok.is_kw("OR", "XOR"):
            op = self.advance()
            right = self.not_expr()
            left = n.Binary(start.span, self.text(start), op.upper, left, right, op.span)
        return left

    def not_expr(self) -> n.Expr:
        start = self.tok
        if self.tok.is_kw("NOT"):
            op = self.advance()
            operand = self.not_expr()
            return n.Unary(start.span, self.text(start), "NOT", operand, op.span)
        return self.and_expr()

    def and_expr(self) -> n.Expr:
        start = self.tok
        left = self.relation()
        while self.tok.is_kw("AND"):
            op = self.advance()
            if self.tok.is_kw("NOT"):  # `a AND NOT b`: NOT applies to the relation that follows
                s2 = self.tok
                nop = self.advance()
                inner = self.relation()
                right: n.Expr = n.Unary(s2.span, self.text(s2), "NOT", inner, nop.span)
            else:
                right = self.relation()
            left = n.Binary(start.span, self.text(start), "AND", left, right, op.span)
        return left

    def relation(self) -> n.Expr:
        start = self.tok
        left = self.simple_expr()
        if self.tok.is_op(*_RELOPS):
            op = self.advance()
            right = self.simple_expr()
            left = n.Binary(start.span, self.text(start), op.text, left, right, op.span)
            if self.tok.is_op(*_RELOPS):
                raise self.error(f"a comparison cannot be chained: write ({left.text}) AND ... instead")
        return left

    def simple_expr(self) -> n.Expr:
        start = self.tok
        if self.tok.is_op("+", "-"):
            op = self.advance()
            first = self.term()
            left: n.Expr = n.Unary(start.span, self.text(start), op.text, first, op.span)
        else:
            left = self.term()
        while self.tok.is_op("+", "-"):
            op = self.advance()
            right = self.term()
            left = n.Binary(start.span, self.text(start), op.text, left, right, op.span)
        return left

    def term(self) -> n.Expr:
        start = self.tok
        left = self.primary()
        while self.tok.is_op("*", "/") or self.tok.is_kw("DIV", "MOD"):
            op = self.advance()
            right = self.primary()
            opname = op.upper if op.kind is Kind.KEYWORD else op.text
            left = n.Binary(start.span, self.text(start), opname, left, right, op.span)
        return left

    def primary(self) -> n.Expr:
        t = self.tok
        if t.kind is Kind.NUM:
            self.advance()
            return n.NumLit(t.span, t.text, float(t.value))
        if t.kind is Kind.STRING:
            self.advance()
            return n.StrLit(t.span, t.text, str(t.value))
        if t.is_kw("TRUE", "FALSE"):
            self.advance()
            return n.BoolLit(t.span, t.text, t.upper == "TRUE")
        if t.is_op("+", "-"):  # a sign inside a term, e.g. `a * -1`
            op = self.advance()
            operand = self.primary()
            return n.Unary(t.span, self.text(t), op.text, operand, op.span)
        if t.is_op("("):
            self.advance()
            inner = self.expression()
            self.expect_op(")", f" to close the '(' on line {t.span.line} col {t.span.col}")
            inner.text = self.text(t)
            return inner
        if t.is_op("["):
            self.advance()
            items: list[n.Expr] = []
            if not self.tok.is_op("]"):
                items.append(self.expression())
                while self.tok.is_op(","):
                    self.advance()
                    items.append(self.expression())
            self.expect_op("]", f" to close the '[' on line {t.span.line} col {t.span.col}")
            return n.Aggregate(t.span, self.text(t), items)
        if t.kind is Kind.IDENT:
            if self.peek().is_op("("):
                name = self.advance()
                self.advance()
                args = self.arguments(")", f"{name.text}()")
                self.expect_op(")", f" to close the call of {name.text}")
                return self.postfix(n.Call(t.span, self.text(t), name.text, args))
            return self.postfix(self.name_expr())
        if t.kind is Kind.KEYWORD:
            raise self.error(f"expected an expression, found the reserved word {t.upper}")
        if t.kind is Kind.EOF:
            raise self.error("expected an expression, found end of file")
        raise self.error(f"expected an expression, found {self.found()}")

    def name_expr(self) -> n.Name:
        t = self.advance()
        return n.Name(t.span, t.text, t.text)

    def postfix(self, expr: n.Expr) -> n.Expr:
        """`expr.field`, `expr{i}`, `expr{i, j}`, in any sequence."""
        start = self.line_starts[expr.span.line - 1] + expr.span.col - 1
        while self.tok.is_op(".", "{"):
            if self.advance().text == ".":
                f = self.expect_ident("a component name after '.'")
                expr = n.Component(expr.span, self.source[start:f.end], expr, f.text, f.span)
            else:
                brace = self.toks[self.pos - 1]
                indices = [self.expression()]
                while self.tok.is_op(","):
                    self.advance()
                    indices.append(self.expression())
                close = self.expect_op("}", f" to close the index on line {brace.span.line} col {brace.span.col}")
                expr = n.Index(expr.span, self.source[start:close.end], expr, indices)
        return expr
