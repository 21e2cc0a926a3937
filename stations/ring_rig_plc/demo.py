"""The main job: the ring rig's full automatic cycle with its gripper PLC on the other side of the network.
(This station's `plc demo`, named in its station.toml's [plugins]; `python3 tasks.py demo` runs it.)

    plc demo [--plc st|python] [--cycles N] [--realtime [--speed X]] [--remove-ring CYCLE] [--faults FILE] [--station DIR]

It starts `twin serve` for `stations/ring_rig_plc` as a subprocess (the twin and its RAPID robot
controller), connects a scan-cycle PLC to it over Modbus/TCP, and runs as the cell's operator: it sets
`fullAutoRun` and takes it back once the last cycle has started. In every cycle the robot picks the ring
from outside on the right pallet, places it on the left, picks it from inside there and places it back
on the right. Each grip, release and finger move is a request of the robot program to the PLC, which
drives the finger setpoints over the network and confirms a grip only when every finger's force has
passed the threshold; fingers that reach the end of travel without it are a missed grip, reported to
the robot, which tries once more and then stops the cycle.

It prints each step as it happens, the robot's TPWrite lines (from the server's events, docs/events.md) and the
PLC's view, both stamped with simulated time, then a summary: cycles, grips, misses, cycle time in
simulated and in wall seconds, and how far the ring ends from where it started. `--remove-ring K`
takes the ring out of the cell (coil `ring.present`) when cycle K starts: the miss is detected and
reported, never hidden: the summary says whether the injected miss was detected and the robot stopped.
`--faults FILE` gives the served twin plant faults (`twin serve --faults`: `[faults.NAME]` tables as in a
campaign, e.g. a finger jammed or its drive lost): the summary says which faults the PLC reported.

Exit status: 0 when every cycle was done and the ring is back within 5 mm of where it started; with
--remove-ring, 0 when the injected miss was detected and the robot stopped the cycle; with --faults, 0
when the cycles were done as without it, or the PLC reported a fault and the robot stopped the cycle; 1 otherwise;
2 for bad arguments or a station the demo cannot run.

The gripper PLC is `gripper.st` (the default, `--plc st`: Structured Text in the project's ST runtime, its
located variables bound through the twin's PLC layout, `twin serve --layout plc`, as on a real Modbus master
PLC) or `plc_logic.py` (`--plc python`); both run the same careful grip sequence.

Lockstep (the default): the PLC advances the twin one scan at a time, so the run is repeatable to the
bit and runs as fast as the machine allows. `--realtime`: the twin runs against the wall clock (at
`--speed` times real time) and the PLC scans on its own clock, as a real PLC would.
"""
from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from plc_client.client import ClientIO
from plc_client.errors import PlcClientError
from plc_client.grip_sequence import INSIDE, Fault, Phase
from plc_client.scan import Combined, ScanCycle, plc_logic
from twin.core.native_output import quiet_native_output

from stations.ring_rig_plc import plc_logic as ring_rig

# plc_client.testing (twin_server) is imported where the demo starts the server, not here: importing it
# early keeps pytest from rewriting it when a test suite loads it as a plugin (PytestAssertRewriteWarning).

DEFAULT_STATION = Path(__file__).resolve().parent
ST_FILES = ("gripper.st", "io.st")  # the ST gripper PLC and its generated declarations, beside this file
PLCS = ("st", "python")
CYCLE_LIMIT_S = 120.0  # simulated seconds one cycle may take before the demo gives up
RING_OK_MM = 5.0  # a cycle puts the ring back within this of where it started


class DemoError(PlcClientError):
    """The demo cannot run (a station that is not such a cell, bad parameters): one line, exit status 2."""


WATCH = ("goCycle", "goCyclesDone", "goMisses", "doCycleFault", "sim.time_ms", "ring.x", "ring.y", "ring.z",
         "ring.present", "L2.actual", "L3.actual", "L4.actual", "doGripInside", "aoFingerReady")


def operator(cycles: int, remove_ring_at: int | None = None):
    """The cell's operator as PLC logic: full automatic run until `cycles` have started; optionally the
    ring is taken out of the cell when cycle `remove_ring_at` starts (a missing part)."""

    @plc_logic(inputs=["goCycle"])
    def run_cycles(inputs, state):
        started = int(inputs["goCycle"])
        out = {"fullAutoRun": started < cycles}
        if remove_ring_at is not None:
            out["ring.present"] = started < remove_ring_at
        return out

    return run_cycles


