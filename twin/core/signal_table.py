"""The static signal table: every signal of a station, derived from its files alone.

`station_signals(station)` reads the station file, the gripper URDF and the controller's declared I/O
(`[controller]`) and returns the whole table a running cell exchanges with the outside world, without
starting physics or running RAPID (this module and what it imports never import pybullet). The running
twin builds its own table with these same functions and the cell checks that the two agree, so `twin
map`, the PLC client and every front end (Modbus, OPC UA, the view) can rely on it before anything runs.

This is the ONE place signals are declared. A new signal is added here, in its group's function (and
published by whoever computes its value: the twin's `_publish`, a device's `read`, the cell's runner):

    group       function               signals
    gripper     gripper_signals        Active, one input per movable joint, doGripped, GrippedPart,
                                       per input NAME.actual, NAME.in_position, NAME.moving
    fingers     gripper_signals        per finger NAME.contact, NAME.force
    robot       robot_signals          robot.busy, robot.j1 .. robot.jN
    targets     target_signals         per target NAME.present (input), NAME.x, NAME.y, NAME.z
    controller  controller_signals     the `[[controller.io]]` signals, then rapid.start, rapid.stop,
                                       rapid.running, rapid.error, rapid.line
    sim         watchdog_signals       comm.lost (the comm-loss watchdog, a device of every cell)
                SIM_SIGNALS            the simulator's own: sim.advance, fault, sim.lockstep, sim.late,
                                       sim.step, sim.time_ms, sim.late_steps, sim.dt_us, sim.mode,
                                       sim.speed_pct, sim.map_crc, comm.watchdog_ms (published by the
                                       cell's exchange from its runner's state)

The order is the station's declaration order and the same from run to run, so anything derived from the
table (the Modbus register map, OPC UA node ids) is stable too.
"""
from __future__ import annotations

from .errors import StationError
from .mechanism import Mechanism, load_mechanism
from dataclasses import replace

from .signals import BOOL, ENUM, FLOAT, INPUT, INT, OPERATOR, OUTPUT, PLC, ROBOT, SIMULATOR, SignalSpec
from .station import ControllerSpec, Station, load_station

# Groups (where a signal belongs; front ends organise their address space by them).
GRIPPER, FINGERS, ROBOT, TARGETS, CONTROLLER, SIM = "gripper", "fingers", "robot", "targets", "controller", "sim"
GROUPS = (GRIPPER, FINGERS, ROBOT, TARGETS, CONTROLLER, SIM)

# What the per-input outputs mean (the gripper computes them with these very numbers).
IN_POSITION_TOLERANCE = {"m": 0.0002, "rad": 0.002}  # 0.2 mm, ~0.1 degree
MOVING_SPEED = {"m": 0.001, "rad": 0.005}  # below this the axis counts as standing still: over the last step, and
MOVING_WINDOW = 0.05  # s: ... over the last this many seconds too (a settling grip's jitter, 0.02 mm to and fro
# from step to step, is no motion; a joint moving on at that speed is, within a few steps)
FORCE_UNIT = {"m": "N", "rad": "N*m"}  # a finger's force: of a prismatic or a revolute joint's servo

# The robot controller's signal types (RAPID's DI/DO/AI/AO/GI/GO) as signal types.
CONTROLLER_SIGNAL_TYPE = {"DI": BOOL, "DO": BOOL, "AI": FLOAT, "AO": FLOAT, "GI": INT, "GO": INT}
# The program's own signals, after the configured I/O: start and stop it from outside, see how it runs.
RAPID_START, RAPID_STOP, RAPID_RUNNING, RAPID_ERROR, RAPID_LINE = (
    "rapid.start", "rapid.stop", "rapid.running", "rapid.error", "rapid.line")

# The simulator's own signals (the runner's state), published by the cell beside the station's.
SIM_ADVANCE, SIM_STEP, SIM_TIME_MS, SIM_LATE_STEPS, SIM_DT_US, SIM_MODE, SIM_SPEED_PCT, SIM_MAP_CRC = (
    "sim.advance", "sim.step", "sim.time_ms", "sim.late_steps", "sim.dt_us", "sim.mode", "sim.speed_pct",
    "sim.map_crc")
SIM_FAULT, SIM_LOCKSTEP, SIM_LATE = "fault", "sim.lockstep", "sim.late"
WATCHDOG_MS, COMM_LOST = "comm.watchdog_ms", "comm.lost"  # the comm-loss watchdog (twin.runtime.watchdog)
U32_MAX = float(0xFFFFFFFF)
U16_MAX = 0xFFFF


