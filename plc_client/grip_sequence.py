"""The reusable grip sequence: the thesis's gripper PLC (section 3.1) as a scan-cycle state machine.

On a grip request the fingers are driven at a set speed (a ramp of their setpoints) until every finger's
force passes a threshold: the torque has built up, the grip is confirmed. If the fingers reach the end of
travel without it, the robot has missed the part: a fault goes to the robot, which must try again.
A release opens the fingers until the part is free (no finger touches it, every force is small), then a
margin further. It grips from outside (closing) and from inside (opening), with any number of fingers.

    IDLE --grip request--> GRIPPING --all forces >= threshold--> HELD --release request--> RELEASING --> IDLE
                                    --end of travel, no force--> FAULT_MISSED
                                                    RELEASING --limit reached, part still touching--> FAULT_STUCK
    (optional) IDLE/FAULT --prepare request--> PREPARING --in position--> IDLE
               IDLE/FAULT --prepare request outside `travel` (or with nowhere to go)--> fault BAD_REQUEST,
                            nothing moves, `done` answers the request
    A new request clears a fault (a release from a fault opens the fingers for the next attempt).

With `done` the handshake is request/acknowledge, safe whatever the scan times on either side: the robot
sets a request, waits for `done`, takes the request back and waits for `done` to fall. `done` is high
while the request that started the last job is still high and that job is over (gripped, missed,
released, prepared).

Positions, speed and forces are in the units of the I/O it runs against: over the network, the register
map's engineering units (mm, N); in process, `TwinIO` publishes the same units. Handshake signals are
edge-triggered requests (a rising edge starts a grip or a release, so the robot may leave the bit set
until it sees `gripped` or `fault`) and level outputs.

    seq = GripSequence(axes=("axis1", "axis2", "axis3"), forces=("axis1.force", "axis2.force", "axis3.force"),
                       speed=20.0, threshold=200.0, end_of_travel={"outside": 290.0, "inside": 230.0})
    ScanCycle(io, seq).run(seconds=5.0)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Mapping

OUTSIDE, INSIDE = "outside", "inside"
MODES = (OUTSIDE, INSIDE)


class Phase(IntEnum):
    """The sequence's state; its value is what the optional `state` output publishes."""

    IDLE = 0
    GRIPPING = 1
    HELD = 2
    FAULT_MISSED = 3
    RELEASING = 4
    FAULT_STUCK = 5  # a release reached its limit with the part still touching a finger
    PREPARING = 6  # moving the fingers to a ready position (optional prepare request)


class Fault(IntEnum):
    """The fault code (optional `fault_code` output)."""

    NONE = 0
    MISSED = 1  # end of travel reached without the force threshold: no part between the fingers
    STUCK = 2  # release limit reached with the part still touching
    BAD_REQUEST = 3  # a prepare request to a position outside the axes' travel (or with none): refused
    # raised by sequences that also watch their fingers (a subclass that compares setpoints and positions):
    JAMMED = 4  # a finger does not follow its setpoint while its drive pushes hard: blocked
    DRIVE_LOST = 5  # a finger does not follow its setpoint and its drive pushes with (almost) nothing
    TIMEOUT = 6  # a grip neither confirmed nor missed within its time
    LOST = 7  # a held part's force went away: the part is no longer held
    FORCE_READING = 8  # a finger on the part, its drive pushing hard, reads no force: its force sensor is wrong


@dataclass(frozen=True)
class Handshake:
    """Names of the handshake signals with the robot. `None` leaves an optional signal out."""

    grip_request: str = "grip_request"  # in, bool: a rising edge starts a grip
    release_request: str = "release_request"  # in, bool: a rising edge starts a release
    inside: str | None = "grip_inside"  # in, bool: True = grip from inside (read at the grip request)
    gripped: str = "gripped"  # out, bool: the grip is confirmed (high until the release has freed the part)
    fault: str = "grip_fault"  # out, bool: missed grip (or stuck release), until the next request
    busy: str | None = "grip_busy"  # out, bool: gripping, releasing or preparing
    fault_code: str | None = None  # out, int: a `Fault`
    state: str | None = None  # out, int: the `Phase`
    prepare_request: str | None = None  # in, bool: a rising edge moves the fingers to the ready position
    prepare_position: str | None = None  # in, number: where a prepare goes (else `ready_position[mode]`)
    done: str | None = None  # out, bool: the job of the request that is still high is finished (its acknowledge)


