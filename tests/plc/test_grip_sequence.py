"""The grip sequence (the thesis's gripper PLC) in process, against real twin physics, scan by scan."""
import math

import pytest

from plc_client.grip_sequence import Fault, GripSequence, Phase
from plc_client.scan import ScanCycle, TwinIO
from tests.plc.conftest import BENCH, RING_FORCES, STATIONS, Bench, ring_sequence
from twin.core import Twin


def test_outside_grip_is_confirmed_when_every_finger_force_passes_the_threshold(bench):
    bench.request("grip_request")
    image = bench.wait(Phase.HELD, Phase.FAULT_MISSED)
    assert bench.plc.state.phase is Phase.HELD
    assert all(image[f] >= 200.0 for f in RING_FORCES)
    assert bench.out("gripped") and not bench.out("grip_fault")
    assert bench.twin.read("doGripped") and bench.twin.read("GrippedPart") == "ring"
    assert image["L2.actual"] == pytest.approx(320.0, abs=1.5)  # stopped on the ring's 320 mm outside
    bench.plc.run(seconds=1.0)  # held: the setpoints stay, the force stays
    assert bench.twin.read("doGripped") and all(bench.io.get(f) >= 100.0 for f in RING_FORCES)


def test_a_held_ring_stands_still_with_every_finger_force_steady_at_its_statics(bench):
    """Held for 1 s, the squeezed ring is at rest, so each finger presses as its drives' springs say: L2 and L3 are
    set more than their full-force error (1 mm) past the ring, so they press with their effort (URDF: 1500 N);
    finger 3 is the fine axis L5 riding on the carriage L4, two springs of 1500 N/mm in series, pressing with
    1500 N/mm / 2 times how far their setpoints together lie past the ring (up to the effort). No flicker."""
    bench.request("grip_request")
    bench.wait(Phase.HELD, Phase.FAULT_MISSED)
    bench.plc.run(seconds=0.2)  # the press settles
    t, effort, k = bench.twin, 1500.0, 1500.0 / 1.0  # N, N/mm (the effort at 1 mm of following error)
    ring = t.object_pose("ring")[0]
    for _ in range(25):
        bench.plc.run(seconds=0.04)
        finger3 = bench.io.get("L4.actual") + bench.io.get("L5.actual")  # its inner face's radius (mm)
        set3 = (t.read("L4") + t.read("L5")) * 1000.0  # the setpoints (m)
        expected = {"L2.force": effort, "L3.force": effort, "L5.force": min(effort, k / 2 * (finger3 - set3))}
        for name, want in expected.items():
            assert bench.io.get(name) == pytest.approx(want, rel=0.1), name
        assert t.read("doGripped")
    assert math.dist(t.object_pose("ring")[0], ring) < 0.0001  # still within 0.1 mm


def test_inside_grip_is_confirmed_by_force_in_the_bore(bench_inside):
    bench_inside.request("grip_request", inside=True)
    image = bench_inside.wait(Phase.HELD, Phase.FAULT_MISSED)
    assert bench_inside.plc.state.phase is Phase.HELD and bench_inside.out("gripped")
    assert image["L2.actual"] == pytest.approx(200.0, abs=1.5)  # 200 + 40 mm finger = the 240 mm bore
    assert bench_inside.twin.read("GrippedPart") == "ring"


@pytest.mark.parametrize("station, inside, end", [(BENCH, False, 290.0), (BENCH.with_name("ring_bench_inside"), True, 230.0)])
def test_missed_grip_raises_the_fault_and_the_fingers_stop_at_end_of_travel(station, inside, end):
    b = Bench(station, remove_ring=True)
    b.request("grip_request", inside=inside)
    b.wait(Phase.HELD, Phase.FAULT_MISSED)
    assert b.plc.state.phase is Phase.FAULT_MISSED and b.plc.state.fault is Fault.MISSED
    assert b.out("grip_fault") and not b.out("gripped") and not b.out("grip_busy")
    b.plc.run(seconds=1.0)  # nothing moves on: the fingers stay at the end of travel
    for axis in ("L2", "L3", "L4"):
        assert b.io.get(axis) == end and b.io.get(f"{axis}.actual") == pytest.approx(end, abs=0.5)
    assert b.out("grip_fault")  # until the robot asks again
    b.twin.close()


def test_release_opens_until_the_part_is_free_and_back_to_the_ready_position(bench):
    bench.request("grip_request")
    bench.wait(Phase.HELD)
    bench.request("release_request")
    bench.plc.scan()
    assert bench.out("gripped") and bench.out("grip_busy")  # gripped stays up until the part is free
    image = bench.wait(Phase.IDLE, Phase.FAULT_STUCK)
    assert bench.plc.state.phase is Phase.IDLE and not bench.out("gripped") and not bench.out("grip_fault")
    assert not bench.twin.read("doGripped")
    assert not any(image[c] for c in ("L2.contact", "L3.contact", "L5.contact"))
    assert all(image[f] < 20.0 for f in RING_FORCES)
    assert image["L2.actual"] >= 330.0 - 0.5  # opened at least to the ready position: the next grip can descend


