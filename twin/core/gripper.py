"""The gripper's behaviour, evaluated at every physics substep and after every simulation step.

The drive model (docs/station-format.md, "Drives"). Every input is a servo drive:
- its *command* moves towards the setpoint at the velocity limit (a ramp; while its finger presses on a part that
  holds it, at least fast enough to reach full force within the force rise time, 50 ms unless the station says), and
  runs ahead of the joint by no more
  than the error at which the drive reaches its force limit, so a new setpoint acts at once;
- a position loop of stiffness K and damping D asks for |K e - D v| (+ a small holding force), e = command - actual,
  v the joint's speed, limited by the effort; within that force pybullet's implicit velocity motor drives the joint
  to the command in one substep (stable for any finger mass), never faster than the velocity limit while the joint
  runs (at least half that speed over the last substep: a part that gives way is pushed along at the drive's speed,
  as a real servo's speed loop does, not kicked ahead by the force the drive has built); a joint held back (by a
  part, a stop) asks for more speed, far more at its force limit (the solver builds a motor's force only as fast as
  the speed it asks for);
- a drive stalled on a part (97.5 % of its full-force error, exactly, short of its goal, its finger pressing on a target) keeps
  its command where it stands until its force falls by a tenth or the goal changes: the finger holds its place, and
  the rest of its effort resists a push, so two fingers squeezing a part cannot walk it sideways.
The gains are derived, not tuned (`_derive_drives`): K and D act explicitly, once per substep h, on what the drive
moves, m (its links, its mimic followers', and the lightest target when it carries a finger; about a revolute axis,
their inertia and the target at the finger's reach), shared by the n fingers' own drives: K <= m / (n h^2) (below
that the spring is stable), D = m_own / (n h) (its own links alone: a part resting on a fixture does not move with
them). Drives in series on a pressed finger (a fine axis on its carriage) take out m_own / m of their error per
substep: the part holds their sum, and only their own links move between them; one pressing on through others that
stand at their goals presses with at most SERIES_HOLD of what they hold (the finger's force passes through each), so
they keep their goals instead of trading places with it at equal limits; one standing at its goal is never dragged
off it, and holds it rigidly where the springs in series would press with the chain's weakest effort anyway (its
spring, derived for finger and part, would rattle the light carriage between a standing part and a constant force).
A station's stiffness above that limit makes its drive rigid up to its effort. A free finger follows its command with
almost no force; a finger stopped by a part presses with K times how far its setpoint lies past it, up to the
effort (and with the effort where it was sent to its range's end, however close past the part: `_past`).
What the PLC reads is measured, not computed: `NAME.effort` is the
motor force pybullet applied (averaged over the substeps), `NAME.force` the force of the finger's contacts on target
objects along its joint's axis, friction included (as the step's last substep leaves them, as a sensor samples; a
revolute finger's is the torque about its joint of those contacts' force),
and an axis's speed comes from its positions (pybullet's joint velocity reads the motor's target where a contact
holds the joint back). Mimic joints are tied to their master by a gear constraint (one motor moves the whole
linkage). Stepping by hand (fixedTimeStep = step / substeps, one stepSimulation per substep) keeps both motor limits
and contact forces true (measured-facts.md: numSubSteps distorts both).

The grip rule (`sense`, after each step), the same for outside and inside grips:
- contact: a finger touches a target when their closest distance (with 0.1 mm collision margins, so corners
  are sharp) is at most `contact_distance` (0 by default: never before true contact); in `friction` mode it
  also has to press on it (a normal force), or, moving, overlap it (it reached the part in the step's last substep);
- `doGripped` / `GrippedPart`: every finger presses on the same target with at least `grip_force`; the grip
  lasts while every finger presses with at least a quarter of it (a swinging part does not make it flicker);
- `grip = "friction"`: nothing is welded, the part is held by friction alone and may slip or drop;
  `grip = "attach"`: the part is fixed to the base link while every finger presses on it with at least
  `attach_force`, released when any finger's force falls below it (the thesis's SmartComponent, honestly);
- `slip`: a gripped part has moved more than `slip_distance` relative to the palm (the link every finger hangs
  from: the base link, unless an axis such as a lift carries all the fingers) since it was gripped (latched until
  the next grip);
- `NAME.status` per finger, as a Robotiq gripper's object status: 0 moving towards the setpoint (while any axis that
  carries it moves), 1 stopped by contact while opening, 2 stopped by contact while closing, 3 at the setpoint.
"""
from __future__ import annotations

import collections
import math
from dataclasses import dataclass, field

from .bullet import pybullet

from .geometry import cross
from .mechanism import JointInput, Mechanism
from .meshes import HULL_MARGIN, prepared
from .signal_table import DEFAULT_EFFORT, IN_POSITION_TOLERANCE, MOVING_SPEED, MOVING_WINDOW  # (what the
# signals mean)
from .signals import FLOAT, INPUT, SignalSpec
from .station import GripperSpec
from .world import COLLISION_MARGIN, warn_once

DEFAULT_VELOCITY = {"m": 0.1, "rad": 1.0}  # when the URDF gives no velocity limit
FULL_FORCE_ERROR = {"m": 0.001, "rad": 0.01}  # default stiffness: the effort limit at this following error ...
STIFFNESS_SHARE = 1.0  # ... at most this share of the stiffest spring the step keeps stable: K h^2 / m per drive
DAMPING_SHARE = 1.0  # the damping: this share of the strongest the step keeps stable, D h / m per drive
HOLD_FRACTION = 0.02  # the force a drive may use near zero error (damps a free finger; static friction of a drive)
PUSH_SPEEDUP = 20.0  # how much faster than its velocity limit a held drive asks to move
PAST_REACH = 3.0  # ... if its full-force error is at most this many times its joint's range: beyond, the effort is a
# placeholder (1000 N m on a 0.1 kg finger), and the finger presses with what its spring gives (a warning says so)
PAST_GAP = IN_POSITION_TOLERANCE  # a drive held by a part further than this short of its range's end, sent there,
# presses past it where it lies closer past the part than full force (`Gripper._past`); nearer, it is at its setpoint
FACING = 0.9999  # a contact whose normal lies within 14 mrad of a prismatic finger's axis: its friction's share of
# the force along the axis is left out (its friction acts across the axis within 1.4 %), the rest is summed
LATCH_FRACTION = 0.975  # a drive pressing with this share of its full-force error stalls: its command waits there
# (K e + the holding force: 99.5 % of its effort), and the rest of its effort holds the finger where it stands; a part
# that gives way is followed back to that error (the force stays), one that pushes back meets up to the whole effort
FORCE_RISE_TIME = 0.05  # s: a drive whose finger presses on a part runs its command on at least this fast to full force
# (a slow drive would build it over `full error / velocity`, 0.23 s on 40 N at 50 mm/s, while the pair drifts). A model
# parameter, not derived: half the position loop's period on what it moves, pi sqrt(m / K) (13 ms on the test
# grippers), or its whole period, lets two 40 N fingers on a 300 g steel cylinder rock it (status 0 again 15 to 41
# steps after touching); 50 ms (4 steps) holds every test gripper. The station's `[gripper] force_rise_time` overrides it
FOLLOW_FRACTION = 0.965  # ... once the error has fallen below this share (both springs of a squeezed pair hold it)
SERIES_HOLD = 1.0 - (1.0 - LATCH_FRACTION - HOLD_FRACTION) / 2  # a drive pressing through drives in series that
# stand at their goals presses with at most this share of what they hold (99.75 %): above a stalled finger's 99.5 %, so
# it presses like the other fingers and resists a push, and short of the one that holds, so that one keeps its goal
RELEASE_FRACTION = 0.9  # a stalled drive moves its command on again once its force has fallen by a tenth
HELD_SHARE = 0.5  # a joint that moved less than this share of its velocity limit the drive's way (over the last
# substep) is held: only then does its command run on to build force, and may it ask for more than its limit's speed
RESTING_DRIFT = 2.0  # resting drives (`_still_resting`) rest on while each joint stays within this many times the
# error a quiet drive's holding force allows of its command (at most half its in-position tolerance); past it (a push,
# a load the holding force gives way to) the loop takes over again
MIMIC_ERP = 0.5  # how fast a mimic joint's drift from its master is taken out, per substep
MIMIC_FORCE_FACTOR = 20.0  # a mimic coupling holds up to this many times the master's effort (a rigid linkage) ...
MIMIC_SETTLED_FACTOR = 0.005  # ... and this once every finger of a linkage of parallel jaws (each on a joint of its
# own: a chuck's, a parallel gripper's) presses on a part: each joint's own motor takes its share of the drive's force
# (`_linkage`) and the gears only keep the jaws in step. Rigid, they carry friction's indeterminate share between the
# jaws: a one-input chuck's three jaws pressed 24 / 35 / 30 N of 90 N on a disc (41 / 28 / 21 N with the whole drive
# on the master), 28.9 / 30.3 / 30.3 N with this (let go entirely, a 1:-1 scissor's levers on a free peg walk it, as
# two drives pressing alone would). Rigid while any finger is free: a jaw that meets an off-centre part first pushes
# it with the whole drive (a self-centring chuck centres its part), and the jaws run in step
GRIP_FORCE_FRACTION = 0.1  # default grip_force: this share of the finger's drive effort
LOST_WATCH_STEPS = 25  # a gripped part no finger presses on any more, and that no setpoint let go, is watched for
# slip this many steps more (0.3 s at 12 ms): a dropped part leaves the fingers within a step
RELEASE_SHARE = 0.25  # a grip lasts while every finger presses with this share of grip_force (no flicker)
ARRIVAL_TRAVEL = 0.0003  # m: a finger reaches a part moving at most this far a substep (0.1 m/s at 3 ms). A drive
# whose fingers may move further at its velocity limit (a fast finger: 1.5 mm a substep at 0.5 m/s) slows down within
# sight of a target: pybullet's box contacts exist only once shapes overlap, so a fast finger is stopped a whole
# substep's travel deep in the part (2.2 mm at 0.5 m/s), kicks it, and is pushed back out over a dozen steps
ARRIVAL_DEPTH = 0.00002  # m: ... and its last substep before the part lands it this far into it (pybullet's contacts
# exist once shapes overlap; a contact flag must not rise a step late)
ARRIVAL_BRAKING = 0.5  # the share of a drive's effort over its own links' mass that slowing down for a part may ask
CONTACT_SLACK = 0.00005  # m: pybullet holds pressed contacts up to 0.02 mm apart; a pressing finger within this touches
STATUS_MOVING, STATUS_OPENING_CONTACT, STATUS_CLOSING_CONTACT, STATUS_AT_SETPOINT = 0, 1, 2, 3