@dataclass
class GripState:
    """The sequence's own memory (a PLC's retained data block)."""

    phase: Phase = Phase.IDLE
    mode: str = OUTSIDE
    fault: Fault = Fault.NONE
    setpoint: dict[str, float] = field(default_factory=dict)  # the commanded value per axis, while moving
    goal: float | None = None  # PREPARING: where to; RELEASING: the limit
    since: float = 0.0  # scan time the current phase (or the end-of-travel wait) started
    at_end_since: float | None = None
    free_from: dict[str, float] | None = None  # RELEASING: where each axis was when the part got free
    last: float | None = None  # scan time of the previous scan
    edges: dict[str, bool] = field(default_factory=dict)  # previous value of each request input
    held_at: dict[str, float] = field(default_factory=dict)  # setpoints when the grip was confirmed
    job: str | None = None  # the request input whose rising edge started the current (or last) job
    forces_at_grip: dict[str, float] = field(default_factory=dict)
    refused: float | None = None  # the position of the last prepare request refused (Fault.BAD_REQUEST)


@dataclass
class GripSequence:
    """A grip/release sequence for N fingers. Call it as a scan-cycle logic: `seq(inputs, state)`.

    axes            input names of the axes it drives (finger setpoints)
    forces          force signal names, one per finger (the threshold applies to each)
    end_of_travel   per mode ("outside", "inside"): the setpoint where a grip that found no force is a miss
    speed           ramp speed of the setpoints while gripping and releasing (units per second)
    travel_speed    ramp speed of a prepare move, where nothing is touched (default: `speed`)
    threshold       force every finger must reach for a confirmed grip
    close_direction per mode, +1 or -1: which way a grip moves the setpoints (outside closes: -1)
    contacts        optional contact signal names (bool, one per finger): a grip is confirmed only when every one
                    is set too (a finger jammed before the part has force but no contact), and a part is free
                    only when none is set
    free_force      a part is free when every finger's force is below this
    release_margin  after the part is free, open this much further
    release_limit   per mode: the furthest a release may open (default: `release_travel` from where it starts)
    release_travel  the furthest a release may open when `release_limit` has no value for the mode
    ready_position  per mode, optional: a release opens at least to here (so the next grip finds the fingers
                    open), and a prepare request goes here
    actuals         actual-position signal names per axis (default `AXIS.actual`)
    tolerance       an axis is at a position when within this
    settle          s: an axis whose setpoint is at the end of travel but that cannot get there (blocked) counts
                    as arrived after this long
    per_finger      stop each axis by its own finger's force (axes and forces paired in order); default: when
                    there are as many axes as forces. Otherwise all axes move until every force passes.
    travel          optional (low, high): the axes' setpoint range; a prepare request outside it is refused
                    (fault `Fault.BAD_REQUEST`, `done` answers it, nothing is written) instead of sending a
                    setpoint the process would refuse
    handshake       the names of the handshake signals (`Handshake`)
    press           once every force passes the threshold, move the setpoints on by this much (closing) before
                    confirming: the holding force of a position servo (stiffness x how far past the part)
    """

    axes: tuple[str, ...]
    forces: tuple[str, ...]
    end_of_travel: Mapping[str, float]
    speed: float = 20.0
    threshold: float = 100.0
    travel_speed: float | None = None
    close_direction: Mapping[str, int] = field(default_factory=lambda: {OUTSIDE: -1, INSIDE: +1})
    contacts: tuple[str, ...] | None = None
    free_force: float = 20.0
    release_margin: float = 10.0
    release_limit: Mapping[str, float] = field(default_factory=dict)
    release_travel: float = 100.0
    ready_position: Mapping[str, float] = field(default_factory=dict)
    actuals: tuple[str, ...] | None = None
    tolerance: float = 0.5
    settle: float = 1.0
    per_finger: bool | None = None
    travel: tuple[float, float] | None = None
    handshake: Handshake = field(default_factory=Handshake)
    press: float = 0.0

    def _within_travel(self, value: float) -> float:
        return value if self.travel is None else min(max(value, self.travel[0]), self.travel[1])

    def __post_init__(self):
        if self.travel is not None:
            try:
                lo, hi = (float(v) for v in self.travel)
            except (TypeError, ValueError):
                raise ValueError(f"travel must be (low, high), not {self.travel!r}") from None
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError(f"travel must be (low, high) with low < high, not {self.travel!r}")
            self.travel = (lo, hi)
        self.axes, self.forces = tuple(self.axes), tuple(self.forces)
        if not self.axes or not self.forces:
            raise ValueError("a grip sequence needs at least one axis and one force signal")
        if self.actuals is None:
            self.actuals = tuple(f"{a}.actual" for a in self.axes)
        self.actuals = tuple(self.actuals)
        if len(self.actuals) != len(self.axes):
            raise ValueError(f"{len(self.actuals)} actual-position signals for {len(self.axes)} axes")
        if self.contacts is not None:
            self.contacts = tuple(self.contacts)
        if self.per_finger is None:
            self.per_finger = len(self.axes) == len(self.forces)
        elif self.per_finger and len(self.axes) != len(self.forces):
            raise ValueError(f"per_finger needs one force per axis ({len(self.axes)} axes, {len(self.forces)} forces)")
        for mode in MODES:
            if mode not in self.end_of_travel:
                raise ValueError(f"end_of_travel needs a value for {mode!r}")
            if self.close_direction.get(mode) not in (-1, 1):
                raise ValueError(f"close_direction[{mode!r}] must be +1 or -1")
        if self.speed <= 0 or self.threshold <= 0 or (self.travel_speed is not None and self.travel_speed <= 0):
            raise ValueError("speed, travel_speed and threshold must be greater than 0")

    # -- what a scan cycle needs to know ------------------------------------------------------------
    @property
    def inputs(self) -> tuple[str, ...]:
        """The signals the sequence reads each scan (its input image)."""
        h = self.handshake
        names = [h.grip_request, h.release_request, h.inside, h.prepare_request, h.prepare_position,
                 *self.actuals, *self.forces, *(self.contacts or ())]
        return tuple(dict.fromkeys(n for n in names if n))

    @property
    def outputs(self) -> tuple[str, ...]:
        h = self.handshake
        names = [*self.axes, h.gripped, h.fault, h.busy, h.fault_code, h.state, h.done]
        return tuple(n for n in names if n)

    def handshake_signals(self) -> dict:
        """The handshake signals with their resting values, e.g. for `TwinIO(twin, local=...)` when a test
        plays the robot in process."""
        h = self.handshake
        values = {h.grip_request: False, h.release_request: False, h.inside: False, h.prepare_request: False,
                  h.prepare_position: 0.0, h.gripped: False, h.fault: False, h.busy: False, h.fault_code: 0,
                  h.state: 0, h.done: False}
        return {k: v for k, v in values.items() if k}

    def initial_state(self) -> GripState:
        return GripState()

    # -- the logic ----------------------------------------------------------------------------------
    def __call__(self, inputs: Mapping, state: GripState) -> dict:
        now = float(getattr(inputs, "time", 0.0))
        elapsed = 0.0 if state.last is None else max(0.0, now - state.last)
        state.last = now
        h = self.handshake
        grip_edge = self._edge(inputs, state, h.grip_request)
        release_edge = self._edge(inputs, state, h.release_request)
        prepare_edge = self._edge(inputs, state, h.prepare_request) if h.prepare_request else False
        forces = [float(inputs[n]) for n in self.forces]
        # with contact signals, a grip is confirmed only when every finger touches the part too: a finger that
        # presses on something else (a jam, an obstacle) has force but no part
        touching = all(bool(inputs[n]) for n in self.contacts) if self.contacts else True
        actual = {a: float(inputs[n]) for a, n in zip(self.axes, self.actuals)}
        out: dict = {}

        # requests (a release wins over a grip in the same scan: it is the safe one)
        if release_edge and state.phase in (Phase.HELD, Phase.GRIPPING, Phase.FAULT_MISSED, Phase.FAULT_STUCK,
                                            Phase.IDLE, Phase.PREPARING):
            self._start_release(state, actual, now)
            state.job = h.release_request
        elif grip_edge and state.phase in (Phase.IDLE, Phase.FAULT_MISSED, Phase.FAULT_STUCK, Phase.PREPARING):
            state.mode = INSIDE if (h.inside and inputs[h.inside]) else OUTSIDE
            state.phase, state.fault, state.since, state.at_end_since = Phase.GRIPPING, Fault.NONE, now, None
            state.setpoint = dict(actual)
            state.job = h.grip_request
        elif prepare_edge and state.phase in (Phase.IDLE, Phase.FAULT_MISSED, Phase.FAULT_STUCK):
            mode = INSIDE if (h.inside and inputs[h.inside]) else OUTSIDE
            goal = inputs[h.prepare_position] if h.prepare_position else self.ready_position.get(mode)
            state.job = h.prepare_request
            if goal is None or not self.within_travel(float(goal)):
                # refuse it: a fault, answered through `done`; nothing moves (and no setpoint the process
                # would refuse is ever sent)
                state.fault, state.refused = Fault.BAD_REQUEST, None if goal is None else float(goal)
            else:
                state.phase, state.fault, state.goal, state.since = Phase.PREPARING, Fault.NONE, float(goal), now
                state.setpoint, state.at_end_since = dict(actual), None

        if state.phase is Phase.GRIPPING:
            self._grip_scan(state, forces, actual, elapsed, now, touching)
        elif state.phase is Phase.RELEASING:
            self._release_scan(inputs, state, forces, actual, elapsed, now)
        elif state.phase is Phase.PREPARING:
            step = (self.travel_speed or self.speed) * elapsed
            for a in self.axes:
                state.setpoint[a] = _towards(state.setpoint[a], state.goal, step)
            if self._arrived(state, {a: state.goal for a in self.axes}, actual, now):
                state.phase = Phase.IDLE

        if state.phase in (Phase.GRIPPING, Phase.RELEASING, Phase.PREPARING) or state.setpoint:
            out.update(state.setpoint)
            if state.phase not in (Phase.GRIPPING, Phase.RELEASING, Phase.PREPARING):
                state.setpoint = {}  # the last command of a motion is written once, then left alone
        out[h.gripped] = state.phase in (Phase.HELD, Phase.RELEASING)
        out[h.fault] = state.fault is not Fault.NONE
        if h.busy:
            out[h.busy] = state.phase in (Phase.GRIPPING, Phase.RELEASING, Phase.PREPARING)
        if h.fault_code:
            out[h.fault_code] = int(state.fault)
        if h.state:
            out[h.state] = int(state.phase)
        if h.done:
            busy = state.phase in (Phase.GRIPPING, Phase.RELEASING, Phase.PREPARING)
            out[h.done] = bool(state.job and not busy and inputs[state.job])
        return out

    def within_travel(self, position: float) -> bool:
        """The position is one the axes can be set to (always, without `travel`; never, for NaN)."""
        if math.isnan(position):
            return False
        return self.travel is None or self.travel[0] <= position <= self.travel[1]

    @staticmethod
    def _edge(inputs: Mapping, state: GripState, name: str | None) -> bool:
        if not name:
            return False
        value = bool(inputs[name])
        rising = value and not state.edges.get(name, False)
        state.edges[name] = value
        return rising

    def _grip_scan(self, state: GripState, forces: list[float], actual: dict[str, float], elapsed: float,
                   now: float, touching: bool = True) -> None:
        if all(f >= self.threshold for f in forces) and touching:
            if self.press:  # press on: a position servo's grip force grows with its setpoint past the part
                close = self.close_direction[state.mode]
                state.setpoint = {a: self._within_travel(v + close * self.press) for a, v in state.setpoint.items()}
            state.phase, state.held_at = Phase.HELD, dict(state.setpoint)
            state.forces_at_grip = dict(zip(self.forces, forces))
            return
        end = float(self.end_of_travel[state.mode])
        step = self.speed * elapsed
        if self.per_finger:
            moving = [a for a, f in zip(self.axes, forces) if f < self.threshold]
        else:
            moving = list(self.axes)
        for a in moving:
            state.setpoint[a] = _towards(state.setpoint[a], end, step)
        # a miss: every axis still looking for force has its setpoint at the end of travel and is there
        # (or has had `settle` seconds to get there)
        if self._arrived(state, {a: end for a in moving}, actual, now):
            state.phase, state.fault = Phase.FAULT_MISSED, Fault.MISSED

    def _start_release(self, state: GripState, actual: dict[str, float], now: float) -> None:
        opening = -self.close_direction[state.mode]
        start = dict(state.held_at) if state.phase is Phase.HELD and state.held_at else dict(actual)
        if state.phase is Phase.GRIPPING:
            start = dict(state.setpoint)
        limit = self.release_limit.get(state.mode)
        if limit is None:
            furthest = max(start.values()) if opening > 0 else min(start.values())
            limit = furthest + opening * self.release_travel
        state.phase, state.fault, state.goal, state.since = Phase.RELEASING, Fault.NONE, float(limit), now
        state.setpoint, state.free_from, state.at_end_since = {a: float(start.get(a, actual[a])) for a in self.axes}, None, None

    def _release_scan(self, inputs: Mapping, state: GripState, forces: list[float], actual: dict[str, float],
                      elapsed: float, now: float) -> None:
        opening = -self.close_direction[state.mode]
        free = all(f < self.free_force for f in forces) and not any(bool(inputs[c]) for c in (self.contacts or ()))
        if not free:
            state.free_from = None
            targets = {a: state.goal for a in self.axes}
        else:
            if state.free_from is None:
                state.free_from, state.at_end_since = dict(actual), None
            targets = {a: self._release_target(state, state.free_from[a], opening) for a in self.axes}
        step = self.speed * elapsed
        for a in self.axes:
            state.setpoint[a] = _towards(state.setpoint[a], targets[a], step)
        if self._arrived(state, targets, actual, now):
            if free:
                state.phase = Phase.IDLE
            else:
                state.phase, state.fault = Phase.FAULT_STUCK, Fault.STUCK

    def _arrived(self, state: GripState, targets: Mapping[str, float], actual: Mapping[str, float], now: float) -> bool:
        """Every setpoint is at its target and every axis there too (or has had `settle` s to get there)."""
        if not all(state.setpoint[a] == targets[a] for a in targets):
            state.at_end_since = None
            return False
        if state.at_end_since is None:
            state.at_end_since = now
        return (all(abs(actual[a] - targets[a]) <= self.tolerance for a in targets)
                or now - state.at_end_since >= self.settle)

    def _release_target(self, state: GripState, free_at: float, opening: int) -> float:
        """Where an axis opens to once the part is free: a margin further, at least to the ready position."""
        target = free_at + opening * self.release_margin
        ready = self.ready_position.get(state.mode)
        if ready is not None:
            target = max(target, ready) if opening > 0 else min(target, ready)
        return min(target, state.goal) if opening > 0 else max(target, state.goal)


def _towards(value: float, goal: float, step: float) -> float:
    """Move `value` towards `goal` by at most `step`, landing exactly on `goal`."""
    if math.isclose(value, goal, abs_tol=1e-12) or abs(goal - value) <= step:
        return float(goal)
    return value + math.copysign(step, goal - value)
