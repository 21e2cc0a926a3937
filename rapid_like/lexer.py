"""Lexer: RAPID source text to a list of tokens, each with its line and column.

`!` starts a comment that runs to the end of the line. Strings are double-quoted; a quote inside a
string is written twice (`""`), a backslash as `\\\\` and a character by its hex code as `\\0A`; a string literal holds at most 80
characters, as every RAPID string does. Numbers are decimal, with an optional fraction and
exponent (`9E9`, `1.5e-3`); `1.2.3` is a malformed number. An old-style
`%%% VERSION:1 LANGUAGE:ENGLISH %%%` header at the top of a file is skipped.
"""
from __future__ import annotations

import re

from .errors import LexError, Span
from .tokens import KEYWORDS, OPERATORS, Kind, Token
from .values import STRING_MAX

_HEADER = re.compile(r"\s*%%%.*?%%%", re.S)


def lex(source: str, file: str = "<input>") -> list[Token]:
    tokens: list[Token] = []
    i, line, line_start, n = 0, 1, 0, len(source)
    header = _HEADER.match(source)  # an old-style `%%% VERSION:1 LANGUAGE:ENGLISH %%%` file header
    if header:
        i = header.end()
        line += source.count("\n", 0, i)
        line_start = source.rfind("\n", 0, i) + 1

    def span_at(pos: int) -> Span:
        return Span(file, line, pos - line_start + 1)

    while i < n:
        ch = source[i]
        if ch == "\n":
            i += 1
            line += 1
            line_start = i
            continue
        if ch in " \t\r\f\v":
            i += 1
            continue
        if ch == "!":
            while i < n and source[i] != "\n":
                i += 1
            continue
        start = i
        if ch.isalpha() or ch == "_":
            while i < n and (source[i].isalnum() or source[i] == "_"):
                i += 1
            text = source[start:i]
            kind = Kind.KEYWORD if text.upper() in KEYWORDS else Kind.IDENT
            tokens.append(Token(kind, text, span_at(start), start, i))
            continue
        if ch.isdigit() or (ch == "." and i + 1 < n and source[i + 1].isdigit()):
            while i < n and source[i].isdigit():
                i += 1
            if i < n and source[i] == "." and (i + 1 >= n or not source[i + 1].isalpha() or source[i + 1] in "eE"):
                i += 1
                while i < n and source[i].isdigit():
                    i += 1
            if i < n and source[i] in "eE":
                j = i + 1
                if j < n and source[j] in "+-":
                    j += 1
                if j < n and source[j].isdigit():
                    i = j
                    while i < n and source[i].isdigit():
                        i += 1
                else:
                    raise LexError(f"malformed number '{source[start:j]}': expected digits after the exponent",
                                   span_at(start))
            if i + 1 < n and source[i] == "." and source[i + 1].isdigit():  # `1.2.3`
                j = i
                while j < n and (source[j].isdigit() or source[j] == "."):
                    j += 1
                raise LexError(f"malformed number '{source[start:j]}'", span_at(start))
            if i < n and (source[i].isalpha() or source[i] == "_"):
                raise LexError(f"malformed number '{source[start:i + 1]}'", span_at(start))
            text = source[start:i]
            tokens.append(Token(Kind.NUM, text, span_at(start), start, i, float(text)))
            continue
        if ch == '"':
            i += 1
            chars: list[str] = []
            while True:
                if i >= n or source[i] == "\n":
                    raise LexError("unterminated string (a string ends on the line where it starts)",
                                   span_at(start))
                c = source[i]
                if c == '"':
                    if i + 1 < n and source[i + 1] == '"':
                        chars.append('"')
                        i += 2
                        continue
                    i += 1
                    break
                if c == "\\" and i + 1 < n and source[i + 1] == "\\":
                    chars.append("\\")
                    i += 2
                    continue
                if c == "\\" and i + 2 < n and all(h in "0123456789abcdefABCDEF" for h in source[i + 1:i + 3]):
                    chars.append(chr(int(source[i + 1:i + 3], 16)))  # `\0A`: a character by its code
                    i += 3
                    continue
                chars.append(c)
                i += 1
            if len(chars) > STRING_MAX:
                raise LexError(f"a string of {len(chars)} characters: a RAPID string holds at most {STRING_MAX}",
                               span_at(start))
            tokens.append(Token(Kind.STRING, source[start:i], span_at(start), start, i, "".join(chars)))
            continue
        for op in OPERATORS:
            if source.startswith(op, i):
                i += len(op)
                tokens.append(Token(Kind.OP, op, span_at(start), start, i))
                break
        else:
            raise LexError(f"unexpected character {ch!r}", span_at(start))
    tokens.append(Token(Kind.EOF, "", span_at(i), i, i))
    return tokens
