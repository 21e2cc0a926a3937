"""The ring rig's RAPID program (stations/ring_rig/ring_rig.mod) offline: it holds the thesis's
procedures verbatim, and drives a full automatic cycle in simulated time."""
from __future__ import annotations

import re
from pathlib import Path

from rapid_like import InMemoryHost, SignalInfo, parse
from rapid_like.checker import check
from rapid_like.offline import SignalChange, run_offline

RIG = Path(__file__).resolve().parents[2] / "stations" / "ring_rig" / "ring_rig.mod"
SIGNALS = [SignalInfo(n, "DO") for n in ("movePickOutside", "movePlaceOutside", "movePickInside",
                                           "movePlaceInside", "fullAutoRun")] + \
          [SignalInfo("diGripped", "DI")] + [SignalInfo(f"aoAxis{i}", "AO") for i in (1, 2, 3)] + \
          [SignalInfo(f"aiAxis{i}", "AI") for i in (1, 2, 3)]
# Offline the actual finger positions (AI) do not follow the setpoints: the fingers are "in the bore"
# (100 mm) from the start, and "open at 400 mm" at 4.0 s, when the cycle's last release is done.
FINGERS_ARRIVE = [SignalChange(f"aiAxis{i}", v, t) for t, v in ((0.0, 100), (4.0, 400)) for i in (1, 2, 3)]

# The thesis's Figures 21 to 23, as printed.
THESIS = {
    "Init": """PROC Init() WHILE TRUE DO IF movePickOutside=1 THEN Path_PickOutside; ELSEIF movePlaceOutside=1 THEN
        Path_PlaceOutside; ELSEIF movePickInside=1 THEN Path_PickInside; ELSEIF movePlaceInside=1 THEN
        Path_PlaceInside; ELSEIF fullAutoRun=1 THEN WHILE fullAutoRun=1 DO Path_FullAutoRun; ENDWHILE ENDIF
        Main; ENDWHILE WaitTime 1; ENDPROC""",
    "Path_PickOutside": """PROC Path_PickOutside() SetDO movePickOutside,0;
        MoveJ Target_AppPickOutside,vmax,fine,tcpGripper\\WObj:=wobj0; SetAO aoAxis1,330; SetAO aoAxis2,330;
        SetAO aoAxis3,330; MoveL Target_PickOutside,v1000,fine,tcpGripper\\WObj:=wobj0;
        DecrementJointValueOutside; MoveJ Target_AppPickOutside,vmax,fine,tcpGripper\\WObj:=wobj0; ENDPROC""",
    "IncrementJointValueOutside": """PROC IncrementJointValueOutside() VAR num Axis1; VAR num Axis2;
        VAR num Axis3; WHILE diGripped=1 AND aoAxis1<=440 AND aoAxis2<=440 AND aoAxis3<=440 DO
        Axis1:=aoAxis1; Axis2:=aoAxis2; Axis3:=aoAxis3; Incr Axis1; Incr Axis2; Incr Axis3;
        SetAO aoAxis1,Axis1; SetAO aoAxis2,Axis2; SetAO aoAxis3,Axis3; WaitTime 0.2; ENDWHILE ENDPROC""",
}


def words(text: str) -> str:
    return " ".join(text.split())


def routine_text(source: str, name: str) -> str:
    m = re.search(rf"^\s*PROC {name}\(\).*?ENDPROC", source, re.S | re.M)
    assert m, name
    return words(m.group(0))


def test_thesis_procedures_are_verbatim():
    source = RIG.read_text()
    for name, text in THESIS.items():
        assert routine_text(source, name) == words(text), name


def test_program_has_all_the_rig_procedures_and_checks():
    module = parse(RIG.read_text(), str(RIG))
    names = {r.name for r in module.routines}
    assert names >= {"Main", "Init", "Path_PickOutside", "Path_PlaceOutside", "Path_PickInside",
                     "Path_PlaceInside", "Path_FullAutoRun", "IncrementJointValueOutside",
                     "DecrementJointValueOutside", "IncrementJointValueInside", "DecrementJointValueInside"}
    check(module, {s.name.lower(): s for s in SIGNALS})


def full_cycle(grip_times):
    """Path_FullAutoRun with diGripped toggled at the given times (grip, release, grip, release)."""
    changes, value = [], 1
    for t in grip_times:
        changes.append(SignalChange("diGripped", value, t))
        value = 1 - value
    changes += FINGERS_ARRIVE
    module = parse(RIG.read_text(), str(RIG))
    return run_offline(module, SIGNALS, changes, entry="Path_FullAutoRun", max_time=60)


