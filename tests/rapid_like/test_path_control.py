"""Path control as the RAPID manual documents it, with real RAPID in the ring rig's cell: a TRAP's StopMove stops
the robot on its path (it decelerates on the programmed line and stands), StartMove resumes the rest of the same
path to the same end point; ClearPath drops the interrupted motion's remaining path; StorePath / RestoPath let a
TRAP move the robot away and back and the stored path go on. Measured on the physics arm's TCP after every step;
the offline run with the station times the same events as the cell."""
from __future__ import annotations

import io
import json
from contextlib import redirect_stderr, redirect_stdout

import numpy as np
import pytest

from rapid_like.cli import main as rapid
from tests.rapid_like.test_motion_model import P0, TOOL, from_line, run_in_cell, speeds, station_with

START, END = np.array([1.5, -0.3, 0.9]), np.array([1.5, 0.5, 0.9])  # p0 and Offs(p0,0,800,0), m


def program(trap_stop: str, trap_go: str = "StartMove;", after: str = "") -> str:
    """MoveL from p0 800 mm along y at v500; a timer 0.6 s after it starts runs `trap_stop`, one 1.5 s after it
    `trap_go`."""
    return f"""MODULE Stops
  {TOOL}
  {P0}
  VAR intnum stopIt;
  VAR intnum goOn;
  PROC main()
    MoveJ p0, v1000, fine, tG;
    CONNECT stopIt WITH TStop;
    CONNECT goOn WITH TGo;
    ITimer \\Single, 0.6, stopIt;
    ITimer \\Single, 1.5, goOn;
    MoveL Offs(p0,0,800,0), v500, fine, tG;
    {after}
  ENDPROC
  TRAP TStop
    {trap_stop}
  ENDTRAP
  TRAP TGo
    {trap_go}
  ENDTRAP
ENDMODULE
"""


def after_start(events, t, p):
    start = next(e["t"] for e in events if e["type"] == "move" and e["instr"] == "MoveL")
    keep = t > start - 1e-9
    return start, t[keep], p[keep]


def test_stopmove_stops_the_tcp_on_its_line_and_startmove_resumes_to_the_same_end_point(tmp_path):
    events, t, p = run_in_cell(tmp_path / "stop", program("StopMove;"))
    start, t, p = after_start(events, t, p)
    v = speeds(t, p)
    assert max(from_line(q, START, END) for q in p) < 0.001  # on the programmed line all along (1 mm: tracking)
    stopped_at = t[0] + 0.6
    standing = (t > stopped_at + 0.5) & (t < start + 1.5)
    assert v[standing].max() < 0.002  # it stands ...
    where = p[standing][-1]
    at_stop = p[np.argmin(np.abs(t - stopped_at))]
    # ... ahead of where it was at StopMove, by a braking distance: 500 mm/s at most a few hundred mm/s^2 of
    # deceleration on this arm (v^2 / 2a: 20 to 250 mm for 0.5 to 6 m/s^2)
    ahead = (where - at_stop) @ (END - START) / np.linalg.norm(END - START)
    assert 0.02 < ahead < 0.25
    assert np.linalg.norm(where - END) > 0.1  # ... short of the end point
    # the deceleration is gradual: no step of speed from 0.5 m/s to 0 within a step
    assert np.abs(np.diff(v[(t > stopped_at) & (t < stopped_at + 0.5)])).max() < 0.05
    assert np.linalg.norm(p[-1] - END) < 0.0005  # StartMove: on to the same end point
    events_plain, t_plain, _ = run_in_cell(tmp_path / "plain", program("", ""))
    plain = events_plain[-1]["t"] - after_start(events_plain, t_plain, t_plain[:, None])[0]
    # the stop cost the standing time at least (from the end of its ramp down to StartMove)
    assert events[-1]["t"] - start > plain + 0.5


def test_stopmove_quick_stops_sooner_than_stopmove(tmp_path):
    def braking(folder, stop):
        events, t, p = run_in_cell(folder, program(stop))
        _, t, p = after_start(events, t, p)
        at_stop = p[np.argmin(np.abs(t - (t[0] + 0.6)))]
        where = p[np.argmin(np.abs(t - (t[0] + 1.4)))]
        return float(np.linalg.norm(where - at_stop))

    normal, quick = braking(tmp_path / "n", "StopMove;"), braking(tmp_path / "q", "StopMove \\Quick;")
    assert quick < 0.75 * normal  # twice the deceleration: about half the braking distance


def test_clearpath_drops_the_rest_of_the_interrupted_motion(tmp_path):
    events, t, p = run_in_cell(tmp_path, program("StopMove;\n    ClearPath;\n    StartMove;", "",
                                                 "MoveL Offs(p0,0,0,-200), v500, fine, tG;"))
    _, t, p = after_start(events, t, p)
    assert np.linalg.norm(p - END, axis=1).min() > 0.1  # it never went on to the end point
    stop_point = p[np.argmin(np.abs(t - (t[0] + 1.4)))]
    below = START + np.array([0.0, 0.0, -0.2])
    assert np.linalg.norm(p[-1] - below) < 0.0005  # the program went on with the next motion
    after = p[t > t[0] + 1.4]
    assert max(from_line(q, stop_point, below) for q in after) < 0.001  # from where it stood, straight there


def test_storepath_and_restopath_let_a_trap_move_away_and_back_then_the_path_goes_on(tmp_path):
    away = """StopMove;
    StorePath;
    here := CRobT(\\Tool:=tG);
    MoveL Offs(here,0,0,100), v500, fine, tG;
    MoveL here, v500, fine, tG;
    RestoPath;
    StartMove;"""
    text = program(away, "").replace("  VAR intnum goOn;", "  VAR intnum goOn;\n  VAR robtarget here;")
    events, t, p = run_in_cell(tmp_path, text)
    _, t, p = after_start(events, t, p)
    assert p[:, 2].max() == pytest.approx(0.9 + 0.1, abs=0.0005)  # up 100 mm from where it stood ...
    assert np.linalg.norm(p[-1] - END) < 0.0005  # ... back, and on to the stored path's end point
    on_line = [q for q in p if q[2] < 0.9005]
    assert max(from_line(q, START, END) for q in on_line) < 0.001


def test_restopath_without_storepath_is_an_error_at_its_line(tmp_path):
    station = station_with(tmp_path, program("RestoPath;"))
    err = io.StringIO()
    with redirect_stdout(io.StringIO()), redirect_stderr(err):
        assert rapid(["run", str(station / "test.mod"), "--station", str(station), "--entry", "main"]) == 70
    assert ":16:5: error:" in err.getvalue() and "StorePath" in err.getvalue()  # the TRAP's first line


def test_an_offline_run_with_the_station_stops_and_resumes_at_the_cells_times(tmp_path):
    text = program("StopMove;", "StartMove;", "SetDO fullAutoRun, 1;")
    cell_events, _, _ = run_in_cell(tmp_path / "cell", text)
    station = station_with(tmp_path / "offline", text)
    out = io.StringIO()
    with redirect_stdout(out):
        assert rapid(["run", str(station / "test.mod"), "--station", str(station), "--entry", "main", "--trace"]) == 0
    offline = [json.loads(line) for line in out.getvalue().splitlines()]
    assert [(e["type"], e["t"]) for e in offline] == [(e["type"], e["t"]) for e in cell_events]
