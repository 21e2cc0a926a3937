"""Lexer: Structured Text source to a list of tokens, each with its line and column.

Comments: `(* ... *)` (nested ones too, as the 3rd edition allows), `/* ... */` and `// ...` to the end of the line; pragmas
`{ ... }` are skipped. Literals: integers with `_` separators, based integers (`16#FF`, `2#1010`,
`8#17`), reals (`1.5`, `1.0E-3`), typed literals (`INT#5`, `REAL#1`, `BOOL#1`, `Color#Red`), durations
(`T#1s500ms`, `TIME#-2.5s`, `T#1d2h3m4s5ms6us7ns`), dates and times of day (`D#2024-01-31`,
`TOD#12:30:00.5`, `DT#2024-01-31-12:30:00`), strings ('$'-escaped: `$$ $' $L $N $P $R $T $0A`),
wide strings ("...") and direct addresses (`%IX0.0`, `%QW100`, `%MD4`).
"""
from __future__ import annotations

import datetime as _dt
import re
from fractions import Fraction

from .errors import LexError, Span
from .tokens import KEYWORDS, OPERATORS, Kind, Lit, Token

NS = {"D": 86_400 * 10**9, "H": 3_600 * 10**9, "M": 60 * 10**9, "S": 10**9, "MS": 10**6, "US": 10**3, "NS": 1}
_DURATION_PART = re.compile(r"(\d+(?:\.\d+)?)(MS|US|NS|D|H|M|S)", re.I)
_TIME_PREFIX = {"T", "TIME", "LT", "LTIME"}
_DATE_PREFIX = {"D", "DATE", "LD", "LDATE"}
_TOD_PREFIX = {"TOD", "TIME_OF_DAY", "LTOD", "LTIME_OF_DAY"}
_DT_PREFIX = {"DT", "DATE_AND_TIME", "LDT", "LDATE_AND_TIME"}
_EPOCH = _dt.datetime(1970, 1, 1)
_ESCAPES = {"$": "$", "'": "'", '"': '"', "L": "\n", "N": "\n", "P": "\f", "R": "\r", "T": "\t"}


def parse_duration(text: str) -> int | None:
    """`1s500ms`, `-2.5s`, `1d_2h` -> nanoseconds; None if it is not a duration."""
    body = text.replace("_", "")
    sign = 1
    if body[:1] in "+-" and body:
        sign = -1 if body[0] == "-" else 1
        body = body[1:]
    if not body:
        return None
    total, pos = Fraction(0), 0
    for m in _DURATION_PART.finditer(body):
        if m.start() != pos:
            return None
        total += Fraction(m.group(1)) * NS[m.group(2).upper()]
        pos = m.end()
    if pos != len(body):
        return None
    return sign * round(total)


def parse_tod(text: str) -> int | None:
    m = re.fullmatch(r"(\d{1,2}):(\d{1,2}):(\d{1,2}(?:\.\d+)?)", text)
    if not m:
        return None
    h, mi, s = int(m.group(1)), int(m.group(2)), Fraction(m.group(3))
    if h > 23 or mi > 59 or s >= 60:
        return None
    return round(((h * 60 + mi) * 60 + s) * 10**9)


def parse_date(text: str) -> int | None:
    try:
        d = _dt.datetime.strptime(text, "%Y-%m-%d")
    except ValueError:
        return None
    return int((d - _EPOCH).total_seconds()) * 10**9


def parse_dt(text: str) -> int | None:
    m = re.fullmatch(r"(\d{4}-\d{1,2}-\d{1,2})-(.*)", text)
    if not m:
        return None
    d, t = parse_date(m.group(1)), parse_tod(m.group(2))
    return None if d is None or t is None else d + t


