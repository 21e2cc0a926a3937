"""`plc check` and `plc run FILE.st --offline --trace` end to end, through the real command (a subprocess)."""
from __future__ import annotations

import json
import os
import subprocess
import sys

from tests.conftest import ROOT


def plc(*args, cwd=None):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "plc_client", *args], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=60)


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def trace(stdout: str):
    return [json.loads(line) for line in stdout.splitlines()]


def test_check_exit_codes_and_error_lines(tmp_path):
    good = write(tmp_path, "good.st", "PROGRAM p\nVAR c : INT; END_VAR\nc := c + 1;\nEND_PROGRAM\n")
    bad = write(tmp_path, "bad.st", "PROGRAM p\nVAR c : INT; END_VAR\nc := d + 1;\nc := TRUE;\nEND_PROGRAM\n")
    r = plc("check", good)
    assert r.returncode == 0, r.stderr
    r = plc("check", bad)
    assert r.returncode == 65
    assert r.stderr.splitlines() == [f"{bad}:3:6: error: undeclared name 'd'",
                                     f"{bad}:4:6: error: type mismatch in the assignment: a BOOL cannot be stored in an INT "
                                     "(convert it: BOOL_TO_INT)"]


def test_run_traces_a_counter_and_a_ton_by_the_standards_timing(tmp_path):
    # TON with PT = 30 ms, IN TRUE from t = 0 on a 10 ms cycle: ET 0, 10, 20, 30 ms; Q rises at t = 30 ms.
    src = write(tmp_path, "ton.st", """
PROGRAM main
VAR
  cnt : INT := 32766;
  t1 : TON;
  go : BOOL;
END_VAR
t1(IN := go, PT := T#30ms);
cnt := cnt + 1;
END_PROGRAM
""")
    r = plc("run", src, "--offline", "--for", "0.06", "--set", "go=TRUE@0.01", "--watch", "cnt,t1.Q,t1.ET", "--trace")
    assert r.returncode == 0, r.stderr
    lines = trace(r.stdout)
    assert lines[:3] == [{"t": 0.0, "scan": 0, "name": "cnt", "value": 32767},
                         {"t": 0.0, "scan": 0, "name": "t1.Q", "value": False},
                         {"t": 0.0, "scan": 0, "name": "t1.ET", "value": 0}]
    cnt = [(x["scan"], x["value"]) for x in lines if x["name"] == "cnt"]
    assert cnt[:3] == [(0, 32767), (1, -32768), (2, -32767)]  # INT wraps
    q = [(x["t"], x["value"]) for x in lines if x["name"] == "t1.Q"]
    assert q == [(0.0, False), (0.04, True)]  # IN rose at 0.01; 0.01 + 30 ms
    et = [(x["t"], x["value"]) for x in lines if x["name"] == "t1.ET"]
    assert et == [(0.0, 0), (0.02, 10), (0.03, 20), (0.04, 30)]
    assert max(x["scan"] for x in lines) == 5  # --for 0.06: scans at 0 .. 50 ms


def test_runtime_error_stops_with_place_and_task(tmp_path):
    src = write(tmp_path, "div.st", "PROGRAM main\nVAR a : INT := 3; b : INT := 2; END_VAR\nb := b - 1;\na := a / b;\nEND_PROGRAM\n")
    r = plc("run", src, "--offline", "--for", "0.1", "--trace", "--watch", "b")
    assert r.returncode == 70
    assert r.stderr.startswith(f"{src}:4:8: error: division by zero")
    assert "MAIN_TASK" in r.stderr and "main" in r.stderr
    assert trace(r.stdout) == [{"t": 0.0, "scan": 0, "name": "b", "value": 1}]  # scan 1 stopped


def test_endless_loop_is_stopped(tmp_path):
    src = write(tmp_path, "loop.st", "PROGRAM main\nVAR i : INT; END_VAR\nWHILE TRUE DO\n  i := i + 1;\nEND_WHILE;\nEND_PROGRAM\n")
    r = plc("run", src, "--offline", "--for", "0.1", "--loop-budget", "1000")
    assert r.returncode == 70
    assert r.stderr.startswith(f"{src}:3:1: error: the scan does not end")


def test_set_and_watch_direct_addresses(tmp_path):
    src = write(tmp_path, "loc.st", """
PROGRAM main
VAR b AT %IX0.0 : BOOL; q AT %QW2 : WORD; END_VAR
q := SEL(b, 16#0001, 16#00FF);
IF %IX0.1 THEN q := 7; END_IF;
END_PROGRAM
""")
    r = plc("run", src, "--offline", "--for", "0.04", "--set", "%IX0.0=TRUE@0.01", "--set", "%IX0.1=1@0.03",
            "--watch", "%QW2,b", "--trace")
    assert r.returncode == 0, r.stderr
    assert [(x["scan"], x["name"], x["value"]) for x in trace(r.stdout)] == [
        (0, "%QW2", 1), (0, "b", False), (1, "%QW2", 255), (1, "b", True), (3, "%QW2", 7)]


def test_check_reports_the_syntax_errors_of_every_file(tmp_path):
    a = write(tmp_path, "a.st", "PROGRAM a\nVAR x : INT; END_VAR\nx := ;\nEND_PROGRAM\n")
    b = write(tmp_path, "b.st", "FUNCTION_BLOCK f\nVAR y : INT END_VAR\nEND_FUNCTION_BLOCK\n")
    r = plc("check", a, b)
    assert r.returncode == 65
    assert [line.split(": error:")[0] for line in r.stderr.splitlines()] == [f"{a}:3:6", f"{b}:2:13"]
