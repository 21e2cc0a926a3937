"""The controller as a station binding drives it: tick(now) once per step, a host whose motions
take time, stop/start/resume, and loops that consume no time."""
from __future__ import annotations

import pytest

from rapid_like import CheckError, Controller, Host, InMemoryHost, MotionRequest, SignalInfo, parse

DT = 0.012


def make(src: str, signals=(), entry="main", host=None, step=None, **kw):
    events: list[dict] = []
    host = host or InMemoryHost([SignalInfo(n, k) for k, n in signals])
    ctl = Controller(parse(src, "t.mod"), host, entry, on_event=events.append, step=step, **kw)
    return ctl, host, events


def prints(events):
    return [(e["t"], e["text"]) for e in events if e["type"] == "print"]


class SlowHost(InMemoryHost):
    """A host whose motions take `ticks` calls of motion_done, like a robot moving in the world."""

    def __init__(self, signals, ticks: int):
        super().__init__(signals)
        self.ticks = ticks
        self.remaining: dict[int, int] = {}

    def start_motion(self, request: MotionRequest) -> object:
        h = super().start_motion(request)
        self.remaining[h] = self.ticks
        return h

    def motion_done(self, handle) -> bool:
        self.remaining[handle] -= 1
        return self.remaining[handle] < 0


def test_in_memory_host_satisfies_the_host_protocol():
    assert isinstance(InMemoryHost([]), Host)


def test_a_time_less_loop_runs_its_budget_then_yields_at_every_tick():
    src = """
        MODULE M
          VAR num n := 0;
          PROC main()
            WHILE TRUE DO
              Incr n;
            ENDWHILE
          ENDPROC
        ENDMODULE"""
    ctl, host, _ = make(src, loop_budget=25)
    for k in range(50):
        ctl.tick(k * DT)  # returns: the loop does not hang the caller
    assert ctl.state == "waiting"
    assert ctl.interp.globals["n"].value == 50 * 25  # the budget's worth of iterations per tick
    ctl, host, _ = make(src)
    ctl.tick(0.0)
    assert ctl.interp.globals["n"].value == 10_000  # the default budget


SUM_TO_1000 = """
        MODULE M
          PROC main()
            VAR num sum := 0;
            FOR i FROM 1 TO 1000 DO
              sum := sum + i;
            ENDFOR
            TPWrite "sum=" \\Num:=sum;{more}
          ENDPROC
        ENDMODULE"""


def test_a_loop_within_the_budget_takes_no_time():
    ctl, _, events = make(SUM_TO_1000.replace("{more}", """
            FOR i FROM 1 TO 3 DO
              TPWrite "i=" \\Num:=i;
            ENDFOR"""))
    ctl.tick(0.0)
    assert ctl.state == "completed"
    assert prints(events) == [(0.0, "sum=500500"), (0.0, "i=1"), (0.0, "i=2"), (0.0, "i=3")]


def test_a_loop_longer_than_the_budget_goes_on_at_the_next_ticks_as_a_polling_loop():
    ctl, _, events = make(SUM_TO_1000.replace("{more}", ""), loop_budget=300)
    k = 0
    while ctl.state != "completed":
        ctl.tick(k * DT)
        k += 1
    # 300 iterations in the first tick; then a loop that used up a whole tick gets POLL_BUDGET (100)
    # per tick: 7 more ticks make the 1000, the 1000th uses up the 8th tick's budget, the loop ends
    # in the 9th tick (t = 8 * 12 ms)
    assert prints(events) == [(0.096, "sum=500500")]


def test_a_busy_loop_in_a_station_binding_reacts_at_the_tick_an_input_changes():
    ctl, host, events = make("""
        MODULE M
          PROC main()
            WHILE di1 = 0 DO
            ENDWHILE
            TPWrite "seen";
          ENDPROC
        ENDMODULE""", signals=[("DI", "di1")], loop_budget=50)
    for k in range(10):
        ctl.tick(k * DT)
    assert prints(events) == [] and ctl.wait.kind == "step"
    host.set_input("di1", 1)
    ctl.tick(10 * DT)
    assert prints(events) == [(0.12, "seen")]


