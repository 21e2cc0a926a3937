"""Every fault injection, with its effect in the physics and on the signals a PLC reads."""
import math

import pytest

from plc_client.link import LINK_OK, LinkFaults
from plc_client.scan import ScanCycle, TwinIO, plc_logic
from tests.conftest import ROOT, STATIONS
from twin.core import Twin
from twin.runtime.faults import (DriveForceLost, FaultError, FaultInjector, FingerJammed, PartDisplaced, PartMissing,
                         ReadingOffset, ReadingStuck, RobotStopped)

BENCH = ROOT / "tests" / "plc" / "stations" / "ring_bench"  # fingers at 330 mm around a ring of radius 320 mm
RING_START = (1.6, -0.8, 0.18)


@pytest.fixture
def bench():
    with Twin.from_station(BENCH) as twin:
        yield twin


def close_all(twin, to=0.300):
    for name in ("L2", "L3", "L4"):
        twin.write(name, to)


def joint_position(twin, name):
    inp = twin.mechanism.input(name)
    return twin.world.client.getJointState(twin.world.machine, twin.world.joint_index[inp.joint])[0]


def test_part_missing_takes_the_part_out_and_puts_it_back(bench):
    injector = FaultInjector.attach(bench, [PartMissing(at=0.12, duration=1.2, target="ring")])
    bench.step(5)
    assert bench.read("ring.present") and bench.object_pose("ring")[0][2] == pytest.approx(0.18, abs=0.002)
    bench.step(10)  # past 0.12 s
    assert not bench.read("ring.present")
    assert bench.object_pose("ring")[0][2] < -50  # physics: parked far below the cell
    close_all(bench)
    bench.step(90)  # fingers close on nothing: no contact, no force, down to the setpoint
    assert not any(bench.read(f"{f}.contact") for f in ("L2", "L3", "L5"))
    assert bench.read("L2.actual") == pytest.approx(0.300, abs=0.001) and bench.read("L2.force") < 5.0
    close_all(bench, 0.33)
    bench.step(40)  # the fault ends at 1.32 s: the ring is back where the station placed it, at rest
    assert bench.time > 1.32
    assert bench.read("ring.present")
    assert bench.object_pose("ring")[0] == pytest.approx(RING_START, abs=0.002)
    assert [text for _, text in injector.log] == ["PartMissing ring: started", "PartMissing ring: ended"]


def test_part_displaced_moves_the_part_at_its_time(bench):
    FaultInjector.attach(bench, [PartDisplaced(at=0.24, target="ring", offset=(0.004, -0.003, 0.0), yaw_deg=30.0)])
    bench.step(20)
    assert bench.read("ring.x") == pytest.approx(1.6, abs=1e-4)
    bench.step(2)
    (x, y, _), orn = bench.object_pose("ring")
    assert (x, y) == pytest.approx((1.604, -0.803), abs=2e-4)  # physics
    assert bench.read("ring.x") == pytest.approx(1.604, abs=2e-4)  # signals
    yaw = bench.world.client.getEulerFromQuaternion(orn)[2]
    assert math.degrees(yaw) == pytest.approx(30.0, abs=0.5)  # (a 12-sided ring turned by one face)
    bench.step(50)  # at rest on its pallet: it stays there
    assert bench.read("ring.x") == pytest.approx(1.604, abs=5e-4)


def test_a_jammed_finger_stops_at_its_position_and_presses_on(bench):
    FaultInjector.attach(bench, [FingerJammed(input="L2", position=0.326)])
    bench.write("L2", 0.300)  # only L2 closes: the jam is 6 mm before the ring (at 320 mm)
    bench.step(150)
    assert joint_position(bench, "L2") == pytest.approx(0.326, abs=0.0005)  # physics: stopped at the jam
    # signals: it stands there touching nothing, yet its servo force builds as against a part
    assert bench.read("L2.actual") == pytest.approx(0.326, abs=0.0005)
    assert not bench.read("L2.contact")
    _, effort = bench.drive_limits("L2")
    assert -bench.read("L2.effort") == pytest.approx(effort, rel=0.05)  # the drive presses on the stop...
    assert bench.read("L2.force") == 0.0  # ...but on no part: the measured finger force stays 0
    bench.write("L2", 0.34)  # stuck: it does not open either
    bench.step(60)
    assert bench.read("L2.actual") == pytest.approx(0.326, abs=0.0005)