@dataclass(slots=True)
class AxisState:
    actual: float = 0.0
    velocity: float = 0.0
    effort: float = 0.0  # the drive's applied force (N) or torque (N*m), signed along the joint axis
    moving: bool = False  # faster than MOVING_SPEED over the last step and over the last MOVING_WINDOW (`NAME.moving`)


@dataclass
class FingerState:
    contacts: tuple[str, ...] = ()  # targets it touches (and, in friction mode, presses on)
    force: float = 0.0  # normal force on target objects (N), or its torque about a revolute finger's joint (N*m)
    pressing: dict[str, float] = field(default_factory=dict)  # target -> that force, per target
    status: int = STATUS_AT_SETPOINT


@dataclass
class GripState:
    gripped: str = ""  # every finger presses on it with at least grip_force ("" for none)
    attached: str = ""  # attach mode: the target fixed to the base link
    slip: bool = False
    slip_distance: float = 0.0  # m: how far the gripped part has moved relative to the base link since the grip
    axes: dict[str, AxisState] = field(default_factory=dict)
    fingers: dict[str, FingerState] = field(default_factory=dict)


@dataclass(frozen=True)
class Drive:
    """One input's servo drive: velocity limit, force limit, stiffness and damping of its position loop, and the
    mass (or inertia about its axis) the loop was derived for (see the module docstring)."""

    velocity: float
    effort: float
    stiffness: float
    damping: float = 0.0
    mass: float = 0.0  # kg (kg m^2 for a revolute drive): what it moves, with the lightest target
    limit: float = float("inf")  # the stiffest spring the step keeps stable for that mass (N/m or N m/rad)
    own: float = 0.0  # kg (kg m^2): its own links' and mimic followers' share of `mass` (without the part)
    # (derived, for every physics substep: the full-force error, stiffer than the step resolves, the holding force)
    full: float = field(init=False, repr=False, compare=False)
    rigid: bool = field(init=False, repr=False, compare=False)
    hold: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "full", self.effort / self.stiffness)
        object.__setattr__(self, "rigid", self.stiffness > self.limit)
        object.__setattr__(self, "hold", HOLD_FRACTION * self.effort)

    @property
    def full_error(self) -> float:
        """The following error at which the drive reaches its force limit."""
        return self.effort / self.stiffness


