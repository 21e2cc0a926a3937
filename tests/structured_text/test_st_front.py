"""Lexer, parser and checker: literals as the standard defines them, precedence, errors at their place."""
from __future__ import annotations

import pytest

from structured_text.checker import check
from structured_text.errors import LexError, ParseError, StaticErrors
from structured_text.lexer import lex
from structured_text.parser import parse


def lit(text):
    return lex(text, "t.st")[0].value


def test_literals_have_the_standards_values():
    assert lit("16#FF").value == 255
    assert lit("2#1010_1010").value == 0xAA
    assert lit("8#17").value == 15
    assert lit("1_000").value == 1000
    assert lit("1.5E3").value == 1500.0
    assert (lit("INT#-5").value, lit("INT#-5").type_name) == (-5, "INT")
    assert lit("T#1s500ms").value == 1_500_000_000
    assert lit("TIME#1m2s3ms").value == 62_003_000_000  # exact, not 62002.999999 ms
    assert lit("T#1.5s").value == 1_500_000_000
    assert lit("t#1d2h").value == (26 * 3600) * 10**9
    assert lit("TOD#12:00:00.5").value == (12 * 3600 + 0.5) * 10**9
    assert lit("'it$'s$N'").value == "it's\n"


def test_comments_pragmas_and_direct_addresses():
    toks = lex("(* a (* nested *) comment *) x // line\n{pragma} AT %QW100 %IX1.7", "t.st")  # ed. 3 nests
    assert [t.text for t in toks[:-1]] == ["x", "AT", "%QW100", "%IX1.7"]
    assert toks[2].value == ("Q", "W", (100,))
    assert toks[3].span.line == 2


@pytest.mark.parametrize("text, message", [
    ("x := %IX0.9;", "bit 9"),
    ("x := 'abc", "unterminated string"),
    ("(* open", "unterminated comment"),
    ("x := T#5q;", "malformed"),
])
def test_lexer_errors_name_the_place(text, message):
    with pytest.raises(LexError) as e:
        lex(text, "t.st")
    assert message in e.value.message
    assert e.value.span.file == "t.st" and e.value.span.line == 1


def body(stmt: str, decls: str = "a, b, c : INT; x, y : BOOL;"):
    return f"PROGRAM p\nVAR {decls} END_VAR\n{stmt}\nEND_PROGRAM\n"


def expr_tree(text: str):
    e = parse(body(f"a := {text};"), "t.st").pous[0].body[0].value

    def show(e):
        from structured_text import nodes as n
        if isinstance(e, n.Binary):
            return f"({show(e.left)} {e.op} {show(e.right)})"
        if isinstance(e, n.Unary):
            return f"({e.op} {show(e.operand)})"
        if isinstance(e, n.Literal):
            return str(e.lit.value)
        return e.name
    return show(e)


def test_operator_precedence_is_the_standards():
    # IEC 61131-3 3rd ed. table 71: unary > ** > * / MOD > + - > comparison > equality > AND > XOR > OR
    assert expr_tree("a + b * c") == "(a + (b * c))"
    assert expr_tree("a - b - c") == "((a - b) - c)"
    assert expr_tree("a OR b AND c") == "(a OR (b AND c))"
    assert expr_tree("a OR b XOR c") == "(a OR (b XOR c))"
    assert expr_tree("a XOR b AND c") == "(a XOR (b AND c))"
    assert expr_tree("NOT a AND b") == "((NOT a) AND b)"
    assert expr_tree("a = b AND c") == "((a = b) AND c)"
    assert expr_tree("a < b = c") == "((a < b) = c)"
    assert expr_tree("a ** b ** c") == "((a ** b) ** c)"
    assert expr_tree("a * b ** c") == "(a * (b ** c))"
    assert expr_tree("a MOD b + c") == "((a MOD b) + c)"
    assert expr_tree("a & b OR c") == "((a AND b) OR c)"


