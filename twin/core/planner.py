"""The motion queue: motions handed to the robot ahead of time, blended in their zones as a controller plans them.

RAPID's program pointer runs ahead of the robot: a motion to a zone point is handed over while the motion
before it still runs, so the path planner knows where the robot goes next before it reaches the point.
`MotionQueue` keeps those motions on the robot's motion clock (seconds). Each is a rest-to-rest
`Trajectory` (motion.py) planned from the previous one's *programmed* end; where the previous one ends in a
zone, the new one starts while the previous one is still running, when its TCP enters the zone, and the two
overlap in joint space:

    q(t) = q_start + sum over motions of (q_i(t - start_i) - q_i(0))

(each q_i held at its ends outside its own time). Where two straight moves meet, the TCP leaves the first
line at the zone's edge, cuts the corner and joins the second line within the zone; the speed never falls
to zero, because the second motion speeds up while the first one slows down.

The zone (RAPID zonedata): the corner path starts when the TCP is within `Zone.tcp` (pzone_tcp) of the
programmed point and, for a reorientation, the tool within `Zone.angle` (zone_ori) of its programmed
orientation. As on the controller, both are reduced to half the distance (and half the reorientation) to the
neighbouring programmed points, so two corners never overlap. The start of the overlap is then delayed (by
bisection) until the whole corner path stays within the zone's radius of the point: the path in a zone stays
in the zone. A zone point whose next motion is not known when the TCP reaches the zone becomes a stop point
(RAPID's "corner path failure"); `Segment.corner_failure` says so. The program goes on past a zone point's
instruction when the TCP reaches the largest of its zones (`Segment.ready`), "some time before" the corner as
the RAPID manual puts it, so the next motion is known when the corner path starts. `Zone.ori`, `Zone.eax`, `Zone.leax` and
`Zone.reax` (pzone_ori, pzone_eax, zone_leax, zone_reax) are kept: the twin has no external axes and blends
orientation and position over one corner.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .geometry import quat_matrix, rotation_angles
from .motion import Trajectory

#: zone entry found to this time (s)
ENTRY_RESOLUTION = 1e-4
#: a reorientation smaller than this (rad) does not count for zone_ori
MIN_TURN = 1e-4
#: a next motion this late (s) after the TCP entered the zone still gets a corner path, from where the TCP is
#: (a controller ticked at its step sees the zone's edge up to a step late)
LATE = 0.025
#: samples of the corner path checked against the zone
CORNER_SAMPLES = 16
#: RestoPath: the robot must be back within this distance (m) of where the stored path stands
REGAIN_DISTANCE = 0.001
#: StopMove without \\Quick decelerates each axis at this share of its acceleration limit at most
STOP_SHARE = 0.5
#: times tried at once where a search narrows an interval (15: 1/16 of it per round)
REFINE = 15


@dataclass(frozen=True)
class Zone:
    """Where a motion may leave its programmed end point (RAPID zonedata, SI units); a stop point if `fine`.

    tcp: pzone_tcp (m); ori: pzone_ori (m); eax: pzone_eax (m); angle: zone_ori (rad); leax: zone_leax (m);
    reax: zone_reax (rad)."""

    fine: bool = True
    tcp: float = 0.0
    ori: float = 0.0
    eax: float = 0.0
    angle: float = 0.0
    leax: float = 0.0
    reax: float = 0.0


FINE = Zone()


class Segment:
    """One motion in the queue: its trajectory and zone, and when it starts on the motion clock."""

    def __init__(self, handle: int, traj: Trajectory, zone: Zone, start: float):
        self.handle, self.traj, self.zone, self.start = handle, traj, zone, start
        self.point = traj.tcp(traj.q_end)  # the programmed point (the TCP at the end)
        self.q0 = traj.q_start
        self.ready = start  # when the program may go on past this motion (its largest zone reached)
        self.corner_failure = False  # a zone point that became a stop point: its next motion came too late
        self.radius = 0.0  # the zone's radius as reduced for its neighbours (m), once its corner is planned
        self.lists = None  # (the queue's base it was formed for, that base and q0 as lists): `MotionQueue.command`
        self.end = start + traj.duration  # when it ends on the motion clock (asked at every physics substep)

    def delta(self, t: float) -> np.ndarray:
        return self.traj.q(t - self.start) - self.q0

    def __repr__(self) -> str:
        return f"Segment({self.handle}, {self.traj!r}, start {self.start:.3f})"


class MotionQueue:
    """Motions on the robot's motion clock, overlapping where they blend; see the module docstring."""

    def __init__(self, q: np.ndarray):
        self.q_base = np.array(q, dtype=float)  # where the first kept segment starts
        self.segments: list[Segment] = []

    @property
    def end(self) -> float:
        """When the last motion ends (0 when empty)."""
        segments = self.segments
        if len(segments) == 1:  # (the common case, asked at every physics substep)
            return segments[0].end
        return max((s.end for s in segments), default=0.0)

    @property
    def q_end(self) -> np.ndarray:
        """The last motion's programmed end (where a new motion is planned from)."""
        return self.segments[-1].traj.q_end if self.segments else self.q_base.copy()

    @property
    def last(self) -> Segment | None:
        return self.segments[-1] if self.segments else None

    def find(self, handle: int) -> Segment | None:
        return next((s for s in self.segments if s.handle == handle), None)

    def add(self, traj: Trajectory, zone: Zone, now: float, handle: int = 0) -> Segment:
        """Append `traj` (planned from `q_end`), starting at `now` at the earliest: after the last motion if that
        ends at a stop point, or at its corner if it ends in a zone and its TCP has not passed the zone's edge."""
        self._prune(now)
        prev = self.last
        start = now
        if prev is not None and prev.end > now:
            start = prev.end
            if not prev.zone.fine:
                corner = self._corner(prev, traj, now)
                if corner is None:
                    prev.corner_failure = True
                else:
                    start = corner
        seg = Segment(handle, traj, zone, start)
        seg.ready = start
        if not zone.fine:  # the program goes on as the TCP reaches the largest zone
            largest = min(max(zone.tcp, zone.ori, zone.eax), traj.tcp(traj.q_start).distance(seg.point) / 2)
            if largest > 1e-6:
                seg.ready = start + self._entry(traj, seg.point, largest, math.inf)
        self.segments.append(seg)
        return seg

    def _prune(self, now: float) -> None:
        """Forget motions over before `now` (their end becomes the base), keeping the last one."""
        while len(self.segments) > 1 and self.segments[0].end <= now and self.segments[1].start <= now:
            first = self.segments.pop(0)
            self.q_base = self.q_base + first.traj.q_end - first.q0

    def q(self, t: float) -> np.ndarray:
        out = self.q_base.copy()
        for s in self.segments:
            if t > s.start:
                out += s.delta(t)
        return out

    def qd(self, t: float) -> np.ndarray:
        out = np.zeros_like(self.q_base)
        for s in self.segments:
            if s.start < t < s.end:
                out += s.traj.qd(t - s.start)
        return out

    def state(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(q, qd) at t: what the robot commands at every physics substep."""
        segments = self.segments
        if len(segments) == 1:  # (the common case: one motion, no blend)
            s = segments[0]
            q, qd = s.traj.state(t - s.start)
            return self.q_base + (q - s.q0), (qd if s.start < t < s.end else qd * 0.0)
        q, qd = self.q_base.copy(), np.zeros_like(self.q_base)
        for s in segments:
            if t > s.start:
                qs, qds = s.traj.state(t - s.start)
                q += qs - s.q0
                if t < s.end:
                    qd += qds
        return q, qd

    def command(self, t: float) -> tuple[list[float], list[float]]:
        """`state` as lists of floats, the same values (what the robot sends pybullet at every physics substep)."""
        segments = self.segments
        if len(segments) != 1:
            q, qd = self.state(t)
            return q.tolist(), qd.tolist()
        s = segments[0]
        lists = s.lists
        if lists is None or lists[0] is not self.q_base:
            lists = s.lists = (self.q_base, self.q_base.tolist(), s.q0.tolist())
        q, qd = s.traj.state_lists(t - s.start, lists[1], lists[2])
        return q, (qd if s.start < t < s.end else [v * 0.0 for v in qd])

    # -- corners ------------------------------------------------------------------------------------
    def _corner(self, prev: Segment, nxt: Trajectory, now: float) -> float | None:
        """When `nxt` starts to blend out of `prev`'s zone, or None when the TCP is already past the zone's edge
        (or the zone shrinks to nothing: a stop point)."""
        traj, point = prev.traj, prev.point
        before = traj.tcp(traj.q_start)
        after = nxt.tcp(nxt.q_end)
        radius = min(prev.zone.tcp, before.distance(point) / 2, point.distance(after) / 2)
        angle = math.inf
        turns = [a for a in (before.angle(point), point.angle(after)) if a > MIN_TURN]
        if prev.zone.angle > 0 and turns:
            angle = min([prev.zone.angle] + [a / 2 for a in turns])
        if radius <= 1e-6 or angle <= MIN_TURN:
            return prev.end  # nothing left of the zone: a stop point, no failure
        prev.radius = radius

        first = prev.start + self._entry(traj, point, radius, angle)
        if first < now - LATE:
            return None  # the TCP has entered the zone already: too late for a corner path
        first = max(first, now)
        # the corner path must stay within the zone: start later (less overlap) until it does, to 1/4096 of the
        # time left (REFINE starts tried at once)
        if self._within(prev, nxt, np.array([first]), point, radius)[0]:
            return first
        lo, hi = first, prev.end
        for _ in range(3):
            starts = lo + (hi - lo) * np.arange(1, REFINE + 1) / (REFINE + 1)
            good = np.flatnonzero(self._within(prev, nxt, starts, point, radius))
            i = int(good[0]) if len(good) else REFINE
            lo, hi = (float(starts[i - 1]) if i > 0 else lo), (float(starts[i]) if i < REFINE else hi)
        return hi

    @staticmethod
    def _entry(traj: Trajectory, point, radius: float, angle: float) -> float:
        """When (s into traj) its TCP enters the zone of `radius` (and `angle`) around `point` for good: the last
        time it is outside, searched back from the end in steps of 1/64 of the motion (64 at a time), then
        narrowed down to ENTRY_RESOLUTION (REFINE times at once)."""
        centre, orientation = point.position, quat_matrix(point.orientation)

        def inside(ts: np.ndarray, first: bool = False) -> np.ndarray:
            cached = getattr(traj, "_last_batch", None) if first else None  # (the zone's and the corner's search)
            if cached is not None and np.array_equal(cached[0], ts):
                positions, rotations = cached[1], cached[2]
            else:
                positions, rotations = traj.tcp_many(traj.q_many(ts))
                if first:
                    traj._last_batch = (ts, positions, rotations)
            ok = np.linalg.norm(positions - centre, axis=1) <= radius
            if math.isfinite(angle) and rotations is not None:
                ok &= rotation_angles(rotations, orientation) <= angle
            return ok

        d = traj.duration
        step = max(d / 64, 0.005)
        top = d
        while True:
            times = np.maximum(top - step * np.arange(64), 0.0)
            outside = np.flatnonzero(~inside(times, top == d))
            if len(outside):
                lo = float(times[outside[0]])
                break
            if times[-1] <= 0:
                return 0.0
            top = float(times[-1]) - step
        hi = min(lo + step, d)
        while hi - lo > ENTRY_RESOLUTION:  # the last time outside between lo (outside) and hi (inside)
            times = lo + (hi - lo) * np.arange(1, REFINE + 1) / (REFINE + 1)
            outside = np.flatnonzero(~inside(times))
            i = int(outside[-1]) if len(outside) else -1
            lo, hi = (float(times[i]) if i >= 0 else lo), (float(times[i + 1]) if i + 1 < REFINE else hi)
        return hi

    @staticmethod
    def _within(prev: Segment, nxt: Trajectory, starts: np.ndarray, point, radius: float) -> np.ndarray:
        """For each start time of nxt: does the TCP of prev + nxt stay within `radius` of `point` while they
        overlap (CORNER_SAMPLES - 1 times checked)?"""
        q_end = prev.traj.q_end
        f = np.arange(1, CORNER_SAMPLES) / CORNER_SAMPLES
        ts = (starts[:, None] + (prev.end - starts)[:, None] * f[None, :]).ravel()
        since = (ts.reshape(len(starts), -1) - starts[:, None]).ravel()
        qs = prev.traj.q_many(ts - prev.start) + (nxt.q_many(since) - q_end)
        positions, _ = nxt.tcp_many(qs)
        far = np.linalg.norm(positions - point.position, axis=1) > radius * (1 + 1e-6) + 1e-6
        return ~far.reshape(len(starts), -1).any(axis=1)


# -- the motion clock: StopMove and StartMove -------------------------------------------------------------
class PathClock:
    """The motion queue's time (tau, s) as a function of the cell's time t: tau = t - t0 while the robot runs.

    `stop(t, ramp)` (StopMove) lowers the clock's rate to 0 over `ramp` seconds as a half cosine, so the robot
    decelerates on its planned path (blends included: they are functions of tau) and stands; `start(t, ramp)`
    (StartMove) raises it to 1 again the same way, and the rest of the same path follows. Every motion keeps its
    plan; only when it runs changes. `shift(dt)` delays everything (a paused robot)."""

    def __init__(self, t0: float):
        # the present phase: from t_a (tau_a there) the rate goes from r_from to r_to in `ramp` s, then stays
        self.t_a, self.tau_a, self.r_from, self.r_to, self.ramp = float(t0), 0.0, 1.0, 1.0, 0.0

    @property
    def stopping(self) -> bool:
        """Stopped or stopping (StopMove), until `start`."""
        return self.r_to == 0.0

    def shift(self, dt: float) -> None:
        self.t_a += dt

    def _phase(self, t: float) -> tuple[float, float]:
        """(tau, rate) at t."""
        u, T, r0, r1 = t - self.t_a, self.ramp, self.r_from, self.r_to
        if u <= 0:
            return self.tau_a + u * r0, r0
        if u >= T:
            return self.tau_a + r1 * T + (r0 - r1) * T / 2 + r1 * (u - T), r1
        w = math.pi * u / T
        return self.tau_a + r1 * u + (r0 - r1) * (u / 2 + T / (2 * math.pi) * math.sin(w)), r1 + (r0 - r1) * (1 + math.cos(w)) / 2

    def tau(self, t: float) -> float:
        return self._phase(t)[0]

    at = _phase  # (tau, rate) at t, in one go (the robot asks at every physics substep)

    def rate(self, t: float) -> float:
        return self._phase(t)[1]

    def t_of(self, tau: float) -> float | None:
        """When the clock reaches tau (at or after the present phase's start), None if it stands before."""
        d, T = tau - self.tau_a, self.ramp
        if d <= 0:
            return self.t_a + d / self.r_from if self.r_from > 0 else self.t_a
        after = self.r_to * T + (self.r_from - self.r_to) * T / 2  # tau gained over the ramp
        if d >= after:
            return None if self.r_to == 0 else self.t_a + T + (d - after) / self.r_to
        lo, hi = self.t_a, self.t_a + T  # within the ramp: tau rises monotonically
        for _ in range(60):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if self.tau(mid) < tau else (lo, mid)
        return hi

    def _to(self, t: float, rate: float, ramp: float) -> None:
        self.tau_a, self.r_from = self._phase(t)
        self.t_a, self.r_to = float(t), rate
        self.ramp = ramp * abs(rate - self.r_from)  # (from a rate part-way: the same steepness)

    def stop(self, t: float, ramp: float) -> None:
        if not self.stopping:
            self._to(t, 0.0, ramp)

    def start(self, t: float, ramp: float) -> None:
        if self.stopping:
            self._to(t, 1.0, ramp)


def stop_on_path(kin, queue: "MotionQueue", clock: "PathClock", t: float, quick: bool, at_end: bool) -> None:
    """StopMove on a running path (robot.Robot and KinematicRobot alike): decelerate along it (`quick`: at the axes'
    full acceleration limits, else half), or with `at_end` stand at the end of the motion under way."""
    tau = clock.tau(t)
    if at_end:
        seg = next((s for s in queue.segments if s.start <= tau < s.end), None)
        clock.stop(clock.t_of(seg.end) if seg is not None else t, 0.0)
    else:
        clock.stop(t, stop_ramp(kin, queue.state(tau)[1], quick))


def restart_on_path(kin, queue: "MotionQueue", clock: "PathClock", t: float) -> None:
    """StartMove: the rest of a stopped path, speeding up as it slowed down."""
    clock.start(t, stop_ramp(kin, queue.state(clock.tau(t))[1], False))


def stand_time(standing: bool, clock: "PathClock | None", t: float) -> float | None:
    """When a path will stand: t if it does (or the robot is idle), the end of its stop ramp while it stops, None
    if it is not stopping."""
    if standing:
        return t
    if clock is not None and clock.stopping:
        return clock.t_a + clock.ramp
    return None


def stop_ramp(kin, qd: np.ndarray, quick: bool) -> float:
    """How long (s) a StopMove takes to bring the clock's rate from 1 to 0 as a half cosine when the axes move at
    qd: the rate's steepest fall (pi / 2 / ramp) times each axis's speed at most its acceleration limit (\\Quick)
    or half of it (StopMove: a longer braking distance, as at a program stop)."""
    accel = np.asarray(kin.accel if kin is not None else np.full(len(qd), 10.0), dtype=float)
    share = 1.0 if quick else STOP_SHARE
    return float(math.pi / 2 * np.max(np.abs(qd) / (share * accel))) if len(qd) else 0.0


# -- planning one motion ---------------------------------------------------------------------------------
def configuration(q: np.ndarray) -> tuple[int, int, int]:
    """RAPID's robconf cf1, cf4, cf6: the quadrants of axes 1, 4 and 6 (0 for 0 to 90 deg, -1 for -90 to 0, ...)."""
    return tuple(int(math.floor(math.degrees(float(q[i])) / 90.0 + 1e-9)) for i in (0, 3, 5))  # type: ignore


def plan_motion(kin, instr: str, q0: np.ndarray, target, speed, via=None, name: str = "",
                conf: tuple[int, int, int] | None = None) -> Trajectory:
    """The trajectory of one motion instruction from q0: MoveJ, MoveL, MoveC (through `via`) to a TCP Pose of
    `kin`'s tool, or MoveAbsJ to joint angles (rad). With `conf` (cf1, cf4, cf6; configuration monitoring on) a
    MoveJ seeks that configuration and any motion ending in another one is refused (MotionError)."""
    from . import motion
    from .errors import MotionError

    name = name or instr
    if instr == "MoveJ":
        traj = motion.movej(kin, q0, target, None, speed, name)
        if conf is not None and configuration(traj.q_end) != tuple(conf):
            seed = np.array(q0, dtype=float)
            for i, c in zip((0, 3, 5), conf):
                seed[i] = math.radians(90.0 * c + 45.0)
            try:
                q1 = kin.ik(target, seed, name)
                traj = motion.movej(kin, q0, None, q1, speed, name)
            except MotionError:
                pass
    elif instr == "MoveL":
        traj = motion.movel(kin, q0, target, speed, name)
    elif instr == "MoveC":
        traj = motion.movec(kin, q0, via, target, speed, name)
    elif instr == "MoveAbsJ":
        traj = motion.moveabsj(q0, target, speed, kin.limits, name, kin)
    else:
        raise MotionError(name, f"unknown motion instruction {instr!r}")
    if conf is not None and instr != "MoveAbsJ" and configuration(traj.q_end) != tuple(conf):
        got = configuration(traj.q_end)
        raise MotionError(name, f"configuration [{conf[0]}, {conf[1]}, *, {conf[2]}] cannot be reached "
                                f"(the arm gets there as [{got[0]}, {got[1]}, *, {got[2]}]; configuration "
                                f"monitoring is on)")
    return traj


class KinematicRobot:
    """The motion queue on a clock without physics (offline runs): the robot is exactly where the plan says, at
    rest once its last motion's plan is over. Same interface as `robot.Robot` for queueing, asking and path
    control (StopMove and the rest: the same PathClock)."""

    def __init__(self, kin, q: np.ndarray):
        self.kinematics = kin
        self._q = np.array(q, dtype=float)
        self._queue: MotionQueue | None = None
        self._clock = PathClock(0.0)
        self._handles = 0
        self._corner_failures: set[int] = set()
        self._stored = None

    def _tau(self, t: float) -> float:
        return self._clock.tau(t)

    def q_at(self, t: float) -> np.ndarray:
        if self._queue is None:
            return self._q.copy()
        return self._queue.q(min(self._tau(t), self._queue.end))

    def busy(self, t: float) -> bool:
        return self._queue is not None and self._tau(t) < self._queue.end

    def plan_start(self, t: float) -> np.ndarray:
        return self._queue.q_end if self.busy(t) else self.q_at(t)

    def queue(self, traj: Trajectory, zone: Zone, t: float) -> int:
        self._handles += 1
        if not self.busy(t):
            last = self._queue.last if self._queue is not None else None
            if last is not None and not last.zone.fine:  # it ran out of motions at a zone point: a stop point
                self._corner_failures.add(last.handle)
            self._q = self.q_at(t)
            self._queue, self._clock = MotionQueue(traj.q_start), PathClock(t)
        prev = self._queue.last
        self._queue.add(traj, zone, self._tau(t), self._handles)
        if prev is not None and prev.corner_failure:
            self._corner_failures.add(prev.handle)
        return self._handles

    def _segment(self, handle: int) -> Segment | None:
        return self._queue.find(handle) if self._queue is not None else None

    def start_time(self, handle: int) -> float | None:
        seg = self._segment(handle)
        return None if seg is None else self._clock.t_of(seg.start)

    def end_time(self, handle: int) -> float | None:
        seg = self._segment(handle)
        return None if seg is None else self._clock.t_of(seg.end)

    def ready_time(self, handle: int) -> float | None:
        seg = self._segment(handle)
        return None if seg is None else self._clock.t_of(seg.ready)

    def ready(self, handle: int, t: float) -> bool:
        seg = self._segment(handle)
        return seg is None or self._tau(t) >= seg.ready - 1e-9

    def done(self, handle: int, t: float) -> bool:
        seg = self._segment(handle)
        return seg is None or self._tau(t) >= seg.end - 1e-9

    def corner_failure(self, handle: int) -> bool:
        return handle in self._corner_failures

    # -- path control, as robot.Robot's --------------------------------------------------------------------
    def stop_path(self, t: float, quick: bool = False, at_end: bool = False) -> None:
        if self.busy(t):
            stop_on_path(self.kinematics, self._queue, self._clock, t, quick, at_end)

    def path_standing(self, t: float) -> bool:
        return not self.busy(t) or (self._clock.stopping and self._clock.rate(t) == 0.0)

    def stand_time(self, t: float) -> float | None:
        return stand_time(self.path_standing(t), self._clock, t)

    def start_path(self, t: float) -> None:
        if self._queue is not None and self._clock.stopping:
            restart_on_path(self.kinematics, self._queue, self._clock, t)

    def _stand(self, t: float) -> np.ndarray:
        q = self.q_at(t)
        self._q, self._queue, self._clock = q, None, PathClock(t)
        return q

    def clear_path(self, t: float) -> None:
        self._stand(t)

    def store_path(self, t: float) -> None:
        stored = (self._queue, self._clock)
        self._stored = (*stored, self._stand(t))

    def restore_path(self, t: float) -> None:
        from .errors import MotionError

        if self._stored is None:
            raise MotionError("RestoPath", "no path is stored (StorePath first)")
        queue, clock, stand = self._stored
        self._stored = None
        off = self.kinematics.fk(self.q_at(t)).distance(self.kinematics.fk(stand))
        if queue is not None and off > REGAIN_DISTANCE:
            raise MotionError("RestoPath", f"the robot is {off * 1000:.1f} mm from where the stored path stands "
                                           f"(at most {REGAIN_DISTANCE * 1000:g} mm): move it back there first")
        if queue is not None:
            self._queue, self._clock = queue, clock
