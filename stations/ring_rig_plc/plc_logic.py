"""The ring rig's gripper PLC (thesis section 3.1): the grip sequence with the rig's numbers, in mm and N.

Fingers (axes L2, L3, L4; finger forces L2, L3 and L5, the fine axis on finger 3) close from outside onto
the ring's 320 mm outer radius, or open from inside into its 240 mm bore (finger outer faces at setpoint
+ 40 mm, so touching at 200 mm). A grip that reaches 290 mm (outside) or 230 mm (inside) without force
has missed the ring. A release opens at least back to where the next grip of the same kind starts
(330 mm outside, 150 mm inside).

`sequence()` uses the generic handshake names (grip_request, gripped, ...), for benches where a test
plays the robot; `cell_sequence()` speaks the robot program of `stations/ring_rig_plc` (doGripRequest,
diGripDone, ...), with the prepare request that puts the fingers where the robot asks (aoFingerReady):

    plc --port 5020 --station stations/ring_rig_plc run stations.ring_rig_plc.plc_logic:cell_sequence
    plc --port 5020 --station stations/ring_rig_plc run          # the same: station.toml names it ([plugins])

It is a careful commissioning engineer's PLC (`CarefulGripSequence`): besides every finger's own force
(and contact) above the threshold, it confirms a grip only when every axis is where its drive put it, i.e.
stopped by the part's reaction and not by something else; it watches each finger while it moves and
declares a fault within a bounded time when one does not follow its setpoint (jammed: its drive pushes
hard and it does not move; drive lost: it lags and its drive pushes with almost nothing), when a grip is
neither confirmed nor missed within the time its ramp needs, and when a held part's force goes away.
A fault during a grip is a failed grip for the robot (diGripFault, as for a miss); during a finger
preparation it answers the request with diGripFault; the axes are then held where they are.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping

from plc_client.grip_sequence import Fault, GripSequence, GripState, Handshake, Phase

AXES = ("L2", "L3", "L4")
FORCES = ("L2.force", "L3.force", "L5.force")
CONTACTS = ("L2.contact", "L3.contact", "L5.contact")
EFFORTS = ("L2.effort", "L3.effort", "L4.effort")  # each axis's drive force, as the drive measures it
MOVING = (Phase.GRIPPING, Phase.PREPARING, Phase.RELEASING)


@dataclass
class CarefulState(GripState):
    """The careful sequence's memory: the fingers' watch, the grip's timers and the last finger fault."""

    held_back: set = field(default_factory=set)  # axes whose ramp waited for them in the last scan
    stall_since: dict[str, float] = field(default_factory=dict)  # axis -> time its ramp began waiting for it
    stall_from: dict[str, float] = field(default_factory=dict)  # axis -> where it was then
    grip_deadline: float | None = None
    grip_started: float | None = None  # `since` of the grip the deadline belongs to
    weak_since: float | None = None  # HELD: when a finger's force fell below hold_force
    fault_axis: str | None = None  # the axis a finger fault names
    fault_lag: float = 0.0  # its distance from its setpoint (units of the axes) when the fault was declared
    fault_effort: float | None = None  # its drive force then
    clock: float = 0.0  # s: the sequence's own time: advanced by the process's clock (or the PLC's) while fresh
    source_last: float | None = None  # that clock's value at the previous scan


CLOCK_GAP = 0.1  # s: a jump of the clock longer than this (and 3 scans) between two scans is a gap, not counted


class _OnClock(Mapping):
    """An input image whose `time` is the sequence's own clock (s). It runs with the process's clock (or the
    PLC's) only while the inputs are fresh: while they are stale (a lost link: the process's clock stands
    still in them, or `link.ok` is false) the sequence's ramps and timers wait; when they come back, the
    time they missed is not counted (no ramp jumps by what it would have moved meanwhile, no timer expires
    on data it never saw)."""

    def __init__(self, inputs: Mapping, now: float):
        self._inputs, self.time = inputs, now

    def __getitem__(self, name):
        return self._inputs[name]

    def __iter__(self):
        return iter(self._inputs)

    def __len__(self):
        return len(self._inputs)