def lex(source: str, file: str = "<input>") -> list[Token]:
    tokens: list[Token] = []
    i, line, line_start, n = 0, 1, 0, len(source)

    def span_at(pos: int) -> Span:
        return Span(file, line, pos - line_start + 1)

    def newlines(a: int, b: int) -> None:
        nonlocal line, line_start
        k = source.count("\n", a, b)
        if k:
            line += k
            line_start = source.rfind("\n", a, b) + 1

    def number_at(j: int) -> tuple[Lit, int] | None:
        """An (unsigned) integer, based integer or real starting at j: (literal, end)."""
        m = re.compile(r"(\d+)#([0-9A-Fa-f_]+)").match(source, j)
        if m:
            base = int(m.group(1))
            if base not in (2, 8, 16):
                raise LexError(f"a based literal has base 2, 8 or 16, not {base}", span_at(j))
            try:
                return Lit("int", int(m.group(2).replace("_", ""), base)), m.end()
            except ValueError:
                raise LexError(f"malformed base-{base} literal '{m.group(0)}'", span_at(j)) from None
        m = re.compile(r"\d[\d_]*(\.\d[\d_]*)?([eE][+-]?\d+)?").match(source, j)
        if not m:
            return None
        text = m.group(0).replace("_", "")
        if m.group(1) or m.group(2):
            return Lit("real", float(text)), m.end()
        return Lit("int", int(text)), m.end()

    def string_at(j: int, quote: str) -> tuple[str, int]:
        return _string(source, j, quote, span_at)

    def typed_literal(prefix: str, up: str, j: int, start: int) -> tuple[Token, int]:
        """`PREFIX#...` with j just after the '#'."""
        span = span_at(start)
        m = re.compile(r"[+-]?[0-9A-Za-z_.:\-]+").match(source, j)
        if up in _TIME_PREFIX | _DATE_PREFIX | _TOD_PREFIX | _DT_PREFIX:
            body = m.group(0) if m else ""
            if up in _TIME_PREFIX:
                body = re.compile(r"[+-]?[0-9A-Za-z_.]+").match(source, j)
                body = body.group(0) if body else ""
                value, cat = parse_duration(body), "time"
            elif up in _DATE_PREFIX:
                body = re.compile(r"[0-9\-]+").match(source, j)
                body = body.group(0) if body else ""
                value, cat = parse_date(body), "date"
            elif up in _TOD_PREFIX:
                body = re.compile(r"[0-9:.]+").match(source, j)
                body = body.group(0) if body else ""
                value, cat = parse_tod(body), "tod"
            else:
                value, cat = parse_dt(body), "dt"
            if value is None:
                raise LexError(f"malformed {up}# literal '{prefix}#{body}'", span)
            end = j + len(body)
            return Token(Kind.LITERAL, source[start:end], span, Lit(cat, value, up)), end
        k, sign = j, 1
        if k < n and source[k] in "+-":
            sign = -1 if source[k] == "-" else 1
            k += 1
        if k < n and source[k].isdigit():
            got = number_at(k)
            lit, end = got
            return Token(Kind.LITERAL, source[start:end], span, Lit(lit.category, sign * lit.value, up)), end
        if k < n and source[k] in "'\"" and k == j:
            text, end = string_at(k, source[k])
            return Token(Kind.LITERAL, source[start:end], span, Lit("string" if source[k] == "'" else "wstring", text, up)), end
        w = re.compile(r"[A-Za-z_][A-Za-z0-9_]*").match(source, j)
        if w and k == j:
            word = w.group(0)
            if word.upper() in ("TRUE", "FALSE"):
                return Token(Kind.LITERAL, source[start:w.end()], span, Lit("bool", word.upper() == "TRUE", up)), w.end()
            return Token(Kind.LITERAL, source[start:w.end()], span, Lit("enum", word, prefix)), w.end()
        raise LexError(f"malformed typed literal after '{prefix}#'", span)

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
        start = i
        if source.startswith("(*", i) or source.startswith("/*", i):
            close = "*)" if ch == "(" else "*/"
            depth, j = 1, i + 2  # comments nest (IEC 61131-3 ed. 3, table 5)
            while depth and j < n:
                if source.startswith(source[i:i + 2], j):
                    depth, j = depth + 1, j + 2
                elif source.startswith(close, j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            if depth:
                raise LexError("unterminated comment", span_at(start))
            newlines(i, j)
            i = j
            continue
        if source.startswith("//", i):
            while i < n and source[i] != "\n":
                i += 1
            continue
        if ch == "{":  # a pragma
            j = source.find("}", i)
            if j < 0:
                raise LexError("unterminated pragma '{'", span_at(start))
            newlines(i, j)
            i = j + 1
            continue
        if ch.isalpha() or ch == "_":
            while i < n and (source[i].isalnum() or source[i] == "_"):
                i += 1
            text = source[start:i]
            up = text.upper()
            if i < n and source[i] == "#" and up not in KEYWORDS:
                tok, i = typed_literal(text, up, i + 1, start)
                tokens.append(tok)
                continue
            if up in ("TRUE", "FALSE"):
                tokens.append(Token(Kind.LITERAL, text, span_at(start), Lit("bool", up == "TRUE")))
                continue
            tokens.append(Token(Kind.KEYWORD if up in KEYWORDS else Kind.IDENT, text, span_at(start)))
            continue
        if ch.isdigit():
            lit, i = number_at(i)
            if i < n and (source[i].isalpha() or source[i] == "_"):
                raise LexError(f"malformed number '{source[start:i + 1]}'", span_at(start))
            tokens.append(Token(Kind.LITERAL, source[start:i], span_at(start), lit))
            continue
        if ch in "'\"":
            text, i = string_at(i, ch)
            tokens.append(Token(Kind.LITERAL, source[start:i], span_at(start),
                                Lit("string" if ch == "'" else "wstring", text)))
            continue
        if ch == "%":
            m = re.compile(r"%([IQM])([XBWDL]?)(\d+(?:\.\d+)*)", re.I).match(source, i)
            if not m:
                if re.compile(r"%[IQM][XBWDL]?\*", re.I).match(source, i):
                    raise LexError("unspecified addresses ('%I*') are not supported", span_at(start))
                raise LexError("malformed direct address (expected e.g. %IX0.0, %QW100, %MD4)", span_at(start))
            area, size = m.group(1).upper(), (m.group(2) or "X").upper()
            idx = tuple(int(p) for p in m.group(3).split("."))
            if size == "X" and len(idx) != 2:
                raise LexError(f"a bit address is BYTE.BIT, e.g. %{area}X0.0, not '{m.group(0)}'", span_at(start))
            if size == "X" and idx[1] > 7:
                raise LexError(f"bit {idx[1]} of '{m.group(0)}': a byte has bits 0 to 7", span_at(start))
            if size != "X" and len(idx) != 1:
                raise LexError(f"'{m.group(0)}': a {size} address has one index, e.g. %{area}{size}4", span_at(start))
            i = m.end()
            tokens.append(Token(Kind.DIRECT, m.group(0), span_at(start), (area, size, idx)))
            continue
        for op in OPERATORS:
            if source.startswith(op, i):
                i += len(op)
                tokens.append(Token(Kind.OP, op, span_at(start)))
                break
        else:
            raise LexError(f"unexpected character {ch!r}", span_at(start))
    tokens.append(Token(Kind.EOF, "", span_at(i)))
    return tokens


def _string(source: str, i: int, quote: str, span_at) -> tuple[str, int]:
    start = i
    i += 1
    out: list[str] = []
    n = len(source)
    while True:
        if i >= n or source[i] == "\n":
            raise LexError("unterminated string", span_at(start))
        c = source[i]
        if c == quote:
            return "".join(out), i + 1
        if c == "$":
            nxt = source[i + 1:i + 2].upper()
            if nxt in _ESCAPES:
                out.append(_ESCAPES[nxt])
                i += 2
                continue
            digits = 2 if quote == "'" else 4
            code = source[i + 1:i + 1 + digits]
            if len(code) == digits and all(h in "0123456789abcdefABCDEF" for h in code):
                out.append(chr(int(code, 16)))
                i += 1 + digits
                continue
            raise LexError(f"unknown escape '${source[i + 1:i + 2]}' in a string", span_at(i))
        out.append(c)
        i += 1
