"""The rig's RAPID program bound to the ring rig station: it is the robot controller of the physics cell.

The station's `[controller]` wires aoAxis1..3 (mm) to the finger inputs L2..L4 (m), diGripped to the
gripper's doGripped and aiAxis1..3 to the actual finger positions; motions drive the arm.
"""
from __future__ import annotations

import math

import pytest

from tests.conftest import STATIONS
from twin_app.cell import open_cell
from twin.core.errors import StationError
from tests.station_copies import edited_station

RIG = STATIONS / "ring_rig"
RIGHT, LEFT = (1.6, -0.8), (1.6, 0.8)


def run_until(twin, done, limit_s: float) -> None:
    end = twin.step_count + round(limit_s / twin.dt)
    while not done():
        assert twin.step_count < end, f"not done after {limit_s} s of simulated time"
        twin.step()


def test_the_program_carries_the_ring_right_to_left_and_back_in_physics():
    events = []
    with open_cell(RIG, on_event=events.append, entry="Path_FullAutoRun") as cell:
        ctl = cell.controller
        grips = []  # (t, gripped, ring xy) at every change of doGripped
        last = False

        def watch():
            nonlocal last
            if cell.read("doGripped") != last:
                last = cell.read("doGripped")
                grips.append((round(cell.time, 3), last, cell.twin.object_pose("ring")[0][:2]))
            return ctl.state == "completed"

        run_until(cell, watch, 60.0)
        assert [e for e in events if e["type"] in ("error", "end")] == [
            {"t": pytest.approx(cell.time - cell.dt, abs=0.013), "type": "end", "reason": "completed"}]
        # gripped on the right, released on the left, gripped on the left, released on the right
        assert [g for _, g, _ in grips] == [True, False, True, False]
        where = [xy for _, _, xy in grips]
        for xy, pallet in zip(where, (RIGHT, LEFT, LEFT, RIGHT)):
            assert xy == pytest.approx(pallet, abs=0.003)
        # the outside grip closed from 330 mm onto the ring's 320 mm radius; the inside one opened to 200
        ao1 = [(e["t"], e["value"]) for e in events if e.get("signal") == "aoAxis1"]
        assert [v for t, v in ao1 if t <= grips[0][0]][-1] == 319  # touching at 320, pressing (by force) at 319
        assert [v for t, v in ao1 if grips[1][0] < t <= grips[2][0]][-1] == 201  # touching at 200, pressing at 201
        (x, y, z), q = cell.twin.object_pose("ring")
        assert math.dist((x, y, z), (*RIGHT, 0.18)) < 0.005  # back where it started, lying flat
        assert abs(q[0]) < 0.01 and abs(q[1]) < 0.01
        assert cell.read("L2.actual") == pytest.approx(0.330, abs=0.001)  # open for the next pick


def test_init_waits_for_a_path_signal_like_the_io_simulator():
    with open_cell(RIG) as cell:
        cell.step(50)
        assert not cell.read("robot.busy") and cell.read("L2") == pytest.approx(0.35)  # idle in Main
        cell.write("movePickOutside", True)
        run_until(cell, lambda: cell.read("doGripped"), 10.0)
        assert not cell.read("movePickOutside")  # Path_PickOutside resets its signal
        assert cell.read("aoAxis1") == 319 and cell.read("L2") == pytest.approx(0.319)  # 1 mm past: pressing
        run_until(cell, lambda: cell.twin.object_pose("ring")[0][2] > 0.5, 5.0)  # lifted to the approach
        assert cell.read("diGripped") and cell.read("GrippedPart") == "ring"


def copy_rig(tmp_path, old: str | None = None, new: str | None = None):
    """A copy of the rig in `tmp_path`, its station.toml with `old` replaced by `new`."""
    return edited_station(RIG, tmp_path / "rig", old, new)


def test_wiring_to_a_signal_the_twin_lacks_names_the_file_and_key(tmp_path):
    station = copy_rig(tmp_path, 'drives = "L3"', 'drives = "L9"')
    with pytest.raises(StationError, match=r"station\.toml: controller\.io\[7\]\.drives: aoAxis2: the twin has no signal 'L9'"):
        open_cell(station)


def test_an_output_of_the_twin_cannot_be_driven(tmp_path):
    station = copy_rig(tmp_path, 'drives = "L3"', 'drives = "doGripped"')
    with pytest.raises(StationError, match=r"controller\.io\[7\]\.drives: aoAxis2: 'doGripped' is an output"):
        open_cell(station)