def test_a_fault_is_cleared_by_the_next_request():
    b = Bench(BENCH, remove_ring=True)
    b.request("grip_request")
    b.wait(Phase.FAULT_MISSED)
    b.request("release_request")  # the robot opens the fingers for a new attempt
    b.wait(Phase.IDLE)
    assert not b.out("grip_fault") and b.io.get("L2.actual") == pytest.approx(330.0, abs=0.5)
    b.twin.close()


def test_the_same_grip_gives_the_same_result_on_every_run():
    def grip():
        b = Bench(BENCH)
        b.request("grip_request")
        image = b.wait(Phase.HELD)
        result = (b.plc.scans, dict(image), b.twin.object_pose("ring"))
        b.twin.close()
        return result

    assert grip() == grip()


def test_the_sequence_is_generic_four_fingers_close_on_the_puck():
    with Twin.from_station(STATIONS / "four_finger") as twin:
        fingers = ("F1", "F2", "F3", "F4")
        seq = GripSequence(axes=fingers, forces=tuple(f"{f}.force" for f in fingers), speed=20.0, threshold=10.0,
                           end_of_travel={"outside": 20.0, "inside": 100.0})
        io = TwinIO(twin, local=seq.handshake_signals())
        plc = ScanCycle(io, seq)
        io.set("grip_request", True)
        image = plc.run_until(lambda i, s: s.phase in (Phase.HELD, Phase.FAULT_MISSED), timeout=10.0)
        assert plc.state.phase is Phase.HELD and twin.read("GrippedPart") == "puck"
        assert all(image[f"{f}.actual"] == pytest.approx(40.0, abs=1.5) for f in fingers)  # the 40 mm radius


def test_with_fewer_forces_than_axes_all_axes_move_together_until_every_force_passes():
    seq = ring_sequence(axes=("L2", "L3", "L4"), forces=("L2.force",), contacts=None)
    assert seq.per_finger is False
    with pytest.raises(ValueError, match="one force per axis"):
        ring_sequence(forces=("L2.force",), per_finger=True)


def test_a_sequence_without_an_end_of_travel_is_refused():
    with pytest.raises(ValueError, match="end_of_travel"):
        GripSequence(axes=("L2",), forces=("L2.force",), end_of_travel={"outside": 290.0})


def test_a_prepare_request_moves_the_fingers_to_the_position_the_robot_asks_for():
    from plc_client.grip_sequence import Handshake

    seq = ring_sequence(handshake=Handshake(prepare_request="prepare", prepare_position="prepare_mm", state="grip_state"))
    b = Bench(BENCH, seq=seq)
    b.io.set("prepare_mm", 340.0)
    b.io.set("prepare", True)
    b.plc.scan()
    assert b.out("grip_busy") and b.out("grip_state") == Phase.PREPARING
    b.wait(Phase.IDLE)
    assert b.io.get("L2.actual") == pytest.approx(340.0, abs=0.5) and not b.out("grip_busy")
    b.twin.close()


def test_a_prepare_request_outside_the_travel_is_refused_with_a_fault_and_answered():
    from plc_client.grip_sequence import Handshake

    seq = ring_sequence(handshake=Handshake(prepare_request="prepare", prepare_position="prepare_mm", done="done",
                                            fault_code="code"))
    assert seq.travel == (0.0, 441.0)
    b = Bench(BENCH, seq=seq)
    b.plc.run(scans=3)
    writes_before = dict(b.plc.written)
    b.io.set("prepare_mm", 500.0)  # the robot asks for a position the axes cannot take
    b.io.set("prepare", True)
    b.plc.run(scans=5)  # no ValueOutOfRangeError from the process: nothing was sent
    assert b.plc.state.phase is Phase.IDLE and b.plc.state.fault is Fault.BAD_REQUEST == 3
    assert b.out("grip_fault") and b.out("code") == 3 and b.out("done") and not b.out("grip_busy")
    assert {k: v for k, v in b.plc.written.items() if k in ("L2", "L3", "L4")} == \
        {k: v for k, v in writes_before.items() if k in ("L2", "L3", "L4")}
    assert b.io.get("L2") == 330.0 and b.io.get("L2.actual") == pytest.approx(330.0, abs=0.5)
    b.io.set("prepare", False)  # the robot takes the request back: done falls, the fault stays
    b.plc.scan()
    assert not b.out("done") and b.out("grip_fault")
    b.io.set("prepare_mm", 340.0)  # a valid request clears it
    b.io.set("prepare", True)
    b.wait(Phase.IDLE)
    b.plc.scan()
    assert not b.out("grip_fault") and b.out("done") and b.io.get("L2.actual") == pytest.approx(340.0, abs=0.5)
    b.twin.close()


@pytest.mark.parametrize("travel", [(441.0, 0.0), (0.0, float("inf")), (1.0,), "far"])
def test_a_travel_that_is_not_low_high_is_refused(travel):
    with pytest.raises(ValueError, match="travel"):
        ring_sequence(travel=travel)


def test_without_travel_any_prepare_position_is_passed_on():
    seq = ring_sequence(travel=None)
    assert seq.within_travel(1e6) and not seq.within_travel(float("nan"))