@pytest.mark.parametrize("src, pos, message", [
    ("PROGRAM p\nVAR a : INT; END_VAR\na := 1\na := 2;\nEND_PROGRAM\n", (4, 1), "expected ';'"),
    ("PROGRAM p\nVAR a : INT; END_VAR\nIF a > 1 THEN a := 1;\nEND_PROGRAM\n", (4, 1), "END_IF to close the IF on line 3"),
    ("PROGRAM p\nVAR a : INT; END_VAR\na = 1;\nEND_PROGRAM\n", (3, 3), "':='"),
    ("PROGRAM p\nVAR a : INT; END_VAR\nJMP lbl;\nEND_PROGRAM\n", (3, 1), "not supported"),
    ("PROGRAM p\nINITIAL_STEP s1: END_STEP\nEND_PROGRAM\n", (2, 1), "SFC"),
    ("FUNCTION_BLOCK f EXTENDS g\nEND_FUNCTION_BLOCK\n", (1, 18), "not supported"),
    ("PROGRAM p\nVAR p : POINTER TO INT; END_VAR\nEND_PROGRAM\n", (2, 9), "pointers"),
    ("PROGRAM p\nVAR a, b : BOOL; END_VAR\n  LD a\n  ST b\nEND_PROGRAM\n", (3, 3), "Instruction List (IL) is not supported"),
])
def test_parse_errors_and_unsupported_features_name_the_place(src, pos, message):
    with pytest.raises(ParseError) as e:
        parse(src, "t.st")
    assert (e.value.span.line, e.value.span.col) == pos
    assert message in e.value.message


def check_errors(src: str) -> list[str]:
    with pytest.raises(StaticErrors) as e:
        check([parse(src, "t.st")])
    return [f"{x.span.line}:{x.span.col} {x.message}" for x in e.value.errors]


def test_checker_reports_every_bad_statement_at_its_place():
    src = body("a := undefined;\nx := a;\na := 1.5;\nb := DINT#5;\nIF a THEN b := 1; END_IF;\nEXIT;\nc := 40000;",
               "a, b, c : INT; x : BOOL;")
    errs = check_errors(src)
    assert errs[0].startswith("3:6 ") and "undeclared name 'undefined'" in errs[0]
    assert errs[1].startswith("4:6 ") and "INT cannot be stored in a BOOL" in errs[1]
    assert errs[2].startswith("5:6 ") and "REAL" in errs[2]
    assert errs[3].startswith("6:6 ") and "a DINT cannot be stored in an INT" in errs[3]
    assert errs[4].startswith("7:4 ") and "not a BOOL" in errs[4]
    assert errs[5].startswith("8:1 ") and "EXIT outside a loop" in errs[5]
    assert errs[6].startswith("9:6 ") and "out of the range of INT" in errs[6]


def test_widening_is_implicit_narrowing_is_not():
    check([parse(body("d := i; r := i; l := r; w := b2;", "i : INT; d : DINT; r : REAL; l : LREAL; w : WORD; b2 : BYTE;"), "t.st")])
    errs = check_errors(body("i := d;", "i : INT; d : DINT;"))
    assert "DINT_TO_INT" in errs[0]


def test_calls_are_checked_against_the_block():
    src = body("t(IN := TRUE, PT := 5);\nt(IN := TRUE, XX := T#1s);\nt.Q := TRUE;\nx := t(IN := TRUE);",
               "t : TON; x : BOOL;")
    errs = check_errors(src)
    assert "3:" in errs[0] and "PT" in errs[0]
    assert errs[1].startswith("4:") and "no parameter 'XX'" in errs[1]
    assert errs[2].startswith("5:1") and "output" in errs[2]
    assert errs[3].startswith("6:") and "statement" in errs[3]


def test_the_for_variable_is_changed_by_its_loop_alone():
    src = body("FOR a := 1 TO 3 DO\n  FOR a := 1 TO 2 DO b := a; END_FOR;\n  a := 2;\nEND_FOR;")
    errs = check_errors(src)
    assert errs[0].startswith("4:7 ") and "control variable" in errs[0]
    assert errs[1].startswith("5:3 ") and "control variable" in errs[1]
