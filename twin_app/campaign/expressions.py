"""Conditions in campaign files: small expressions such as `cycles_done >= 1 or cycle_fault` or
`fault == 'ring_missing' and abs(ring.offset_x_mm) > 30`.

They are parsed with Python's own parser and then checked: only names (dotted names such as
`ring.offset_x_mm` or `axis1.force` are one name), numbers, strings, true/false, comparisons, `and`/`or`/`not`,
arithmetic and the functions `abs`, `min`, `max` and `round` are allowed, so a condition can read values but
never run code.
"""
from __future__ import annotations

import ast
import math
import operator
from collections.abc import Mapping

from twin.core.errors import TwinError

FUNCTIONS = {"abs": abs, "min": min, "max": max, "round": round}
CONSTANTS = {"true": True, "false": False, "True": True, "False": False, "none": None, "inf": math.inf}
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Mod: operator.mod, ast.Pow: operator.pow, ast.FloorDiv: operator.floordiv}
_COMPARE = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
            ast.Gt: operator.gt, ast.GtE: operator.ge, ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b}


class ExpressionError(TwinError):
    """A condition that is not an allowed expression, or names a value that does not exist."""


class Expression:
    """A checked condition; `names` are the values it reads, `evaluate(values)` its result."""

    def __init__(self, text: str):
        if not isinstance(text, str) or not text.strip():
            raise ExpressionError(f"a condition must be a non-empty string, not {text!r}")
        self.text = text
        try:
            tree = ast.parse(text.strip(), mode="eval")
        except SyntaxError as exc:
            raise ExpressionError(f"{text!r} is not a condition: {exc.msg} at column {exc.offset}") from None
        self.names: set[str] = set()
        self._check(tree.body)
        self._tree = tree.body

    def _check(self, node) -> None:
        if isinstance(node, ast.Constant):
            if not isinstance(node.value, (int, float, str, bool)) and node.value is not None:
                raise ExpressionError(f"{self.text!r}: {node.value!r} is not allowed")
            return
        if isinstance(node, (ast.Name, ast.Attribute)):
            name = _dotted(node)
            if name is None:
                raise ExpressionError(f"{self.text!r}: only plain dotted names may be read")
            if name not in CONSTANTS:
                self.names.add(name)
            return
        if isinstance(node, ast.BoolOp):
            for v in node.values:
                self._check(v)
            return
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.Not, ast.USub, ast.UAdd)):
            self._check(node.operand)
            return
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            self._check(node.left), self._check(node.right)
            return
        if isinstance(node, ast.Compare) and all(type(op) in _COMPARE for op in node.ops):
            self._check(node.left)
            for c in node.comparators:
                self._check(c)
            return
        if isinstance(node, (ast.List, ast.Tuple)):
            for e in node.elts:
                self._check(e)
            return
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS
                and not node.keywords):
            for a in node.args:
                self._check(a)
            return
        what = type(node).__name__
        raise ExpressionError(f"{self.text!r}: {what} is not allowed (names, numbers, strings, comparisons, "
                              f"and/or/not, + - * /, abs/min/max/round)")

    def evaluate(self, values: Mapping[str, object]):
        return self._eval(self._tree, values)

    def _eval(self, node, values):
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, (ast.Name, ast.Attribute)):
            name = _dotted(node)
            if name in values:
                return values[name]
            if name in CONSTANTS:
                return CONSTANTS[name]
            raise ExpressionError(f"{self.text!r}: no value named {name!r}")
        if isinstance(node, ast.BoolOp):
            if isinstance(node.op, ast.And):
                result = True
                for v in node.values:
                    result = self._eval(v, values)
                    if not result:
                        return result
                return result
            result = False
            for v in node.values:
                result = self._eval(v, values)
                if result:
                    return result
            return result
        if isinstance(node, ast.UnaryOp):
            v = self._eval(node.operand, values)
            return (not v) if isinstance(node.op, ast.Not) else (-v if isinstance(node.op, ast.USub) else +v)
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](self._eval(node.left, values), self._eval(node.right, values))
        if isinstance(node, ast.Compare):
            left = self._eval(node.left, values)
            for op, comp in zip(node.ops, node.comparators):
                right = self._eval(comp, values)
                if not _COMPARE[type(op)](left, right):
                    return False
                left = right
            return True
        if isinstance(node, (ast.List, ast.Tuple)):
            return [self._eval(e, values) for e in node.elts]
        if isinstance(node, ast.Call):
            return FUNCTIONS[node.func.id](*(self._eval(a, values) for a in node.args))
        raise ExpressionError(f"{self.text!r}: cannot evaluate")  # pragma: no cover - _check refused it

    def __repr__(self) -> str:
        return f"Expression({self.text!r})"

    def __reduce__(self):
        return (Expression, (self.text,))


def _dotted(node) -> str | None:
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    parts.append(node.id)
    return ".".join(reversed(parts))