@dataclass
class Summary:
    cycles_wanted: int
    cycles_done: int = 0
    grips: int = 0
    misses: int = 0
    stopped: bool = False  # the robot stopped the cycle (doCycleFault)
    sim_time: float = 0.0
    wall_time: float = 0.0
    cycle_sim: list[float] = field(default_factory=list)
    cycle_wall: list[float] = field(default_factory=list)
    ring_error_mm: float | None = None  # None: the ring is not in the cell
    ring_end: tuple[float, float, float] | None = None
    remove_ring_at: int | None = None  # --remove-ring: the cycle at whose start the ring is taken away
    ring_removed: bool = False  # ... and it was (cycle `remove_ring_at` started)
    misses_after_removal: int = 0  # misses the PLC detected once the ring was gone
    faults: str | None = None  # --faults: the faults file the served twin meets
    plc_faults: list[str] = field(default_factory=list)  # the faults the PLC reported, in order (names)

    @property
    def ok(self) -> bool:
        return self.cycles_done == self.cycles_wanted and self.ring_error_mm is not None and self.ring_error_mm < RING_OK_MM

    @property
    def fault_detected(self) -> bool:
        """--remove-ring: the injected miss was detected by the PLC and the robot stopped the cycle."""
        return self.ring_removed and self.misses_after_removal > 0 and self.stopped

    @property
    def exit_status(self) -> int:
        if self.remove_ring_at is not None:
            return 0 if self.fault_detected else 1
        if self.faults is not None and self.stopped and self.plc_faults:
            return 0  # the injected fault was reported by the PLC and the robot stopped
        return 0 if self.ok else 1


def _process_cpu(pid: int) -> float:
    """CPU seconds (user + system) a process has used so far; 0 where /proc is not there."""
    try:
        fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return 0.0


