"""Tokens: the kinds the lexer produces and the reserved words of the RAPID subset.

Keywords and identifiers are case-insensitive, so every token keeps the text as written (for
messages and traces) and keywords are matched on their upper-case form.
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from .errors import Span


class Kind(Enum):
    IDENT = "identifier"
    KEYWORD = "keyword"
    NUM = "number"
    STRING = "string"
    OP = "operator"
    EOF = "end of file"


# Reserved words of the subset (RAPID reserves more; these are the ones the grammar uses).
KEYWORDS = frozenset(
    """
    MODULE ENDMODULE PROC ENDPROC FUNC ENDFUNC TRAP ENDTRAP ERROR LOCAL TASK
    VAR PERS CONST INOUT
    IF THEN ELSEIF ELSE ENDIF WHILE DO ENDWHILE FOR FROM TO STEP ENDFOR
    TEST CASE DEFAULT ENDTEST RETURN EXIT RETRY TRYNEXT RAISE GOTO
    AND OR XOR NOT DIV MOD TRUE FALSE
    RECORD ENDRECORD UNDO CONNECT WITH ALIAS BACKWARD
    """.split()
)

# Multi-character operators first, so the lexer tries them before their prefixes.
OPERATORS = (":=", "<>", "<=", ">=", "<", ">", "=", "+", "-", "*", "/", "(", ")", "[", "]",
             "{", "}", ",", ";", ":", ".", "\\", "|", "%", "?")


@dataclass(frozen=True)
class Token:
    kind: Kind
    text: str            # as written
    span: Span
    offset: int          # character offset of the first character in the source
    end: int             # offset one past the last character
    value: object = None  # float for NUM, str for STRING

    @property
    def upper(self) -> str:
        return self.text.upper()

    def is_kw(self, *words: str) -> bool:
        return self.kind is Kind.KEYWORD and self.text.upper() in words

    def is_op(self, *ops: str) -> bool:
        return self.kind is Kind.OP and self.text in ops

    def describe(self) -> str:
        if self.kind is Kind.EOF:
            return "end of file"
        if self.kind is Kind.KEYWORD:
            return self.text.upper()
        if self.kind is Kind.STRING:
            return "a string"
        if self.kind is Kind.NUM:
            return f"number {self.text}"
        return f"'{self.text}'"
