"""Small helpers of rapid_like.values: the num format of TPWrite/ValToStr and articles in messages."""
from __future__ import annotations

import pytest

from rapid_like.values import a_, fmt_num


@pytest.mark.parametrize("word, expected", [
    ("AO", "an AO"), ("AI", "an AI"), ("DO", "a DO"), ("DI", "a DI"), ("GO", "a GO"), ("GI", "a GI"),
    ("num", "a num"), ("orient", "an orient"), ("errnum", "an errnum"), ("robtarget", "a robtarget"),
    ("intnum", "an intnum"), ("string", "a string"),
])
def test_articles(word, expected):
    assert a_(word) == expected


@pytest.mark.parametrize("x, expected", [
    (0.0, "0"), (-0.0, "0"), (330.0, "330"), (123456.0, "123456"), (1e6, "1E+06"), (9e9, "9E+09"),
    (1234567.8, "1.23457E+06"), (1.141367, "1.14137"), (2.9999999, "3"), (-2.9999999, "-3"),
    (0.000015, "1.5E-05"), (0.000001, "0"), (0.1 + 0.2, "0.3"), (-0.5, "-0.5"), (True, "TRUE"),
])
def test_num_format(x, expected):
    assert fmt_num(x) == expected
