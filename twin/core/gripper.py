"""The gripper's behaviour, evaluated every simulation step (the SmartComponent's OnSimulationStep).

Before physics (`command`): each input is a servo setpoint. The joint moves towards it at its velocity
limit with at most its effort limit (URDF velocity and effort, or the station's overrides), so it never
jumps and it stops by itself against a part: unlike RobotStudio, each finger stops on contact and its
force is known. Mimic joints are tied to their master by a gear constraint (a linkage, not a motor of their
own). While a part is held (fixed to the base link) a joint presses towards it no further than 0.5 mm
(0.005 rad) beyond where it gripped: it keeps its grip during fast moves but cannot sink into the part.
While `Active` is low every joint holds its command.

The force of a joint is its servo's: a command position moves towards the setpoint at the velocity
limit, the joint follows it, and the force is `effort * following error / FULL_FORCE_ERROR` (2 mm or
0.02 rad), up to the effort limit. A free finger follows its command closely and reads almost nothing; a
finger blocked by a part stops while its command runs on (no further than full force, so a new setpoint
acts at once), and its force builds up to the effort limit, the way a real servo's torque builds when it
presses on something. That is what a PLC's torque threshold reads. (pybullet's own motor force against a
contact depends on its solver and the finger's mass, not on the effort: it is not what is reported. How
far a finger sinks into a part, and so the force part-way up, still depends on the contact's softness.)

After physics (`sense`): per finger, a contact flag (a real geometric contact: closest distance to a
target object within `contact_distance`, 0.5 mm by default, never the early contacts pybullet reports
within its collision margin) and its force: the largest servo force of the driven joints that carry it
(its own joint, and e.g. the carriage a fine axis sits on). When every finger touches the same target, the target
is fixed to the gripper's base link; when any finger loses it, it is released to physics again. This
needs no setting for outside or inside grips: the rule is the same.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import pybullet

from .errors import SignalRangeError
from .mechanism import JointInput, Mechanism
from .station import GripperSpec

IN_POSITION_TOLERANCE = {"m": 0.0002, "rad": 0.002}  # 0.2 mm, ~0.1 degree
MOVING_SPEED = {"m": 0.001, "rad": 0.005}  # below this the axis counts as standing still
DEFAULT_VELOCITY = {"m": 0.1, "rad": 1.0}  # when the URDF gives no velocity limit
DEFAULT_EFFORT = {"m": 100.0, "rad": 10.0}  # when the URDF gives no effort limit
FULL_FORCE_ERROR = {"m": 0.002, "rad": 0.02}  # following error at which a servo applies its effort limit
POSITION_GAIN = 0.3  # pybullet motor: the velocity it asks for is POSITION_GAIN * error / substep
BLOCKED_ERROR = {"m": 0.0002, "rad": 0.002}  # lag beyond the motor's own that says a part holds the joint back
BLOCKED_SPEEDUP = 20.0  # how much faster than its limit a held-back joint's motor may ask to move (it cannot)
HOLD_PRESS = {"m": 0.0005, "rad": 0.005}  # a held part: how far beyond the grip position a joint may still press
MIMIC_ERP = 0.5  # how fast a mimic joint's drift from its master is taken out, per substep
MIMIC_FORCE_FACTOR = 20.0  # a mimic coupling holds up to this many times the master's effort (a rigid linkage)


@dataclass
class AxisState:
    actual: float = 0.0
    velocity: float = 0.0
    force: float = 0.0


@dataclass
class FingerState:
    contacts: tuple[str, ...] = ()  # target names within contact distance
    force: float = 0.0  # magnitude of the force (N) or torque (N*m) of the finger's joint servo


@dataclass
class GripState:
    gripped: str = ""  # the target fixed to the base link, "" for none
    axes: dict[str, AxisState] = field(default_factory=dict)
    fingers: dict[str, FingerState] = field(default_factory=dict)


class Gripper:
    """Servoes the gripper's joints and decides grip and release from finger contacts."""

    def __init__(self, client, body: int, joint_index: dict[str, int], link_index: dict[str, int],
                 mechanism: Mechanism, spec: GripperSpec, targets: dict[str, int]):
        self.client, self.body, self.mechanism, self.spec = client, body, mechanism, spec
        self.targets = targets  # target name -> body id, in station order
        self._target_by_id = {uid: name for name, uid in targets.items()}
        self.base_link = link_index[mechanism.base_link]
        self.joint = {inp.name: joint_index[inp.joint] for inp in mechanism.inputs}
        self.limits: dict[str, tuple[float, float]] = {}
        for inp in mechanism.inputs:
            o = spec.joints.get(inp.name)
            velocity = (o.velocity if o and o.velocity else None) or inp.velocity or DEFAULT_VELOCITY[inp.unit]
            effort = (o.effort if o and o.effort else None) or inp.effort or DEFAULT_EFFORT[inp.unit]
            self.limits[inp.name] = (velocity, effort)
        master_input = {inp.joint: inp.name for inp in mechanism.inputs}
        self.mimics = [(joint_index[m.joint], master_input[m.master], m.multiplier, m.offset) for m in mechanism.mimics]
        self.finger_links = {f.name: [link_index[n] for n in f.links] for f in mechanism.fingers}
        # the servos (inputs) that drive each finger: those of the joints that carry it, a mimic joint's being
        # its master's (a linkage has one motor); a finger presses with the servos behind it
        servo_of = {j: name for name, j in self.joint.items()} | {j: master for j, master, _, _ in self.mimics}
        self.finger_servos = {f.name: list(dict.fromkeys(servo_of[j] for j in self._chain(joint_index[f.joint])
                                                          if j in servo_of))
                              for f in mechanism.fingers}
        self.active_input = spec.always_active  # the `Active` input as last written
        self.setpoint = {inp.name: self._initial(inp) for inp in mechanism.inputs}
        self.command_position = dict(self.setpoint)  # where each servo is heading now (moves at the velocity limit)
        self.unit = {inp.name: inp.unit for inp in mechanism.inputs}
        params = client.getPhysicsEngineParameters()
        self.dt = float(params["fixedTimeStep"])
        # how far pybullet's motor trails a target moving at 1 unit/s: it asks for POSITION_GAIN * error / h
        self._lag_per_speed = self.dt / max(1, int(params["numSubSteps"])) / POSITION_GAIN
        self._hold: dict[str, float] | None = None
        self._constraint: int | None = None
        self._held_at: dict[str, tuple[float, float]] = {}  # while a part is held: input -> (position, pressing sign)
        self.state = GripState()
        for inp in mechanism.inputs:
            client.resetJointState(body, self.joint[inp.name], self.setpoint[inp.name])
        for joint, master, mult, off in self.mimics:
            client.resetJointState(body, joint, mult * self.setpoint[master] + off)
            self._couple(joint, master, mult, off)
        for links in self.finger_links.values():
            for link in links:
                client.changeDynamics(body, link, lateralFriction=spec.friction)
        self.sense()

    def _initial(self, inp: JointInput) -> float:
        value = self.spec.initial.get(inp.name, min(max(0.0, inp.min), inp.max))
        self.check(inp, value)
        return value

    @staticmethod
    def check(inp: JointInput, value: float) -> None:
        if not (inp.min <= value <= inp.max):
            raise SignalRangeError(inp.name, value, inp.min, inp.max, inp.unit)

    def set_setpoint(self, name: str, value: float) -> None:
        """Validate and store a setpoint; it takes effect at the next step. Out of range: rejected."""
        inp = self.mechanism.input(name)
        slack = 1e-9 * max(1.0, abs(inp.min), abs(inp.max))  # a range end sent in other units (deg, mm) is the end
        value = inp.max if inp.max < value <= inp.max + slack else inp.min if inp.min - slack <= value < inp.min else value
        self.check(inp, value)
        self.setpoint[name] = float(value)

    def set_limits(self, name: str, velocity: float | None = None, effort: float | None = None) -> None:
        """Change an input's velocity or effort limit from the next step on (a drive that loses force, a
        slower axis: fault injection and parameter studies). None keeps the present value."""
        old_velocity, old_effort = self.limits[self.mechanism.input(name).name]
        for what, value in (("velocity", velocity), ("effort", effort)):
            if value is not None and not (value >= 0.0 and value < float("inf")):
                raise ValueError(f"{name}: the {what} limit must be a finite number >= 0, not {value!r}")
        self.limits[name] = (old_velocity if velocity is None else float(velocity),
                             old_effort if effort is None else float(effort))

    def set_active(self, active: bool) -> None:
        """Store the `Active` input; an always-active gripper keeps what was written but ignores it."""
        self.active_input = bool(active)

    @property
    def active(self) -> bool:
        return self.active_input or self.spec.always_active

    def command(self) -> None:
        """Send this step's servo commands (before physics): move each command position on by at most the
        velocity limit, and let each servo push with the force its following error calls for."""
        if not self.active and self._hold is None:
            self._hold = dict(self.command_position)
        elif self.active:
            self._hold = None
        goal = self._hold if self._hold is not None else self.setpoint
        c, dt = self.client, self.dt
        for name, joint in self.joint.items():
            velocity, effort = self.limits[name]
            full = FULL_FORCE_ERROR[self.unit[name]]
            target = _towards(self.command_position[name], goal[name], velocity * dt)
            actual, joint_speed = c.getJointState(self.body, joint)[:2]
            # a blocked joint's command runs on only as far as full force: a new setpoint acts at once
            target = min(max(target, actual - full), actual + full)
            # and a joint already further on its way than its command (leaving a part) pulls the command along
            ahead = (actual - target) * (goal[name] - target)
            if ahead > 0:
                target = actual if abs(goal[name] - target) > abs(actual - target) else goal[name]
            speed = abs(target - self.command_position[name]) / dt
            self.command_position[name] = target
            # a joint held back by a part (its lag beyond what its speed explains) may press with its whole effort:
            # pybullet's motor only pushes as hard as the velocity it asks for allows, so let it ask for more
            blocked = (abs(target - actual) > speed * self._lag_per_speed + BLOCKED_ERROR[self.unit[name]]
                       and abs(joint_speed) < MOVING_SPEED[self.unit[name]])  # standing: not merely lagging
            self._drive(joint, self._press_limit(name, target), velocity * (BLOCKED_SPEEDUP if blocked else 1.0), effort)

    def _couple(self, joint: int, master: str, mult: float, off: float) -> None:
        """Tie a mimic joint to its master as a mechanism does (a gear constraint: joint = mult * master + off),
        with no motor of its own: the master's servo moves the whole linkage, and a part pushing one coupled
        finger pushes them all (a self-centring chuck centres its part)."""
        c = self.client
        c.setJointMotorControl2(self.body, joint, pybullet.VELOCITY_CONTROL, targetVelocity=0.0, force=0.0)
        gear = c.createConstraint(self.body, joint, self.body, self.joint[master], pybullet.JOINT_GEAR,
                                  [0, 0, 1], [0, 0, 0], [0, 0, 0])
        # the constraint holds q_joint + gearRatio * q_master = relativePositionTarget
        c.changeConstraint(gear, gearRatio=-mult, relativePositionTarget=off, erp=MIMIC_ERP,
                           maxForce=MIMIC_FORCE_FACTOR * self.limits[master][1] * max(1.0, abs(mult)))

    def _force(self, name: str, actual: float, joint_speed: float) -> float:
        """The servo force of input `name` after the step: effort * following error / full-force error. The lag
        that a joint moving at its speed has behind its command (the motor's, not a load's) does not count; a
        joint held by a part stands, so all of its error does."""
        error = max(0.0, abs(self.command_position[name] - actual) - abs(joint_speed) * self._lag_per_speed)
        return self.limits[name][1] * min(1.0, error / FULL_FORCE_ERROR[self.unit[name]])

    def _chain(self, joint: int) -> list[int]:
        """`joint` and the joints between it and the body's base, nearest first."""
        chain = []
        while joint >= 0:
            chain.append(joint)
            joint = self.client.getJointInfo(self.body, joint)[16]  # the parent link's (= its joint's) index
        return chain

    def _press_limit(self, name: str, target: float) -> float:
        """While a part is fixed to the base link, a joint goes no further towards it than HOLD_PRESS beyond where
        it held it when it was fixed: it keeps pressing (a carried part stays between the fingers) but cannot
        sink on into the fixed part. Its command, and so its force, builds as before. Moving the
        other way (opening a grip) is not held back."""
        if name not in self._held_at:
            return target
        held, sign = self._held_at[name]
        reach = held + sign * HOLD_PRESS[self.unit[name]]
        return min(target, reach) if sign > 0 else max(target, reach)

    def _drive(self, joint: int, target: float, velocity: float, effort: float) -> None:
        """Command one joint towards its command position with at most its effort limit. (pybullet's motor is an
        implicit velocity constraint: stable for any finger mass, and it holds a carried part with the full
        effort; the force it reaches against a contact grows with the velocity it asks for.)"""
        self.client.setJointMotorControl2(self.body, joint, pybullet.POSITION_CONTROL, targetPosition=target,
                                          force=effort, maxVelocity=velocity, positionGain=POSITION_GAIN, velocityGain=1.0)

    def _touching(self, finger: str) -> tuple[str, ...]:
        c, d = self.client, self.spec.contact_distance
        found: set[str] = set()
        for link in self.finger_links[finger]:
            lo, hi = c.getAABB(self.body, link)
            nearby = c.getOverlappingObjects([v - d for v in lo], [v + d for v in hi]) or ()
            for uid in {uid for uid, _ in nearby if uid in self._target_by_id}:
                points = c.getClosestPoints(self.body, uid, d, linkIndexA=link)
                if any(pt[8] <= d for pt in points):
                    found.add(self._target_by_id[uid])
        return tuple(name for name in self.targets if name in found)

    def sense(self) -> None:
        """Read joints and contacts after physics, then attach or release (the grip rule)."""
        c = self.client
        axes = {}
        for name, joint in self.joint.items():
            pos, vel, _, _ = c.getJointState(self.body, joint)
            axes[name] = AxisState(pos, vel, self._force(name, pos, vel))
        fingers = {}
        for finger, servos in self.finger_servos.items():
            force = max((axes[name].force for name in servos), default=0.0)
            fingers[finger] = FingerState(self._touching(finger), force)
        self.state.axes, self.state.fingers = axes, fingers
        common = set(self.targets)
        for f in fingers.values():
            common &= set(f.contacts)
        if not fingers:
            common = set()
        gripped = self.state.gripped
        if gripped and gripped not in common:
            self._release()
        if not self.state.gripped and common:
            self._attach(next(name for name in self.targets if name in common))

    def _attach(self, name: str) -> None:
        c, uid = self.client, self.targets[name]
        if self.base_link == -1:
            base_pos, base_orn = c.getBasePositionAndOrientation(self.body)
        else:
            base_pos, base_orn = c.getLinkState(self.body, self.base_link)[:2]  # the link's centre of mass frame
        obj_pos, obj_orn = c.getBasePositionAndOrientation(uid)
        inv_pos, inv_orn = c.invertTransform(base_pos, base_orn)
        rel_pos, rel_orn = c.multiplyTransforms(inv_pos, inv_orn, obj_pos, obj_orn)
        self._constraint = c.createConstraint(self.body, self.base_link, uid, -1, pybullet.JOINT_FIXED, [0, 0, 0],
                                              rel_pos, [0, 0, 0], rel_orn, [0, 0, 0, 1])
        c.changeConstraint(self._constraint, maxForce=1e6)
        self.state.gripped = name
        # where each joint holds the part, and which way it was heading (towards the part)
        goal = self._hold if self._hold is not None else self.setpoint
        self._held_at = {}
        for inp, joint in self.joint.items():
            actual = c.getJointState(self.body, joint)[0]
            heading = goal[inp] - actual
            if abs(heading) > 1e-9:
                self._held_at[inp] = (actual, 1.0 if heading > 0 else -1.0)

    def _release(self) -> None:
        if self._constraint is not None:
            self.client.removeConstraint(self._constraint)
        self._constraint = None
        self.state.gripped = ""
        self._held_at = {}


def _towards(value: float, goal: float, step: float) -> float:
    """`value` moved towards `goal` by at most `step`, landing exactly on it."""
    return goal if abs(goal - value) <= step else value + (step if goal > value else -step)
