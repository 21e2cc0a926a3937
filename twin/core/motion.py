"""Robot motions as pure functions of time: MoveJ, MoveL, MoveC and MoveAbsJ trajectories.

A `Trajectory` is planned completely when it is built: Cartesian moves (MoveL, MoveC) solve IK at
sample points every 5 mm (and every 0.5 degrees of reorientation) along the path, each seeded by the
previous solution, so a path through an unreachable point, past a joint limit or through a
configuration flip raises `MotionError` naming the target before the robot moves. Executing it is then
only a lookup: `q(t)` and `qd(t)` for t in seconds since the motion started.

Timing: every motion runs from rest to rest along its path, with a jerk-limited ("S-curve") speed profile
(`Profile`): the path speed rises with the acceleration growing over RAMP_TIME to its limit, cruises and falls
again. The cruise speed is the highest at which the TCP keeps to v_tcp, the tool to v_ori and every axis to
its speed limit (`JointLimit.velocity` x `Speed.joint_fraction`) where it moves fastest along the path; the
acceleration the highest at which every axis keeps to its acceleration limit (`ArmKinematics.accel`, a
station's `[robot] accel_deg`) there, scaled by `Speed.acc` (AccSet, payload) and the jerk by `Speed.ramp`.
Like a real controller, a move that would need an axis faster than it can go is slowed down, not refused;
the whole move runs at one speed, so a MoveL passing close to a wrist singularity (joint_5 near 0) becomes
slow from start to end. Motions that blend in a zone overlap in time (planner.py): each is still planned
from rest to rest.
"""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from typing import Callable, Iterable, Sequence

import numpy as np

from .errors import MotionError
from .geometry import Pose, quat_from_matrix, quat_matrices, rotation_angles, slerp, slerp_many
from .kinematics import DEFAULT_ACCEL_TIME, ArmKinematics, JointLimit, check_limits

#: Cartesian paths are solved at least every SAMPLE_STEP m and SAMPLE_ANGLE rad.
SAMPLE_STEP = 0.005
SAMPLE_ANGLE = math.radians(0.5)
#: Between two neighbouring samples no axis may jump more than this (a configuration flip).
MAX_JOINT_JUMP = math.radians(5.0)
#: The acceleration rises to its limit (and falls from it) in this time (s) at AccSet's Ramp 100: the jerk limit
#: is the acceleration limit / RAMP_TIME.
RAMP_TIME = 0.1
#: Solve a Cartesian path's samples all at once (`_cartesian`); False: sample by sample only (the reference the
#: batch solve is tested and benchmarked against)
BATCH_IK = True
#: MoveC: the three points must be this far apart and not within 0.06 degrees of one line.
MIN_CIRCLE_POINT_DISTANCE = 0.001


@dataclass(frozen=True)
class Speed:
    """How fast a motion may go.

    v_tcp:          TCP speed along the path, m/s (RAPID speeddata v_tcp / 1000).
    v_ori:          reorientation speed of the tool, rad/s (RAPID v_ori; v1000 has 500 deg/s).
    joint_fraction: fraction of each axis's maximum speed (URDF `velocity`) a move may use, 0 to 1.
    acc:            fraction of the axes' acceleration limits (AccSet Acc / 100, times the payload's factor).
    ramp:           fraction of the normal jerk: how fast the acceleration may rise (AccSet Ramp / 100).
    time:           the move's duration in s (RAPID \\T) instead of v_tcp and v_ori (never faster than the axes).
    tcp_acc:        the TCP's acceleration limit along the path, m/s^2 (PathAccLim), or None.
    """

    v_tcp: float = 1.0
    v_ori: float = math.radians(500.0)
    joint_fraction: float = 1.0
    acc: float = 1.0
    ramp: float = 1.0
    time: float | None = None
    tcp_acc: float | None = None

    def check(self, name: str) -> None:
        for field in ("v_tcp", "v_ori", "joint_fraction", "acc", "ramp"):
            v = getattr(self, field)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise MotionError(name, f"speed {field} must be a positive number, not {v!r}")
        if self.joint_fraction > 1.0:
            raise MotionError(name, f"speed joint_fraction must be at most 1, not {self.joint_fraction!r}")
        for field in ("time", "tcp_acc"):
            v = getattr(self, field)
            if v is not None and not (math.isfinite(v) and v > 0):
                raise MotionError(name, f"speed {field} must be a positive number, not {v!r}")


