"""Fault injection in the plant: physics and sensor faults, stepped with the twin at given simulated times.

    from twin.runtime.faults import FaultInjector, PartMissing, FingerJammed, ReadingStuck

    injector = FaultInjector.attach(twin, [PartMissing("part", at=2.0),
                                           FingerJammed("axis1", position=0.300),    # m
                                           ReadingStuck("axis2.force", value=0.0, at=1.0)])
    twin.step(500)
    injector.log            # [(time, "PartMissing part: started"), ...]

Every fault starts at `at` (s of simulated time, 0 = from the first step) and lasts `duration` s (None: to
the end). The injector is a `Device` of the twin (the core steps it and knows nothing of faults), so the
same fault acts on a twin in process (campaigns, tests), in `twin serve` and behind any front end. Units
are the twin's (SI: m, rad, N). The faults of the PLC link (lost, latency, jitter) are on the PLC's side of
the link: `plc_client.link.LinkFaults`.

| fault | what the physics does | what the signals show |
|---|---|---|
| `PartMissing` | the part is taken out of the cell (`TARGET.present` = 0), put back when it ends | no contact; a grip closes to the end of travel |
| `PartDisplaced` | the part is moved by an offset (and turned about z), at rest | `TARGET.x/y/z` jump |
| `FingerJammed` | a hard stop at `position`: the joint gets there and no further, then stays stuck there | `NAME.actual` stops; its drive's effort builds as against a part (its `NAME.force`, on no part, stays 0) |
| `DriveForceLost` | the joint's drive pushes with at most `effort` (N or N*m) | the finger's force stays at or below it; no grip force |
| `ReadingStuck` | nothing | an output keeps one value (its value when the fault starts, or `value`) |
| `ReadingOffset` | nothing | an output reads `offset` more than it is |
| `RobotStopped` | the arm holds where it is; a motion under way waits (protective stop), goes on when it ends | `robot.busy` stays up, `robot.j*` stand still |
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from twin.core.errors import SignalError, TwinError
from twin.core.signals import BOOL, ENUM, FLOAT, INPUT, INT
from twin.core.device import ObservingDevice

EPS = 1e-9
JAM_REACHED = {"m": 0.0001, "rad": 0.001}  # a joint this close to its jam position is stuck there


class FaultError(TwinError):
    """A fault that does not fit the twin (an unknown target, input or signal): names the fault and why."""


@dataclass
class Fault:
    """One fault: acts from `at` (s of simulated time) for `duration` s (None: to the end of the run)."""

    at: float = 0.0
    duration: float | None = None

    def check(self, twin) -> None:
        """Raise FaultError if the fault cannot act on this twin."""
        if not (math.isfinite(self.at) and self.at >= 0):
            raise FaultError(f"{self.label()}: 'at' must be a time >= 0 s, not {self.at!r}")
        if self.duration is not None and not (math.isfinite(self.duration) and self.duration > 0):
            raise FaultError(f"{self.label()}: 'duration' must be > 0 s, not {self.duration!r}")

    def label(self) -> str:
        return type(self).__name__

    @property
    def end(self) -> float:
        return math.inf if self.duration is None else self.at + self.duration

    # called by the injector
    def start(self, twin) -> None: ...

    def before_step(self, twin) -> None: ...

    def after_step(self, twin) -> None: ...

    def stop(self, twin) -> None: ...


@dataclass
class PartMissing(Fault):
    """The part is not in the cell (taken out at `at`, back where the station placed it when it ends)."""

    target: str = ""

    def check(self, twin) -> None:
        super().check(twin)
        _check_target(self, twin, self.target)

    def label(self) -> str:
        return f"PartMissing {self.target}"

    def start(self, twin) -> None:
        twin.write(f"{self.target}.present", False)

    def stop(self, twin) -> None:
        twin.write(f"{self.target}.present", True)


@dataclass
class PartDisplaced(Fault):
    """At `at`, the part is moved by `offset` (m, world frame) and turned by `yaw_deg` about the vertical
    through its centre, at rest (bumped on its pallet by hand, say). The duration does not apply."""

    target: str = ""
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_deg: float = 0.0

    def check(self, twin) -> None:
        super().check(twin)
        _check_target(self, twin, self.target)
        if len(self.offset) != 3 or not all(math.isfinite(v) for v in self.offset) or not math.isfinite(self.yaw_deg):
            raise FaultError(f"{self.label()}: offset must be 3 finite numbers (m) and yaw_deg finite")

    def label(self) -> str:
        return f"PartDisplaced {self.target}"

    def start(self, twin) -> None:
        c, uid = twin.world.client, twin.world.body_ids[self.target]
        pos, orn = c.getBasePositionAndOrientation(uid)
        turn = c.getQuaternionFromEuler([0.0, 0.0, math.radians(self.yaw_deg)])
        _, new_orn = c.multiplyTransforms([0, 0, 0], turn, [0, 0, 0], orn)
        c.resetBasePositionAndOrientation(uid, [p + d for p, d in zip(pos, self.offset)], new_orn)
        c.resetBaseVelocity(uid, [0, 0, 0], [0, 0, 0])


@dataclass
class FingerJammed(Fault):
    """A hard stop in the joint of input `input` at `position` (m or rad; None: where it is when the fault
    starts): the joint moves freely up to it, then it is stuck there, whatever its drive does. Its servo
    pushes on against the stop, so its force builds as it would against a part."""

    input: str = ""
    position: float | None = None

    def check(self, twin) -> None:
        super().check(twin)
        inp = _check_input(self, twin, self.input)
        if self.position is not None and not (inp.min <= self.position <= inp.max):
            raise FaultError(f"{self.label()}: position {self.position:g} {inp.unit} is outside the joint's "
                             f"range {inp.min:g}..{inp.max:g} {inp.unit}")

    def label(self) -> str:
        return f"FingerJammed {self.input}"

    def _joint(self, twin):
        inp = twin.mechanism.input(self.input)
        return twin.world.machine, twin.world.joint_index[inp.joint], inp

    def start(self, twin) -> None:
        body, joint, inp = self._joint(twin)
        actual = twin.world.client.getJointState(body, joint)[0]
        self._at = actual if self.position is None else float(self.position)
        self._side = 1.0 if actual >= self._at else -1.0  # which side of the stop the joint comes from
        self._stuck = False
        self._limit(twin, actual)

    def before_step(self, twin) -> None:
        if not self._stuck:
            body, joint, _ = self._joint(twin)
            self._limit(twin, twin.world.client.getJointState(body, joint)[0])

    def _limit(self, twin, actual: float) -> None:
        body, joint, inp = self._joint(twin)
        p = self._at
        if (actual - p) * self._side <= JAM_REACHED[inp.unit]:  # there, or a hair past it within a step
            lo = hi = p
            self._stuck = True
        elif self._side > 0:
            lo, hi = p, inp.max  # the stop is below: it may move up, and down as far as the stop
        else:
            lo, hi = inp.min, p
        twin.world.client.changeDynamics(body, joint, jointLowerLimit=lo, jointUpperLimit=hi)

    def stop(self, twin) -> None:
        body, joint, inp = self._joint(twin)
        twin.world.client.changeDynamics(body, joint, jointLowerLimit=inp.min, jointUpperLimit=inp.max)


@dataclass
class DriveForceLost(Fault):
    """The drive of input `input` pushes with at most `effort` (N or N*m; 0: none at all): a finger that
    loses force (a tripped drive, a worn gear). Its limit comes back when the fault ends."""

    input: str = ""
    effort: float = 0.0

    def check(self, twin) -> None:
        super().check(twin)
        _check_input(self, twin, self.input)
        if not (math.isfinite(self.effort) and self.effort >= 0):
            raise FaultError(f"{self.label()}: effort must be a finite number >= 0, not {self.effort!r}")

    def label(self) -> str:
        return f"DriveForceLost {self.input}"

    def start(self, twin) -> None:
        self._before = twin.drive_limits(self.input)[1]
        twin.set_drive_limits(self.input, effort=self.effort)

    def stop(self, twin) -> None:
        twin.set_drive_limits(self.input, effort=self._before)


@dataclass
class ReadingStuck(Fault):
    """Output `signal` keeps reading `value` (None: what it read when the fault started): a sensor that
    froze. Only the reading: the physics and the gripper's own logic go on."""

    signal: str = ""
    value: object = None

    def check(self, twin) -> None:
        """A stuck value is one the reading could show: checked as a write to it would be (`SignalSpec.check`:
        type, range; an enumeration's index becomes its text), so a wrong one is refused here, naming it."""
        super().check(twin)
        spec = _check_output(self, twin, self.signal)
        if self.value is not None:
            value = self.value
            if isinstance(value, float) and spec.type in (INT, ENUM, BOOL) and value.is_integer():
                value = int(value)  # a whole number read from a file as a float
            try:
                self.value = replace(spec, direction=INPUT).check(value)
            except SignalError as exc:
                raise FaultError(f"{self.label()}: value: {exc}") from None

    def label(self) -> str:
        return f"ReadingStuck {self.signal}"

    def start(self, twin) -> None:
        self._value = twin.read(self.signal) if self.value is None else self.value

    def after_step(self, twin) -> None:
        twin.override_outputs({self.signal: self._value})


