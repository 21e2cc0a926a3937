"""Runs every program under corpus/ through the real CLI and checks what its comments promise.

Each `.mod` file states its own expectations in comments (as craftinginterpreters' test/*.lox do):

    ! args: --io DI:di1,DO:do1 --set di1=1@0.5      extra arguments for `rapid run` (repeatable)
    ! modules: parts/cell.sys parts/grip.modx        more modules of the task (beside the file)
    ! trace: {"t": 0.0, "type": "print", "text": "x"}  the trace, line by line, in order (whole trace)
    ! error: 4:10 division by zero                   stderr holds FILE:4:10: error: ...division by zero...
    ! exit: 70                                       the exit status (0 when not given)
    ! note: 7:5 take no time                         stderr holds FILE:7:5: note: ...take no time...

When a file has `trace:` lines the run uses --trace and the whole trace must match (JSON-equal);
otherwise stdout is not checked.
"""
from __future__ import annotations

import io
import json
import shlex
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pytest

from rapid_like.cli import main

CORPUS = Path(__file__).parent / "corpus"
FILES = sorted(CORPUS.rglob("*.mod"))


def expectations(path: Path) -> dict:
    exp: dict = {"args": [], "trace": [], "error": None, "exit": 0, "modules": [], "notes": []}
    for line in path.read_text().splitlines():
        s = line.strip()
        if not s.startswith("!"):
            continue
        body = s[1:].strip()
        key, _, rest = body.partition(":")
        key, rest = key.strip().lower(), rest.strip()
        if key == "args":
            exp["args"] += shlex.split(rest)
        elif key == "modules":
            exp["modules"] += [str(path.parent / m) for m in rest.split()]
        elif key == "trace":
            exp["trace"].append(json.loads(rest))
        elif key == "error":
            pos, _, msg = rest.partition(" ")
            exp["error"] = (pos, msg.strip())
        elif key == "note":
            pos, _, msg = rest.partition(" ")
            exp["notes"].append((pos, msg.strip()))
        elif key == "exit":
            exp["exit"] = int(rest)
    return exp


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def test_corpus_is_not_empty():
    assert len(FILES) >= 30


@pytest.mark.parametrize("path", FILES, ids=[str(p.relative_to(CORPUS)) for p in FILES])
def test_program(path: Path):
    exp = expectations(path)
    argv = ["run", str(path), *exp["modules"], *exp["args"]]
    if exp["trace"]:
        argv.append("--trace")
    code, out, err = run_cli(argv)
    assert code == exp["exit"], f"exit {code}, stderr:\n{err}"
    if exp["trace"]:
        got = [json.loads(line) for line in out.splitlines()]
        assert got == exp["trace"], "trace differs:\n" + "\n".join(json.dumps(g) for g in got)
    notes = [line for line in err.splitlines() if ": note: " in line and not line.startswith(" ")]
    assert len(notes) == len(exp["notes"]), notes
    for line, (pos, msg) in zip(notes, exp["notes"]):
        assert line.startswith(f"{path}:{pos}: note: ") and msg in line, line
    err = "\n".join(line for line in err.splitlines() if line not in notes)
    if exp["error"]:
        pos, msg = exp["error"]
        first = err.splitlines()[0] if err else ""
        assert first.startswith(f"{path}:{pos}: error: "), first
        assert msg in first, first
    else:
        assert err == "", err