def test_a_jam_further_out_lets_the_finger_move_until_it_gets_there(bench):
    FaultInjector.attach(bench, [FingerJammed(input="L3", position=0.310, at=0.0)])
    close_all(bench)
    bench.step(150)
    # L3 closes freely onto the ring (the jam is beyond it): a grip as usual
    assert bench.read("L3.contact") and bench.read("doGripped")


def test_a_finger_that_loses_force_does_not_squeeze(bench):
    with Twin.from_station(BENCH) as healthy:
        FaultInjector.attach(bench, [DriveForceLost(input="L3", effort=20.0)])
        for twin in (bench, healthy):
            close_all(twin)
            twin.step(150)
        _, full = healthy.drive_limits("L3")
        assert healthy.read("L3.force") == pytest.approx(full, rel=0.05)
        # signals: its force stays at the lost drive's (pushed back by the ring, it balances it with its motor's 20 N,
        # not the 1500 N the other drives press with). The contact force, averaged over the step's substeps, jitters
        # about the 20 N as the finger rocks against the ring: within 0.05 % from step 100 on (0.17 % when the drive
        # was first held to its velocity limit), so 0.5 % above the motor's limit is all a reading may show
        assert bench.read("L3.force") <= 20.0 * 1.005
        assert bench.read("L3.force") == pytest.approx(20.0, rel=0.1)
        assert bench.drive_limits("L3")[1] == 20.0  # physics: the motor pushes with 20 N at most


def test_a_stuck_force_reading_hides_the_real_force(bench):
    with Twin.from_station(BENCH) as healthy:
        FaultInjector.attach(bench, [ReadingStuck(at=0.0, signal="L5.force", value=0.0)])
        for twin in (bench, healthy):
            close_all(twin)
            twin.step(150)
        assert bench.read("L5.force") == 0.0  # the reading
        assert bench.finger_forces()["L5"] == pytest.approx(healthy.read("L5.force"), rel=1e-9)  # the real force
        assert bench.finger_forces()["L5"] > 500.0
        # only the reading: the physics is the healthy twin's, bit for bit
        assert bench.object_pose("ring") == healthy.object_pose("ring")
        assert bench.read("L2.actual") == healthy.read("L2.actual")


def test_a_reading_stuck_at_its_value_keeps_it(bench):
    FaultInjector.attach(bench, [ReadingStuck(at=0.24, signal="L2.actual")])
    bench.step(20)
    frozen = bench.read("L2.actual")
    close_all(bench)
    bench.step(100)
    assert bench.read("L2.actual") == frozen  # the reading froze at 0.24 s
    assert joint_position(bench, "L2") == pytest.approx(0.320, abs=0.003)  # the finger did move


def test_an_offset_force_reading(bench):
    FaultInjector.attach(bench, [ReadingOffset(at=0.0, duration=0.6, signal="L2.force", offset=75.0)])
    bench.step(10)
    assert bench.finger_forces()["L2"] < 1.0
    assert bench.read("L2.force") == pytest.approx(bench.finger_forces()["L2"] + 75.0)
    bench.step(50)  # past 0.6 s: the reading is true again
    assert bench.read("L2.force") == bench.finger_forces()["L2"]


def test_faults_that_do_not_fit_the_station_are_refused(bench):
    for fault, words in ((PartMissing(target="puck"), "no target 'puck'"),
                         (FingerJammed(input="L9"), "no gripper input 'L9'"),
                         (FingerJammed(input="L2", position=2.0), "outside the joint's range"),
                         (ReadingStuck(signal="L2"), "is an input"),
                         (ReadingOffset(signal="doGripped", offset=1.0), "not a number"),
                         (RobotStopped(), "has no robot"),
                         (PartMissing(at=-1.0, target="ring"), "'at' must be")):
        with pytest.raises(FaultError, match=words):
            FaultInjector.attach(bench, [fault])