class CellDemo:
    """Runs the cell and narrates it; `run()` returns the `Summary`."""

    def __init__(self, station: str | Path = DEFAULT_STATION, cycles: int = 1, *, realtime: bool = False,
                 speed: float = 1.0, remove_ring_at: int | None = None, scan_cycle: float = 0.010,
                 out: Callable[[str], None] | None = None, record: str | Path | None = None,
                 faults: str | Path | None = None, plc: str = "python"):
        if cycles < 1:
            raise ValueError("at least one cycle")
        if not (speed > 0 and scan_cycle > 0):
            raise ValueError("speed and scan cycle must be greater than 0")
        if remove_ring_at is not None and not 1 <= remove_ring_at <= cycles:
            raise ValueError(f"the ring can be taken away at the start of cycle 1 to {cycles}, not {remove_ring_at}")
        self.station, self.cycles, self.realtime, self.speed = Path(station), cycles, realtime, speed
        self.remove_ring_at, self.scan_cycle = remove_ring_at, scan_cycle
        self.out = out or (lambda line: print(line, flush=True))
        self.now = 0.0  # simulated s, as last read from the server
        self.scans = 0  # PLC scans of the last run
        self.requests = 0  # Modbus requests the PLC sent in the last run
        if plc not in PLCS:
            raise ValueError(f"the gripper PLC is one of {', '.join(PLCS)}, not {plc!r}")
        self.plc = plc
        self.grip = ring_rig.cell_sequence()  # the gripper PLC (--plc python), and the numbers the narration uses
        self.record = record  # twin serve --record FILE: every signal and body pose at every step
        self.faults = None if faults is None else Path(faults)  # twin serve --faults FILE: plant faults

    def say(self, who: str, text: str, t: float | None = None) -> None:
        """A narration line stamped with simulated time: `t` (the robot's own, from the server's events), else now."""
        self.out(f"[t={self.now if t is None else t:8.3f} s] {who}: {text}")

    def run(self) -> Summary:
        """Run the cell; a `DemoError` (or another `PlcClientError`) when it cannot."""
        with quiet_native_output(stderr=True):  # pybullet's banner on import: an error must stay one line
            from twin.core.errors import TwinError
            from twin.core.station import load_station

            from plc_client.testing import twin_server
            try:
                station = load_station(self.station)
            except TwinError as exc:
                station, error = None, str(exc)
        if station is None:
            raise DemoError(error)
        ring = next((t for t in station.targets if t.name == "ring"), None)
        if ring is None:
            raise DemoError(f"{self.station}: the demo needs a target 'ring' (its cell is stations/ring_rig_plc)")
        start_xyz = ring.pose.xyz
        mode = "lockstep: the PLC steps the twin" if not self.realtime else f"real time x{self.speed:g}"
        self.out(f"demo: {self.station.name}, {self.cycles} cycle(s), {mode}, PLC scan {self.scan_cycle * 1000:g} ms")
        if self.plc == "st":
            self.out(f"demo: the gripper PLC is {' + '.join(ST_FILES)} (Structured Text, located variables on the "
                     "twin's PLC layout; --plc python runs plc_logic.py)")
        else:
            self.out("demo: the gripper PLC is plc_logic.py (Python; --plc st runs gripper.st)")
        extra = ["--record", str(self.record)] if self.record is not None else []
        if self.faults is not None:
            self.out(f"demo: the twin meets the faults of {self.faults}")
        with twin_server(self.station, lockstep=not self.realtime, speed=None if not self.realtime else self.speed,
                         extra_args=extra, faults=self.faults, layout="plc" if self.plc == "st" else "") as server:
            logic = Combined(self._gripper_plc(server.map), operator(self.cycles, self.remove_ring_at))
            missing = [n for n in dict.fromkeys((*logic.inputs, *logic.outputs, *WATCH)) if n not in server.map]
            if missing:
                raise DemoError(f"{self.station}: not a cell the demo can run: it has no {', '.join(missing)} "
                                "(the demo runs stations/ring_rig_plc)")
            self.out(f"demo: twin serve (pid {server.process.pid}) listens on {server.host}:{server.port}; "
                     "the gripper PLC connects over Modbus/TCP")
            with server.client() as client:
                return self._run(server, client, start_xyz, logic)

    def _gripper_plc(self, rmap):
        """The gripper PLC's logic: the Python sequence, or gripper.st bound through the map's PLC layout."""
        if self.plc == "python":
            return self.grip
        from plc_client.st_io import StLogic

        logic = StLogic([DEFAULT_STATION / f for f in ST_FILES], rmap)
        probe = logic.initial_state()
        get = lambda n: float(probe.get(f"{logic.instance}.{n}"))  # noqa: E731
        self.grip = StNumbers(speed=get("SPEED"), threshold=get("THRESHOLD"), travel=(get("TRAVEL_LOW"), get("TRAVEL_HIGH")))
        return logic

    def _run(self, server, client, start_xyz, logic) -> Summary:
        plc = ScanCycle(ClientIO(client, lockstep=not self.realtime), logic, cycle=self.scan_cycle,
                        inputs=tuple(dict.fromkeys((*logic.inputs, *WATCH))), speed=self.speed if self.realtime else 1.0)
        grip_state = plc.state[0] if self.plc == "python" else StGripView(logic.logics[0], plc.state[0])
        events = server.events  # written as they happen: a scan's answer comes after its steps' events
        s = Summary(self.cycles, remove_ring_at=self.remove_ring_at, faults=None if self.faults is None else str(self.faults))
        cpu0 = (time.process_time(), _process_cpu(server.process.pid))
        wall0 = time.perf_counter()
        cycle_started: tuple[float, float] | None = None
        seen = {"cycle": 0, "done": 0, "phase": Phase.IDLE, "fault": Fault.NONE}
        limit = CYCLE_LIMIT_S * self.cycles
        while True:
            image = plc.scan()
            self.now = image["sim.time_ms"] / 1000.0
            for t, line in robot_lines(events.new()):
                self.say("robot", line, t)
            phase = grip_state.phase
            if phase != seen["phase"]:
                self._narrate_grip(seen["phase"], grip_state, image, s)
                seen["phase"] = phase
            if grip_state.fault != seen["fault"]:
                if grip_state.fault is Fault.BAD_REQUEST:
                    self._narrate_refusal(grip_state)
                elif grip_state.fault in FINGER_FAULTS and grip_state.phase is not Phase.FAULT_MISSED:
                    self.say("plc", f"FINGER FAULT while {'releasing' if grip_state.phase is Phase.FAULT_STUCK else 'preparing the fingers'}: "
                                    f"{finger_fault_text(grip_state)}; axes held, fault to the robot")
                if grip_state.fault is not Fault.NONE:
                    s.plc_faults.append(grip_state.fault.name.lower())
                seen["fault"] = grip_state.fault
            if image["goCyclesDone"] != seen["done"]:
                seen["done"] = s.cycles_done = image["goCyclesDone"]
                if cycle_started is not None:
                    s.cycle_sim.append(self.now - cycle_started[0])
                    s.cycle_wall.append(time.perf_counter() - cycle_started[1])
                    x, y, z = (image[f"ring.{a}"] for a in "xyz")
                    self.say("demo", f"cycle {s.cycles_done} done in {s.cycle_sim[-1]:.2f} s simulated, "
                                     f"{s.cycle_wall[-1]:.2f} s wall; ring at ({x:.1f}, {y:.1f}, {z:.1f}) mm")
            if image["goCycle"] != seen["cycle"]:
                seen["cycle"] = image["goCycle"]
                cycle_started = (self.now, time.perf_counter())
                if self.remove_ring_at == seen["cycle"]:
                    s.ring_removed = True
                    self.say("operator", "takes the ring out of the cell (ring.present = 0)")
            if image["doCycleFault"]:
                s.stopped = True
                break
            if s.cycles_done >= self.cycles:
                break
            if self.now > limit:
                self.say("demo", f"gave up: the cycles did not end within {limit:g} s of simulated time")
                break
        for t, line in robot_lines(events.new()):
            self.say("robot", line, t)
        self.scans, self.requests = plc.scans, client.requests
        self.cpu = (time.process_time() - cpu0[0], _process_cpu(server.process.pid) - cpu0[1])  # PLC, twin serve
        final = client.read("ring.present", "ring.x", "ring.y", "ring.z", "sim.time_ms")
        s.sim_time = final["sim.time_ms"] / 1000.0
        s.wall_time = time.perf_counter() - wall0
        if final["ring.present"]:
            s.ring_end = (final["ring.x"], final["ring.y"], final["ring.z"])
            s.ring_error_mm = math.dist(s.ring_end, [v * 1000.0 for v in start_xyz])
        self._print_summary(s, start_xyz, plc)
        return s

    def _narrate_grip(self, before: Phase, st, image, s: Summary) -> None:
        fingers = " / ".join(f"{image[f'{a}.actual']:.1f}" for a in ring_rig.AXES)
        if st.phase is Phase.PREPARING:
            self.say("plc", f"fingers to {st.goal:g} mm ({'inside' if image['doGripInside'] else 'outside'})")
        elif st.phase is Phase.GRIPPING:
            how = "opening into the bore" if st.mode == INSIDE else "closing on the ring"
            self.say("plc", f"grip from {st.mode}: {how} at {self.grip.speed:g} mm/s until every finger "
                            f"reaches {self.grip.threshold:g} N")
        elif st.phase is Phase.HELD:
            s.grips += 1
            forces = " / ".join(f"{v:.0f}" for v in st.forces_at_grip.values())
            self.say("plc", f"grip confirmed from {st.mode}: fingers at {fingers} mm, forces {forces} N")
        elif st.phase is Phase.FAULT_MISSED:
            s.misses += 1
            if s.ring_removed:
                s.misses_after_removal += 1
            if st.fault in FINGER_FAULTS:
                self.say("plc", f"GRIP FAILED from {st.mode}: {finger_fault_text(st)}; fingers at {fingers} mm, "
                                "axes held; fault to the robot")
            elif st.fault is Fault.TIMEOUT:
                self.say("plc", f"GRIP FAILED from {st.mode}: neither confirmed nor missed in time; fingers at "
                                f"{fingers} mm; fault to the robot")
            elif st.fault is Fault.LOST:
                self.say("plc", f"RING LOST: a finger's force went away while holding it; fingers at {fingers} mm; "
                                "grip withdrawn, fault to the robot")
            else:
                self.say("plc", f"MISSED GRIP from {st.mode}: end of travel at {fingers} mm without force; fault to the robot")
        elif st.phase is Phase.RELEASING:
            how = "closing out of the bore" if st.mode == INSIDE else "opening"
            self.say("plc", f"release: {how} until the ring is free")
        elif st.phase is Phase.FAULT_STUCK:
            self.say("plc", f"RELEASE STUCK: the ring still touches a finger at {fingers} mm")
        elif st.phase is Phase.IDLE and before is Phase.RELEASING:
            self.say("plc", f"released: fingers at {fingers} mm")
        elif st.phase is Phase.IDLE and before is Phase.PREPARING and st.fault is Fault.NONE:
            self.say("plc", f"fingers ready at {fingers} mm")

    def _narrate_refusal(self, st) -> None:
        where = "no position" if st.refused is None else f"{st.refused:g} mm"
        travel = "" if self.grip.travel is None else f", outside the axes' travel {self.grip.travel[0]:g}..{self.grip.travel[1]:g} mm"
        self.say("plc", f"REFUSED the finger preparation to {where}{travel}: nothing moves; fault to the robot")

    def _print_summary(self, s: Summary, start_xyz, plc: ScanCycle) -> None:
        def avg(v):
            return sum(v) / len(v)

        ring = ("not in the cell" if s.ring_end is None else
                f"{s.ring_error_mm:.1f} mm from its start "
                f"(at {s.ring_end[0]:.1f}, {s.ring_end[1]:.1f}, {s.ring_end[2]:.1f} mm; start "
                f"{start_xyz[0] * 1000:.1f}, {start_xyz[1] * 1000:.1f}, {start_xyz[2] * 1000:.1f})")
        self.out("summary:")
        self.out(f"  cycles          {s.cycles_done} of {s.cycles_wanted} completed"
                 + (("; the robot stopped the cycle" + (" after a missed grip" if s.misses else "")) if s.stopped else ""))
        self.out(f"  grips           {s.grips} confirmed by force, {s.misses} missed")
        if s.cycle_sim:
            self.out(f"  cycle time      {avg(s.cycle_sim):.2f} s simulated, {avg(s.cycle_wall):.2f} s wall (mean of "
                     f"{len(s.cycle_sim)})")
        else:
            self.out("  cycle time      no cycle completed")
        self.out(f"  total           {s.sim_time:.2f} s simulated in {s.wall_time:.2f} s wall "
                 f"({s.sim_time / max(s.wall_time, 1e-9):.1f}x real time), {plc.scans} PLC scans")
        self.out(f"  ring            {ring}")
        if s.remove_ring_at is not None:
            self.out(f"  injected fault  {injected_fault_text(s)}")
        if s.faults is not None:
            found = ", ".join(dict.fromkeys(s.plc_faults)) or "none"
            self.out(f"  injected faults {s.faults}: the PLC reported {found}"
                     + ("; the robot stopped the cycle" if s.stopped else ""))


