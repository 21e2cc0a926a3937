"""Runs every Structured Text program under corpus/ through the real `plc` command and checks what its
comment promises.

Each `.st` file states its expectations in its first comment, on lines starting with `!` (as
tests/rapid_like/corpus does), computed by hand from IEC 61131-3 and the issue's trace format, never taken
from the runtime's output:

    ! args: --for 0.095 --cycle 10 --watch cnt     arguments for `plc run FILE --offline --trace`
    ! files: parts/types.st                        more files of the same PLC (beside the file)
    ! trace: {"t": 0.0, "scan": 0, "name": "cnt", "value": 1}   the whole trace, line by line, in order
    ! cmd: check                                   run `plc check FILE` instead of `plc run`
    ! error: 7:12 zero                             stderr is FILE:7:12: error: ... and its message holds
                                                   every word (a|b: either), any case; several `error:`
                                                   lines: one stderr line each, in that order;
    ! error: parts/x.st:3:5 y                      an error in another file of the PLC (beside the file)
    ! usage: --set n                               a command-line mistake: stderr's one line holds every
                                                   word (a|b: either), any case (with `! exit: 2`)
    ! exit: 70                                     the exit status (0 when not given)
    ! lreal: x,y                                   these names are LREAL: floats within 1e-12 (else 1e-6)
    ! exact: r                                     floats of these names compared exactly

A file with `trace:` lines has its whole stdout compared (JSON-equal; `t` within 1e-9, floats of REALs
within a relative 1e-6 as REAL is IEC 60559 single precision). Without `error:`, stderr must be empty.
"""
from __future__ import annotations

import importlib.util
import json
import math
import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

CORPUS = Path(__file__).parent / "corpus"
ROOT = Path(__file__).resolve().parents[2]  # the tree these tests belong to: its runtime is the one run
FILES = sorted(p for p in CORPUS.rglob("*.st") if "parts" not in p.relative_to(CORPUS).parts)


def _runtime_present() -> bool:
    """The runtime's package, not this test directory (pytest puts tests/ on sys.path: a namespace
    package of the same name, with no origin)."""
    spec = importlib.util.find_spec("structured_text")
    return spec is not None and spec.origin is not None and Path(__file__).parent not in Path(spec.origin).parents


RUNTIME_PRESENT = _runtime_present()

# Cases that fail because of a runtime bug not fixed yet: path -> the entry of /work/team/st-bugs.md.
# Strict: once the runtime is fixed the xfail turns into a failure, and the entry here must go.
KNOWN_BUGS: dict[str, str] = {
}

REAL_TOLERANCE = 1e-6
LREAL_TOLERANCE = 1e-12
TIME_TOLERANCE = 1e-9


def expectations(path: Path) -> dict:
    exp: dict = {"args": [], "files": [], "trace": [], "cmd": "run", "errors": [], "usage": None, "exit": 0,
                 "lreal": set(), "exact": set()}
    for line in path.read_text(encoding="utf-8").splitlines():
        s = line.strip()
        if not s.startswith("!"):
            continue
        key, _, rest = s[1:].strip().partition(":")
        key, rest = key.strip().lower(), rest.strip()
        if key == "args":
            exp["args"] += shlex.split(rest)
        elif key == "files":
            exp["files"] += [str(path.parent / f) for f in rest.split()]
        elif key == "trace":
            exp["trace"].append(json.loads(rest))
        elif key == "cmd":
            exp["cmd"] = rest
        elif key == "error":
            pos, _, words = rest.partition(" ")
            exp["errors"].append((pos, words.split()))
        elif key == "usage":
            exp["usage"] = rest.split()
        elif key == "exit":
            exp["exit"] = int(rest)
        elif key in ("lreal", "exact"):
            exp[key] |= {n.strip() for n in rest.split(",") if n.strip()}
    return exp


def plc_command() -> list[str]:
    script = Path(sys.executable).with_name("plc")
    return [str(script)] if script.exists() else [sys.executable, "-m", "plc_client"]


def run_plc(argv: list[str]) -> subprocess.CompletedProcess:
    env = dict(os.environ)  # PYTHONPATH kept, this tree first: its packages shadow any installed ones
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p)
    return subprocess.run([*plc_command(), *argv], capture_output=True, text=True, timeout=60, env=env)