def test_a_stopped_robot_holds_and_its_motion_waits():
    with Twin.from_station(STATIONS / "ring_rig") as twin, Twin.from_station(STATIONS / "ring_rig") as free:
        FaultInjector.attach(twin, [RobotStopped(at=0.36, duration=1.2)])
        for t in (twin, free):
            t.move("MoveJ", t.target("app_right") if "app_right" in t.station.robot_targets else next(iter(t.station.robot_targets)), 1.0)
        twin.step(31)
        free.step(31)
        held = [twin.read(f"robot.j{i}") for i in range(1, 7)]
        twin.step(80)  # 0.96 s into the stop
        # physics and signals: the arm stands (within the servo's settling) while the free one goes on
        assert [twin.read(f"robot.j{i}") for i in range(1, 7)] == pytest.approx(held, abs=0.01)
        assert twin.read("robot.busy")
        free.step(80)
        assert max(abs(a - b) for a, b in zip([free.read(f"robot.j{i}") for i in range(1, 7)], held)) > 0.05
        # after the stop the motion goes on to its target, and ends
        for _ in range(2000):
            if not twin.read("robot.busy"):
                break
            twin.step()
        while free.read("robot.busy"):
            free.step()
        assert not twin.read("robot.busy")
        assert [twin.read(f"robot.j{i}") for i in range(1, 7)] == pytest.approx(
            [free.read(f"robot.j{i}") for i in range(1, 7)], abs=2e-3)


# -- the link ------------------------------------------------------------------------------------------
@plc_logic(inputs=["L2.actual", LINK_OK])
def ramp(inputs, state):
    """Close L2 at 20 mm/s from 330 mm, every scan (the PLC's own count of time)."""
    return {"L2": max(300.0, 330.0 - 20.0 * inputs.time)}


@plc_logic(inputs=["L2.actual", LINK_OK])
def steps(inputs, state):
    """L2 to 330 mm, to 300 mm at 0.25 s, to 315 mm at 0.5 s."""
    return {"L2": 330.0 if inputs.time < 0.25 else 300.0 if inputs.time < 0.5 else 315.0}


def test_a_lost_link_freezes_the_plc_inputs_and_holds_its_outputs(bench):
    link = LinkFaults(TwinIO(bench), lost=[(0.3, 0.8)])
    plc = ScanCycle(link, steps, cycle=0.012)
    seen = []
    for _ in range(90):  # 1.08 s
        image = plc.scan()
        seen.append((image.time, image["L2.actual"], image[LINK_OK], bench.read("L2") * 1000, bench.read("L2.actual") * 1000))
    during = [s for s in seen if 0.3 + 0.013 <= s[0] < 0.8 - 0.013]  # (a scan reads, then writes, then advances)
    assert during and not any(s[2] for s in during)  # the PLC sees its link down
    assert len({s[1] for s in during}) == 1  # its input image froze ...
    assert during[-1][4] < during[0][1] - 5.0  # ... while the finger moved on in the physics
    assert all(s[3] == pytest.approx(300.0) for s in during)  # its 315 mm from 0.5 s on never arrived meanwhile
    after = seen[-1]
    assert after[2] and after[3] == pytest.approx(315.0)  # back: the latest output is written at once
    assert link.dropped_writes >= 1 and link.dropped_reads >= 30


def test_a_link_lost_from_the_start_reads_the_process_once():
    with Twin.from_station(BENCH) as twin:
        link = LinkFaults(TwinIO(twin), lost=[(0.0, 0.5)])
        image = ScanCycle(link, steps, cycle=0.012).scan()
        assert image["L2.actual"] == pytest.approx(330.0) and not image[LINK_OK]


def test_latency_delays_what_the_plc_reads_and_jitter_is_seeded(bench):
    link = LinkFaults(TwinIO(bench), latency=0.048)
    plc = ScanCycle(link, ramp, cycle=0.012)
    truth, seen = {}, {}
    for _ in range(60):
        t = round(plc.time, 6)
        truth[t] = bench.read("L2.actual") * 1000  # the process when the scan starts
        seen[t] = plc.scan()["L2.actual"]
    # the PLC reads at t what the process was at t - 48 ms (4 scans)
    for t in list(seen)[6:]:
        assert seen[t] == truth[round(t - 0.048, 6)]
    # and its writes reach the process 48 ms late: the setpoint trails the PLC's ramp by 4 scans
    assert bench.read("L2") * 1000 == pytest.approx(330.0 - 20.0 * (plc.time - 0.048), abs=1e-6)

    def jittered(seed):
        with Twin.from_station(BENCH) as twin:
            link = LinkFaults(TwinIO(twin), latency=0.012, jitter=0.036, seed=seed)
            plc = ScanCycle(link, ramp, cycle=0.012)
            return [plc.scan()["L2.actual"] for _ in range(50)]

    a, b, c = jittered(1), jittered(1), jittered(2)
    assert a == b and a != c