def test_the_station_binding_gives_a_busy_loop_a_small_budget_per_step():
    from rapid_like.controller import DEFAULT_LOOP_BUDGET
    from rapid_like.station_host import STATION_LOOP_BUDGET

    with open_cell(RIG) as cell:
        assert cell.controller.interp.loop_budget == STATION_LOOP_BUDGET < DEFAULT_LOOP_BUDGET


TOOL_AND_WOBJ = """MODULE ToolWobj
  PERS tooldata tLong := [TRUE,[[0,0,450],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];
  PERS wobjdata wPallet := [FALSE,TRUE,"",[[1600,-800,150],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  CONST robtarget pAbove := [[0,0,500],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS robtarget pHere := [[0,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS robtarget pWorld := [[0,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    MoveL pAbove,v1000,fine,tLong\\WObj:=wPallet;
    pHere := CRobT();
    pWorld := CRobT(\\Tool:=tool0\\WObj:=wobj0);
  ENDPROC
ENDMODULE
"""


def test_motions_and_crobt_use_the_programs_tooldata_and_wobjdata(tmp_path):
    station = copy_rig(tmp_path)
    (station / "tool_wobj.mod").write_text(TOOL_AND_WOBJ)
    toml = station / "station.toml"
    toml.write_text(toml.read_text().replace('program = "ring_rig.mod"', 'program = "tool_wobj.mod"')
                    .replace('entry = "Init"', 'entry = "main"'))
    with open_cell(station) as cell:
        run_until(cell, lambda: cell.controller.state == "completed", 20.0)
        # the long tool's TCP (450 mm out) is 500 mm above the pallet's top: the station's tcp (350 mm) 100 mm higher
        assert cell.twin.tcp_pose().position == pytest.approx((1.6, -0.8, 0.15 + 0.5 + 0.1), abs=0.001)
        data = cell.controller.interp.globals
        here = data["phere"].value.fields["trans"]
        assert [float(here.fields[k]) for k in "xyz"] == pytest.approx([0, 0, 500], abs=0.5)  # in wPallet, for tLong
        world = data["pworld"].value.fields["trans"]
        assert [float(world.fields[k]) for k in "xyz"] == pytest.approx([1600, -800, 150 + 500 + 450], abs=0.5)  # the flange


def test_the_program_can_be_stopped_and_started_again_from_its_entry_routine_by_signals():
    with open_cell(RIG) as cell:
        cell.step(10)
        assert cell.read("rapid.running") and not cell.read("rapid.error")
        assert cell.read("rapid.line") > 0  # waiting in Main (the WaitTime)
        cell.write("rapid.stop", True)
        cell.step(2)
        assert not cell.read("rapid.running") and cell.read("rapid.line") == 0
        cell.write("movePickOutside", True)
        cell.step(100)
        assert cell.read("movePickOutside") and cell.read("L2") == pytest.approx(0.35)  # nothing runs
        cell.write("rapid.start", True)  # from Init again: it sees the request and picks the ring
        run_until(cell, lambda: cell.read("doGripped"), 10.0)
        assert cell.read("rapid.running") and not cell.read("movePickOutside")


def test_the_robots_outputs_are_read_only_from_outside_and_its_inputs_writable():
    from twin.core.errors import SignalError

    with open_cell(STATIONS / "ring_rig_plc") as cell:
        kinds = {s.name: s.direction for s in cell.signals}
        assert kinds["doGripRequest"] == kinds["goCycle"] == kinds["aoFingerReady"] == "output"  # robot DO/GO/AO
        assert kinds["diGripDone"] == kinds["diGripOk"] == "input"  # the PLC's answers
        assert kinds["fullAutoRun"] == "input"  # settable = true: the I/O simulator's signal
        with pytest.raises(SignalError, match="doGripRequest.*output"):
            cell.write("doGripRequest", True)


def test_settable_is_only_for_outputs_that_drive_nothing(tmp_path):
    station = copy_rig(tmp_path, 'name = "diGripped"\ntype = "DI"\n', 'name = "diGripped"\ntype = "DI"\nsettable = true\n')
    with pytest.raises(StationError, match=r"controller\.io\[5\]\.settable"):
        open_cell(station)


