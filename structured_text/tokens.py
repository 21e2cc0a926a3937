"""Tokens: the kinds the lexer produces, the reserved words of Structured Text and literal values.

Keywords and identifiers are case-insensitive: every token keeps the text as written (for messages)
and keywords are matched on their upper-case form. Data-type names (INT, TIME, ...) and standard
function names are identifiers, resolved by the checker.
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from .errors import Span


class Kind(Enum):
    IDENT = "identifier"
    KEYWORD = "keyword"
    LITERAL = "literal"
    DIRECT = "direct address"
    OP = "operator"
    EOF = "end of file"


KEYWORDS = frozenset(
    """
    PROGRAM END_PROGRAM FUNCTION END_FUNCTION FUNCTION_BLOCK END_FUNCTION_BLOCK
    VAR VAR_INPUT VAR_OUTPUT VAR_IN_OUT VAR_GLOBAL VAR_EXTERNAL VAR_TEMP VAR_ACCESS VAR_CONFIG END_VAR
    CONSTANT RETAIN NON_RETAIN AT TYPE END_TYPE STRUCT END_STRUCT ARRAY OF
    IF THEN ELSIF ELSE END_IF CASE END_CASE FOR TO BY DO END_FOR WHILE END_WHILE REPEAT UNTIL END_REPEAT
    EXIT CONTINUE RETURN AND OR XOR NOT MOD TRUE FALSE
    CONFIGURATION END_CONFIGURATION RESOURCE END_RESOURCE ON TASK WITH READ_WRITE READ_ONLY
    END_STEP INITIAL_STEP END_TRANSITION END_ACTION
    METHOD END_METHOD INTERFACE END_INTERFACE PROPERTY END_PROPERTY CLASS END_CLASS EXTENDS IMPLEMENTS
    POINTER REF_TO REFERENCE THIS SUPER JMP NAMESPACE END_NAMESPACE R_EDGE F_EDGE
    """.split()
)

# Keywords of parts of IEC 61131-3 this runtime does not run: a program using one gets
# "... is not supported" at its position, never a wrong run.
UNSUPPORTED = {
    "STEP": "SFC (sequential function charts)", "INITIAL_STEP": "SFC (sequential function charts)",
    "TRANSITION": "SFC (sequential function charts)", "ACTION": "SFC actions",
    "END_STEP": "SFC", "END_TRANSITION": "SFC", "END_ACTION": "SFC actions",
    "METHOD": "object-oriented extensions (METHOD)", "INTERFACE": "object-oriented extensions (INTERFACE)",
    "PROPERTY": "object-oriented extensions (PROPERTY)", "CLASS": "object-oriented extensions (CLASS)",
    "EXTENDS": "object-oriented extensions (EXTENDS)", "IMPLEMENTS": "object-oriented extensions (IMPLEMENTS)",
    "THIS": "object-oriented extensions (THIS)", "SUPER": "object-oriented extensions (SUPER)",
    "ABSTRACT": "object-oriented extensions", "FINAL": "object-oriented extensions",
    "END_METHOD": "object-oriented extensions", "END_INTERFACE": "object-oriented extensions",
    "END_PROPERTY": "object-oriented extensions", "END_CLASS": "object-oriented extensions",
    "POINTER": "pointers", "REF_TO": "references (REF_TO)", "REFERENCE": "references",
    "JMP": "jumps (IL)", "NAMESPACE": "namespaces", "END_NAMESPACE": "namespaces",
    "R_EDGE": "edge-declared inputs (R_EDGE)", "F_EDGE": "edge-declared inputs (F_EDGE)",
    "VAR_ACCESS": "VAR_ACCESS", "VAR_CONFIG": "VAR_CONFIG",
}

# Multi-character operators first, so the lexer tries them before their prefixes.
OPERATORS = (":=", "=>", "<>", "<=", ">=", "**", "..", "<", ">", "=", "+", "-", "*", "/", "&", "(", ")",
             "[", "]", ",", ";", ":", ".", "^", "#")


@dataclass(frozen=True)
class Lit:
    """A literal's value. `category`: int, real, bool, time, date, tod, dt, string, wstring, enum;
    `type_name`: the type prefix of a typed literal (`INT#5`), else None."""

    category: str
    value: object
    type_name: str | None = None


@dataclass(frozen=True)
class Token:
    kind: Kind
    text: str
    span: Span
    value: object = None  # Lit for LITERAL, (area, size, (indexes...)) for DIRECT

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
        return f"'{self.text}'"
