"""Argument types shared by every command line (twin, plc, rapid, the front ends' option groups).

Each turns the text of one option into a value or raises `argparse.ArgumentTypeError` with a message that
says what the option needs, so all commands refuse bad input the same way. Imports nothing heavy: the parsers
are built before the simulation loads.
"""
from __future__ import annotations

import argparse
import math


def _number(text: str, kind=float, what: str = "a number"):
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"needs {what}, not {text!r}") from None


def positive_float(text: str) -> float:
    """A finite number greater than 0 (seconds, speeds, factors)."""
    v = _number(text)
    if not (v > 0 and math.isfinite(v)):
        raise argparse.ArgumentTypeError(f"must be greater than 0, not {text}")
    return v


def nonnegative_float(text: str) -> float:
    """A finite number of 0 or more (0 usually means "off")."""
    v = _number(text)
    if not (v >= 0 and math.isfinite(v)):
        raise argparse.ArgumentTypeError(f"must be 0 or more, not {text}")
    return v


def positive_int(text: str) -> int:
    """A whole number of at least 1 (counts, workers, requests)."""
    v = _number(text, int, "a whole number")
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, not {text}")
    return v


def tcp_port(text: str) -> int:
    """A TCP port, 0..65535 (0: any free port)."""
    v = _number(text, int, "a whole number (a TCP port)")
    if not 0 <= v <= 0xFFFF:
        raise argparse.ArgumentTypeError(f"a TCP port is 0..65535, not {text}")
    return v