def test_a_gripper_plc_that_does_not_answer_stops_the_cycle_with_a_clear_message():
    events = []
    with open_cell(STATIONS / "ring_rig_plc", on_event=events.append) as cell:  # no PLC connected
        cell.write("fullAutoRun", True)
        run_until(cell, lambda: not cell.read("rapid.running"), 40.0)
        printed = [e["text"] for e in events if e["type"] == "print"]
        assert printed[-1] == "The gripper PLC did not answer the finger preparation request within 30 s"
        assert cell.read("doCycleFault") and not cell.read("fullAutoRun") and not cell.read("doPrepare")
        assert cell.read("L2") == pytest.approx(0.35)  # nobody moved the fingers


STATION_DATA = """MODULE station_data(SYSMODULE)
  PERS tooldata tLong := [TRUE,[[0,0,450],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];
  PERS wobjdata wPallet := [FALSE,TRUE,"",[[1600,-800,150],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
ENDMODULE
"""
USES_STATION_DATA = """MODULE UsesData
  CONST robtarget pAbove := [[0,0,500],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS num height := 0;
  PROC main()
    TPReadNum height, "Height above the pallet?";
    MoveL Offs(pAbove, 0, 0, height), v1000, fine, tLong\\WObj:=wPallet;
  ENDPROC
ENDMODULE
"""


def test_a_station_controller_lists_several_modules_and_answers_its_dialogs(tmp_path):
    station = copy_rig(tmp_path)
    (station / "uses_data.mod").write_text(USES_STATION_DATA)
    (station / "station_data.sys").write_text(STATION_DATA)
    toml = station / "station.toml"
    toml.write_text(toml.read_text().replace('program = "ring_rig.mod"',
                                             'program = "uses_data.mod"\nmodules = ["station_data.sys"]\n'
                                             'answers = ["100"]')
                    .replace('entry = "Init"', 'entry = "main"'))
    with open_cell(station) as cell:
        run_until(cell, lambda: cell.controller.state == "completed", 20.0)
        # the answer raised the target 100 mm: the long tool's TCP 600 mm above the pallet's top, the flange 450 mm more
        assert cell.twin.tcp_pose().position == pytest.approx((1.6, -0.8, 0.15 + 0.6 + 0.1), abs=0.001)


def test_a_missing_module_of_the_station_controller_names_the_key(tmp_path):
    station = copy_rig(tmp_path, 'program = "ring_rig.mod"', 'program = "ring_rig.mod"\nmodules = ["nope.sys"]')
    with pytest.raises(StationError, match=r"controller\.modules\[0\]: file 'nope.sys' not found"):
        open_cell(station)


ZONES = """MODULE Zones
  PERS tooldata tLong := [TRUE,[[0,0,450],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];
  PERS wobjdata wPallet := [FALSE,TRUE,"",[[1600,-800,150],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  CONST robtarget pAbove := [[0,0,500],[0,1,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS robtarget pAt := [[0,0,0],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    MoveL pAbove, v1000, fine, tLong\\WObj:=wPallet;
    MoveL Offs(pAbove, 200, 0, 0), v200, {zone}, tLong\\WObj:=wPallet;
    pAt := CRobT(\\Tool:=tLong\\WObj:=wPallet);
    MoveL Offs(pAbove, 200, 200, 0), v200, fine, tLong\\WObj:=wPallet;
  ENDPROC
ENDMODULE
"""


@pytest.mark.parametrize("zone, low, high", [("z50", 200.0 - 75.0, 200.0 - 50.0), ("fine", 199.5, 200.5)])
def test_a_zone_lets_the_program_go_on_before_the_robot_reaches_the_point_and_fine_stops_at_it(tmp_path, zone,
                                                                                              low, high):
    station = copy_rig(tmp_path)
    (station / "zones.mod").write_text(ZONES.replace("{zone}", zone))
    toml = station / "station.toml"
    toml.write_text(toml.read_text().replace('program = "ring_rig.mod"', 'program = "zones.mod"')
                    .replace('entry = "Init"', 'entry = "main"'))
    with open_cell(station) as cell:
        run_until(cell, lambda: cell.controller.state == "completed", 30.0)
        at = cell.controller.interp.globals["pat"].value.fields["trans"]
        # the program read the robot's position on its way to x = 200 mm: "some time before" the corner path, as
        # the TCP reached z50's largest zone (pzone_ori, 75 mm) and not yet its 50 mm TCP zone; or at the point
        # for fine
        assert low <= float(at.fields["x"]) <= high
        assert cell.twin.tcp_pose().position[1] == pytest.approx(-0.8 + 0.2, abs=0.001)  # then on to the last point
