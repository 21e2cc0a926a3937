"""Errors of the RAPID interpreter, one class per stage, each with the span where it happened.

    RapidError                 base: a message and a Span (file, line, column)
    ├── LexError               a character or literal the lexer cannot read
    ├── ParseError             the token stream does not follow the grammar
    ├── CheckError             static check: undefined name, wrong arity or type, bad assignment
    └── ExecError              runtime error; carries a RAPID error number (ERRNO), so ERROR
                               handlers can recover from it

The names avoid Python's SyntaxError and RuntimeError. `RapidError.render(source)` gives the
message a robot programmer reads: `FILE:LINE:COL: error: message`, the source line and a caret.
"""
from __future__ import annotations

from twin.core.errors import Span, TwinError  # the project's one error tree, and the place in a file


class RapidError(TwinError):
    """Base class of every error the interpreter reports to the user."""

    kind = "error"

    def __init__(self, message: str, span: Span | None):
        super().__init__(message)
        self.message = message
        self.span = span

    def headline(self) -> str:
        where = f"{self.span}: " if self.span else ""
        return f"{where}error: {self.message}"

    def render(self, source: str | None = None) -> str:
        """`FILE:LINE:COL: error: message`, then the source line and a caret under the column."""
        text = self.headline()
        if source is not None and self.span is not None:
            lines = source.splitlines()
            if 1 <= self.span.line <= len(lines):
                line = lines[self.span.line - 1].rstrip("\r\n")
                caret = "".join("\t" if ch == "\t" else " " for ch in line[: self.span.col - 1]) + "^"
                text += f"\n    {line}\n    {caret}"
        return text


class LexError(RapidError):
    """A character or a literal the lexer cannot read."""


class ParseError(RapidError):
    """The program does not follow RAPID's grammar."""


class CheckError(RapidError):
    """A static error found before anything runs (undefined name, arity, type, constant)."""


class ExecError(RapidError):
    """A runtime error. `errno` is the RAPID error number an ERROR handler sees in ERRNO."""

    def __init__(self, message: str, span: Span | None, errno: int, errname: str = ""):
        super().__init__(message, span)
        self.errno = errno
        self.errname = errname