def test_a_retry_loop_without_time_uses_the_loop_budget():
    ctl, _, events = make("""
        MODULE M
          VAR num zero := 0;
          VAR num tries := 0;
          PROC main()
            VAR num r;
            r := 1 / zero;
          ERROR
            Incr tries;
            RETRY;
          ENDPROC
        ENDMODULE""", loop_budget=40)
    ctl.tick(0.0)
    assert ctl.state == "waiting" and ctl.wait.what == "RETRY"
    assert ctl.interp.globals["tries"].value == 40
    ctl.tick(DT)
    assert ctl.interp.globals["tries"].value == 80


def test_wait_time_resumes_at_the_first_tick_after_its_end():
    ctl, _, events = make("""
        MODULE M
          PROC main()
            WaitTime 0.2;
            TPWrite "done";
          ENDPROC
        ENDMODULE""")
    k = 0
    while ctl.state != "completed":
        ctl.tick(k * DT)
        k += 1
    # 0.2 s is not a multiple of 12 ms: the first tick at or after it is 17 * 0.012 = 0.204
    assert prints(events) == [(0.204, "done")]


def test_motion_waits_until_the_host_reports_it_done():
    host = SlowHost([SignalInfo("doAtPick", "DO")], ticks=5)
    ctl, host, events = make("""
        MODULE M
          PERS tooldata tGrip := [TRUE,[[0,0,350],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];
          PERS wobjdata wPallet := [FALSE,TRUE,"",[[1600,-800,150],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
          CONST robtarget pPick := [[0,0,30],[0,1,0,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
          PROC main()
            MoveL pPick, v1000, fine, tGrip \\WObj:=wPallet;
            Set doAtPick;
          ENDPROC
        ENDMODULE""", host=host)
    ctl.tick(0.0)
    assert ctl.state == "waiting"
    req = host.moves[0]
    assert (req.instr, req.target_name, req.speed_name, req.zone_name, req.tool_name, req.wobj_name) == \
        ("MoveL", "pPick", "v1000", "fine", "tGrip", "wPallet")
    assert req.target.fields["trans"].fields["z"] == 30
    assert req.wobj.fields["uframe"].fields["trans"].fields["x"] == 1600
    assert req.tool.fields["tframe"].fields["trans"].fields["z"] == 350
    ticks = 1
    while host.values["doAtPick"] == 0:
        ctl.tick(ticks * DT)
        ticks += 1
        assert ticks < 20
    assert ticks == 6  # motion_done was False five times, True on the sixth poll
    assert [e["type"] for e in events] == ["move", "DO", "end"]


def test_stop_then_start_restarts_from_the_entry_routine():
    ctl, _, events = make("""
        MODULE M
          PERS num runs := 0;
          VAR num stepsDone := 0;
          PROC main()
            Incr runs;
            TPWrite "run " \\Num:=runs;
            WaitTime 1;
            Incr stepsDone;
            TPWrite "steps " \\Num:=stepsDone;
          ENDPROC
        ENDMODULE""")
    ctl.tick(0.0)
    ctl.tick(0.5)
    ctl.stop()
    ctl.tick(1.2)  # stopped: the WaitTime does not finish
    assert ctl.state == "stopped"
    ctl.start()
    ctl.tick(2.0)
    ctl.tick(3.0)
    assert ctl.state == "completed"
    assert prints(events) == [(0.0, "run 1"), (2.0, "run 2"), (3.0, "steps 1")]
    ends = [e["reason"] for e in events if e["type"] == "end"]
    assert ends == ["stop", "completed"]


def test_resume_continues_after_a_stop_instruction():
    ctl, _, events = make("""
        MODULE M
          PROC main()
            TPWrite "a";
            Stop;
            TPWrite "b";
          ENDPROC
        ENDMODULE""")
    ctl.tick(0.0)
    assert ctl.state == "stopped" and ctl.end_reason == "stop"
    ctl.resume()
    ctl.tick(0.1)
    assert ctl.state == "completed"
    assert [t for _, t in prints(events)] == ["a", "b"]


def test_signals_are_read_live_each_time_they_are_evaluated():
    ctl, host, events = make("""
        MODULE M
          PROC main()
            WaitUntil diGripped = 1;
            TPWrite "gripped";
          ENDPROC
        ENDMODULE""", signals=[("DI", "diGripped")])
    for k in range(10):
        ctl.tick(k * 0.05)
    assert prints(events) == []
    host.set_input("diGripped", 1)
    ctl.tick(0.5)
    assert prints(events) == [(0.5, "gripped")]