@dataclass
class ReadingOffset(Fault):
    """Output `signal` (a number) reads `offset` more than it is (in its SI unit: N, m, rad): a sensor out of
    calibration. A reading that cannot be negative (a force magnitude) is held at 0 or above."""

    signal: str = ""
    offset: float = 0.0

    def check(self, twin) -> None:
        super().check(twin)
        spec = _check_output(self, twin, self.signal)
        if spec.type != FLOAT:
            raise FaultError(f"{self.label()}: {self.signal} is not a number; an offset needs one")

    def label(self) -> str:
        return f"ReadingOffset {self.signal}"

    def after_step(self, twin) -> None:
        spec = twin.spec(self.signal)
        value = float(twin.read(self.signal)) + self.offset
        if spec.min is not None:
            value = max(value, spec.min)
        twin.override_outputs({self.signal: value})


@dataclass
class RobotStopped(Fault):
    """The robot stops (a protective stop): the arm holds where it is, a motion under way waits with its
    time frozen (`robot.busy` stays up, so the robot program waits too) and goes on when the fault ends."""

    def check(self, twin) -> None:
        super().check(twin)
        if twin.robot is None:
            raise FaultError(f"{self.label()}: station {twin.station.name!r} has no robot")

    def start(self, twin) -> None:
        twin.robot.pause(True)

    def stop(self, twin) -> None:
        twin.robot.pause(False)


