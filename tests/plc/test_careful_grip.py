"""The ring rig's careful grip sequence (`stations.ring_rig_plc.plc_logic.CarefulGripSequence`) in process,
against real twin physics on the ring bench, scan by scan: what it must not take for a finger fault (a slow
drive, inputs that stand still while the link is lost) and the faults it declares on its own clock (a grip
that takes too long, a ring that goes away while held). Reference values come from the bench's geometry
and the speeds set, not from the sequence."""
import pytest

from plc_client.grip_sequence import Fault, Phase
from plc_client.link import LinkFaults
from plc_client.scan import ScanCycle
from tests.plc.conftest import BENCH, RING_FORCES, Bench, ring_sequence
from twin.runtime.faults import DriveForceLost, FaultInjector, FingerJammed, ReadingStuck


def test_a_slow_drive_is_waited_for_not_taken_for_a_fault(bench):
    for axis in ("L2", "L3", "L4"):
        bench.twin.set_drive_limits(axis, velocity=0.005)  # 5 mm/s, a quarter of the PLC's 20 mm/s ramp
    bench.request("grip_request")
    image = bench.wait(Phase.HELD, Phase.FAULT_MISSED, timeout=10.0)
    assert bench.plc.state.phase is Phase.HELD and bench.plc.state.fault is Fault.NONE
    assert all(image[f] >= 200.0 for f in RING_FORCES)
    # from 330 mm to the ring's 320 mm radius at the drives' 5 mm/s, not the ramp's 20 mm/s: 2 s
    assert image.time == pytest.approx(10.0 / 5.0, abs=0.2)


def test_a_finger_that_follows_at_a_crawl_is_not_following():
    b = Bench(BENCH)
    b.twin.set_drive_limits("L3", velocity=0.002)  # 2 mm/s: a tenth of the ramp, below the 4 mm/s it accepts
    b.request("grip_request")
    b.wait(Phase.HELD, Phase.FAULT_MISSED)
    st = b.plc.state
    assert st.phase is Phase.FAULT_MISSED and st.fault in (Fault.DRIVE_LOST, Fault.JAMMED) and st.fault_axis == "L3"
    assert b.out("grip_fault") and not b.out("gripped")
    b.twin.close()


def test_inputs_that_stand_still_while_the_link_is_lost_are_no_finger_fault():
    """The link drops for 0.5 s while the fingers close (0.1 s into the grip): the PLC sees link.ok fall, its
    ramps and timers wait, and the grip is confirmed once the link is back. A PLC that cannot see its link
    would take the frozen positions for fingers that do not move."""
    outcomes = {}
    for sees_link in (True, False):
        b = Bench(BENCH, seq=ring_sequence(link_ok="link.ok" if sees_link else None))
        b.io = LinkFaults(b.io, lost=[(0.1, 0.6)])
        b.plc = ScanCycle(b.io, b.seq)
        b.request("grip_request")
        b.wait(Phase.HELD, Phase.FAULT_MISSED, timeout=5.0)
        outcomes[sees_link] = (b.plc.state.phase, b.plc.state.fault)
        b.twin.close()
    assert outcomes[True] == (Phase.HELD, Fault.NONE)
    assert outcomes[False][0] is Phase.FAULT_MISSED and outcomes[False][1] in (Fault.JAMMED, Fault.DRIVE_LOST)


def test_a_grip_that_takes_longer_than_its_time_is_a_fault_and_the_fingers_stop():
    b = Bench(BENCH, seq=ring_sequence(grip_time=0.2))  # less than the 0.5 s from 330 mm to the ring at 20 mm/s
    b.request("grip_request")
    image = b.wait(Phase.HELD, Phase.FAULT_MISSED)
    assert b.plc.state.fault is Fault.TIMEOUT and b.out("grip_fault") and not b.out("gripped")
    # 0.2 s at 20 mm/s from 330 mm: the fingers were near 326 mm, well short of the ring, and stay there
    assert image["L2.actual"] == pytest.approx(326.0, abs=0.6)
    b.plc.run(seconds=0.5)
    for axis in ("L2", "L3", "L4"):
        assert b.io.get(f"{axis}.actual") == pytest.approx(image[f"{axis}.actual"], abs=0.3)
    assert b.twin.read("L2.force") == 0.0
    b.twin.close()


def test_a_held_ring_whose_finger_lets_go_is_no_longer_reported_held(bench):
    bench.request("grip_request")
    bench.wait(Phase.HELD, Phase.FAULT_MISSED)
    assert bench.out("gripped")
    t0 = bench.plc.time
    FaultInjector.attach(bench.twin, [DriveForceLost(bench.twin.time, input="L3", effort=0.0)])
    image = bench.plc.run_until(lambda i, s: s.phase is not Phase.HELD, timeout=2.0)
    st = bench.plc.state
    assert st.fault is Fault.LOST and not bench.out("gripped") and bench.out("grip_fault")
    assert image["L3.force"] < 100.0  # the physics: the ring no longer presses on the finger that let go
    assert image.time - t0 < 0.5  # within the hold time of the force going away (0.1 s) and a few scans


def test_a_jam_on_the_bench_is_named_with_its_finger_and_the_ring_stays_put(bench):
    start = bench.twin.object_pose("ring")[0]
    FaultInjector.attach(bench.twin, [FingerJammed(input="L4", position=0.326)])  # 6 mm short of the ring
    bench.request("grip_request")
    bench.wait(Phase.HELD, Phase.FAULT_MISSED)
    st = bench.plc.state
    assert st.phase is Phase.FAULT_MISSED and (st.fault, st.fault_axis) == (Fault.JAMMED, "L4")
    assert bench.io.get("L4.actual") == pytest.approx(326.0, abs=0.3)
    end = bench.twin.object_pose("ring")[0]
    assert sum((a - b) ** 2 for a, b in zip(start, end)) ** 0.5 < 0.002  # m: the ring was not pushed into the jam


def test_a_force_reading_stuck_at_zero_never_confirms_and_names_the_sensor(bench):
    FaultInjector.attach(bench.twin, [ReadingStuck(signal="L3.force", value=0.0)])
    bench.request("grip_request")
    pressed = []  # finger 2's true force at every scan (the PLC lets go within the scan that names the fault)
    image = bench.plc.run_until(lambda image, state: pressed.append(bench.twin.finger_forces()["L3"])
                                or state.phase in (Phase.HELD, Phase.FAULT_MISSED), timeout=10.0)
    st = bench.plc.state
    assert st.phase is Phase.FAULT_MISSED and (st.fault, st.fault_axis) == (Fault.FORCE_READING, "L3")
    # the physics: finger 2 does press on the ring (its true force), only its reading says 0 N
    assert image["L3.contact"] and image["L3.force"] == 0.0
    assert max(pressed) >= 200.0