FINGER_FAULTS = (Fault.JAMMED, Fault.DRIVE_LOST, Fault.FORCE_READING)


@dataclass(frozen=True)
class StNumbers:
    """The ST PLC's constants the narration quotes (the Python sequence's attributes of the same names)."""

    speed: float
    threshold: float
    travel: tuple[float, float]


class StGripView:
    """gripper.st's sequence as the narration reads the Python one's state (`plc_logic.CarefulState`): its
    program variables phase, fault_code, inside, goal, force[], ready_at, fault_axis, fault_lag, fault_effort."""

    def __init__(self, logic, plc):
        self.logic, self.plc = logic, plc
        self._refs = {}

    def _get(self, name: str):
        ref = self._refs.get(name)
        if ref is None:
            ref = self._refs[name] = self.plc.resolve(f"{self.logic.instance}.{name}")
        return ref.get()

    @property
    def phase(self) -> Phase:
        return Phase(int(self._get("phase")))

    @property
    def fault(self) -> Fault:
        return Fault(int(self._get("fault_code")))

    @property
    def mode(self) -> str:
        return INSIDE if self._get("inside") else "outside"

    @property
    def goal(self) -> float:
        return float(self._get("goal"))

    @property
    def forces_at_grip(self) -> dict:
        return {f: float(self._get(f"force[{i}]")) for i, f in enumerate(ring_rig.FORCES, start=1)}

    @property
    def refused(self) -> float:
        return float(self._get("ready_at"))

    @property
    def fault_axis(self) -> str:
        i = int(self._get("fault_axis"))
        return ring_rig.AXES[i - 1] if 1 <= i <= len(ring_rig.AXES) else "?"

    @property
    def fault_lag(self) -> float:
        return float(self._get("fault_lag"))

    @property
    def fault_effort(self) -> float:
        return float(self._get("fault_effort"))