class Profile:
    """Path parameter s(t) from 0 to 1, from rest to rest: a jerk-limited ("S-curve") rise to the rate `rate`
    (ds/dt), at most `accel` (d2s/dt2) with the acceleration changing at most `jerk` (d3s/dt3), a cruise, and the
    mirror-image fall. A move too short to reach `rate` peaks lower. `time`: stretch the move to last that long
    (a lower cruise rate), if it is not already slower."""

    def __init__(self, rate: float, accel: float = math.inf, jerk: float = math.inf, time: float | None = None):
        self.accel, self.jerk = float(accel), float(jerk)
        if not (rate > 0 and math.isfinite(rate)):
            self.rate, self.ap, self.tj, self.tc, self.ta, self.duration = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            self.cruise = 0.0
            return
        u = float(rate)
        if u * self._rise(u)[2] > 1.0:  # too short to reach the rate: the highest rate that fits
            lo, hi = 0.0, u
            for _ in range(60):
                mid = (lo + hi) / 2
                lo, hi = (mid, hi) if mid * self._rise(mid)[2] <= 1.0 else (lo, mid)
            u = lo
        if time is not None and 1.0 / u + self._rise(u)[2] < time:  # \T: slower, to take `time`
            lo, hi = 0.0, u
            for _ in range(60):
                mid = (lo + hi) / 2
                lo, hi = (mid, hi) if mid > 0 and 1.0 / mid + self._rise(mid)[2] > time else (lo, mid)
            u = hi
        self.rate = u
        self.ap, self.tj, self.ta = self._rise(u)
        self.tc = max(self.ta - 2 * self.tj, 0.0)
        self.duration = 1.0 / u + self.ta
        self.cruise = 1.0 / u - self.ta  # time at full rate

    def _rise(self, u: float) -> tuple[float, float, float]:
        """(peak acceleration, time of each jerk phase, whole rise time) of a rise from rest to rate u."""
        a, j = self.accel, self.jerk
        if not math.isfinite(a):
            return math.inf, 0.0, 0.0
        ap = min(a, math.sqrt(u * j)) if math.isfinite(j) else a
        tj = ap / j if math.isfinite(j) else 0.0
        return ap, tj, u / ap + tj

    def _up(self, t: float) -> tuple[float, float]:
        """(s, ds/dt) t seconds into the rise from rest."""
        ap, tj, tc, j = self.ap, self.tj, self.tc, self.jerk
        if not math.isfinite(ap):
            return self.rate * t, self.rate
        if t <= tj:
            return j * t ** 3 / 6, j * t * t / 2
        v1, x1 = ap * tj / 2, (j * tj ** 3 / 6 if tj > 0 else 0.0)
        tau = t - tj
        if tau <= tc:
            return x1 + v1 * tau + ap * tau * tau / 2, v1 + ap * tau
        v2, x2 = v1 + ap * tc, x1 + v1 * tc + ap * tc * tc / 2
        tau = min(tau - tc, tj)
        return x2 + v2 * tau + ap * tau * tau / 2 - j * tau ** 3 / 6, v2 + ap * tau - j * tau * tau / 2

    def s_many(self, ts: np.ndarray) -> np.ndarray:
        """s at many times at once (the planner's searches; `s` is the one the robot follows)."""
        ts = np.asarray(ts, dtype=float)
        if self.rate <= 0:
            return np.ones_like(ts)
        ta, d = self.ta, self.duration
        with np.errstate(invalid="ignore", over="ignore"):
            both = self._up_many(np.concatenate([np.clip(ts, 0.0, ta), np.clip(d - ts, 0.0, ta)]))
            up, down = both[:len(ts)], both[len(ts):]
            out = np.where(ts < ta, up, np.where(ts <= d - ta, self._up(ta)[0] + self.rate * (ts - ta), 1.0 - down))
        return np.where(ts <= 0, 0.0, np.where(ts >= d, 1.0, out))

    def _up_many(self, t: np.ndarray) -> np.ndarray:
        """`_up`'s s at many times at once."""
        ap, tj, tc, j = self.ap, self.tj, self.tc, self.jerk
        if not math.isfinite(ap):
            return self.rate * t
        v1, x1 = ap * tj / 2, (j * tj ** 3 / 6 if tj > 0 else 0.0)
        v2, x2 = v1 + ap * tc, x1 + v1 * tc + ap * tc * tc / 2
        tau = t - tj
        tau3 = np.minimum(tau - tc, tj)
        first = j * t ** 3 / 6 if tj > 0 else np.zeros_like(t)
        return np.where(t <= tj, first, np.where(tau <= tc, x1 + v1 * tau + ap * tau * tau / 2,
                                                 x2 + v2 * tau3 + ap * tau3 * tau3 / 2 - j * tau3 ** 3 / 6))

    def s(self, t: float) -> tuple[float, float]:
        """(s, ds/dt) at time t."""
        if self.rate <= 0 or t >= self.duration:
            return 1.0, 0.0
        if t <= 0:
            return 0.0, 0.0
        ta = self.ta
        if t < ta:
            return self._up(t)
        if t <= self.duration - ta:
            return self._up(ta)[0] + self.rate * (t - ta), self.rate
        s, v = self._up(self.duration - t)
        return 1.0 - s, v