@dataclass
class CarefulGripSequence(GripSequence):
    """A `GripSequence` that watches its fingers (the parameters of `GripSequence`, and):

    max_lag         a ramp (grip, release, preparation) never runs more than max_lag / 2 ahead of its axis: it
                    waits for a finger that lags; no grip is confirmed with an axis further than `max_lag`
                    from its setpoint (a finger stopped by something else than the part's reaction)
    lag_time        a finger whose ramp waits for it and that makes less headway in this long (s) than
                    `follow_ratio` x the ramp's speed (and at least max_lag / 6) does not follow: a finger
                    fault (`Fault.JAMMED` or `Fault.DRIVE_LOST`), whatever the phase (ring rig: a finger
                    slower than 4 mm/s in a grip, 20 mm/s in a preparation)
    follow_ratio    see lag_time
    efforts         optional drive-force signals, one per axis: a finger that does not follow, stood still
                    meanwhile and whose drive pushes with at least `blocked_effort` is jammed; one whose drive
                    pushes less, or that goes where it is pushed, has lost its drive. (Without them, standing
                    still is jammed.)
    grip_time       s: a grip neither confirmed nor missed within this is `Fault.TIMEOUT` (default: the time
                    the ramp needs from where the grip starts to the end of travel, plus `settle` and
                    `grip_margin`)
    hold_force      HELD: a finger whose force stays below this (default: threshold / 2) for `hold_time` s
                    has lost the part: `Fault.LOST`, `gripped` falls
    clock           optional input giving the process's time in ms (e.g. "sim.time_ms"): the sequence's ramps
                    and timers run on it (else on the PLC's time), so inputs that stop changing (a lost link)
                    are not judged
    link_ok         optional input, false while the PLC's inputs are stale (`plc_client.link`'s `link.ok`, a
                    PLC's communication status): the ramps and timers wait meanwhile. A PLC with neither
                    cannot tell a lost link from a finger that does not move.
    """

    max_lag: float = 3.0
    lag_time: float = 0.2
    follow_ratio: float = 0.2
    efforts: tuple[str, ...] | None = None
    blocked_effort: float = 1000.0
    grip_time: float | None = None
    grip_margin: float = 1.0
    hold_force: float | None = None
    hold_time: float = 0.1
    clock: str | None = None
    link_ok: str | None = None

    def __post_init__(self):
        super().__post_init__()
        if self.efforts is not None:
            self.efforts = tuple(self.efforts)
            if len(self.efforts) != len(self.axes):
                raise ValueError(f"{len(self.efforts)} effort signals for {len(self.axes)} axes")
        if not self.max_lag > 0 or self.lag_time < 0 or self.hold_time < 0 or self.grip_margin < 0 or not 0 <= self.follow_ratio < 1:
            raise ValueError("max_lag must be greater than 0; lag_time, hold_time and grip_margin not negative; "
                             "follow_ratio from 0 to below 1")
        if self.grip_time is not None and not self.grip_time > 0:
            raise ValueError(f"grip_time must be greater than 0 s, not {self.grip_time!r}")
        if self.hold_force is None:
            self.hold_force = self.threshold / 2.0

    @property
    def inputs(self) -> tuple[str, ...]:
        extra = (*(self.efforts or ()), *(n for n in (self.clock, self.link_ok) if n))
        return tuple(dict.fromkeys((*super().inputs, *extra)))

    def handshake_signals(self) -> dict:
        return {**super().handshake_signals(), **({self.link_ok: True} if self.link_ok else {})}

    def initial_state(self) -> CarefulState:
        return CarefulState()

    def __call__(self, inputs: Mapping, state: CarefulState) -> dict:
        source = float(inputs[self.clock]) / 1000.0 if self.clock else float(getattr(inputs, "time", 0.0))
        fresh = not self.link_ok or bool(inputs[self.link_ok])
        if state.source_last is not None and fresh:
            gap = max(3.0 * float(getattr(inputs, "cycle", 0.0) or 0.0), CLOCK_GAP)
            step = source - state.source_last
            state.clock += step if 0.0 <= step <= gap else 0.0
        state.source_last = source
        inputs = _OnClock(inputs, state.clock)
        self._watch(inputs, state, state.clock)
        return super().__call__(inputs, state)

    # what the scan sees before the sequence acts on it
    def _watch(self, inputs: Mapping, state: CarefulState, now: float) -> None:
        actual = {a: float(inputs[n]) for a, n in zip(self.axes, self.actuals)}
        if state.phase in MOVING:
            speed = (self.travel_speed or self.speed) if state.phase is Phase.PREPARING else self.speed
            headway = max(self.max_lag / 6.0, self.follow_ratio * speed * self.lag_time)
            for a in self.axes:
                if a not in state.held_back:
                    state.stall_since.pop(a, None)
                    state.stall_from.pop(a, None)
                elif a not in state.stall_since or _headway(state, a, actual[a]) >= headway:
                    state.stall_since[a], state.stall_from[a] = now, actual[a]  # (re)start: it follows, if slowly
            stalled = [a for a in self.axes if a in state.stall_since and now - state.stall_since[a] >= self.lag_time]
            if stalled:
                return self._finger_fault(inputs, state, stalled[0], actual)
        else:
            state.held_back.clear()
            state.stall_since.clear()
            state.stall_from.clear()
        if state.phase is Phase.GRIPPING:
            if state.grip_started != state.since:  # a new grip: its deadline
                close = self.close_direction[state.mode]
                end = float(self.end_of_travel[state.mode])
                ramp = max(max(0.0, (actual[a] - end) * -close) for a in self.axes) / self.speed
                state.grip_started = state.since
                state.grip_deadline = state.since + (self.grip_time if self.grip_time is not None
                                                     else ramp + self.settle + self.grip_margin)
            if now > state.grip_deadline:
                self._fail(state, Fault.TIMEOUT, actual)
        elif state.phase is Phase.HELD:
            weak = any(float(inputs[n]) < self.hold_force for n in self.forces)
            if not weak:
                state.weak_since = None
            elif state.weak_since is None:
                state.weak_since = now
            elif now - state.weak_since >= self.hold_time:
                self._fail(state, Fault.LOST, actual)

    def _finger_fault(self, inputs: Mapping, state: CarefulState, axis: str, actual: dict) -> None:
        """A finger that does not follow: jammed if it stood still while its drive pushed hard (or, without
        drive-force signals, if it stood still), else its drive is lost (it pushes with little, or the
        finger goes where it is pushed). Jammed on the part itself (its contact set) with a force reading
        below the threshold: its force reading is wrong (`Fault.FORCE_READING`)."""
        i = self.axes.index(axis)
        effort = None if self.efforts is None else abs(float(inputs[self.efforts[i]]))
        still = abs(actual[axis] - state.stall_from.get(axis, actual[axis])) < self.max_lag / 6.0  # (0.5 mm)
        pushing = effort is None or effort >= self.blocked_effort
        kind = Fault.JAMMED if still and pushing else Fault.DRIVE_LOST
        if (kind is Fault.JAMMED and self.per_finger and self.contacts and bool(inputs[self.contacts[i]])
                and float(inputs[self.forces[i]]) < self.threshold):
            kind = Fault.FORCE_READING  # it is on the part and pushes hard, yet its force reading says otherwise
        state.fault_axis, state.fault_lag, state.fault_effort = axis, abs(state.setpoint[axis] - actual[axis]), effort
        self._fail(state, kind, actual)

    @staticmethod
    def _fail(state: CarefulState, fault: Fault, actual: dict) -> None:
        """Declare `fault`: a grip (or a held part) has failed, a preparation is answered with the fault, a
        release is stuck; the axes are held where they are (written once), and every timer is reset."""
        if fault in (Fault.TIMEOUT, Fault.LOST):
            state.fault_axis = None
        state.phase = {Phase.PREPARING: Phase.IDLE, Phase.RELEASING: Phase.FAULT_STUCK}.get(state.phase, Phase.FAULT_MISSED)
        state.fault = fault
        state.setpoint = dict(actual)
        state.held_back.clear()
        state.stall_since.clear()
        state.stall_from.clear()
        state.weak_since = state.grip_deadline = state.grip_started = None

    def _grip_scan(self, state, forces, actual, elapsed, now, touching=True) -> None:
        if all(f >= self.threshold for f in forces) and touching and any(
                abs(state.setpoint[a] - actual[a]) > self.max_lag for a in self.axes):
            return  # the forces are there, but an axis is not where its drive put it: no grip; the watch decides
        super()._grip_scan(state, forces, actual, elapsed, now, touching)

    def _arrived(self, state, targets, actual, now) -> bool:
        """Every motion phase (grip, release, preparation) ends its scan here, its setpoints moved: first keep
        each ramp within max_lag / 2 of its axis (a ramp waits for a finger that lags), then the usual check."""
        state.held_back = set()
        lead = self.max_lag / 2.0
        for a, goal in targets.items():
            ahead = state.setpoint[a] - actual[a]
            if abs(ahead) >= lead - 1e-9 and ahead * (goal - actual[a]) > 0:  # (at the lead: still waiting)
                state.setpoint[a] = actual[a] + math.copysign(lead, ahead)
                state.held_back.add(a)
        return super()._arrived(state, targets, actual, now)