def finger_fault_text(st) -> str:
    """What the PLC found wrong with a finger, from its grip state (`plc_logic.CarefulState`)."""
    what = {Fault.JAMMED: "jammed (its drive pushes, it does not move)",
            Fault.DRIVE_LOST: "drive lost (it lags, its drive pushes with nothing)",
            Fault.FORCE_READING: "force reading wrong (it presses on the ring, its drive pushes, it reads no force)"}[st.fault]
    effort = "" if st.fault_effort is None else f", drive force {st.fault_effort:.0f} N"
    return f"finger {st.fault_axis} {what}: {st.fault_lag:.1f} mm from its setpoint{effort}"


def injected_fault_text(s: Summary) -> str:
    """The summary's verdict on --remove-ring: was the injected miss detected, did the robot stop?"""
    k = s.remove_ring_at
    if not s.ring_removed:
        return f"ring to be taken away at the start of cycle {k}: NOT injected, cycle {k} never started"
    text = f"ring taken away at the start of cycle {k}: "
    n = s.misses_after_removal
    if n:
        text += f"the missed grip was detected ({n} miss{'es' if n != 1 else ''}), "
        return text + ("the robot stopped the cycle" if s.stopped else "but the robot did NOT stop the cycle")
    return text + "the missed grip was NOT detected" + (
        ", though the robot stopped the cycle" if s.stopped else ", and the robot did not stop the cycle")