class Gripper:
    """Servoes the gripper's joints, measures forces and contacts, and decides grip, slip and release."""

    def __init__(self, client, body: int, joint_index: dict[str, int], link_index: dict[str, int],
                 mechanism: Mechanism, spec: GripperSpec, targets: dict[str, int], substep: float,
                 contact_probe=None, substeps: int = 1):
        self.client, self.body, self.mechanism, self.spec = client, body, mechanism, spec
        self._joint_kinds: dict[int, tuple[int, tuple]] = {}  # joint -> (its type, its axis in its frame), as read
        self.targets = targets  # target name -> body id, in station order
        self._target_by_id = {uid: name for name, uid in targets.items()}
        self.base_link = link_index[mechanism.base_link]
        self.h = substep
        self.substeps = substeps  # physics substeps in one simulation step
        self.names = [inp.name for inp in mechanism.inputs]
        self.joint = {inp.name: joint_index[inp.joint] for inp in mechanism.inputs}
        self._joint_ids = [self.joint[n] for n in self.names]
        self.unit = {inp.name: inp.unit for inp in mechanism.inputs}
        self._range = {inp.name: (inp.min, inp.max) for inp in mechanism.inputs}
        self.drives: dict[str, Drive] = {}
        stiffness_given: dict[str, float | None] = {}
        defaulted = []  # (input, "velocity" or "effort"): neither the station nor the URDF gives it
        for inp in mechanism.inputs:
            o = spec.joints.get(inp.name)
            velocity = (o.velocity if o and o.velocity else None) or inp.velocity
            effort = (o.effort if o and o.effort else None) or inp.effort
            defaulted += [(inp, what) for what, value in (("velocity", velocity), ("effort", effort)) if not value]
            velocity, effort = velocity or DEFAULT_VELOCITY[inp.unit], effort or DEFAULT_EFFORT[inp.unit]
            stiffness_given[inp.name] = o.stiffness if o and o.stiffness else None
            self.drives[inp.name] = Drive(velocity, effort, stiffness_given[inp.name] or effort / FULL_FORCE_ERROR[inp.unit])
        master_input = {inp.joint: inp.name for inp in mechanism.inputs}
        self.mimics = [(joint_index[m.joint], master_input[m.master], m.multiplier, m.offset) for m in mechanism.mimics]
        self.finger_links = {f.name: [link_index[n] for n in f.links] for f in mechanism.fingers}
        self._finger_of_link = {link: f for f, links in self.finger_links.items() for link in links}
        # exact shapes for the contact flag (contact.py); links it cannot copy are asked of the physics world
        self.probe = contact_probe(self.finger_links, targets) if contact_probe is not None else None
        self.finger_joint = {f.name: joint_index[f.joint] for f in mechanism.fingers}
        servo_of = {j: name for name, j in self.joint.items()} | {j: master for j, master, _, _ in self.mimics}
        # the servos (inputs) that drive each finger, nearest first: its own joint's (or its master's), then those
        # of the joints that carry it (e.g. the carriage a fine axis sits on)
        self.finger_servos = {f.name: list(dict.fromkeys(servo_of[j] for j in self._chain(joint_index[f.joint])
                                                          if j in servo_of))
                              for f in mechanism.fingers}
        # the palm: the link every finger hangs from (the base link, unless an axis such as a lift carries them
        # all): a held part is watched for slip, and attached, relative to it
        chains = [self._chain(joint_index[f.joint]) for f in mechanism.fingers]
        own = set(self.finger_joint.values())
        common = [j for j in chains[0] if j not in own and all(j in ch for ch in chains[1:])] if chains else []
        self.palm_link = common[0] if common else self.base_link
        self._fingers_of_servo = {name: [f for f, servos in self.finger_servos.items() if name in servos]
                                  for name in self.names}
        self._pressing_none = {name: False for name in self.names}  # (read only: no drive's finger presses)
        self._derive_drives(stiffness_given)
        self.rise_time = spec.force_rise_time or FORCE_RISE_TIME  # s (docs/station-format.md, "Drives")
        self._constants: list[tuple] | None = None  # what `drive` asks of each drive at every substep, formed once
        # one line per drive limit the station runs with but does not give, or cannot reach: (the limit, the line)
        self.limit_notes = self._defaulted_limits(defaulted) + [("effort", n) for n in self._unreachable_efforts()]
        self.revolute_fingers = {f.name for f in mechanism.fingers
                                 if client.getJointInfo(body, joint_index[f.joint])[2] == pybullet.JOINT_REVOLUTE}
        self.grip_force = {f: spec.grip_force if spec.grip_force is not None
                           else GRIP_FORCE_FRACTION * min((self.drives[s].effort for s in servos), default=1.0)
                           for f, servos in self.finger_servos.items()}
        self._release_force = {f: RELEASE_SHARE * force for f, force in self.grip_force.items()}
        self.attach_force = {f: spec.attach_force if spec.attach_force is not None else self.grip_force[f]
                             for f in self.finger_servos}
        self.active_input = spec.always_active  # the `Active` input as last written
        self.setpoint = {inp.name: self._initial(inp) for inp in mechanism.inputs}
        self.command_position = dict(self.setpoint)  # where each servo is heading now (moves at the velocity limit)
        self._stalled: dict[str, float | None] = {}  # input -> the direction it presses in, while stalled on a part
        # inputs stalled past their range's end, sent there: an end that lies closer past the part than the drive's
        # full-force error (a short stroke) is pressed past, with the effort, not with what the spring gives there
        self._past: dict[str, float] = {}  # (input -> the way it presses)
        self._new_goal: set[str] = set()  # inputs given a setpoint since their drive last ran
        self._hold: dict[str, float] | None = None
        self._constraint: int | None = None
        self._grip_reference: tuple | None = None  # (the gripped part, its position in the palm's frame at the grip)
        self._slip_part = ""
        self._opened_since_grip = False  # a finger's setpoint was moved the opening way since the grip
        self._lost_steps = 0  # steps since no finger pressed on the gripped part
        for inp in mechanism.inputs:
            client.resetJointState(body, self.joint[inp.name], self.setpoint[inp.name])
        for joint, master, mult, off in self.mimics:
            client.resetJointState(body, joint, mult * self.setpoint[master] + off)
        self.closing = self._closing_directions()
        self._series_loads = self._series_couplings()
        # how many springy drives move each drive's fingers in series along its motion (a fine axis and the carriage it
        # rides on: 2; a lift across the closing direction is no spring in that chain;
        # a drive stiffer than the step resolves holds its command rigidly, and is no spring in the chain)
        springy = {name for name, d in self.drives.items() if d.stiffness <= d.limit}
        self._series = {name: 1 + sum(1 for other, _ in self._series_loads.get(name, ()) if other in springy)
                        if name in springy else 1 for name in self.names}
        self._series_holders = {s for ss in self._series_loads.values() for s, _ in ss}  # drives others press through
        self._series_share = {p: dict(ss) for p, ss in self._series_loads.items()}
        self._holding: set[str] = set()  # series drives holding their goals rigidly against one pressing through them
        self._index = {name: i for i, name in enumerate(self.names)}
        self._settled_linkages: dict[str, bool] = {}  # per master input: every finger of its linkage presses
        gears = [(master, self._couple(joint, master, mult, off), mult) for joint, master, mult, off in self.mimics]
        jaws = set(self.finger_joint.values())  # parallel jaws: every joint of the linkage a finger's own
        self._gears: dict[str, list[tuple[int, float]]] = {}  # per linkage of parallel jaws (its master): its gears
        for master, gear, mult in gears:
            if self.joint[master] in jaws and all(j in jaws for j, m, _, _ in self.mimics if m == master):
                self._gears.setdefault(master, []).append((gear, mult))
        # linkages whose gears stay rigid (joints in series: a finger's knuckles): the solver needs more sweeps to
        # hold a chain of gears under load (world.py, `World.iterations_for`)
        self.rigid_linkages = sorted({master for _, master, _, _ in self.mimics} - set(self._gears))
        # a linkage's drive acts on each of its joints (its master's and its mimics'), each with the drive's force
        # over the sum of the multipliers' sizes: by virtual work the linkage then presses as the drive does (sum |m|
        # f = F), and every joint alike, as a part held between its fingers needs in statics, without the gear
        # constraints carrying the difference (through them alone, friction held a one-input chuck's three jaws at
        # 41 / 28 / 21 N of 90 N)
        self._linkage = [(self._index[master], joint, mult, off) for joint, master, mult, off in self.mimics]
        # (per follower: its master's input index, its joint, multiplier and offset)
        self._master_share = [1.0 / (1.0 + sum(abs(mult) for _, m, mult, _ in self.mimics if m == name))
                              for name in self.names]  # each joint's share of its drive's force
        self._motor_ids = self._joint_ids + [joint for _, joint, _, _ in self._linkage]
        self._mesh_links: set[int] = set()
        for finger, links in self.finger_links.items():
            for link in links:
                client.changeDynamics(body, link, lateralFriction=spec.friction)
                client.changeDynamics(body, link, collisionMargin=COLLISION_MARGIN)  # (in one call pybullet drops the friction)
                shapes = client.getCollisionShapeData(body, link)
                if any(s[2] == pybullet.GEOM_MESH and not prepared(s[4].decode()) for s in shapes):
                    self._mesh_links.add(link)  # pybullet's hull of a mesh lies 1 mm outside it: distances read short
                # torsional friction: a pad pressing on a face resists turning about its normal with (2/3) mu N a
                # (uniform pressure over a patch of radius a), which pybullet's few contact points per face do not
                # give: a 2 kg block between 80 N pads turned 15 degrees about the jaws' axis in a 1 m/s lift. a: half
                # the pad's middle size (its face across the thickness); pybullet multiplies this by the part's
                # friction, as it does the lateral friction. A sliding jaw's flat pad: a lever's pad rolls over the part
                # as it closes, touching along a line (the PR2's mesh fingers on a peg flickered with it)
                if finger not in self.revolute_fingers:
                    lo, hi = client.getAABB(body, link)
                    middle = sorted(h - l for l, h in zip(lo, hi))[1]
                    client.changeDynamics(body, link, spinningFriction=2.0 / 3.0 * middle / 2 * spec.friction)
        # pybullet_utils' client looks every function up anew on each call: the per-substep ones are bound once
        self._joint_states, self._motors = client.getJointStates, client.setJointMotorControlArray
        self._contact_points = client.getContactPoints
        self._sliding: list | None = None  # (`_thrust_axis`)
        self._palm_now = None  # the palm's pose, read after the step's physics, until the step has been sensed
        self._link_keys = {(link, uid): ((finger, uid), finger in self.revolute_fingers)
                           for link, finger in self._finger_of_link.items()
                           for uid in targets.values()}  # a contact's (finger link, target): its force's key, revolute?
        self._quiet = False
        self._resting: tuple | None = None  # (Active, per input the joint's bounds) while the drives rest
        self._gaps: dict[str, tuple[int, float]] = {}  # per fast drive: (substep, its fingers' gap to the nearest
        # target then), as it last looked
        self._substep_count = 0  # physics substeps driven or coasted since the start
        # the joints' states as last read (after the last physics substep: what the next drive starts from), and
        # the drive command last sent (pybullet keeps it: an identical one is not sent again)
        self._states = None
        self._step_positions: list[float] | None = None  # the joints' positions at the end of the last step
        # the joints' positions at the ends of the last steps, over MOVING_WINDOW (whether each moves: `sense`)
        self._window = collections.deque(maxlen=max(1, round(MOVING_WINDOW / (substeps * substep))))
        self._step_ticks = 0  # physics substeps since the last sense
        self._speeds = [0.0] * len(self.names)  # each joint's speed over the last substep(s) measured, from positions
        self._ticks = 0  # physics substeps since the joints were last read
        self._sent: tuple | None = None
        self._per_input = [(name, self.unit[name], MOVING_SPEED[self.unit[name]]) for name in self.names]
        self._ranges = [(name, *self._range[name], IN_POSITION_TOLERANCE[self.unit[name]]) for name in self.names]
        self._settled_statuses = [STATUS_AT_SETPOINT] * len(self.finger_links)
        self._servo_limits = {f: [(name, IN_POSITION_TOLERANCE[self.unit[name]], MOVING_SPEED[self.unit[name]])
                                  for name in servos] for f, servos in self.finger_servos.items()}
        self.read_along([])
        self._idle_statuses: list[int] | None = None  # the fingers' statuses while their states are of touching nothing
        self._joint_frames: dict[str, tuple] = {}  # revolute fingers' joint frames, this substep
        self.state = GripState()
        self._reset_sums()
        self.sense()

    # -- inputs -------------------------------------------------------------------------------------------
    def _initial(self, inp: JointInput) -> float:
        value = self.spec.initial.get(inp.name, min(max(0.0, inp.min), inp.max))
        self.check(inp, value)
        return value

    @staticmethod
    def check(inp: JointInput, value: float) -> float:
        """The value as the input takes it, by the one write validation (`SignalSpec.check`: a range end sent
        in other units is the end; out of range or not a finite number: rejected, never clamped)."""
        return SignalSpec(inp.name, INPUT, FLOAT, inp.unit, inp.min, inp.max).check(value)

    def set_setpoint(self, name: str, value: float) -> None:
        """Validate and store a setpoint; it takes effect at the next step. Out of range: rejected."""
        value = self.check(self.mechanism.input(name), value)
        if (value - self.setpoint[name]) * self.closing.get(name, 0.0) < 0.0:
            self._opened_since_grip = True
        self.setpoint[name] = value
        self._new_goal.add(name)

    @property
    def limits(self) -> dict[str, tuple[float, float]]:
        """Each input's (velocity, effort) limits as applied now."""
        return {name: (d.velocity, d.effort) for name, d in self.drives.items()}

    def set_limits(self, name: str, velocity: float | None = None, effort: float | None = None) -> None:
        """Change an input's velocity or effort limit from the next step on (a drive that loses force, a
        slower axis: fault injection and parameter studies); its stiffness stays. None keeps the present value."""
        d = self.drives[self.mechanism.input(name).name]
        for what, value in (("velocity", velocity), ("effort", effort)):
            if value is not None and not (value >= 0.0 and value < float("inf")):
                raise ValueError(f"{name}: the {what} limit must be a finite number >= 0, not {value!r}")
        self.drives[name] = Drive(d.velocity if velocity is None else float(velocity),
                                  d.effort if effort is None else float(effort), d.stiffness, d.damping, d.mass,
                                  d.limit, d.own)
        self._constants = None  # (formed anew at the next substep)

    def set_active(self, active: bool) -> None:
        """Store the `Active` input; an always-active gripper keeps what was written but ignores it."""
        self.active_input = bool(active)

    @property
    def active(self) -> bool:
        return self.active_input or self.spec.always_active

    # -- set-up ---------------------------------------------------------------------------------------------
    def _derive_drives(self, stiffness_given: dict[str, float | None]) -> None:
        """Each drive's stiffness and damping from what it moves (module docstring, "Derived gains"): the mass of
        the links it carries (a revolute drive: their inertia about its axis), with the lightest target (pressed by
        a finger, it moves with the finger; about a revolute axis at the finger's reach), shared among the drives
        that press independently (the fingers' own)."""
        c, body, h = self.client, self.body, self.h
        children: dict[int, list[int]] = {}
        for j in range(c.getNumJoints(body)):
            children.setdefault(c.getJointInfo(body, j)[16], []).append(j)

        def subtree(j: int) -> list[int]:
            out, stack = [], [j]
            while stack:
                k = stack.pop()
                out.append(k)
                stack += children.get(k, [])
            return out

        masses = [c.getDynamicsInfo(uid, -1)[0] for uid in self.targets.values()]
        part = min((m for m in masses if m > 0), default=0.0)
        finger_links = set(self._finger_of_link)
        moved = {}
        self._link_mover: dict[str, dict[int, tuple[int, float]]] = {}  # per drive: link -> (joint moving it, mult)
        for name in self.names:
            movers = {k: (self.joint[name], 1.0) for k in subtree(self.joint[name])}
            for joint, master, mult, _ in self.mimics:
                if master == name:
                    movers.update({k: (joint, mult) for k in subtree(joint)})
            moved[name] = [(k, mult) for k, (_, mult) in movers.items()]
            self._link_mover[name] = movers
        carriers = {name for name in self.names if finger_links & {k for k, _ in moved[name]}}
        share = max(1, len({servos[0] for servos in self.finger_servos.values() if servos}))  # the fingers' own drives
        self.finger_forces: dict[str, float] = {}  # N: what each finger-carrying drive presses a finger with, at most
        # per finger-carrying drive: the finger links it moves, and how fast the fastest of their points moves for a
        # unit of the joint's speed (a mimic's multiplier; a revolute drive: its fingers' reach), for `_arrival`
        self._finger_travel: dict[str, tuple[list[int], float]] = {}
        for name in self.names:
            d, links = self.drives[name], moved[name]
            fingers = name in carriers
            pads = [(k, m) for k, m in links if k in finger_links]  # the finger links it moves
            jaws = sum(abs(m) for _, m in pads) or 1.0  # a linkage shares its effort out
            if self.unit[name] == "m":
                own = sum(mult * mult * c.getDynamicsInfo(body, k)[0] for k, mult in links)
                mass, floor = own + (part if fingers else 0.0), 1e-3
                if fingers:
                    self.finger_forces[name] = d.effort / jaws
                    self._finger_travel[name] = ([k for k, _ in pads], max(abs(m) for _, m in pads))
            else:
                own, reach = self._inertia_about_axis(name, links, finger_links)
                mass, floor = own + (part * reach * reach if fingers else 0.0), 1e-7
                if fingers and reach > 0.0:
                    self.finger_forces[name] = d.effort / reach / jaws  # at the fingers' reach
                    self._finger_travel[name] = ([k for k, _ in pads], reach)
            mass, own = max(mass, floor), max(own, floor)
            limit = STIFFNESS_SHARE * mass / (share * h * h)
            stiffness = stiffness_given[name] or min(d.effort / FULL_FORCE_ERROR[self.unit[name]], limit)
            # the damping acts on the drive's own links alone: a part resting on a fixture, or a finger's carriage
            # swinging against the fine axis it carries, leaves them without the part's mass, and damping derived
            # with it would overshoot every substep (a limit cycle: a squeezed heavy ring rocked by its fingers)
            self.drives[name] = Drive(d.velocity, d.effort, stiffness, DAMPING_SHARE * own / (share * h), mass, limit,
                                      own)
        # how many times the lightest part's mass (at the finger) a finger's own drive moves: the solver's sweeps
        # needed to squeeze that part between such fingers grow with it (world.py, `World.iterations_for`)
        own_drives = {servos[0] for servos in self.finger_servos.values() if servos}
        self.mass_ratio = max((self.drives[n].own / (self.drives[n].mass - self.drives[n].own) for n in own_drives
                               if self.drives[n].mass > self.drives[n].own), default=0.0)
        # the sweeps a finger's own drive needs to build its spring's force on its own links, K h^2 / m_own: many where
        # its spring was derived for a part far heavier than the finger (world.py, `SPRING_SWEEP_MARGIN`; a rigid drive,
        # a station's choice, presses with its effort at any error and is left out)
        self.spring_sweeps = max((self.drives[n].stiffness * h * h / self.drives[n].own for n in own_drives
                                  if not self.drives[n].rigid), default=0.0)

    @property
    def effort_notes(self) -> list[str]:
        """The lines of `limit_notes` (`twin info`'s warnings)."""
        return [note for _, note in self.limit_notes]

    def _defaulted_limits(self, defaulted: list[tuple[JointInput, str]]) -> list[tuple[str, str]]:
        """One warning line per drive limit that neither the URDF (a joint's <limit> velocity or effort missing, or 0,
        as exporters leave them) nor the station gives (`defaulted`: (input, "velocity" or "effort")): the default the
        drive runs with, and where to give the real one: (the limit, the line)."""
        notes = []
        for inp, what in defaulted:
            value = getattr(self.drives[inp.name], what)
            unit = f"{inp.unit}/s" if what == "velocity" else "N" if inp.unit == "m" else "N m"
            line = (f"{self.spec.urdf}: joint {inp.joint} (input {inp.name}) has no {what} limit (missing or 0): its "
                    f"drive runs with {value:g} {unit}; give the real one in the URDF's <limit {what}=...> or in "
                    f"[gripper.joints.{inp.name}] {what}")
            warn_once(str(self.spec.urdf), line, line)
            notes.append((what, line))
        return notes

    def _unreachable_efforts(self) -> list[str]:
        """One warning line per drive whose effort it cannot reach anywhere in its joint's range: its full-force
        error (effort / stiffness, the stiffness capped by what the step keeps stable for what it moves) is longer
        than the range, so a finger pressing on a part gets at most stiffness x range (an exported placeholder, such
        as 1000 N m on a 0.1 kg finger). The drive is kept as given; the station should give a real effort."""
        notes = []
        for name, d in self.drives.items():
            lo, hi = self._range[name]
            if d.stiffness > d.limit or d.full_error <= PAST_REACH * (hi - lo):
                continue
            m = self.unit[name] == "m"
            u, k = ("N", "N/m") if m else ("N m", "N m/rad")
            line = (f"{self.spec.urdf}: input {name}: effort {d.effort:g} {u} cannot be reached: the stiffest position "
                    f"loop the {self.h * 1000:g} ms substep keeps stable for what it moves ({d.stiffness:.4g} {k}) needs "
                    f"{d.full_error:.3g} {self.unit[name]} of following error for it, more than {PAST_REACH:g} times "
                    f"the joint's range ({hi - lo:.3g} {self.unit[name]}): a finger presses with at most "
                    f"{d.stiffness * (hi - lo) + d.hold:.3g} {u} (with its holding force). A placeholder? Give the "
                    f"drive's real effort in [gripper.joints.{name}] effort")
            warn_once(str(self.spec.urdf), line, line)
            notes.append(line)
        return notes

    def _inertia_about_axis(self, name: str, links, finger_links: set[int]) -> tuple[float, float]:
        """The inertia (kg m^2) about input `name`'s joint axis of the links it moves, and the reach (m) of its
        fingers: the farthest corner of their bounding boxes from the axis."""
        c, body = self.client, self.body
        j = self.joint[name]
        origin, axis = self._joint_frame(j)

        def off_axis(p) -> float:
            r = [p[i] - origin[i] for i in range(3)]
            along = sum(r[i] * axis[i] for i in range(3))
            return math.sqrt(max(0.0, sum(x * x for x in r) - along * along))

        inertia = reach = 0.0
        for k, mult in links:
            info = c.getDynamicsInfo(body, k)
            link = c.getLinkState(body, k, computeForwardKinematics=True)
            m = pybullet.getMatrixFromQuaternion(link[1])  # the link's inertial frame in the world
            local = [sum(m[3 * row + col] * axis[row] for row in range(3)) for col in range(3)]  # the axis in it
            own = sum(info[2][i] * local[i] * local[i] for i in range(3))
            inertia += mult * mult * (info[0] * off_axis(link[0]) ** 2 + own)
            if k in finger_links:
                lo, hi = c.getAABB(body, k)
                for corner in ((x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])):
                    reach = max(reach, abs(mult) * off_axis(corner))
        return inertia, reach

    def _series_couplings(self) -> dict[str, tuple[tuple[str, float], ...]]:
        """Per input, the other drives in series with it on a finger (a fine axis and the carriage it rides on) that
        a force it presses with loads, and how much: a finger pushed along its drive's motion with the drive's force
        (generalised force E over the finger's motion per unit of the drive's, |J_p|) loads another drive in its
        chain with E (J_s . J_p) / |J_p|^2 (the two drives' linear Jacobians at the finger, mimic followers counted
        with their multipliers), in the station's initial pose: a fine axis collinear with its carriage carries all
        of the carriage's force, a lift across the closing direction none."""
        c, body = self.client, self.body
        movable = [j for j in range(c.getNumJoints(body)) if c.getJointInfo(body, j)[2] != pybullet.JOINT_FIXED]
        column = {j: i for i, j in enumerate(movable)}
        q = [c.getJointState(body, j)[0] for j in movable]
        zero = [0.0] * len(movable)
        weights: dict[str, dict[int, float]] = {name: {self.joint[name]: 1.0} for name in self.names}
        for joint, master, mult, _ in self.mimics:
            weights[master][joint] = mult
        loads: dict[str, dict[str, float]] = {}
        for finger, servos in self.finger_servos.items():
            if len(servos) < 2:
                continue
            chain = self._chain(self.finger_joint[finger])
            linear = c.calculateJacobian(body, self.finger_joint[finger], [0.0, 0.0, 0.0], q, zero, zero)[0]
            cols = {}
            for name in servos:
                cols[name] = [sum(w * linear[axis][column[j]] for j, w in weights[name].items() if j in chain)
                              for axis in range(3)]
            for p in servos:
                norm = sum(v * v for v in cols[p])
                for s in servos:
                    if s == p or norm == 0.0:
                        continue
                    share = abs(sum(a * b for a, b in zip(cols[s], cols[p]))) / norm
                    if share > 1e-6:
                        loads.setdefault(p, {})[s] = max(share, loads.get(p, {}).get(s, 0.0))
        return {p: tuple(sorted(ss.items())) for p, ss in loads.items()}

    def chain_effort(self, name: str) -> float:
        """The most input `name` presses a finger with, along its own motion: its effort, or less where the force
        passes through drives in series that hold less (a carriage through a weaker fine axis, or the other way
        round: statics, a finger's force is at most the weakest effort in its chain)."""
        return min([self.drives[name].effort]
                   + [self.drives[other].effort / share for other, share in self._series_loads.get(name, ())])

    def _chain(self, joint: int) -> list[int]:
        """`joint` and the joints between it and the body's base, nearest first."""
        chain = []
        while joint >= 0:
            chain.append(joint)
            joint = self.client.getJointInfo(self.body, joint)[16]  # the parent link's (= its joint's) index
        return chain

    def _closing_directions(self) -> dict[str, float]:
        """Per input, +1 or -1: the way that brings the fingers together (the spread of their collision shapes'
        centres about their common centre shrinks), found by moving each input a little in the loaded world and
        putting it back. The shapes, not the link frames: a revolute finger's frame often sits on its pivot (a
        mesh finger's, as in pybullet_data's pr2_gripper) and moves the other way round than its surface."""
        c, body = self.client, self.body
        fingers = [links for links in self.finger_links.values() if links]
        if not fingers:
            return {n: -1.0 for n in self.names}

        def shape_centre(links):
            shaped = [k for k in links if c.getCollisionShapeData(body, k)]
            if not shaped:  # no collision shape: the link's frame is all there is
                return c.getLinkState(body, links[0], computeForwardKinematics=True)[0]
            boxes = [c.getAABB(body, k) for k in shaped]  # a box's centre is a point fixed in its link
            return [(min(b[0][i] for b in boxes) + max(b[1][i] for b in boxes)) / 2 for i in range(3)]

        # one finger: its distance from the part it is nearest to (a ram pressing a part onto an anvil, a jaw closing
        # on a fixed one with the part between), or from the base where the station has no target
        alone = None
        if len(fingers) == 1:
            here = shape_centre(fingers[0])
            alone = min((c.getBasePositionAndOrientation(uid)[0] for uid in self.targets.values()),
                        key=lambda p: math.dist(p, here), default=None)
            if alone is None:
                alone = (c.getBasePositionAndOrientation(body)[0] if self.base_link < 0
                         else c.getLinkState(body, self.base_link, computeForwardKinematics=True)[0])

        def points():
            pts = [shape_centre(links) for links in fingers]
            if alone is not None:
                pts.append(alone)
            return pts

        def spread(pts, centre):
            return sum(math.dist(p, centre) for p in pts)

        pts = points()
        centre = [sum(p[i] for p in pts) / len(pts) for i in range(3)]
        base = spread(pts, centre)
        result = {}
        for name in self.names:
            inp = self.mechanism.input(name)
            q = self.setpoint[name]
            delta = (0.001 if inp.unit == "m" else 0.01) * (1 if q + 0.001 <= inp.max else -1)
            self._set_input(name, q + delta)
            moved = spread(points(), centre) - base
            self._set_input(name, q)
            result[name] = (-1.0 if moved > 0 else 1.0) * (1 if delta > 0 else -1)
        return result

    def _set_input(self, name: str, q: float) -> None:
        c = self.client
        c.resetJointState(self.body, self.joint[name], q)
        for joint, master, mult, off in self.mimics:
            if master == name:
                c.resetJointState(self.body, joint, mult * q + off)

    def _couple(self, joint: int, master: str, mult: float, off: float) -> int:
        """Tie a mimic joint to its master as a mechanism does (a gear constraint: joint = mult * master + off): the
        master's drive moves the whole linkage (its motors on every joint, `_linkage`), and a part pushing one coupled
        finger pushes them all (a self-centring chuck centres its part)."""
        c = self.client
        c.setJointMotorControl2(self.body, joint, pybullet.VELOCITY_CONTROL, targetVelocity=0.0, force=0.0)
        gear = c.createConstraint(self.body, joint, self.body, self.joint[master], pybullet.JOINT_GEAR,
                                  [0, 0, 1], [0, 0, 0], [0, 0, 0])
        # the constraint holds q_joint + gearRatio * q_master = relativePositionTarget
        c.changeConstraint(gear, gearRatio=-mult, relativePositionTarget=off, erp=MIMIC_ERP,
                           maxForce=MIMIC_FORCE_FACTOR * self.drives[master].effort * max(1.0, abs(mult)))
        return gear

    def _settle_linkages(self, pressed: set[str]) -> None:
        """Each linkage of parallel jaws: its gears rigid while any of its fingers is free, let go
        (MIMIC_SETTLED_FACTOR) once every one presses on a part. (A linkage whose joints lie in series, as a finger's
        knuckles do, stays rigid: its gears carry the finger.)"""
        for master, gears in self._gears.items():
            settled = all(f in pressed for f in self._fingers_of_servo[master])
            if settled != self._settled_linkages.get(master, False):
                self._settled_linkages[master] = settled
                factor = MIMIC_SETTLED_FACTOR if settled else MIMIC_FORCE_FACTOR
                effort = self.drives[master].effort
                for gear, mult in gears:
                    self.client.changeConstraint(gear, maxForce=factor * effort * max(1.0, abs(mult)))

    # -- every substep ------------------------------------------------------------------------------------
    def _reset_sums(self) -> None:
        self._n = 0
        self._effort_sum = [0.0] * len(self.names)
        self._force_sum: dict[tuple[str, int], float] = {}

    def drive(self, substep: int = 0) -> None:
        """Before a physics substep: move each command on along its ramp and set each drive's velocity and force.
        Drives that all stand still at their goal, pressing on nothing, keep the first substep's settings for the
        rest of the step: nothing changes there but cost. The joints' states are those `measure` read after the
        substep before (nothing moves the joints in between)."""
        self._step_ticks += 1
        self._ticks += 1
        self._substep_count += 1
        if substep and self._quiet:
            return
        if self._resting is not None:
            if self._still_resting():
                return
            self._resting = None
        if not self.active and self._hold is None:
            self._hold = dict(self.command_position)
        elif self.active:
            self._hold = None
        goal = self._hold if self._hold is not None else self.setpoint
        h = self.h
        states = self._states
        if states is None:
            states = self._states = self._joint_states(self.body, self._joint_ids)
        velocities, forces = [], []
        quiet = True
        drives, command, stalled, turned = self.drives, self.command_position, self._stalled, self._new_goal
        past, units, ends = self._past, self.unit, self._range
        axes, presses, loads = self.state.axes, self._presses, self._series_loads  # as the last step left them
        constants = self._constants
        if constants is None:
            constants = self._constants = self._drive_constants()
        holding, now_holding = self._holding, set()  # series drives holding rigidly, as the last substep left them
        index, series_share = self._index, self._series_share
        for (name, moving, full, velocity, effort, held_speed, rise_rate, release, latch, follow, at_limit, in_loads,
             in_holders, in_series, own_share, rigid, stiffness, damping, hold, arrival), (actual, joint_speed, _, _), \
                moved in zip(constants, states, self._speeds):
            g = goal[name]
            before = command[name]
            pressing = presses[name]  # a finger it moves pressed on a part in the last step
            short = False  # a drive in one of the states a cell stands in, which the loop below gives in short
            if pressing and not in_series and name not in turned and name not in past:
                # pressing on a part, with no new goal: its command at its goal (a setpoint within full force past the
                # part; pressing through drives in series, while those its force loads stand at theirs: the ring rig's
                # carriage and fine axis carrying the ring), or, alone, stalled short of it on a part that holds: the
                # command stays, and so does its stall (its way)
                way = stalled.get(name)
                if way is None:
                    short = before == g and (in_holders or actual - full <= g <= actual + full)
                    if short and in_loads and in_holders and not rigid:
                        for other, _ in loads[name]:
                            if command[other] != goal[other]:
                                short = False  # (the loop below asks whether it must hold rigidly against the other)
                                break
                elif not in_loads:
                    pushed = (before - actual) * way  # how far its command stands past the joint, the way it presses
                    short = ((g - before) * way > 0.0 and pushed > release and pushed >= follow
                             and actual - full <= before <= actual + full)
                target = before
            elif before == g and not pressing and name not in turned and stalled.get(name) is None:
                # standing at its goal, pressing on nothing (a cell at rest, a drive the arm carries): the goal itself,
                # within full force of the joint unless others press through it
                way, short = None, True
                target = g if in_holders else min(max(g, actual - full), actual + full)
                if target != g:
                    command[name] = target
            if short:  # (the same values as the loop below, without the cases that cannot arise here)
                error = target - actual
                speed = error / h
                if abs(error) >= at_limit and (joint_speed if error > 0.0 else -joint_speed) <= 0.0:
                    speed = max(abs(speed), PUSH_SPEEDUP * velocity) * (1.0 if error > 0.0 else -1.0)
                elif abs(speed) > velocity and moved * error >= held_speed * abs(error):
                    speed = velocity if speed > 0.0 else -velocity
                velocities.append(speed)
                forces.append(effort if rigid else min(effort, abs(stiffness * error - damping * joint_speed) + hold))
                quiet = (quiet and way is None and abs(axes[name].velocity if axes else joint_speed) < moving
                         and stiffness * abs(error) <= hold)
                continue
            if name in turned:
                turned.discard(name)
                past.pop(name, None)
                if (g - actual) * (before - actual) < 0.0:
                    before = actual  # a new goal the other way: the drive turns at once, from where the joint is
                    stalled[name] = None
            way = stalled.get(name)
            if (way is not None and (before - actual) * way > release
                    and ((g - before) * way > 0.0 or name in past and (g - actual) * way > PAST_GAP[units[name]])):
                # stalled on a part: the command waits, so the finger holds where the part stopped it
                target = before
                if (target - actual) * way < follow:
                    # the part gave way: followed, pressing as stalled
                    target = actual + way * latch
                    if (g - target) * way < 0.0 and name not in past:
                        target = g
            else:
                way = None
                rate = velocity
                side = past.get(name)
                aim = g if side is None else actual + side * latch  # (pressing past its range's end: to full force)
                if ((before - actual) * (aim - actual) > 0.0 and pressing
                        and (moved if aim > actual else -moved) < held_speed):
                    # pressing on a part that holds the finger (held: the joint moved slower than HELD_SHARE of
                    # its velocity limit the way its goal lies, last substep): full force within the rise time (a
                    # part that gives way is pushed at the velocity limit, as a real servo's speed loop does, not
                    # run over by the command)
                    rate = max(rate, rise_rate)
                run = rate * h  # (the command moved towards its goal by at most that, landing exactly on it)
                target = aim if abs(aim - before) <= run else before + (run if aim > before else -run)
                if side is not None and target == aim:
                    way = side  # (at full force past its range's end: stalled there)
            # the command runs ahead of a blocked joint no further than full force: a new setpoint acts at once. A
            # drive others press through (a fine axis under its carriage) keeps a command that stands at its goal:
            # pushed off it, it pushes back with its effort, and is not dragged along into a stall of its own
            if target != g or not in_holders:
                target = min(max(target, actual - full), actual + full)
            if (target != g and abs(target - actual) >= latch
                    and (g - actual) * (target - actual) > 0.0 and pressing):
                if way is None:  # stalls now: at exactly that error, however far its ramp's last substep ran on
                    # past it, so fingers that stall a substep apart press alike (a squeezed part does not jump)
                    target = actual + (1.0 if target > actual else -1.0) * latch
                # held short of its goal by a part, at its force limit: stalled
                way = 1.0 if target > actual else -1.0
            elif (way is None and target == g and pressing and name in self._pressing_past
                  and PAST_GAP[units[name]] < (g - actual) * (1.0 if g > actual else -1.0) < latch
                  and (moved if g > actual else -moved) < held_speed
                  and (g >= ends[name][1] - PAST_GAP[units[name]] if g > actual
                       else g <= ends[name][0] + PAST_GAP[units[name]])):
                # held by a part short of its range's end, sent there (closed all the way), the end closer past the
                # part than full force (a short stroke): from the next substep its command runs on past the end, at the
                # force's rise rate, and stalls at full force as any drive (the spring at the end would give a fraction
                # of it: a setpoint within the range presses with what the spring gives there); it aims at its goal
                # again once the part gives way to within its in-position tolerance of it
                past[name] = 1.0 if g > actual else -1.0
            if name in past and (not pressing or (g - actual) * past[name] <= PAST_GAP[units[name]]):
                del past[name]
            stalled[name] = way
            command[name] = target
            error = target - actual
            speed = error / h  # to be at the command after the substep, as far as the force allows
            # (rigid: stiffer than the step resolves, a station's choice: rigid up to its effort)
            leaning = False
            if pressing and in_loads:
                if target != g:  # pressing through drives in series: leaning on those that stand at their goals
                    leaning = any(command[other] == goal[other] for other, _ in loads[name])
                elif not rigid and in_holders:
                    for other, _ in loads[name]:
                        if command[other] == goal[other]:
                            continue
                        # at its goal, another drive pressing on through it: by their springs in series the finger
                        # would press with K_series times how far its setpoint lies past where it stands (the sum of
                        # both drives' errors), up to the chain's weakest effort. Where that reaches the effort (a
                        # carriage sent to its range's end), it holds its goal rigidly instead, as a fine axis
                        # stiffer than the step resolves: the finger presses with that effort either way, and its
                        # spring, derived for its finger and the part, would act between a part that stands and the
                        # light carriage a constant force pushes on (too stiff for that mass: the carriage rattles
                        # between them, the drives trading places, the part walking)
                        do, share = drives[other], series_share[other].get(name, 0.0)
                        if not share:
                            continue
                        gap = abs(goal[other] - states[index[other]][0]) + share * abs(g - actual)
                        springs = 1.0 / (1.0 / do.stiffness + share * share / stiffness)
                        if springs * gap >= LATCH_FRACTION * min(do.effort, effort / share):
                            rigid = True
                            now_holding.add(name)
                            break
            if in_series and pressing and not rigid and not any(o in holding for o, _ in loads[name]):
                # drives in series on one pressed finger (a fine axis on its carriage): the part holds their sum, and
                # what moves between them is their own links alone, not the part: each taking its whole error out
                # in one substep throws the pair against each other (every substep, the part standing); each takes
                # out the share of it that its own links bear to the mass its gains were derived for (leaning on
                # one that holds rigidly, it presses alone, as on a fine axis stiffer than the step resolves)
                speed *= own_share
            if abs(error) >= at_limit and (joint_speed if error > 0.0 else -joint_speed) <= 0.0:
                # at its force limit and held (or pushed) back: pybullet's solver builds a motor's force only as fast
                # as the speed it asks for, so a held drive asks for far more than it can have: it presses at its limit
                speed = max(abs(speed), PUSH_SPEEDUP * velocity) * (1.0 if error > 0.0 else -1.0)
            elif abs(speed) > velocity and moved * error >= held_speed * abs(error):
                # running free (a part that gives way, a finger catching up): never faster than the velocity limit;
                # a held joint asks for more (the solver builds the force against the part from that speed)
                speed = velocity if speed > 0.0 else -velocity
            if arrival is not None and way is None and not pressing:
                speed = self._arrival(name, arrival, speed)
            velocities.append(speed)
            if leaning:
                # pressing through drives in series that stand at their goals (a carriage through its fine axis):
                # never harder than they hold, less a reserve, or the one that holds is pushed off its goal at its
                # limit and the pair trade places, the finger standing (status 0, `moving`, while it presses)
                for other, share in loads[name]:
                    if command[other] == goal[other]:
                        effort = min(effort, SERIES_HOLD * drives[other].effort / share)
            if rigid:
                forces.append(effort)
            else:
                forces.append(min(effort, abs(stiffness * error - damping * joint_speed) + hold))
            quiet = (quiet and before == g and abs(axes[name].velocity if axes else joint_speed) < moving
                     and stiffness * abs(error) <= hold)  # a pressing drive: every substep
        if quiet and self._quiet and substep == 0:
            # quiet for a second step: the drives rest (`_still_resting`), each held where its command stands by
            # pybullet's own position motor, taking out a substeps-th of its error at each substep (what the
            # loop asks of a quiet drive), with the force the loop gives it
            positions = [command[name] for name in self.names]
            if self._linkage:
                positions, forces = self._linkage_command(positions, forces, True)
            self._motors(self.body, self._motor_ids, pybullet.POSITION_CONTROL,
                         targetPositions=positions, targetVelocities=[0.0] * len(forces),
                         forces=forces, positionGains=[1.0 / self.substeps] * len(forces),
                         velocityGains=[1.0] * len(forces))
            self._sent = None  # (the loop's next command is sent whatever it is)
            bounds = []
            for name, unit, _ in self._per_input:
                d = drives[name]
                allowed = min(RESTING_DRIFT * d.hold / d.stiffness if d.stiffness else 0.0,
                              0.5 * IN_POSITION_TOLERANCE[unit])
                bounds.append((command[name] - allowed, command[name] + allowed))
            self._resting = (self.active, bounds)
            self._quiet, self._holding = quiet, now_holding
            return
        if quiet and substep == 0 and self.substeps > 1:  # these settings hold for the whole step: the small error
            velocities = [v / self.substeps for v in velocities]  # left is taken out over it, not in every substep
        self._quiet = quiet
        self._holding = now_holding
        sent = (velocities, forces)
        if sent != self._sent:  # pybullet keeps a motor's command: the same one needs no call
            self._sent = sent
            if self._linkage:
                velocities, forces = self._linkage_command(velocities, forces, False)
            self._motors(self.body, self._motor_ids, pybullet.VELOCITY_CONTROL, targetVelocities=velocities,
                         forces=forces)

    def _linkage_command(self, values: list[float], forces: list[float], positions: bool) -> tuple[list, list]:
        """The inputs' motor command (velocities, or positions) and forces, spread over their linkages' joints: each
        follower moves as its multiplier says, and takes its share of its master's force (`_linkage`)."""
        values = values + [mult * values[i] + (off if positions else 0.0) for i, _, mult, off in self._linkage]
        shared = [f * share for f, share in zip(forces, self._master_share)]
        return values, shared + [shared[i] for i, _, _, _ in self._linkage]

    def _still_resting(self) -> bool:
        """Whether resting drives rest on: each holds where its command stands (pybullet's position motor, with the
        force the quiet step gave it), and nothing in them is worked out at all while no setpoint, limit or `Active`
        changes, no finger presses on a part, and every joint stays within its bounds (`sense` looks): RESTING_DRIFT
        times the error a quiet drive's holding force allows, at most half its in-position tolerance. (A cell at rest
        asked for its drives' whole loop at every step: a third of the twin's own Python there.)"""
        return not (self._new_goal or self.pressing or self._constants is None or self._resting[0] != self.active)

    def _drive_constants(self) -> list[tuple]:
        """Per input (`names` order), what `drive` asks of its drive at every substep, formed once (again after
        `set_limits`): its name, the speed under which it stands, its full-force error, velocity, effort,
        the speed under which it is held, the force rise's rate, its release, latch and follow errors, the error at its
        limit, whether it presses through drives in series (and which hold others), whether it has springs in series,
        its own links' share of its mass, and the drive's rigidity, stiffness, damping and holding force."""
        out = []
        # the drives that may press past their range's end where it lies closer past the part than full force
        # (`_past`): alone on its finger (no drives in series), not rigid, its effort within reach of its range
        # (PAST_REACH)
        self._pressing_past = {name for name, d in self.drives.items()
                               if not (d.rigid or name in self._series_loads or name in self._series_holders
                                       or self._series[name] > 1)
                               and d.full <= PAST_REACH * (self._range[name][1] - self._range[name][0])}
        for name, _, moving in self._per_input:
            d = self.drives[name]
            full = d.full
            out.append((name, moving, full, d.velocity, d.effort, HELD_SHARE * d.velocity, full / self.rise_time,
                        RELEASE_FRACTION * full, full * LATCH_FRACTION, full * FOLLOW_FRACTION, full * (1.0 - 1e-9),
                        name in self._series_loads, name in self._series_holders, self._series[name] > 1,
                        d.own / d.mass if d.mass else 0.0, d.rigid, d.stiffness, d.damping, d.hold,
                        self._arrival_constants(name, d)))
        return out

    def derived_notes(self) -> list[str]:
        """What the drives do beyond their gains, one line each (`twin info`): how a linkage's drive shares its force
        among its joints, and where fast fingers slow down for a part."""
        lines = []
        for i, name in enumerate(self.names):
            followers = [m.joint for m in self.mechanism.mimics if m.master == self.mechanism.input(name).joint]
            if followers:
                d, share = self.drives[name], self._master_share[i]
                unit = "N" if self.unit[name] == "m" else "N m"
                joints = ", ".join([self.mechanism.input(name).joint] + followers)
                lines.append(f"linkage: {name} drives {joints}, each joint's motor with {d.effort * share:.4g} "
                             f"{unit} ({d.effort:g} {unit} over the sum of the multipliers' sizes, {1.0 / share:g}); "
                             "its gears " + ("let go once every jaw presses" if name in self._gears else "stay rigid"))
        for name, d in self.drives.items():
            arrival = self._arrival_constants(name, d)
            if arrival is not None:
                _, rate, _, sight = arrival
                fastest = d.velocity * rate
                lines.append(f"arrival: {name}'s fingers move up to {fastest:.3g} m/s ({fastest * self.h * 1000:.3g} mm "
                             f"a substep); nearing a target, within {(sight - fastest * self.h) * 1000:.3g} mm, they "
                             f"slow down to reach it at {ARRIVAL_TRAVEL * 1000:g} mm a substep at most")
        return lines

    def _arrival_constants(self, name: str, d: Drive) -> tuple | None:
        """For a drive whose fingers may move further than ARRIVAL_TRAVEL in a substep: its finger links, their
        travel per unit of its speed, the deceleration they may slow down with, and how far ahead a part is looked
        for (from there on they slow down; a substep's travel more). Else None."""
        links, rate = self._finger_travel.get(name, ((), 0.0))
        fastest = d.velocity * rate  # m/s at the fingers
        if not links or fastest * self.h <= ARRIVAL_TRAVEL * (1.0 + 1e-9) or d.effort <= 0.0:
            return None
        braking = ARRIVAL_BRAKING * d.effort / max(d.own, 1e-9) * rate  # m/s^2 at the fingers
        sight = max(2.0 * self.h * fastest, fastest * fastest / braking) + fastest * self.h
        return links, rate, braking, sight

    def _arrival(self, name: str, arrival: tuple, speed: float) -> float:
        """`speed` (a drive's, running free), slowed down so that its fingers reach a target gently: within sight of
        one and nearing it, they close half the gap a substep (no faster than the drive can still brake from,
        sqrt(a gap)) until that is slower than ARRIVAL_TRAVEL a substep; then they move on at that, the last
        substep landing ARRIVAL_DEPTH into the part. Moving away from a part, they are not slowed."""
        links, rate, braking, sight = arrival
        c, body, h = self.client, self.body, self.h
        gap, nearest = sight, None
        for link in links:
            for uid in self._targets_near(link, sight):
                for pt in c.getClosestPoints(body, uid, sight, linkIndexA=link):
                    if pt[8] < gap:
                        gap, nearest = pt[8], pt
        seen = self._gaps.get(name)  # (the gap the substep before, if it looked)
        last = seen[1] if seen is not None and seen[0] == self._substep_count - 1 else None
        self._gaps[name] = (self._substep_count, gap)
        if gap >= sight or (last is not None and gap > last):
            return speed  # (out of sight, or moving away)
        if (last is None or gap == last) and not self._moves_towards(name, nearest, speed):
            return speed  # (setting off from beside a part, away from it)
        gap = max(gap, 0.0)
        final = min(ARRIVAL_TRAVEL, gap + ARRIVAL_DEPTH) / h
        cap = min(max(gap / (2.0 * h), final), final + math.sqrt(braking * gap)) / rate
        return speed if abs(speed) <= cap else (cap if speed > 0.0 else -cap)

    def _moves_towards(self, name: str, point, speed: float) -> bool:
        """Whether input `name` running at `speed` moves the finger link of closest point `point` (a pybullet
        closest-points row) towards the part there: against the normal on the part, by the joint that moves that link
        (a mimic's with its multiplier), along its axis (prismatic) or about it (revolute)."""
        joint, mult = self._link_mover[name][point[3]]
        origin, axis = self._joint_frame(joint)
        if self._joint_kind(joint)[0] == pybullet.JOINT_PRISMATIC:
            motion = axis
        else:  # the contact point's motion about the axis: axis x (point - origin)
            motion = cross(axis, [point[5][i] - origin[i] for i in range(3)])
        return sum(motion[i] * point[7][i] for i in range(3)) * mult * speed < 0.0

    def read_along(self, joints: list[int]) -> None:
        """Read `joints` (of the same body) with the inputs' joints after each step's last substep, into `along`
        (one pybullet call where the twin would make two)."""
        self._along_ids = self._joint_ids + list(joints) if joints else []
        self._along_from = len(self._joint_ids)
        self.along = ()

    def coast(self, substeps: int) -> None:
        """`substeps` physics substeps run while every drive stands quiet (`quiet`): they keep the step's first
        substep's settings and nothing is measured before the last (`drive` and `measure` would do nothing else)."""
        self._step_ticks += substeps
        self._ticks += substeps
        self._substep_count += substeps

    @property
    def step_positions(self) -> list[float] | None:
        """The input joints' positions (`joint_ids`' order) as read after the last step's last substep."""
        return self._step_positions

    @property
    def joint_ids(self) -> list[int]:
        return self._joint_ids

    @property
    def quiet(self) -> bool:
        """Every drive stood at its goal, pressing on nothing, at the last step's first substep."""
        return self._quiet

    def measure(self, last: bool = True) -> None:
        """After a physics substep: add up the drives' applied forces; after the step's last, read the fingers'
        contact forces. While every drive stands quiet, the step's last substep alone is read (nothing moves in
        between)."""
        self._palm_now = None
        if self._quiet and not last:
            return
        self._n += 1
        before = self._states
        if last and self._along_ids:
            states = self._joint_states(self.body, self._along_ids)
            self.along, states = states[self._along_from:], states[:self._along_from]
        else:
            states = self._joint_states(self.body, self._joint_ids)
        self._states = states
        if before is not None:  # how fast each joint ran, from its positions (pybullet's joint velocity reads the
            # motor's target where a contact holds the joint back): whether a part holds it (`drive`)
            elapsed = self._ticks * self.h
            self._speeds = [(s[0] - b[0]) / elapsed for s, b in zip(states, before)]
        self._ticks = 0
        if self._linkage:  # (a master's motor applies its share of the drive's force: the drive's, as the linkage's)
            self._effort_sum = [e + s[3] / k for e, s, k in zip(self._effort_sum, states, self._master_share)]
        else:
            self._effort_sum = [e + s[3] for e, s in zip(self._effort_sum, states)]
        if not last:  # the contacts' forces: as the step's last substep leaves them (one query a step, not one a
            return  # substep: a held part's dozen contact points cost a quarter of the twin's own work in motion)
        sums, key_of = self._force_sum, self._link_keys.get
        if self._joint_frames:
            self._joint_frames.clear()
        axes = self._joint_frames
        for pt in self._contact_points(self.body):  # one query for all of the machine's contacts (a crowded cell's
            # parts that touch nothing cost nothing), its finger links' on targets kept
            force = pt[9]
            if force <= 0.0:
                continue
            key = key_of((pt[3], pt[2]))
            if key is None:  # not a finger link on a target
                continue
            key, revolute = key
            if revolute:
                force = abs(self._torque(key[0], pt))
            else:  # the contact's whole force along the finger's joint axis (`_thrust_axis`; in line: every contact)
                frame = axes.get(key[0])
                if frame is None:
                    frame = self._thrust_axis(key[0])
                if frame:
                    a0, a1, a2 = frame
                    n = pt[7]
                    along = n[0] * a0 + n[1] * a1 + n[2] * a2
                    if -FACING < along < FACING:  # (facing the axis closer than that: friction adds < 1.4 % of it)
                        d1, d2 = pt[11], pt[13]
                        force = abs(along * force + (d1[0] * a0 + d1[1] * a1 + d1[2] * a2) * pt[10]
                                    + (d2[0] * a0 + d2[1] * a1 + d2[2] * a2) * pt[12])
                    else:
                        force *= abs(along)
            sums[key] = sums.get(key, 0.0) + force

    def _torque(self, finger: str, pt) -> float:
        """The torque about a revolute finger's joint axis of one contact's force (normal and friction) on the part."""
        frame = self._joint_frames.get(finger)
        if frame is None:  # (read once per substep)
            frame = self._joint_frames[finger] = self._joint_frame(self.finger_joint[finger])
        origin, axis = frame
        r = [pt[5][i] - origin[i] for i in range(3)]
        # the contact's whole force on B (the normal on B points at A, the finger: -n N; and its friction), as the
        # joint carries it in statics (the normal force alone reads 10 % short where friction carries a share)
        f = [-(pt[7][i] * pt[9] + pt[10] * pt[11][i] + pt[12] * pt[13][i]) for i in range(3)]
        tau = cross(r, f)
        return sum(tau[i] * axis[i] for i in range(3))

    def _thrust_axis(self, finger: str) -> tuple | bool:
        """A prismatic finger's joint axis in the world, worked out once a step for every prismatic finger: the
        contacts' whole force (normal and friction) along it is what its drive carries in statics, whatever way they
        face (a V-groove's flanks, a part turned in the grip), as a revolute finger's torque (`_torque`). An axis
        that only slides relative to the palm is the palm's rotation of a fixed one: one pybullet query a step for
        all, the palm's pose, which the slip watch then reads too. False for a finger on a fixed joint: its contacts'
        normal force."""
        sliding = self._sliding
        if sliding is None:
            sliding = self._sliding = self._sliding_axes()
        frames = self._joint_frames
        if sliding:
            pose = self._palm_now = self._base_pose()
            m = pybullet.getMatrixFromQuaternion(pose[1])
            for f, joint, axis, in_palm in sliding:
                if in_palm:
                    frames[f] = _turn(m, axis)
                else:  # (a joint a revolute one turns relative to the palm: its own link's frame)
                    frames[f] = _rotate(self.client.getLinkState(self.body, joint)[5], axis)
        return frames.setdefault(finger, False)

    def _sliding_axes(self) -> list[tuple]:
        """Per finger on a prismatic joint: (finger, joint, axis, True) with its axis in the palm's frame where only
        prismatic and fixed joints lie between them, else (finger, joint, its axis in its own frame, False)."""
        c, body, out = self.client, self.body, []
        palm = c.getMatrixFromQuaternion(self._base_pose()[1])
        for f in self.finger_links:
            joint = self.finger_joint[f]
            kind, axis = self._joint_kind(joint)
            if kind != pybullet.JOINT_PRISMATIC:
                continue
            link, rigid = c.getJointInfo(body, joint)[16], True
            while link not in (self.palm_link, -1):
                info = c.getJointInfo(body, link)
                rigid = rigid and info[2] in (pybullet.JOINT_PRISMATIC, pybullet.JOINT_FIXED)
                link = info[16]
            if rigid and link == self.palm_link:
                w = _rotate(c.getLinkState(body, joint, computeForwardKinematics=True)[5], axis)
                out.append((f, joint, _unturn(palm, w), True))
            else:
                out.append((f, joint, axis, False))
        return out

    def _joint_kind(self, joint: int) -> tuple[int, tuple]:
        """A joint's type and its axis in its own frame (read from pybullet once)."""
        kind = self._joint_kinds.get(joint)
        if kind is None:
            info = self.client.getJointInfo(self.body, joint)
            kind = self._joint_kinds[joint] = (info[2], info[13])
        return kind

    def _joint_frame(self, joint: int) -> tuple[tuple, tuple]:
        """A joint's origin and axis in the world, where its links stand now (computed from the joints' positions:
        pybullet's link state without that is where they stood at the last substep's start, a substep's travel
        behind a moving arm)."""
        state = self.client.getLinkState(self.body, joint, computeForwardKinematics=True)
        return state[4], _rotate(state[5], self._joint_kind(joint)[1])  # (the child link's URDF frame: the joint's)

    # -- after each step --------------------------------------------------------------------------------------
    def sense(self) -> None:
        """Read joints, efforts and contacts after physics; decide grip, attachment, slip and status."""
        measured = self._n
        n = max(1, measured)
        if not measured:  # no substep measured since the last sense (a new gripper): read the joints now
            self._states = self._joint_states(self.body, self._joint_ids)
        positions = [s[0] for s in self._states]
        last = self._step_positions or positions
        dt = max(1, self._step_ticks) * self.h
        self._step_positions, self._step_ticks = positions, 0
        window = self._window
        oldest, span = (window[0], len(window) * self.substeps * self.h) if window else (last, dt)
        window.append(positions)
        axes = {}
        # (lo, hi: the joint's stop: the solver's give at a stop is no position the joint has)
        for (name, lo, hi, _), q, before, effort, (_, _, moving), then in zip(self._ranges, positions, last,
                                                                             self._effort_sum, self._per_input, oldest):
            speed = (q - before) / dt
            axes[name] = AxisState(min(max(q, lo), hi), speed, effort / n if measured else 0.0,
                                   (speed > moving or speed < -moving) and abs(q - then) > moving * span)
        self.state.axes = axes
        if self._resting is not None:  # resting drives rest on while each joint stays within its bounds
            for q, (lo, hi) in zip(positions, self._resting[1]):
                if not lo <= q <= hi:
                    self._resting = None  # (the next step's loop takes the error out, and its command is sent)
                    break
        friction = self.spec.grip == "friction"
        reached = self._reached(axes) if friction else {}
        if friction and not self._force_sum and not reached:  # no finger pressed on anything in this step, and
            # none that moves overlaps a target: none touches
            goals = self._hold if self._hold is not None else self.setpoint
            if self._resting is not None:  # (each joint within half its in-position tolerance of its goal)
                statuses = self._settled_statuses
            else:
                for name, _, _, tolerance in self._ranges:
                    if abs(goals[name] - axes[name].actual) > tolerance:
                        statuses = [self._status(f, axes, False) for f in self.finger_links]
                        break
                else:  # every axis at its goal: what `_status` gives every finger touching nothing
                    statuses = self._settled_statuses
            if statuses != self._idle_statuses:  # (else the fingers' states of the step before hold, unchanged)
                self.state.fingers = {f: FingerState((), 0, {}, status)  # (0: an empty sum)
                                      for f, status in zip(self.finger_links, statuses)}
                self._idle_statuses = statuses
            self._presses, self.pressing = self._pressing_none, False
            if self._gears:
                self._settle_linkages(set())
            self._n, self._effort_sum = 0, [0.0] * len(self.names)  # (the force sums are empty)
            if self._grip_reference is None:  # no finger touches: nothing is gripped, and no part is watched for slip
                self.state.gripped = ""
            else:
                self._grip_rule()
            return
        self._idle_statuses = None
        pressing: dict[str, dict[str, float]] = {}
        for (finger, uid), total in self._force_sum.items():
            pressing.setdefault(finger, {})[self._target_by_id[uid]] = total
        fingers = {}
        for finger in self.finger_links:
            pressed = pressing.get(finger)
            on = {t: pressed[t] for t in self.targets if pressed.get(t, 0.0) > 0.0} if pressed else {}
            # friction mode: no contact without a normal force (or, moving, an overlap: `_reached`), so a finger
            # pressing on nothing needs no query
            if on and friction and all(f >= self._release_force[finger] for f in on.values()):
                touching = tuple(on)  # pressing with a quarter of its grip force or more: touching, no query needed
            else:
                touching = self._touching(finger, CONTACT_SLACK) if on else () if friction else self._touching(finger)
            contacts = tuple(t for t in touching if not friction or t in on)
            if finger in reached:
                contacts = tuple(t for t in self.targets if t in contacts or t in reached[finger])
            force = sum(on.values())
            fingers[finger] = FingerState(contacts, force, on, self._status(finger, axes, bool(contacts)))
        self.state.fingers = fingers
        pressed = {f for f, state in fingers.items() if state.force > 0.0}
        self._presses = {name: not pressed.isdisjoint(fs) for name, fs in self._fingers_of_servo.items()}
        if self._gears:
            self._settle_linkages(pressed)
        self.pressing = bool(pressed)  # a finger pressed on a part in this step
        self._reset_sums()
        self._grip_rule()

    def touched_bodies(self) -> set[int]:
        """The targets (body ids) a finger touches, as the last step sensed them."""
        targets = self.targets
        return {targets[t] for f in self.state.fingers.values() for t in f.contacts}

    def _grip_rule(self) -> None:
        """Grip, attachment and slip from the fingers' contacts and forces of the step just sensed."""
        held = self.state.gripped
        if held and self._pressed_by_all(self._release_force, held):
            gripped = [held]  # hysteresis: a grip lasts while every finger presses with a quarter of the grip force
        else:
            gripped = self._pressed_by_all(self.grip_force)
        if self.spec.grip == "attach":
            held = self.state.attached
            if held and held not in self._pressed_by_all(self.attach_force, held):
                self._release()
            if not self.state.attached:
                candidates = self._pressed_by_all(self.attach_force)
                if candidates:
                    self._attach(candidates[0])
        newly = gripped[0] if gripped else ""
        if newly and newly != self.state.gripped:
            self._grip_reference = (newly, self._relative_position(newly))
            self._slip_part, self.state.slip, self.state.slip_distance = newly, False, 0.0
            self._opened_since_grip, self._lost_steps = False, 0
        self.state.gripped = newly
        self._watch_slip()
        self._palm_now = None

    def _pressed_by_all(self, threshold: dict[str, float], only: str | None = None) -> list[str]:
        """The targets (station order) every finger presses on with at least its threshold force."""
        fingers = self.state.fingers
        if not fingers or not all(f.contacts for f in fingers.values()):
            return []
        names = [only] if only else list(self.targets)
        return [t for t in names if all(t in f.contacts and f.pressing.get(t, 0.0) >= threshold[name]
                                        for name, f in fingers.items())]

    def _reached(self, axes: dict[str, AxisState]) -> dict[str, tuple[str, ...]]:
        """Friction mode: the targets that fingers moving in this step, and pressing on nothing, overlap (their true
        shapes). Such a finger reached the part in the step's last substep: pybullet's contact, and its force, come
        with the next substep, and its flag would rise a step late (0.1 mm into the part at 0.04 m/s)."""
        out = {}
        if self._quiet:  # (every drive stood still at its goal in this step: a cell at rest asks nothing here)
            return out
        for finger, servos in self._servo_limits.items():
            for name, _, moving in servos:
                speed = axes[name].velocity
                if speed > moving or speed < -moving:
                    break
            else:  # (standing: reached nothing new)
                continue
            if any(pressed == finger for pressed, _ in self._force_sum):
                continue
            touching = self._touching(finger, within=0.0)
            if touching:
                out[finger] = touching
        return out

    def _targets_near(self, link: int, reach: float) -> list[int]:
        """The targets (body ids, in order) whose bounding boxes come within `reach` of the link's: pybullet's
        broadphase, before any exact query."""
        lo, hi = self.client.getAABB(self.body, link)
        found = self.client.getOverlappingObjects([v - reach for v in lo], [v + reach for v in hi]) or ()
        return sorted({uid for uid, _ in found if uid in self._target_by_id})

    def _touching(self, finger: str, slack: float = 0.0, within: float | None = None) -> tuple[str, ...]:
        """Targets within contact_distance (+ slack; or `within`) of the finger's true shape (never before they
        touch)."""
        c, d = self.client, max(self.spec.contact_distance, slack) if within is None else within
        found: set[str] = set()
        for link in self.finger_links[finger]:
            limit = d - (HULL_MARGIN if link in self._mesh_links else 0.0)
            exact = self.probe is not None and self.probe.covers(link)
            for uid in self._targets_near(link, d + COLLISION_MARGIN):
                if exact:
                    gap = self.probe.distance(link, uid, d)
                    touching = gap is not None and gap <= d
                else:
                    touching = any(pt[8] <= limit for pt in c.getClosestPoints(self.body, uid, d + HULL_MARGIN,
                                                                               linkIndexA=link))
                if touching:
                    found.add(self._target_by_id[uid])
        return tuple(name for name in self.targets if name in found)

    def _status(self, finger: str, axes: dict[str, AxisState], contact: bool) -> int:
        """The finger's object status, Robotiq's way, from every servo that moves it: moving while any of them
        moves; else stopped by contact when one of them (the nearest) stands short of its goal with its drive
        pushing; else at the setpoint."""
        stopped = None
        goals = self._hold if self._hold is not None else self.setpoint
        for name, tolerance, _ in self._servo_limits[finger]:
            goal, axis = goals[name], axes[name]
            if abs(goal - axis.actual) <= tolerance:
                continue
            if axis.moving or abs(self.command_position[name] - axis.actual) <= tolerance:
                return STATUS_MOVING
            if stopped is None:
                stopped = STATUS_CLOSING_CONTACT if (goal - axis.actual) * self.closing[name] > 0 else STATUS_OPENING_CONTACT
        return STATUS_AT_SETPOINT if stopped is None else stopped

    # -- slip -----------------------------------------------------------------------------------------------
    def _base_pose(self):
        if self._palm_now is not None:  # (read after this step's physics already: `_thrust_axis`)
            return self._palm_now
        c = self.client
        if self.palm_link == -1:
            return c.getBasePositionAndOrientation(self.body)
        # (its centre of mass frame, where it stands now: without forward kinematics pybullet gives it as of the
        # last substep's start, a substep's travel behind, which a carry at 1.7 m/s took for a 5 mm slip)
        return c.getLinkState(self.body, self.palm_link, computeForwardKinematics=True)[:2]

    def _relative_pose(self, name: str):
        c = self.client
        base_pos, base_orn = self._base_pose()
        obj_pos, obj_orn = c.getBasePositionAndOrientation(self.targets[name])
        inv_pos, inv_orn = c.invertTransform(base_pos, base_orn)
        return c.multiplyTransforms(inv_pos, inv_orn, obj_pos, obj_orn)

    def _relative_position(self, name: str) -> tuple[float, float, float]:
        """Target `name`'s position in the palm's frame (`_relative_pose`'s, in one pybullet query fewer and no
        transform calls: the slip watch asks at every step of a grip)."""
        base_pos, base_orn = self._base_pose()
        p = self.client.getBasePositionAndOrientation(self.targets[name])[0]
        d = (p[0] - base_pos[0], p[1] - base_pos[1], p[2] - base_pos[2])
        return _unturn(pybullet.getMatrixFromQuaternion(base_orn), d)  # (d in the palm's frame)

    def _watch_slip(self) -> None:
        """While a part is gripped, still pressed by a finger after its grip was lost (it is sliding out), or lost
        without a setpoint that let it go (for LOST_WATCH_STEPS more): how far it has moved relative to the palm
        since the grip; beyond slip_distance `slip` is raised, and it stays raised until the next grip."""
        if self._grip_reference is None:
            return
        name, ref_pos = self._grip_reference
        if self.state.gripped != name and not any(name in f.pressing for f in self.state.fingers.values()):
            # no finger presses on it any more: let go (a setpoint opened a finger since the grip), or lost; a lost
            # part is watched a while longer, for it may leave the fingers within a step (a dropped part)
            self._lost_steps += 1
            if self._opened_since_grip or self._lost_steps > LOST_WATCH_STEPS:
                self._grip_reference = None
                return
        else:
            self._lost_steps = 0
        self.state.slip_distance = math.dist(self._relative_position(name), ref_pos)
        if self.state.slip_distance > self.spec.slip_distance:
            self.state.slip = True

    # -- attach mode ----------------------------------------------------------------------------------------
    def _attach(self, name: str) -> None:
        c, uid = self.client, self.targets[name]
        rel_pos, rel_orn = self._relative_pose(name)
        self._constraint = c.createConstraint(self.body, self.palm_link, uid, -1, pybullet.JOINT_FIXED, [0, 0, 0],
                                              rel_pos, [0, 0, 0], rel_orn, [0, 0, 0, 1])
        c.changeConstraint(self._constraint, maxForce=1e6)
        self.state.attached = name

    def _release(self) -> None:
        if self._constraint is not None:
            self.client.removeConstraint(self._constraint)
        self._constraint = None
        self.state.attached = ""

    def forget(self, name: str) -> None:
        """A target taken out of the cell: it is no longer attached, gripped or watched."""
        if self.state.attached == name:
            self._release()
        if self._grip_reference is not None and self._grip_reference[0] == name:
            self._grip_reference = None


def _rotate(orn, v):
    return _turn(pybullet.getMatrixFromQuaternion(orn), v)


def _turn(m, v) -> tuple[float, float, float]:
    """v turned by the rotation matrix m (pybullet's 9 floats, row by row), in plain floats: the hot path's."""
    return (m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
            m[6] * v[0] + m[7] * v[1] + m[8] * v[2])


def _unturn(m, v) -> tuple[float, float, float]:
    """v turned back by the rotation matrix m (by its transpose): a world vector in the rotated frame."""
    return (m[0] * v[0] + m[3] * v[1] + m[6] * v[2], m[1] * v[0] + m[4] * v[1] + m[7] * v[2],
            m[2] * v[0] + m[5] * v[1] + m[8] * v[2])
