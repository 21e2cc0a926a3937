"""A cell at rest costs almost no physics: its loose bodies are frozen until something can move them.

pybullet solves every resting contact at every substep: a steel ring lying flat on a pallet (12 boxes, 48 contact
points) cost three quarters of the ring rig's physics, while nothing happens. pybullet's own sleeping cannot
help there: a body shares its simulation island with every body whose bounding box overlaps its own (the open
gripper's fingers around the ring), and the arm, which holds its pose under motor control, never sleeps.

So the twin decides itself, from the state alone (replays stay bit for bit), when the whole cell is at rest: the
arm idle, every gripper drive standing at its goal and pressing on nothing, no loose body touching the gripper or
the arm, and every loose body (dynamic targets and fixtures) moving slower than REST_SPEED / REST_SPIN for
REST_STEPS steps in a row. Then nothing can move until an input changes, and the loose bodies are made static
(mass 0: pybullet skips a static body's contacts with the static fixtures). Before the physics of the first step
in which the arm or a drive moves again, or a frozen body has been moved from outside (a fault displacing a part,
a target taken out or put back), every frozen body gets its mass back, where it lay.

What a user sees: a resting body stays where it rests either way; the forces and contacts of a body frozen at rest
are not read (nothing touches it). After a thaw the contacts are found anew, without the solver's warm start, so
a part settles on its support within a micrometre rather than bit for bit as it would have without the freeze.
"""
from __future__ import annotations

from collections.abc import Callable

REST_SPEED = 1e-5  # m/s: a body slower than this is at rest
REST_SPIN = 1e-4  # rad/s
REST_STEPS = 25  # steps (0.3 s at 12 ms) the cell has to stay at rest before it is frozen (CHECK_EVERY's multiple)
CHECK_EVERY = 5  # steps between two looks at the loose bodies' speeds (a body that creeps is not looked at each step)


STANDING = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


class Stasis:
    """Freezes a station's loose bodies while the whole cell rests, thaws them when anything may move."""

    def __init__(self, client, machine: int, loose: list[int]):
        self.client, self.machine = client, machine
        self.loose = list(loose)  # dynamic targets and fixtures, station order
        self._loose = set(self.loose)
        self.frozen: dict[int, tuple] = {}  # body -> (its mass, its pose and velocity when frozen)
        self._resting = 0  # steps in a row the cell has been at rest

    def before_physics(self, machine_still: Callable[[], bool]) -> None:
        """Thaw every frozen body unless the machine stands still and no frozen body was moved from outside.
        (`machine_still` is asked only while something is frozen: most steps need no answer.)"""
        if not self.frozen:
            return
        if machine_still():
            pose_of, velocity_of = self.client.getBasePositionAndOrientation, self.client.getBaseVelocity
            for uid, (_, pose, _) in self.frozen.items():
                if pose_of(uid) != pose or velocity_of(uid) != STANDING:
                    break
            else:
                return
        self.thaw()

    def after_step(self, machine_still: Callable[[], bool]) -> None:
        """Count the steps the cell has rested; freeze the loose bodies once it has rested REST_STEPS."""
        if self.frozen or not self.loose:
            return
        if not machine_still():
            self._resting = 0
            return
        self._resting += 1
        if self._resting % CHECK_EVERY:
            return
        if not self._at_rest():
            self._resting = 0
        elif self._resting >= REST_STEPS:
            if self._touching_machine():  # a part lying against a finger or the arm is not frozen
                self._resting = 0
            else:
                self.freeze()

    def _at_rest(self) -> bool:
        c = self.client
        for uid in self.loose:
            (vx, vy, vz), (wx, wy, wz) = c.getBaseVelocity(uid)
            if vx * vx + vy * vy + vz * vz > REST_SPEED ** 2 or wx * wx + wy * wy + wz * wz > REST_SPIN ** 2:
                return False
        return True

    def _touching_machine(self) -> bool:
        return any(pt[2] in self._loose for pt in self.client.getContactPoints(self.machine))

    def freeze(self) -> None:
        c = self.client
        for uid in self.loose:
            mass = c.getDynamicsInfo(uid, -1)[0]
            if mass > 0.0:  # (a target taken out of the cell is static already)
                velocity = c.getBaseVelocity(uid)
                c.changeDynamics(uid, -1, mass=0.0)
                c.resetBaseVelocity(uid, *STANDING)  # a static multibody still drifts at its (residual) velocity
                self.frozen[uid] = (mass, c.getBasePositionAndOrientation(uid), velocity)

    def thaw(self) -> None:
        c = self.client
        for uid, (mass, _, velocity) in self.frozen.items():
            c.changeDynamics(uid, -1, mass=mass)
            c.resetBaseVelocity(uid, *velocity)
        self.frozen.clear()
        self._resting = 0