def robot_lines(events: list[dict]) -> list[tuple[float, str]]:
    """(simulated time, text) of what the robot controller said, from the server's events (docs/events.md):
    its TPWrite lines, a runtime error, the end of its program."""
    lines = []
    for e in events:
        if e["event"] != "controller":
            continue
        if e["type"] == "print":
            lines.append((e["t"], e["text"]))
        elif e["type"] == "error":
            lines.append((e["t"], f"program error at line {e['line']}: {e['message']}"))
        elif e["type"] == "end":
            lines.append((e["t"], f"program ended ({e['reason']})"))
    return lines


def main(args) -> int:
    if args.remove_ring is not None and args.remove_ring > args.cycles:
        raise DemoError(f"--remove-ring {args.remove_ring} is after the last cycle (--cycles {args.cycles}): "
                        "the ring would never be taken away")
    from plc_client.demo_report import recording_for, report

    lines: list[str] = []
    record = recording_for(args.record, args.report)

    def out(line: str) -> None:
        lines.append(line)
        print(line, flush=True)

    demo = CellDemo(args.station, args.cycles, realtime=args.realtime, speed=args.speed,
                    remove_ring_at=args.remove_ring, scan_cycle=args.scan, record=record, out=out,
                    faults=args.faults, plc=args.plc)
    summary = demo.run()
    if args.report is not None:
        report(record, args.report, threshold=demo.grip.threshold, narration=lines,
               title="gripper-twin demo: the ring rig's automatic cycle")
    return summary.exit_status


EXIT_STATUS_HELP = """exit status:
  0  every cycle was done and the ring is back within 5 mm of where it started;
     with --remove-ring: the injected miss was detected and the robot stopped the cycle;
     with --faults: as without, or the PLC reported a fault and the robot stopped the cycle
  1  otherwise (a cycle not done, the ring not back; with --remove-ring: the miss not detected,
     or the robot did not stop)
  2  bad arguments, or a station the demo cannot run"""


def add_arguments(p) -> None:
    """The options of `plc demo` for this station (the command adds --station)."""
    import argparse

    from twin_app.cli_args import positive_float, positive_int

    p.description, p.epilog = __doc__.split("\n\n")[2], EXIT_STATUS_HELP
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument("--plc", choices=PLCS, default="st",
                   help="the gripper PLC: st, gripper.st in Structured Text (the default), or python, plc_logic.py")
    p.add_argument("--cycles", type=positive_int, metavar="N", default=1, help="full cycles to run (default 1)")
    p.add_argument("--realtime", action="store_true", help="run the twin against the wall clock (default: lockstep)")
    p.add_argument("--speed", type=positive_float, metavar="X", default=1.0, help="with --realtime: X times real time (default 1)")
    p.add_argument("--remove-ring", type=positive_int, metavar="CYCLE", default=None,
                   help="take the ring out of the cell when this cycle starts (1..--cycles): a missed grip, "
                        "detected and reported; exit status 0 only if it is")
    p.add_argument("--faults", metavar="FILE", default=None,
                   help="plant faults for the served twin (twin serve --faults): [faults.NAME] tables as in a campaign "
                        "(docs/campaigns.md), e.g. a finger jammed or its drive lost")
    p.add_argument("--scan", type=positive_float, metavar="S", default=0.010, help="PLC scan cycle, s (default 0.010)")
    p.add_argument("--record", metavar="FILE", default=None,
                   help="record every signal and body pose at every step (twin serve --record): .parquet or .csv")
    rep = p.add_mutually_exclusive_group()
    rep.add_argument("--report", metavar="DIR", default="demo-report",
                     help="write the run's report there: index.html, the signal plot, the cell at each grip and release "
                          "(default demo-report)")
    rep.add_argument("--no-report", dest="report", action="store_const", const=None, help="no report")