def _headway(state: CarefulState, axis: str, actual: float) -> float:
    """How far the axis has moved towards its setpoint since its ramp began waiting for it."""
    start = state.stall_from[axis]
    return (actual - start) * math.copysign(1.0, state.setpoint.get(axis, actual) - start)


def sequence(handshake: Handshake | None = None, **overrides) -> CarefulGripSequence:
    """The ring rig's grip sequence; any `CarefulGripSequence` parameter can be overridden."""
    params = dict(axes=AXES, forces=FORCES, contacts=CONTACTS, efforts=EFFORTS, speed=20.0, threshold=200.0,
                  travel_speed=100.0,
                  end_of_travel={"outside": 290.0, "inside": 230.0},
                  ready_position={"outside": 330.0, "inside": 150.0},
                  release_limit={"outside": 441.0, "inside": 0.0},
                  travel=(0.0, 441.0),  # the axes' setpoint range (L2..L4: 0..441 mm)
                  press=1.0,  # then 1 mm on: 1500 N per finger, and the ring is held by friction alone
                  # a finger on the ring lags its setpoint by force / stiffness (4000 N at most: 1.6 mm); the
                  # ramps wait for a finger 1.5 mm behind; one that makes no 0.5 mm of headway in 0.2 s is held
                  # by something else (a jam) or not driven (a dead drive)
                  max_lag=3.0, lag_time=0.2, blocked_effort=1000.0,
                  link_ok="link.ok",  # the PLC's communication status (plc_client.link)
                  handshake=handshake or Handshake())
    params.update(overrides)
    return CarefulGripSequence(**params)


# The handshake with stations/ring_rig_plc/ring_rig_plc.mod (robot DOs are the PLC's inputs, and back).
CELL_HANDSHAKE = Handshake(grip_request="doGripRequest", release_request="doReleaseRequest", inside="doGripInside",
                           gripped="diGripOk", fault="diGripFault", busy=None, done="diGripDone",
                           prepare_request="doPrepare", prepare_position="aoFingerReady")


def cell_sequence(**overrides) -> GripSequence:
    """The gripper PLC of `stations/ring_rig_plc`: the rig's grip sequence on the robot program's handshake."""
    # on the cell's clock (in its register map, unlike link.ok): stale inputs stand still in it
    return sequence(CELL_HANDSHAKE, **{"clock": "sim.time_ms", "link_ok": None, **overrides})
