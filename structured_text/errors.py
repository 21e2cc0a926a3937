"""Errors of the Structured Text runtime, one class per stage, each with the place it happened.

    StError                    base: a message and a Span (file, line, column)
    ├── LexError               a character or literal the lexer cannot read
    ├── ParseError             the token stream does not follow the grammar (or uses what is not supported)
    ├── CheckError             static check: undeclared name, type mismatch, bad call
    └── PlcFault               runtime error: the PLC goes to STOP (division by zero, index out of
                               bounds, a scan that does not end); names the task and program instance

`headline()` is the line a PLC programmer reads: `FILE:LINE:COL: error: message`.
"""
from __future__ import annotations

from twin.core.errors import Span, TwinError  # the project's one error tree, and the place in a file


class StError(TwinError):
    """Base class of every error the runtime reports to the user."""

    def __init__(self, message: str, span: Span | None):
        super().__init__(message)
        self.message = message
        self.span = span

    def headline(self) -> str:
        where = f"{self.span}: " if self.span else ""
        return f"{where}error: {self.message}"

    def __str__(self) -> str:
        return self.headline()


class LexError(StError):
    """A character or a literal the lexer cannot read."""


class ParseError(StError):
    """The program does not follow the grammar of IEC 61131-3 Structured Text (or uses an unsupported part)."""


class CheckError(StError):
    """A static error found before anything runs."""


class StaticErrors(StError):
    """Several static errors of one check, reported one line each."""

    def __init__(self, errors: list[StError]):
        super().__init__(errors[0].message, errors[0].span)
        self.errors = errors

    def headline(self) -> str:
        return "\n".join(e.headline() for e in self.errors)


class PlcFault(StError):
    """A runtime error: the PLC is in STOP. `task` and `instance` say where it ran."""

    def __init__(self, message: str, span: Span | None, task: str = "", instance: str = ""):
        super().__init__(message, span)
        self.task = task
        self.instance = instance

    def headline(self) -> str:
        where = f"{self.span}: " if self.span else ""
        ctx = []
        if self.task:
            ctx.append(f"task {self.task}")
        if self.instance:
            ctx.append(f"program {self.instance}")
        tail = f" (in {', '.join(ctx)}; the PLC is in STOP)" if ctx else " (the PLC is in STOP)"
        return f"{where}error: {self.message}{tail}"
