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


WAITS_FOR_A_PART = """MODULE Cell
  PROC main()
    SetDO doClamp, 1;
    WaitDI diPart, 1;
    TPWrite "part";
  ENDPROC
ENDMODULE
"""


def test_without_io_a_wait_nothing_drives_ends_the_dry_run_and_says_where(tmp_path: Path):
    p = tmp_path / "cell.mod"
    p.write_text(WAITS_FOR_A_PART)
    code, out, err = run_cli(["run", str(p), "--trace"])
    assert code == 0
    ev = [json.loads(x) for x in out.splitlines()]
    assert ev == [{"t": 0.0, "type": "DO", "signal": "doClamp", "value": 1},
                  {"t": 0.0, "type": "end", "reason": "blocked", "waiting": "WaitDI diPart", "line": 4}]
    assert err.startswith(f"{p}:4:5: note: WaitDI diPart waits for an input that nothing drives")
    # with an I/O configuration the same wait is an error: the user said what drives the inputs
    code, out, err = run_cli(["run", str(p), "--io", "DO:doClamp,DI:diPart"])
    assert code == 70 and "waits forever" in err


def test_task_dir_runs_a_robotstudio_backup_with_its_calibration_module(tmp_path: Path):
    progmod = tmp_path / "RAPID" / "TASK1" / "PROGMOD"
    progmod.mkdir(parents=True)
    (progmod / "CalibData.mod").write_text(
        "MODULE CalibData\n  PERS tooldata tGrip:=[TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]];\nENDMODULE\n")
    (progmod / "Module1.mod").write_text(
        "MODULE Module1\n  CONST robtarget p1:=[[500,0,400],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
        "  PROC main()\n    MoveL p1,v100,fine,tGrip;\n    TPWrite \"at \" \\Num:=CRobT(\\Tool:=tool0).trans.z;\n"
        "  ENDPROC\nENDMODULE\n")
    code, out, err = run_cli(["run", "--task", str(tmp_path / "RAPID" / "TASK1")])
    assert code == 0 and err.startswith(f"{progmod / 'Module1.mod'}:4:5: note: MoveL and the motions after it take "
                                        f"no time without --station") and len(err.splitlines()) == 1
    assert out == "at 500\n"  # the flange is 100 mm above the TCP of tGrip, which points down


def test_check_lists_what_is_approximate_with_file_and_line(tmp_path: Path):
    p = tmp_path / "zones.mod"
    p.write_text("MODULE Z\n  PROC main()\n    SingArea \\Wrist;\n    VelSet 50, 800;\n    AccSet 50, 50;\n"
                 "    MoveL CRobT(), v100, z10, tool0;\n"
                 "    MoveL CRobT(), v100, fine, tool0 \\Conc;\n  ENDPROC\nENDMODULE\n")
    code, out, err = run_cli(["check", str(p)])
    assert (code, err) == (0, "")
    lines = out.splitlines()
    assert lines[0].startswith(f"{p}:3:5: warning: SingArea: ")
    assert lines[1].startswith(f"{p}:7:5: warning: MoveL \\Conc: ")
    assert len(lines) == 2  # VelSet, AccSet and the zone are what the planner does (docs/rapid.md)


def test_a_loop_of_motions_that_never_waits_runs_at_the_robots_pace_offline(tmp_path: Path):
    p = tmp_path / "paced.mod"
    p.write_text("MODULE PacedLoop\n"
                 "  CONST robtarget pA := [[0,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                 "  CONST robtarget pB := [[100,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                 "  PROC main()\n    WHILE TRUE DO\n      MoveL pA, v50, fine, tool0;\n      MoveL pB, v50, fine, tool0;\n"
                 "    ENDWHILE\n  ENDPROC\nENDMODULE\n")
    code, out, err = run_cli(["run", str(p), "--max-time", "20", "--loop-budget", "30", "--trace"])
    assert code == 0 and err.startswith(f"{p}:6:7: note: ") and "in a polling loop a motion takes distance / v_tcp" in err
    times = [json.loads(x)["t"] for x in out.splitlines() if '"move"' in x]
    later = [t for t in times if t > 0]
    # the first tick's turns take no time; from then on each 100 mm at 50 mm/s takes 2 s
    assert len(later) >= 9 and all(b - a == pytest.approx(2.0) for a, b in zip(later[1:], later[2:]))
    assert len(times) - len(later) <= 30  # the first tick's budget (30 turns here) bounds the instant ones