def test_full_automatic_cycle_moves_the_ring_right_to_left_and_back():
    out = full_cycle([1.0, 2.0, 3.0, 4.0])
    assert out.reason == "completed" and out.t == 4.0
    moves = [(e["t"], e["instr"], e["to"]["trans"]) for e in out.events if e["type"] == "move"]
    right, left = (1600, -800), (1600, 800)
    expected_xy = [right, right, right,  # pick outside on the right pallet: approach, grip, leave
                   left, left, left,  # place outside on the left pallet
                   left, left, left,  # pick inside on the left pallet
                   right, right, right]  # place inside on the right pallet
    assert [tuple(m[2][:2]) for m in moves] == expected_xy
    heights = [m[2][2] for m in moves]
    assert heights == [580, 180, 580] * 4  # approach 400 mm above, grip at the ring's mid-height
    # The robot leaves each pallet exactly when the gripper has reported the change.
    assert [m[0] for m in moves if m[2][2] == 580][1::2] == [1.0, 2.0, 3.0, 4.0]
    assert all(e["tool"] == "tcpGripper" and e["wobj"] == "wobj0" for e in out.events if e["type"] == "move")


def test_fingers_close_then_open_then_grip_the_bore_then_release():
    out = full_cycle([1.0, 2.0, 3.0, 4.0])
    ax1 = [(e["t"], e["value"]) for e in out.events if e.get("signal") == "aoAxis1"]
    # outside: open to 330, close 1 mm per 200 ms until gripped at 1.0 (5 steps)
    assert ax1[:6] == [(0.0, 330), (0.0, 329), (0.2, 328), (0.4, 327), (0.6, 326), (0.8, 325)]
    # release on the left pallet: open 1 mm per 200 ms while gripped, from 1.0 to 1.8
    assert [v for t, v in ax1 if 1.0 <= t < 2.0] == [326, 327, 328, 329, 330]
    # inside: fingers to 150 inside the bore, then open while not gripped (2.0 .. 2.8)
    inside = [v for t, v in ax1 if 2.0 <= t < 3.0]
    assert inside == [150, 151, 152, 153, 154, 155]
    # release on the right pallet: close while gripped (3.0 .. 3.8)
    assert [v for t, v in ax1 if 3.0 <= t < 4.0] == [154, 153, 152, 151, 150]
    # then open to 330 for the next pick from outside
    assert [v for t, v in ax1 if t >= 4.0] == [330]
    assert out.host.values["aoAxis1"] == out.host.values["aoAxis2"] == out.host.values["aoAxis3"] == 330


def test_init_idles_in_main_and_starts_a_path_on_its_signal():
    module = parse(RIG.read_text(), str(RIG))
    changes = [SignalChange("movePickOutside", 1, 1.0), SignalChange("diGripped", 1, 2.0)]
    out = run_offline(module, SIGNALS, changes, entry="Init", max_time=3.0)
    assert out.reason == "time_limit"
    moves = [(e["t"], e["instr"], e["to"]["trans"]) for e in out.events if e["type"] == "move"]
    assert all(t >= 1.0 for t, _, _ in moves)  # Main only waits: the robot stays put until a path is asked for
    resets = [e for e in out.events if e.get("signal") == "movePickOutside"]
    assert resets == [{"t": 1.0, "type": "DO", "signal": "movePickOutside", "value": 0}]
    assert moves[0] == (1.0, "MoveJ", [1600, -800, 580])  # Path_PickOutside: to the approach at once
    assert moves[-1] == (2.0, "MoveJ", [1600, -800, 580])  # and back up once the ring is gripped


def test_rig_program_runs_with_the_cli(capsys):
    from rapid_like.cli import main
    io = ",".join(f"{s.kind}:{s.name}" for s in SIGNALS)
    code = main(["run", str(RIG), "--entry", "Path_FullAutoRun", "--io", io, "--set", "diGripped=1@1",
                 "--set", "diGripped=0@2", "--set", "diGripped=1@3", "--set", "diGripped=0@4",
                 "--set", "aiAxis1=100", "aiAxis2=100", "aiAxis3=100", "--set", "aiAxis1=400@4", "aiAxis2=400@4", "aiAxis3=400@4",
                 "--trace"])
    out = capsys.readouterr().out.splitlines()
    assert code == 0
    assert out[-1] == '{"t": 4.0, "type": "end", "reason": "completed"}'


def test_in_memory_host_ends_at_the_last_target():
    out = full_cycle([1.0, 2.0, 3.0, 4.0])
    assert isinstance(out.host, InMemoryHost)
    assert out.host.position.fields["trans"].fields["y"] == -800
