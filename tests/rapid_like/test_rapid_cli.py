"""The `rapid` command line: the module entry point, usage errors, exit statuses and plain output."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import io
from contextlib import redirect_stderr, redirect_stdout

from rapid_like.cli import main


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()

PROGRAM = """MODULE Hello
  PROC main()
    TPWrite "hello";
    SetDO doLamp, 1;
  ENDPROC
  PROC Other()
    TPWrite "other";
  ENDPROC
ENDMODULE
"""


@pytest.fixture
def prog(tmp_path: Path) -> Path:
    p = tmp_path / "hello.mod"
    p.write_text(PROGRAM)
    return p


def test_python_dash_m_runs_a_program(prog: Path):
    r = subprocess.run([sys.executable, "-m", "rapid_like", "run", str(prog), "--io", "DO:doLamp", "--trace"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    lines = [json.loads(x) for x in r.stdout.splitlines()]
    assert [e["type"] for e in lines] == ["print", "DO", "end"]


def test_without_trace_tpwrite_lines_go_to_stdout(prog: Path):
    code, out, err = run_cli(["run", str(prog), "--io", "DO:doLamp"])
    assert (code, out, err) == (0, "hello\n", "")


def test_entry_selects_the_routine(prog: Path):
    code, out, _ = run_cli(["run", str(prog), "--io", "DO:doLamp", "--entry", "other"])
    assert (code, out) == (0, "other\n")


def test_unknown_entry_is_a_static_error(prog: Path):
    code, out, err = run_cli(["run", str(prog), "--io", "DO:doLamp", "--entry", "Init"])
    assert code == 65 and out == ""
    assert "no routine named 'Init'" in err


def test_a_signal_missing_from_io_fails_before_anything_runs(prog: Path):
    code, out, err = run_cli(["run", str(prog), "--io", "DI:diOther", "--trace"])
    assert code == 65
    assert out == ""  # not even the TPWrite on the line before
    assert err.startswith(f"{prog}:4:11: error: undefined name 'doLamp'")
    assert "    SetDO doLamp, 1;\n" in err and "\n              ^" in err


@pytest.mark.parametrize("args, message", [
    (["--io", "XX:foo"], "unknown signal type"),
    (["--io", "diGripped"], "expected TYPE:NAME"),
    (["--io", "DO:doLamp", "--set", "nothere=1"], "not a configured signal"),
    (["--io", "DO:doLamp", "--set", "doLamp=2"], "digital signal is 0 or 1"),
    (["--io", "DO:doLamp", "--set", "doLamp=1@soon"], "is not a number"),
])
def test_usage_errors_exit_2(prog: Path, args, message):
    code, _, err = run_cli(["run", str(prog), *args])
    assert code == 2
    assert message in err


def test_missing_file_exits_66(tmp_path: Path):
    code, _, err = run_cli(["run", str(tmp_path / "nope.mod")])
    assert code == 66 and "cannot read" in err


def test_check_reports_ok_without_running(prog: Path):
    assert run_cli(["check", str(prog), "--io", "DO:doLamp"]) == (0, "", "")
    code, _, err = run_cli(["check", str(prog), "--io", "DI:diOther"])
    assert code == 65 and "doLamp" in err


def test_without_any_io_the_signals_are_taken_from_the_program_and_check_says_so(prog: Path):
    code, out, err = run_cli(["check", str(prog)])
    assert (code, err) == (0, "")
    assert f"{prog}:4:11: warning: doLamp is not a configured I/O signal: taken as a DO from its use" in out
    code, out, err = run_cli(["run", str(prog), "--trace"])
    assert code == 0, err
    assert {"t": 0.0, "type": "DO", "signal": "doLamp", "value": 1} in [json.loads(x) for x in out.splitlines()]


def test_io_accepts_comma_lists_and_repeats(tmp_path: Path):
    p = tmp_path / "io.mod"
    p.write_text("MODULE M\n PROC main()\n  SetAO aoX, diY + 2;\n  SetGO goZ, 5;\n ENDPROC\nENDMODULE\n")
    code, out, err = run_cli(["run", str(p), "--io", "AO:aoX,DI:diY", "--io", "GO:goZ", "--set", "diY=1",
                              "--trace"])
    assert code == 0, err
    ev = [json.loads(x) for x in out.splitlines()]
    assert ev[0] == {"t": 0.0, "type": "AO", "signal": "aoX", "value": 3}
    assert ev[1] == {"t": 0.0, "type": "GO", "signal": "goZ", "value": 5}


def test_io_and_set_take_space_separated_lists_before_or_after_the_program(prog: Path):
    code, out, err = run_cli(["run", "--io", "DO:doLamp", "DI:diX", str(prog), "--set", "diX=1", "diX=0@1"])
    assert (code, out, err) == (0, "hello\n", "")


@pytest.mark.parametrize("io, message", [
    ("DI:reg1", "the configured I/O signal reg1 (DI) has the name of the predefined data reg1"),
    ("DO:v100", "the configured I/O signal v100 (DO) has the name of the predefined data v100"),
    ("DO:tool0", "has the name of the predefined data tool0"),
    ("DO:Fine", "has the name of the predefined data fine"),
    ("DO:z10", "has the name of the predefined data z10"),
    ("DO:SetDO", "has the name of the built-in instruction SetDO"),
    ("AI:abs", "has the name of the built-in function Abs"),
    ("DI:errno", "has the name of the predefined data ERRNO"),
    ("DI:While", "is the reserved word WHILE"),
])
def test_an_io_name_that_clashes_with_a_predefined_name_fails_before_anything_runs(prog: Path, io, message):
    code, out, err = run_cli(["run", str(prog), "--io", "DO:doLamp," + io, "--trace"])
    assert (code, out) == (65, "")
    assert err.startswith(f"{prog}: error: the configured I/O signal ") and message in err.splitlines()[0], err
    code, _, err = run_cli(["check", str(prog), "--io", "DO:doLamp," + io])
    assert code == 65 and message in err


def test_an_io_name_that_clashes_with_a_routine_is_reported_at_the_routine(prog: Path):
    code, out, err = run_cli(["run", str(prog), "--io", "DO:doLamp,DI:other", "--trace"])
    assert (code, out) == (65, "")
    assert err.startswith(f"{prog}:6:3: error: PROC Other has the name of the configured I/O signal other (DI)")


def test_help_documents_pulses_that_outlive_the_program(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "after the edges of any PulseDO still running when the program ended" in text
