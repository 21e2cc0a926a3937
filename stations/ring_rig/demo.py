"""The ring rig's demo through the simulation API (`twin demo`, named in station.toml's [plugins]): grip,
lift and place the ring.

It plays the thesis's sequence with Python in place of RAPID: approach, fingers to 330 mm, down,
close 1 mm every 200 ms until `doGripped`, lift, carry to the other pallet, put down, open 1 mm every
200 ms until released, retract. Then the same with an inside grip back to the first pallet. It prints
each step in simulated time and, at the end, how far the ring ended from where it should be.
"""
from __future__ import annotations

import math
import time
from pathlib import Path

from twin.core.errors import StationError
from twin.core.station import Station, gripper_mechanism, load_station

FINGERS = ("L2", "L3", "L4")
STEP_MM = 0.001  # the thesis's 1 mm per increment
INCREMENT_TIME = 0.2  # s between increments


class Script:
    def __init__(self, twin):
        self.twin = twin

    def say(self, text: str) -> None:
        print(f"[t={self.twin.time:7.3f} s] {text}", flush=True)

    def move(self, instr: str, target: str, speed: float) -> None:
        self.twin.run_motion(instr, target, speed)
        self.say(f"{instr} {target} done")

    def set_fingers(self, value: float) -> None:
        for name in FINGERS:
            self.twin.write(name, value)

    def fingers_to(self, value: float, settle: float = 1.5) -> None:
        self.set_fingers(value)
        self.twin.step(round(settle / self.twin.dt))
        self.say(f"fingers at {value * 1000:.0f} mm")

    def step_fingers_until(self, direction: int, want_gripped: bool, limit: float) -> float:
        """Move the fingers 1 mm per 200 ms (as the thesis's Rapid) until doGripped == want_gripped."""
        twin = self.twin
        value = twin.read(FINGERS[0])
        while twin.read("doGripped") != want_gripped:
            nxt = value + direction * STEP_MM
            if not (0.0 <= nxt <= limit if direction > 0 else nxt >= limit):
                break
            value = nxt
            self.set_fingers(value)
            twin.step(round(INCREMENT_TIME / twin.dt))
        return value

    def grip(self, inside: bool) -> bool:
        value = self.step_fingers_until(+1 if inside else -1, True, 0.441 if inside else 0.0)
        ok = self.twin.read("doGripped")
        forces = ", ".join(f"{k} {v:.0f} N" for k, v in self.twin.finger_forces().items())
        self.say(f"{'gripped ' + self.twin.read('GrippedPart') if ok else 'MISSED'} from the {'inside' if inside else 'outside'}"
                 f" at {value * 1000:.0f} mm (finger forces: {forces})")
        return ok

    def carry(self, pick: str, place: str, inside: bool, ready: float) -> bool:
        """Half a cycle from above the `pick` pallet: fingers ready, down, grip, up, over to the `place` pallet,
        down, release, up. True when the grip held."""
        self.fingers_to(ready)
        self.move("MoveL", f"grip_{pick}", 0.5)
        gripped = self.grip(inside)
        self.move("MoveL", f"app_{pick}", 0.5)
        self.move("MoveJ", f"app_{place}", 2.0)
        self.move("MoveL", f"grip_{place}", 0.5)
        self.release(inside)
        self.move("MoveL", f"app_{place}", 0.5)
        return gripped

    def release(self, inside: bool) -> None:
        value = self.step_fingers_until(-1 if inside else +1, False, 0.0 if inside else 0.441)
        self.say(f"released at {value * 1000:.0f} mm")


ROBOT_TARGETS = ("app_right", "grip_right", "app_left", "grip_left")


def check_ring_rig(station: Station) -> None:
    """This script plays the ring rig only; any other station would fail half-way with a KeyError."""
    missing = []
    if station.robot is None:
        missing.append("a robot")
    if "ring" not in {t.name for t in station.targets}:
        missing.append("a target named ring")
    targets = [t for t in ROBOT_TARGETS if t not in station.robot_targets]
    if targets:
        missing.append("robot targets " + ", ".join(targets))
    have = {i.name for i in gripper_mechanism(station).inputs}
    inputs = [name for name in FINGERS if name not in have]
    if inputs:
        missing.append("gripper inputs " + ", ".join(inputs))
    if missing:
        raise StationError(str(station.file), "", "twin demo plays the ring rig (stations/ring_rig) and needs "
                           + "; ".join(missing) + " (the cell's main demo is `plc demo`)")


def run_demo(station: str | Path, cycles: int = 1) -> int:
    wall0 = time.perf_counter()
    st = load_station(station)
    check_ring_rig(st)
    from twin.core.twin import Twin  # after the check: importing pybullet prints a banner

    with Twin(st) as twin:
        s = Script(twin)
        s.say(f"station {twin.station.name}: inputs {', '.join(i.name for i in twin.mechanism.inputs)}, "
              f"fingers {', '.join(f.name for f in twin.mechanism.fingers)}")
        start = twin.object_pose("ring")[0]
        misses = 0
        for cycle in range(1, cycles + 1):
            s.say(f"cycle {cycle}: pick from outside on the right pallet")
            s.move("MoveJ", "app_right", 2.0)
            misses += not s.carry("right", "left", inside=False, ready=0.330)
            s.say(f"cycle {cycle}: pick from inside on the left pallet")
            misses += not s.carry("left", "right", inside=True, ready=0.150)
        end = twin.object_pose("ring")[0]
        error = math.dist(start, end)
        print(f"summary: {cycles} cycle(s), {2 * cycles - misses} grips, {misses} misses, "
              f"{twin.time:.1f} s simulated in {time.perf_counter() - wall0:.1f} s wall; "
              f"the ring ended {error * 1000:.1f} mm from its start "
              f"({end[0]:.4f}, {end[1]:.4f}, {end[2]:.4f})")
        return 0 if misses == 0 and error < 0.005 else 1


def add_arguments(parser) -> None:
    """`twin demo [STATION] [--cycles N]`: the options this demo adds to the command."""
    parser.description = __doc__.split("\n\n")[0]
    parser.add_argument("--cycles", type=int, default=1, help="how many full cycles to run")


def main(args) -> int:
    return run_demo(args.station, cycles=args.cycles)