def strict_json(line: str):
    """One trace line as JSON proper: NaN and Infinity are not JSON (a reader in another language refuses them)."""
    def refuse(constant):
        raise ValueError(f"{constant} is not JSON: {line}")
    return json.loads(line, parse_constant=refuse)


def same_value(name: str, want, got, exp: dict) -> bool:
    if isinstance(want, bool) or isinstance(got, bool):
        return type(want) is type(got) and want == got
    if isinstance(want, float):
        if not isinstance(got, float):  # a REAL prints as a float ("REAL as floats"), even when integral
            return False
        if name in exp["exact"]:
            return got == want
        tol = LREAL_TOLERANCE if name in exp["lreal"] else REAL_TOLERANCE
        return math.isclose(got, want, rel_tol=tol, abs_tol=tol)
    return type(want) is type(got) and want == got


def same_line(want: dict, got: dict, exp: dict) -> bool:
    if set(want) != set(got):
        return False
    if not isinstance(got["t"], (int, float)) or abs(got["t"] - want["t"]) > TIME_TOLERANCE:
        return False
    if got["scan"] != want["scan"] or got["name"] != want["name"]:
        return False
    return same_value(want["name"], want["value"], got["value"], exp)


def test_corpus_is_not_empty():
    assert len(FILES) >= 40


def _marks(path: Path):
    rel = str(path.relative_to(CORPUS))
    if rel in KNOWN_BUGS:
        return [pytest.mark.xfail(strict=True, reason=KNOWN_BUGS[rel])]
    return []


@pytest.mark.parametrize("path", [pytest.param(p, marks=_marks(p), id=str(p.relative_to(CORPUS)))
                                  for p in FILES])
def test_program(path: Path):
    assert RUNTIME_PRESENT, "the structured_text package (the ST runtime) is not importable"
    exp = expectations(path)
    if exp["cmd"] == "check":
        argv = ["check", str(path), *exp["files"]]
    else:
        argv = ["run", str(path), *exp["files"], "--offline", "--trace", *exp["args"]]
    proc = run_plc(argv)
    out, err = proc.stdout, proc.stderr
    assert proc.returncode == exp["exit"], f"plc {' '.join(argv)}\nexit {proc.returncode}, stderr:\n{err}"
    if exp["trace"]:
        got = [strict_json(line) for line in out.splitlines() if line.strip()]
        ok = len(got) == len(exp["trace"]) and all(same_line(w, g, exp) for w, g in zip(exp["trace"], got))
        if not ok:
            diff = [f"{'  ' if i < len(got) and i < len(exp['trace']) and same_line(exp['trace'][i], got[i], exp) else '!!'}"
                    f" want {json.dumps(exp['trace'][i]) if i < len(exp['trace']) else '-'}"
                    f"\n   got  {json.dumps(got[i]) if i < len(got) else '-'}"
                    for i in range(max(len(got), len(exp["trace"])))]
            pytest.fail("trace differs:\n" + "\n".join(diff))
    if exp["errors"]:
        lines = [line for line in err.splitlines() if line.strip()]
        assert len(lines) == len(exp["errors"]), f"want {len(exp['errors'])} error line(s), got:\n{err}"
        for line, (pos, words) in zip(lines, exp["errors"]):
            where = f"{path}:{pos}" if pos[0].isdigit() else f"{path.parent / pos}"  # parts/x.st:L:C
            assert line.startswith(f"{where}: error: "), f"want {where}: error: ..., got:\n{err}"
            message = line.split(": error: ", 1)[1].lower()
            for word in words:
                assert any(alt.lower() in message for alt in word.split("|")), f"{word!r} not in: {line}"
    elif exp["usage"] is not None:
        lines = [line for line in err.splitlines() if line.strip()]
        assert len(lines) == 1, f"want one line on stderr, got:\n{err}"
        for word in exp["usage"]:
            assert any(alt.lower() in lines[0].lower() for alt in word.split("|")), f"{word!r} not in: {lines[0]}"
    else:
        assert err.strip() == "", err


def test_every_file_states_an_expectation():
    """The corpus itself is well formed: every file has a run or a check with an expectation."""
    for path in FILES:
        exp = expectations(path)
        assert exp["trace"] or exp["errors"] or exp["exit"] or exp["cmd"] == "check", path
        assert not (exp["usage"] is not None and exp["errors"]), path
        if exp["cmd"] == "run" and exp["trace"]:
            assert "--watch" in exp["args"] and "--for" in exp["args"], path