class Trajectory:
    """Joint positions as a function of time since the motion started.

    `q(t)`, `qd(t)` (rad, rad/s), `done(t)`, `duration` (s), `q_start`, `q_end`, `name` (the target),
    `kind` (MoveJ, MoveL, MoveC, MoveAbsJ). Cartesian moves also keep `path(s) -> Pose`, the planned TCP
    pose at path parameter s (0 to 1), and `tcp_path_length` (m).
    """

    def __init__(self, kind: str, name: str, knots: np.ndarray, profile: Profile,
                 path: Callable[[float], Pose] | None = None, tcp_path_length: float = 0.0,
                 s_knots: np.ndarray | None = None, kin: ArmKinematics | None = None):
        self.kind, self.name = kind, name
        self._knots = np.array(knots, dtype=float)  # shape (n + 1, axes): q at path parameter s_knots[i]
        self._n = len(self._knots) - 1
        self._s = np.linspace(0.0, 1.0, self._n + 1) if s_knots is None else np.array(s_knots, dtype=float)
        self._s_list = self._s.tolist()  # (looked up at every physics substep: bisect on a list beats numpy's search)
        # each knot interval's step and slope dq/ds, as `_at` would form them at every physics substep
        self._steps = np.diff(self._knots, axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):  # (an interval of no length is never looked up)
            self._slopes = self._steps / np.diff(self._s)[:, None]
        self._lists = None  # knots, steps and slopes as lists (`state_lists`), formed when first asked for
        self.profile = profile
        self.duration = profile.duration
        self.path = path
        self.tcp_path_length = tcp_path_length
        self.kin = kin  # (for the TCP along a blend; None: the knots are TCP positions themselves)

    @property
    def q_start(self) -> np.ndarray:
        return self._knots[0].copy()

    @property
    def q_end(self) -> np.ndarray:
        return self._knots[-1].copy()

    def _at(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """q and dq/ds at path parameter s (linear between knots)."""
        if self._n == 0:
            return self._knots[0].copy(), np.zeros(self._knots.shape[1])
        i = min(max(bisect.bisect_right(self._s_list, s) - 1, 0), self._n - 1)
        s0, s1 = self._s_list[i], self._s_list[i + 1]
        f = (s - s0) / (s1 - s0)
        return self._knots[i] + f * self._steps[i], self._slopes[i]

    def q(self, t: float) -> np.ndarray:
        s, _ = self.profile.s(t)
        return self._at(s)[0]

    def q_many(self, ts) -> np.ndarray:
        """q at many times at once (N, axes): for the planner's searches along a motion."""
        s = self.profile.s_many(ts)
        if self._n == 0:
            return np.repeat(self._knots[:1], len(s), axis=0)
        i = np.clip(np.searchsorted(self._s, s, side="right") - 1, 0, self._n - 1)
        s0, s1 = self._s[i], self._s[i + 1]
        f = ((s - s0) / (s1 - s0))[:, None]
        a, b = self._knots[i], self._knots[i + 1]
        return a + f * (b - a)

    def qd(self, t: float) -> np.ndarray:
        s, v = self.profile.s(t)
        return self._at(s)[1] * v

    def state(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(q, qd) at time t, the profile and the knots looked up once (for every physics substep)."""
        s, v = self.profile.s(t)
        q, dq = self._at(s)
        return q, dq * v

    def state_lists(self, t: float, shift: list[float], zero: list[float]) -> tuple[list[float], list[float]]:
        """`state` as lists, q shifted: q + shift - zero elementwise (a blend's base and start), the very floats the
        arrays would hold, in plain Python: at every physics substep a handful of numpy operations on six values cost
        more than the arithmetic (the arm's command at each substep)."""
        s, v = self.profile.s(t)
        if self._n == 0:
            return [b + (k - z) for b, k, z in zip(shift, self._knots[0].tolist(), zero)], [0.0] * len(zero)
        lists = self._lists
        if lists is None:
            lists = self._lists = (self._knots.tolist(), self._steps.tolist(), self._slopes.tolist())
        s_list = self._s_list
        i = min(max(bisect.bisect_right(s_list, s) - 1, 0), self._n - 1)
        s0 = s_list[i]
        f = (s - s0) / (s_list[i + 1] - s0)
        knots, steps, slopes = lists
        return ([b + ((k + f * d) - z) for b, k, d, z in zip(shift, knots[i], steps[i], zero)],
                [k * v for k in slopes[i]])

    def done(self, t: float) -> bool:
        return t >= self.duration

    def tcp(self, q: np.ndarray) -> Pose:
        """The TCP for joint positions q of this motion (its tool); a point motion's q is the TCP's position."""
        if self.kin is None:
            return Pose(q[:3])
        position, rotation = self.kin.fk_many(np.asarray(q, dtype=float)[None, :])
        return Pose(position[0], quat_from_matrix(rotation[0]))

    def tcp_many(self, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """`tcp` of many joint positions (N, axes) at once: positions (N, 3), rotation matrices (N, 3, 3) or None
        for a point motion."""
        if self.kin is not None:
            return self.kin.fk_many(qs)
        return np.asarray(qs, dtype=float)[:, :3], None

    def __repr__(self) -> str:
        return f"Trajectory({self.kind} {self.name!r}, {self.duration:.3f} s)"


# -- helpers -----------------------------------------------------------------------------------------
def default_accel(limits: Sequence[JointLimit]) -> np.ndarray:
    """Each axis's acceleration limit (rad/s^2) when the station gives none: top speed in DEFAULT_ACCEL_TIME."""
    return np.array([lim.velocity for lim in limits]) / DEFAULT_ACCEL_TIME


def _timing(knots: np.ndarray, limits: Sequence[JointLimit], accel: Sequence[float] | None, speed: Speed,
            length: float = 0.0, angle: float = 0.0, s_knots: np.ndarray | None = None) -> Profile:
    """The profile of a path through joint-space `knots` (at path parameters s_knots, 0 to 1).

    Its rate is the highest at which the TCP keeps to v_tcp over `length` (m), the tool to v_ori over `angle`
    (rad), and no axis exceeds its speed limit where it moves fastest along the path; its acceleration the
    highest at which no axis exceeds its acceleration limit there (x speed.acc), with the jerk that takes
    RAMP_TIME to reach the full limit (x speed.ramp)."""
    accel = default_accel(limits) if accel is None else np.asarray(accel, dtype=float)
    rate, acc = math.inf, math.inf
    if len(knots) >= 2:
        if s_knots is None:
            s_knots = np.linspace(0.0, 1.0, len(knots))
        dq_ds = (np.abs(np.diff(knots, axis=0)) / np.diff(s_knots)[:, None]).max(axis=0)
        vmax = np.array([lim.velocity for lim in limits]) * speed.joint_fraction
        moving = dq_ds > 1e-12
        if np.any(moving):
            rate = float(np.min(vmax[moving] / dq_ds[moving]))
            acc = float(np.min(accel[moving] / dq_ds[moving]))
    if speed.time is None:
        if length > 0:
            rate = min(rate, speed.v_tcp / length)
        if angle > 0:
            rate = min(rate, speed.v_ori / angle)
    if speed.tcp_acc is not None and length > 0:
        acc = min(acc, speed.tcp_acc / length)
    if not math.isfinite(rate):
        return Profile(0.0)
    return Profile(rate, acc * speed.acc, acc * speed.ramp / RAMP_TIME, speed.time)


def _as_q(q: Iterable[float], n: int, name: str, what: str) -> np.ndarray:
    arr = np.array([float(v) for v in q])
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise MotionError(name, f"{what} needs {n} finite joint values")
    return arr


def _cartesian(kind: str, kin: ArmKinematics, q_start: np.ndarray, path: Callable[[float], Pose], length: float,
               angle: float, speed: Speed, name: str, path_many=None, q_end: np.ndarray | None = None) -> Trajectory:
    """Solve IK along path(s), s in [0, 1], and time it.

    All samples at once first (`ArmKinematics.solve_path`: Newton from the joint-space line to `q_end`, the
    end point's solution; `path_many(s)` gives the TCP's positions and rotation matrices): kept when every
    sample converged within the joint limits and no axis moves more than MAX_JOINT_JUMP between neighbours, the
    path the sample-to-sample solve below finds, at a fraction of its cost (no step of the cell stalls while a
    motion is planned). Otherwise sample by sample, each seeded by the previous solution: where an axis moves
    more than MAX_JOINT_JUMP between two samples, the stretch is bisected (down to 1/16 of a sample); if it
    still jumps there, the arm would flip configuration and the move is refused.
    """
    n = max(1, math.ceil(length / SAMPLE_STEP), math.ceil(angle / SAMPLE_ANGLE))
    knots_arr = s_arr = None
    if BATCH_IK and path_many is not None and q_end is not None:
        s = np.arange(1, n + 1) / n
        positions, rotations = path_many(s)
        q, ok = kin.solve_path(positions, rotations, q_start + s[:, None] * (q_end - q_start))
        knots = np.vstack([q_start, q])
        if ok.all() and float(np.max(np.abs(np.diff(knots, axis=0)))) <= MAX_JOINT_JUMP:
            knots_arr, s_arr = knots, np.concatenate([[0.0], s])
    if knots_arr is None:
        s_knots, knots_l = [0.0], [q_start]
        for i in range(1, n + 1):
            _sample(kin, path, (i - 1) / n, i / n, knots_l[-1], name, s_knots, knots_l, 0)
        knots_arr, s_arr = np.array(knots_l), np.array(s_knots)
    profile = _timing(knots_arr, kin.limits, kin.accel, speed, length, angle, s_arr)
    return Trajectory(kind, name, knots_arr, profile, path, length, s_arr, kin)


def _solve_at(kin: ArmKinematics, path: Callable[[float], Pose], s: float, seed: np.ndarray, name: str) -> np.ndarray:
    try:
        return kin.ik(path(s), seed, name, restarts=False)
    except MotionError as exc:
        reason = str(exc).removeprefix(f"target {name!r}: ")
        p = path(s).position * 1000
        raise MotionError(name, f"at ({p[0]:.0f}, {p[1]:.0f}, {p[2]:.0f}) mm, {s * 100:.0f}% along the path: "
                                f"{reason}") from None


def _sample(kin: ArmKinematics, path: Callable[[float], Pose], s0: float, s1: float, q0: np.ndarray, name: str,
            s_knots: list, knots: list, depth: int) -> None:
    """Append the knot at s1 (and, where an axis jumps, knots between s0 and s1)."""
    q1 = _solve_at(kin, path, s1, q0, name)
    if np.max(np.abs(q1 - q0)) <= MAX_JOINT_JUMP:
        s_knots.append(s1)
        knots.append(q1)
        return
    if depth >= 4:
        k = int(np.argmax(np.abs(q1 - q0)))
        p = path(s1).position * 1000
        raise MotionError(name, f"the path passes a singularity near ({p[0]:.0f}, {p[1]:.0f}, {p[2]:.0f}) mm: "
                                f"{kin.joint_names[k]} would have to turn abruptly")
    sm = (s0 + s1) / 2
    _sample(kin, path, s0, sm, q0, name, s_knots, knots, depth + 1)
    _sample(kin, path, sm, s1, knots[-1], name, s_knots, knots, depth + 1)


# -- constructors ------------------------------------------------------------------------------------
def movej(kin: ArmKinematics, q_start: Iterable[float], target_pose: Pose | None = None,
          q_target: Iterable[float] | None = None, speed: Speed = Speed(), name: str = "MoveJ") -> Trajectory:
    """Joint-interpolated move to a TCP pose (solved by IK near q_start) or to joint positions.

    All axes start and stop together. The cruise time is the longest of each axis's |dq| / max speed,
    the TCP's path length / v_tcp and the tool's rotation / v_ori.
    """
    speed.check(name)
    q0 = _as_q(q_start, kin.n, name, "the start")
    if (target_pose is None) == (q_target is None):
        raise MotionError(name, "MoveJ needs either a target pose or target joint positions")
    if target_pose is not None:
        q1 = kin.ik(target_pose, q0, name)
    else:
        q1 = _as_q(q_target, kin.n, name, "the target")
        check_limits(q1, kin.limits, name)
    # TCP path length and rotation, sampled along the joint-space line
    steps = max(2, min(64, math.ceil(float(np.max(np.abs(q1 - q0))) / math.radians(2.0))))
    positions, rotations = kin.fk_many(q0 + (q1 - q0) * (np.arange(steps + 1) / steps)[:, None])
    length = float(np.sum(np.linalg.norm(np.diff(positions, axis=0), axis=1)))
    angle = float(np.sum(rotation_angles(rotations[:-1], rotations[1:])))
    knots = np.array([q0, q1])
    return Trajectory("MoveJ", name, knots, _timing(knots, kin.limits, kin.accel, speed, length, angle), None,
                      length, kin=kin)


def moveabsj(q_start: Iterable[float], q_target: Iterable[float], speed: Speed = Speed(),
             joint_limits: Sequence[JointLimit] = (), name: str = "MoveAbsJ",
             kin: ArmKinematics | None = None) -> Trajectory:
    """Joint move to absolute joint positions (rad). Without `kin` only the axes' speed limits time it;
    with it, the TCP speed and reorientation speed count too (as in `movej`)."""
    speed.check(name)
    if kin is not None:
        traj = movej(kin, q_start, None, q_target, speed, name)
        traj.kind = "MoveAbsJ"
        return traj
    n = len(joint_limits)
    q0 = _as_q(q_start, n, name, "the start")
    q1 = _as_q(q_target, n, name, "the target")
    check_limits(q1, joint_limits, name)
    knots = np.array([q0, q1])
    return Trajectory("MoveAbsJ", name, knots, _timing(knots, joint_limits, None, speed))


def movel(kin: ArmKinematics, q_start: Iterable[float], target_pose: Pose, speed: Speed = Speed(),
          name: str = "MoveL") -> Trajectory:
    """The TCP on a straight line to target_pose, orientation slerped, at v_tcp and v_ori."""
    speed.check(name)
    q0 = _as_q(q_start, kin.n, name, "the start")
    start = kin.fk(q0)
    end = Pose(target_pose.position, target_pose.orientation)
    q1 = kin.ik(end, q0, name)  # an unreachable end point is reported as such, before any sampling

    def path_many(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        positions = start.position + s[:, None] * (end.position - start.position)
        return positions, quat_matrices(slerp_many(start.orientation, end.orientation, s))

    return _cartesian("MoveL", kin, q0, lambda s: start.interpolate(end, s), start.distance(end), start.angle(end),
                      speed, name, path_many, q1)


def circle_through(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray, name: str) -> tuple[np.ndarray, float, np.ndarray, np.ndarray, float, float]:
    """Centre, radius, in-plane unit vectors u (towards p0) and w, and the angles of p1 and p2 (rad)."""
    a, b = p1 - p0, p2 - p0
    n = np.cross(a, b)
    nn = float(n @ n)
    la, lb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
    if min(la, lb, float(np.linalg.norm(p2 - p1))) < MIN_CIRCLE_POINT_DISTANCE or math.sqrt(nn) < 1e-3 * la * lb:
        raise MotionError(name, "no circle: the start, via point and end point are on one line or less than "
                                f"{MIN_CIRCLE_POINT_DISTANCE * 1000:g} mm apart")
    centre = p0 + np.cross((a @ a) * b - (b @ b) * a, n) / (2.0 * nn)
    radius = float(np.linalg.norm(p0 - centre))
    u = (p0 - centre) / radius
    w = np.cross(n / math.sqrt(nn), u)

    def ang(p: np.ndarray) -> float:
        d = p - centre
        return math.atan2(float(d @ w), float(d @ u)) % (2 * math.pi)

    return centre, radius, u, w, ang(p1), ang(p2)


def movec(kin: ArmKinematics, q_start: Iterable[float], via_pose: Pose, target_pose: Pose, speed: Speed = Speed(),
          name: str = "MoveC") -> Trajectory:
    """The TCP on the circular arc from where it is, through via_pose's position, to target_pose.

    The orientation is slerped from the start to the target's (the via point's orientation is not used).
    """
    speed.check(name)
    q0 = _as_q(q_start, kin.n, name, "the start")
    start = kin.fk(q0)
    end = Pose(target_pose.position, target_pose.orientation)
    centre, radius, u, w, _, phi = circle_through(start.position, via_pose.position, end.position, name)
    q1 = kin.ik(end, q0, name)

    def path(s: float) -> Pose:
        a = s * phi
        return Pose(centre + radius * (math.cos(a) * u + math.sin(a) * w), slerp(start.orientation, end.orientation, s))

    def path_many(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        a = (s * phi)[:, None]
        positions = centre + radius * (np.cos(a) * u + np.sin(a) * w)
        return positions, quat_matrices(slerp_many(start.orientation, end.orientation, s))

    return _cartesian("MoveC", kin, q0, path, radius * phi, start.angle(end), speed, name, path_many, q1)


def payload_factor(load_kg: float, rated_kg: float | None) -> float:
    """How much of the arm's acceleration is left with a payload of `load_kg`: 1 / (1 + load / rated), so the
    rated payload halves it (the axes' torque is limited; the load's inertia adds to the arm's own). Without a
    rated payload (None) a load changes nothing."""
    if not rated_kg or load_kg <= 0:
        return 1.0
    return 1.0 / (1.0 + load_kg / rated_kg)