def test_runtime_error_sets_error_state_with_position():
    ctl, _, events = make("""MODULE M
  PROC main()
    VAR num z;
    z := 4 / z;
  ENDPROC
ENDMODULE""")
    ctl.tick(0.0)
    assert ctl.state == "error"
    assert (ctl.error.span.line, ctl.error.span.col) == (4, 12)
    assert events[-1]["type"] == "error" and events[-1]["line"] == 4


def test_static_errors_are_raised_before_anything_runs():
    with pytest.raises(CheckError) as e:
        make("""MODULE M
  PROC main()
    SetDO doMissing, 1;
  ENDPROC
ENDMODULE""")
    assert (e.value.span.line, e.value.span.col) == (3, 11)


def test_missing_entry_routine_is_a_check_error():
    with pytest.raises(CheckError, match="no routine named 'Init'"):
        make("MODULE M\n PROC main()\n ENDPROC\nENDMODULE", entry="Init")


def test_next_wake_reports_the_end_of_a_wait_and_pending_pulses():
    ctl, _, _ = make("""
        MODULE M
          PROC main()
            PulseDO \\PLength:=0.3, doP;
            WaitTime 0.5;
          ENDPROC
        ENDMODULE""", signals=[("DO", "doP")])
    ctl.tick(0.0)
    assert ctl.next_wake_ns() == 300_000_000
    ctl.tick(0.3)
    assert ctl.next_wake_ns() == 500_000_000


class RefusingHost(InMemoryHost):
    """A host that refuses analog setpoints above 441, as the cell does."""

    def write_signal(self, name: str, value: float) -> None:
        from rapid_like.builtins import ERRORS
        from rapid_like.errors import ExecError
        if value > 441:
            raise ExecError(f"{name} = {value:g} is out of range (ERR_AO_LIM)", None, ERRORS["ERR_AO_LIM"],
                            "ERR_AO_LIM")
        super().write_signal(name, value)


def test_host_errors_are_positioned_at_the_statement_and_can_be_handled():
    host = RefusingHost([SignalInfo("aoAxis1", "AO")])
    ctl, host, events = make("""MODULE M
  PROC main()
    SetAO aoAxis1, 500;
    TPWrite "after";
  ERROR
    IF ERRNO = ERR_AO_LIM THEN
      TPWrite "clamped";
      SetAO aoAxis1, 441;
      TRYNEXT;
    ENDIF
  ENDPROC
ENDMODULE""", host=host)
    ctl.tick(0.0)
    assert [t for _, t in prints(events)] == ["clamped", "after"]
    assert host.values["aoAxis1"] == 441

    ctl2, _, events2 = make("MODULE M\n  PROC main()\n    SetAO aoAxis1, 500;\n  ENDPROC\nENDMODULE",
                            host=RefusingHost([SignalInfo("aoAxis1", "AO")]))
    ctl2.tick(0.0)
    assert ctl2.state == "error" and (ctl2.error.span.line, ctl2.error.span.col) == (3, 5)


def test_a_runtime_error_lets_a_running_pulse_end_and_reports_the_error_last():
    ctl, host, events = make("""MODULE M
  PROC main()
    PulseDO \\PLength:=0.5, doP;
    reg1 := 1 / 0;
  ENDPROC
ENDMODULE""", signals=[("DO", "doP")])
    ctl.tick(0.0)
    assert ctl.state == "error" and ctl.error.errname == "ERR_DIVZERO"  # at once
    assert not ctl.finished and ctl.next_wake_ns() == 500_000_000  # the pulse is still running
    assert [e["type"] for e in events] == ["DO"]
    ctl.tick(0.5)
    assert host.values["doP"] == 0  # not stuck at 1
    assert events[-2:] == [{"t": 0.5, "type": "DO", "signal": "doP", "value": 0},
                           {"t": 0.5, "type": "error", "line": 4, "message": "division by zero (ERR_DIVZERO)"}]
    assert ctl.finished
    ctl.tick(0.6)
    assert len(events) == 3  # reported once