def _sim(name, direction, type_, unit, lo, hi, description) -> SignalSpec:
    return SignalSpec(name, direction, type_, unit, lo, hi, description, group=SIM, owner=SIMULATOR)


# Published by the exchange (the runner's state), not by the twin: `SIM_NAMES`.
SIM_SIGNALS: tuple[SignalSpec, ...] = (
    _sim(SIM_ADVANCE, INPUT, INT, "steps", 0, U16_MAX,
         "lockstep: write N to run N more steps; reads the steps still to run (0 when done). "
         "Real time: reads 0 and only 0 may be written"),
    _sim(SIM_FAULT, OUTPUT, BOOL, "", None, None,
         "the simulation stopped on an error (see the server's log); outputs are frozen"),
    _sim(SIM_LOCKSTEP, OUTPUT, BOOL, "", None, None, "the server runs in lockstep (steps only through sim.advance)"),
    _sim(SIM_LATE, OUTPUT, BOOL, "", None, None, "real time: the last step finished after its wall-clock deadline"),
    _sim(SIM_STEP, OUTPUT, INT, "steps", 0, U32_MAX, "simulation steps completed"),
    _sim(SIM_TIME_MS, OUTPUT, INT, "ms", 0, U32_MAX, "simulated time (steps x step length)"),
    _sim(SIM_LATE_STEPS, OUTPUT, INT, "steps", 0, U32_MAX,
         "real time: steps that finished after their wall-clock deadline"),
    _sim(SIM_DT_US, OUTPUT, INT, "us", 0, U16_MAX, "simulation step length"),
    _sim(SIM_MODE, OUTPUT, INT, "", 0, 1, "0 = lockstep, 1 = real time"),
    _sim(SIM_SPEED_PCT, OUTPUT, INT, "%", 0, U16_MAX,
         "real time: speed in percent of real time (100 = real time); 0 in lockstep"),
    _sim(SIM_MAP_CRC, OUTPUT, INT, "", 0, U32_MAX,
         "CRC-32 of this register map (name, table, address, count, type and scale of every other entry): "
         "a client compares it with the CRC of the map it was given"),
    _sim(WATCHDOG_MS, OUTPUT, INT, "ms", 0, U32_MAX,
         "the comm-loss watchdog's time (0: off): a client sends a request at least this often (a heartbeat), "
         "else comm.lost rises and the gripper goes to the station's safe state"),
)

SIM_NAMES = frozenset(s.name for s in SIM_SIGNALS)


# -- the groups ----------------------------------------------------------------------------------------
def joint_unit(mechanism: Mechanism, joint: str) -> str:
    """The unit (m or rad) of a joint's position, a mimic joint's through its master."""
    for inp in mechanism.inputs:
        if inp.joint == joint:
            return inp.unit
    for mim in mechanism.mimics:
        if mim.joint == joint:
            return joint_unit(mechanism, mim.master)
    return "m"


DEFAULT_EFFORT = {"m": 100.0, "rad": 10.0}  # a drive's effort limit when the URDF gives none


def effort_limit(station: Station, inp) -> float:
    """An input's effort limit: the station's override, else the URDF's, else DEFAULT_EFFORT."""
    o = station.gripper.joints.get(inp.name)
    return (o.effort if o and o.effort else None) or inp.effort or DEFAULT_EFFORT[inp.unit]


