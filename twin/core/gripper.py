"""The gripper's behaviour, evaluated every simulation step (the SmartComponent's OnSimulationStep).

Before physics (`command`): each input is a servo setpoint. The joint is driven towards it by a
position servo limited in velocity and force (URDF velocity and effort, or the station's override), so
it never jumps, and it stops on contact once the force limit is reached: unlike RobotStudio, each
finger stops by itself and the force it applies is known. Mimic joints follow their master's setpoint.
While `Active` is low every joint holds the position it had when `Active` fell.

After physics (`sense`): per finger, a contact flag (a real geometric contact: closest distance to a
target object within `contact_distance`, 0.5 mm by default, never the early contacts pybullet reports
within its collision margin) and the servo force. When every finger touches the same target, the target
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
        self.finger_joint = {f.name: joint_index[f.joint] for f in mechanism.fingers}
        self.active_input = spec.always_active  # the `Active` input as last written
        self.setpoint = {inp.name: self._initial(inp) for inp in mechanism.inputs}
        self._hold: dict[str, float] | None = None
        self._constraint: int | None = None
        self.state = GripState()
        for inp in mechanism.inputs:
            client.resetJointState(body, self.joint[inp.name], self.setpoint[inp.name])
        for joint, master, mult, off in self.mimics:
            client.resetJointState(body, joint, mult * self.setpoint[master] + off)
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
        self.check(self.mechanism.input(name), value)
        self.setpoint[name] = float(value)

    def set_active(self, active: bool) -> None:
        """Store the `Active` input; an always-active gripper keeps what was written but ignores it."""
        self.active_input = bool(active)

    @property
    def active(self) -> bool:
        return self.active_input or self.spec.always_active

    def command(self) -> None:
        """Send this step's servo commands (before physics)."""
        if not self.active and self._hold is None:
            self._hold = {name: axis.actual for name, axis in self.state.axes.items()}
        elif self.active:
            self._hold = None
        goal = self._hold if self._hold is not None else self.setpoint
        c = self.client
        for name, joint in self.joint.items():
            velocity, effort = self.limits[name]
            c.setJointMotorControl2(self.body, joint, pybullet.POSITION_CONTROL, targetPosition=goal[name],
                                    force=effort, maxVelocity=velocity, positionGain=0.3, velocityGain=1.0)
        for joint, master, mult, off in self.mimics:
            velocity, effort = self.limits[master]
            c.setJointMotorControl2(self.body, joint, pybullet.POSITION_CONTROL, targetPosition=mult * goal[master] + off,
                                    force=effort, maxVelocity=velocity * abs(mult), positionGain=0.3, velocityGain=1.0)

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
            pos, vel, _, torque = c.getJointState(self.body, joint)
            axes[name] = AxisState(pos, vel, abs(torque))
        fingers = {}
        for finger, joint in self.finger_joint.items():
            fingers[finger] = FingerState(self._touching(finger), abs(c.getJointState(self.body, joint)[3]))
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

    def _release(self) -> None:
        if self._constraint is not None:
            self.client.removeConstraint(self._constraint)
        self._constraint = None
        self.state.gripped = ""