def _check_target(fault: Fault, twin, name: str) -> None:
    names = [t.name for t in twin.station.targets]
    if name not in names:
        raise FaultError(f"{fault.label()}: no target {name!r} in station {twin.station.name!r} "
                         f"(targets: {', '.join(names) or 'none'})")


def _check_input(fault: Fault, twin, name: str):
    for inp in twin.mechanism.inputs:
        if inp.name == name:
            return inp
    raise FaultError(f"{fault.label()}: no gripper input {name!r} in station {twin.station.name!r} "
                     f"(inputs: {', '.join(i.name for i in twin.mechanism.inputs)})")


def _check_output(fault: Fault, twin, name: str):
    try:
        spec = twin.spec(name)
    except SignalError as exc:
        raise FaultError(f"{fault.label()}: {exc}") from None
    if spec.direction == INPUT:
        raise FaultError(f"{fault.label()}: {name} is an input; only readings (outputs) can be stuck or offset")
    return spec


@dataclass
class FaultInjector(ObservingDevice):
    """The faults of one run, as a `Device` of the twin: each starts and ends at its simulated time."""

    faults: list[Fault]
    signals: tuple = ()
    log: list[tuple[float, str]] = field(default_factory=list)

    def __post_init__(self):
        self.faults = list(self.faults)
        self._state = ["pending"] * len(self.faults)  # pending -> active -> over

    @classmethod
    def attach(cls, twin, faults) -> "FaultInjector":
        """Check every fault against `twin` and step them with it."""
        injector = cls(list(faults))
        for fault in injector.faults:
            fault.check(twin)
        twin.add_device(injector)
        return injector

    def before_step(self, twin) -> None:
        t = twin.time
        for i, fault in enumerate(self.faults):
            if self._state[i] == "pending" and t >= fault.at - EPS:
                self._state[i] = "active"
                fault.start(twin)
                self.log.append((t, f"{fault.label()}: started"))
            if self._state[i] == "active" and t >= fault.end - EPS:
                self._state[i] = "over"
                fault.stop(twin)
                self.log.append((t, f"{fault.label()}: ended"))
            if self._state[i] == "active":
                fault.before_step(twin)

    def after_step(self, twin) -> None:
        for i, fault in enumerate(self.faults):
            if self._state[i] == "active":
                fault.after_step(twin)

    def active(self) -> list[Fault]:
        return [f for f, s in zip(self.faults, self._state) if s == "active"]