def gripper_signals(station: Station, mechanism: Mechanism) -> list[SignalSpec]:
    """`Active`, the joint inputs, the grip outputs, per input its state, per finger contact and force."""
    m, st = mechanism, station
    targets = tuple(t.name for t in st.targets)
    sig = [SignalSpec("Active", INPUT, BOOL, owner=PLC, description="gripper enable: while low the fingers hold still"
                      + (" (this station's gripper is always active)" if st.gripper.always_active else ""))]
    for inp in m.inputs:
        sig.append(SignalSpec(inp.name, INPUT, FLOAT, inp.unit, inp.min, inp.max, owner=PLC, description=
                              f"setpoint of {inp.type} joint {inp.joint}" + (f" ({inp.note})" if inp.note else "")))
    sig.append(SignalSpec("doGripped", OUTPUT, BOOL, description="every finger presses on the same target with at least "
                          "its grip force" + (f" ({st.gripper.grip_force:g})" if st.gripper.grip_force else "")))
    sig.append(SignalSpec("GrippedPart", OUTPUT, ENUM, description="the held target (none, or one of the target group)",
                          choices=("",) + targets))
    sig.append(SignalSpec("slip", OUTPUT, BOOL, description=f"the gripped part moved more than "
                          f"{st.gripper.slip_distance * 1000:g} mm relative to the palm (the link every finger hangs from) "
                          "since it was gripped (held until the next grip)"))
    for inp in m.inputs:
        sig.append(SignalSpec(f"{inp.name}.actual", OUTPUT, FLOAT, inp.unit, inp.min, inp.max,
                              f"actual position of joint {inp.joint}"))
        sig.append(SignalSpec(f"{inp.name}.in_position", OUTPUT, BOOL,
                              description=f"{inp.name} is within {IN_POSITION_TOLERANCE[inp.unit]:g} {inp.unit} of its setpoint"))
        sig.append(SignalSpec(f"{inp.name}.moving", OUTPUT, BOOL, description=f"{inp.name} is moving"))
        limit = effort_limit(st, inp)
        sig.append(SignalSpec(f"{inp.name}.effort", OUTPUT, FLOAT, FORCE_UNIT[inp.unit], -limit, limit,
                              f"force of {inp.name}'s drive, signed along the joint (measured)"))
    for f in m.fingers:
        unit = FORCE_UNIT["m" if joint_unit(m, f.joint) == "m" else "rad"]
        touch = "touches" if st.gripper.grip == "attach" else "touches and presses on"
        sig.append(SignalSpec(f"{f.name}.contact", OUTPUT, BOOL, group=FINGERS, description=f"finger {f.name} {touch} a target"))
        sig.append(SignalSpec(f"{f.name}.force", OUTPUT, FLOAT, unit, 0.0, None, group=FINGERS,
                              description=f"force of finger {f.name}'s contacts on target objects (measured"
                              + (", as torque about its joint)" if unit == "N*m" else ", along its joint's axis)")))
        sig.append(SignalSpec(f"{f.name}.status", OUTPUT, INT, "", 0, 3, group=FINGERS,
                              description=f"finger {f.name}'s object status: 0 moving, 1 stopped by contact while opening, "
                              "2 stopped by contact while closing, 3 at the setpoint"))
    return sig


def robot_signals(station: Station) -> list[SignalSpec]:
    if station.robot is None:
        return []
    sig = [SignalSpec("robot.busy", OUTPUT, BOOL, group=ROBOT, owner=ROBOT, description="the robot is executing a motion")]
    for i, _ in enumerate(station.robot.joints, start=1):
        sig.append(SignalSpec(f"robot.j{i}", OUTPUT, FLOAT, "rad", group=ROBOT, owner=ROBOT, description=f"robot axis {i} position"))
    return sig


def target_signals(station: Station) -> list[SignalSpec]:
    sig = []
    for t in station.targets:
        sig.append(SignalSpec(f"{t.name}.present", INPUT, BOOL, group=TARGETS, owner=SIMULATOR,
                              description=f"{t.name} is in the cell: write 0 to take it away (a missing part), "
                                          "1 to put it back where the station places it"))
        for axis in "xyz":
            sig.append(SignalSpec(f"{t.name}.{axis}", OUTPUT, FLOAT, "m", group=TARGETS,
                                  description=f"{axis} of {t.name}'s centre in the world frame"))
    return sig


def twin_signals(station: Station, mechanism: Mechanism | None = None) -> tuple[SignalSpec, ...]:
    """The twin's own signals (no controller, no simulator): gripper, fingers, robot, targets.

    Link and target names are free text: two of them making the same signal name is a StationError."""
    mechanism = mechanism or load_mechanism(station.gripper.urdf, station.gripper.fingers)
    sig = gripper_signals(station, mechanism) + robot_signals(station) + target_signals(station)
    seen: dict[str, SignalSpec] = {}
    for spec in sig:
        if spec.name in seen:
            raise StationError(str(station.file), "gripper.urdf", f"two signals would be named {spec.name!r} "
                               f"({seen[spec.name].description}; {spec.description}): rename a link or target")
        seen[spec.name] = spec
    return tuple(sig)


def watchdog_signals(safe_state: str = "hold") -> tuple[SignalSpec, ...]:
    """The comm-loss watchdog's output (`twin.runtime.watchdog`, in every cell; off until it has a time)."""
    return (SignalSpec(COMM_LOST, OUTPUT, BOOL, group=SIM,
                       description="comm-loss watchdog: no request from any client for the watchdog time; "
                                   f"the gripper went to its safe state ({safe_state}); cleared by the next request"),)


def settable_from_outside(sig) -> bool:
    """Who may set a controller signal from outside (a PLC, a test, an engineer): its inputs that no twin output
    feeds (DI, AI, GI: the PLC's outputs to the robot), and outputs marked `settable` (RobotStudio's I/O
    simulator, e.g. the thesis's path signals). The robot's other outputs are read-only, like every output."""
    if sig.drives or sig.source:
        return False
    return sig.type in ("DI", "AI", "GI") or sig.settable


