"""The server's log: one line on stderr per event, prefixed so it reads apart from a client's output.
Imports nothing, so `twin serve` can log before it loads anything heavy."""
from __future__ import annotations

import sys


def log(text: str) -> None:
    print(f"twin serve: {text}", file=sys.stderr, flush=True)