def _wiring(sig) -> str:
    if sig.drives:
        return f"drives {sig.drives}"
    if sig.source:
        return f"reads {sig.source}"
    if sig.type in ("DO", "AO", "GO"):
        return "set by the robot program" + (", and from outside (I/O simulator)" if sig.settable else "")
    return "set from outside"


def controller_owner(sig) -> str:
    """Who a controller signal belongs to: an input no twin output feeds (DI, AI, GI) is the PLC's answer to the
    robot; a `settable` output the operator's (the I/O simulator); everything else the robot controller's."""
    if settable_from_outside(sig):
        return OPERATOR if sig.settable and sig.type in ("DO", "AO", "GO") else PLC
    return ROBOT


def controller_signals(spec: ControllerSpec) -> tuple[SignalSpec, ...]:
    """The robot controller's signals: its declared I/O, then the program-control signals `rapid.*`."""
    specs = [SignalSpec(sig.name, INPUT if settable_from_outside(sig) else OUTPUT, CONTROLLER_SIGNAL_TYPE[sig.type],
                        sig.unit, description=f"robot controller {sig.type} {sig.name} ({_wiring(sig)})",
                        group=CONTROLLER, owner=controller_owner(sig))
             for sig in spec.io]
    specs += [
        SignalSpec(RAPID_START, INPUT, BOOL, group=CONTROLLER, owner=OPERATOR,
                   description="a rising edge (re)starts the RAPID program from its entry routine (VAR data anew, PERS kept)"),
        SignalSpec(RAPID_STOP, INPUT, BOOL, group=CONTROLLER, owner=OPERATOR, description="a rising edge stops the RAPID program where it is"),
        SignalSpec(RAPID_RUNNING, OUTPUT, BOOL, group=CONTROLLER, owner=ROBOT, description="the RAPID program is running (or waiting)"),
        SignalSpec(RAPID_ERROR, OUTPUT, BOOL, group=CONTROLLER, owner=ROBOT,
                   description="the RAPID program stopped on a runtime error (the server's log says where)"),
        SignalSpec(RAPID_LINE, OUTPUT, INT, min=0, max=65535, group=CONTROLLER, owner=ROBOT,
                   description="the line of the program's module the robot controller waits at (0: none)"),
    ]
    return tuple(specs)


def check_wiring(station: Station, signals: tuple[SignalSpec, ...]) -> None:
    """Every controller signal's `drives` names an input of the twin and every `source` an output (StationError
    naming the key otherwise); no controller signal takes a twin signal's name."""
    spec = station.controller
    if spec is None:
        return
    file = str(station.file)
    known = {s.name: s for s in signals}
    for i, sig in enumerate(spec.io):
        if sig.name in known:
            raise StationError(file, f"controller.io[{i}].name",
                               f"{sig.name!r} is already a signal of the twin ({known[sig.name].description})")
        for key, want in (("drives", INPUT), ("source", None)):
            target = getattr(sig, key)
            if not target:
                continue
            found = known.get(target)
            if found is None:
                names = [s.name for s in signals if (s.direction == INPUT) == (want == INPUT)]
                raise StationError(file, f"controller.io[{i}].{key}",
                                   f"{sig.name}: the twin has no signal {target!r} (it has: {', '.join(names)})")
            if want == INPUT and found.direction != INPUT:
                raise StationError(file, f"controller.io[{i}].{key}",
                                   f"{sig.name}: {target!r} is an output of the twin; an output can only be a `source`")


def station_signals(station: Station | str, *, sim: bool = True) -> tuple[SignalSpec, ...]:
    """The full signal table of a station (a Station, a folder or a station.toml), as a running cell has it:
    the twin's signals, the watchdog's, the controller's (when the station has a `[controller]`), then the simulator's
    (`sim=False` leaves those out). Pure: reads files, starts no physics and runs no program."""
    if not isinstance(station, Station):
        station = load_station(station)
    own = twin_signals(station)
    watchdog = getattr(station, "watchdog", None)
    table = list(own) + list(watchdog_signals(watchdog.safe_state if watchdog is not None else "hold"))
    if station.controller is not None:
        check_wiring(station, tuple(table))
        driven = {sig.drives for sig in station.controller.io if sig.drives}
        table = [replace(s, owner=ROBOT) if s.name in driven else s for s in table]  # the robot's, not a PLC's
        table += controller_signals(station.controller)
    if sim:
        table += SIM_SIGNALS
    return tuple(table)
