"""Forward and inverse kinematics of a robot arm, on a private pybullet connection.

`ArmKinematics` loads only the arm's URDF into its own DIRECT connection, so solving IK or FK never
disturbs the physics world. The TCP is the flange link's frame times the tool pose (flange -> TCP).

IK uses pybullet's `calculateInverseKinematics` (damped least squares with joint limits in the null
space) on the flange link, restarted from its own result until the flange is within 0.1 mm and 0.01
degrees of the target; a damped-least-squares polish on pybullet's Jacobian finishes the last bits.
Every query resets the joint states first, so the result depends only on the inputs: the same inputs
give the same outputs, bit for bit.
"""
from __future__ import annotations

import copy

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

import numpy as np
from .bullet import BulletClient, pybullet

from .errors import MotionError
from .geometry import Pose, quat_conj, quat_matrix, quat_mul, quat_rotate
from .native_output import quiet_native_output
from .defaults import ARM_JOINTS

#: IK converges when the TCP is this close (m, rad) ...
IK_TOL_POS = 1e-4
IK_TOL_ORI = math.radians(0.01)
#: ... and fails with MotionError if it cannot get this close.
IK_FAIL_POS = 1e-3
IK_FAIL_ORI = math.radians(0.1)
#: Restart seeds when the seed fails: joint_1 turned towards the wrist centre, then joint_2..6 in degrees.
RESTART_POSES = ((0, 0, 0, 90, 0), (30, 30, 0, 30, 0), (-20, -60, 0, 60, 0), (0, 0, 0, -60, 0), (20, 0, 180, 60, 0))
RESTART_ITERATIONS = 15
#: Without acceleration limits from the station, an axis reaches its top speed in this time (s).
DEFAULT_ACCEL_TIME = 0.25


@dataclass(frozen=True)
class JointLimit:
    """One arm axis as its URDF declares it: range (rad), max speed (rad/s), max effort (N m)."""

    name: str
    lower: float
    upper: float
    velocity: float
    effort: float

    def contains(self, q: float, margin: float = 1e-9) -> bool:
        return self.lower - margin <= q <= self.upper + margin


def check_limits(q: Iterable[float], limits: Sequence[JointLimit], target_name: str) -> None:
    """MotionError naming the target (and the first joint) when a joint value is outside its range."""
    for lim, v in zip(limits, q):
        if not lim.contains(float(v)):
            raise MotionError(target_name, f"would need {lim.name} beyond its limit ({math.degrees(v):.1f} deg, "
                                           f"range {math.degrees(lim.lower):.0f} to {math.degrees(lim.upper):.0f} deg)")


class ArmKinematics:
    """FK/IK of one arm: `fk(q) -> Pose` (TCP in the world), `ik(pose, seed_q, target_name) -> q`.

    `base_position`/`base_orientation_xyzw` place the arm's base in the world (as in the physics world),
    `tool` is the TCP in the flange frame. `limits` lists the arm's axes (JointLimit) in order.
    """

    def __init__(self, urdf_path: str | Path, base_position: Iterable[float] = (0.0, 0.0, 0.0),
                 base_orientation_xyzw: Iterable[float] = (0.0, 0.0, 0.0, 1.0), flange_link: str = "flange",
                 tool: Pose | None = None, joint_names: Sequence[str] = ARM_JOINTS):
        self.urdf_path = Path(urdf_path)
        self.base = Pose(base_position, base_orientation_xyzw)
        self.tool = tool if tool is not None else Pose.identity()
        self._tool_inv = self.tool.inverse()
        with quiet_native_output():
            self.client = BulletClient(connection_mode=pybullet.DIRECT)
            self.body = self.client.loadURDF(str(self.urdf_path), self.base.position.tolist(),
                                             self.base.orientation.tolist(), useFixedBase=True,
                                             flags=pybullet.URDF_USE_INERTIA_FROM_FILE)
        from .world import bind_calls

        bind_calls(self.client)  # (forward kinematics is asked at every step while the robot settles)
        c = self.client
        by_name: dict[str, int] = {}
        links: dict[str, int] = {}
        movable: list[int] = []
        for j in range(c.getNumJoints(self.body)):
            info = c.getJointInfo(self.body, j)
            by_name[info[1].decode()] = j
            links[info[12].decode()] = j
            if info[2] != pybullet.JOINT_FIXED:
                movable.append(j)
        if flange_link not in links:
            raise MotionError(flange_link, f"{self.urdf_path.name} has no link {flange_link!r}")
        missing = [n for n in joint_names if n not in by_name]
        if missing:
            raise MotionError(missing[0], f"{self.urdf_path.name} has no joint {missing[0]!r}")
        self.joint_names = tuple(joint_names)
        self.joints = [by_name[n] for n in joint_names]
        if movable != self.joints:
            raise MotionError(flange_link, f"{self.urdf_path.name}: the movable joints must be exactly {self.joint_names} in order")
        self.flange = links[flange_link]
        limits = []
        for n, j in zip(self.joint_names, self.joints):
            info = c.getJointInfo(self.body, j)  # [8] lower, [9] upper, [10] max force, [11] max velocity
            limits.append(JointLimit(n, float(info[8]), float(info[9]), float(info[11]), float(info[10])))
        self.limits = tuple(limits)
        self.lower = np.array([lim.lower for lim in self.limits])
        self.upper = np.array([lim.upper for lim in self.limits])
        self.max_velocity = np.array([lim.velocity for lim in self.limits])
        #: each axis's acceleration limit (rad/s^2): a station's `[robot] accel_deg`, else top speed in
        #: DEFAULT_ACCEL_TIME
        self.accel = self.max_velocity / DEFAULT_ACCEL_TIME
        self.n = len(self.joints)
        # the wrist centre (joint_5's axis, on the forearm axis) seen from the flange, for IK restarts
        wrist_link = self.joints[-2] if self.n >= 2 else self.flange
        self._set(np.zeros(self.n))
        w = c.getLinkState(self.body, wrist_link, computeForwardKinematics=True)[4]
        self._wrist_in_flange = self._flange().inverse().transform(w)
        # calculateJacobian takes a point in the link's centre-of-mass frame: the flange frame's origin there
        ls = c.getLinkState(self.body, self.flange)
        self._flange_origin_in_com = Pose(ls[2], ls[3]).inverse().position.tolist()
        self._screws()

    def _screws(self) -> None:
        """The arm as a product of exponentials (read off pybullet at q = 0): each axis's direction and a point
        on it in the world, and the flange at q = 0; `fk_many` and `solve_path` evaluate it in numpy."""
        c = self.client
        self._set(np.zeros(self.n))
        axes, points, prismatic = [], [], []
        for j in self.joints:
            info = c.getJointInfo(self.body, j)
            s = c.getLinkState(self.body, j, computeForwardKinematics=True)  # the joint's frame (child link's)
            w = quat_rotate(np.array(s[5], dtype=float), np.array(info[13], dtype=float))
            axes.append(w / np.linalg.norm(w))
            points.append(np.array(s[4], dtype=float))
            prismatic.append(info[2] == pybullet.JOINT_PRISMATIC)
        self._w, self._p = np.array(axes), np.array(points)
        self._k = np.array([[[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]] for w in self._w])
        self._k2 = self._k @ self._k
        self._kp = np.einsum("nij,nj->ni", self._k, self._p)
        self._k2p = np.einsum("nij,nj->ni", self._k2, self._p)
        self._prismatic = np.array(prismatic)
        self._home_flange = self._flange()
        # checked against pybullet at a few poses: an arm the model does not describe (a URDF axis pybullet reads
        # otherwise) is computed by pybullet, pose by pose
        self._numpy = True
        span = np.clip(self.upper, -math.pi, math.pi) - np.clip(self.lower, -math.pi, math.pi)
        for f in (0.2, 0.5, 0.85):
            q = np.clip(self.lower, -math.pi, math.pi) + f * span
            p, r = self.fk_many(q[None, :])
            pose = self.flange_pose(q) * self.tool
            if not (np.allclose(p[0], pose.position, atol=1e-6) and np.allclose(r[0], quat_matrix(pose.orientation), atol=1e-6)):
                self._numpy = False

    def _exp(self, qs: np.ndarray, jacobian: bool = False):
        """For joint positions qs (N, n): the product of the axes' motions (rotation (N,3,3), translation (N,3)),
        and with `jacobian` each axis's direction and point in the world as the axes before it place it
        ((N,n,3) each)."""
        qs = np.asarray(qs, dtype=float)
        m = len(qs)
        rot = np.broadcast_to(np.eye(3), (m, 3, 3))
        trans = np.zeros((m, 3))
        axes = points = None
        if jacobian:
            axes, points = np.empty((m, self.n, 3)), np.empty((m, self.n, 3))
        for i in range(self.n):
            th = qs[:, i]
            if jacobian:
                axes[:, i] = rot @ self._w[i]
                points[:, i] = rot @ self._p[i] + trans
            if self._prismatic[i]:
                trans = trans + (rot @ self._w[i]) * th[:, None]
                continue
            sin, vers = np.sin(th)[:, None], (1.0 - np.cos(th))[:, None]
            k, k2 = self._k[i], self._k2[i]
            r_i = np.eye(3) + sin[:, :, None] * k + vers[:, :, None] * k2
            t_i = -(sin * self._kp[i] + vers * self._k2p[i])  # (I - R) p: the rotation about the axis through p
            trans = trans + (rot @ t_i[:, :, None])[:, :, 0]
            rot = rot @ r_i
        return rot, trans, axes, points

    def _tcp_at_home(self) -> tuple[np.ndarray, np.ndarray]:
        """The TCP at q = 0 (this tool): position, rotation matrix."""
        if getattr(self, "_home_tool", None) is not self.tool:
            tcp = self._home_flange * self.tool
            self._home_tcp = (tcp.position, quat_matrix(tcp.orientation))
            self._home_tool = self.tool
        return self._home_tcp

    def fk_many(self, qs) -> tuple[np.ndarray, np.ndarray]:
        """The TCP for many joint positions at once (N, n): positions (N, 3) and rotation matrices (N, 3, 3), in
        numpy (the same arm as `fk`, to 1e-6 mm)."""
        qs = np.atleast_2d(qs)
        if not self._numpy:
            poses = [self.fk(q) for q in qs]
            return (np.array([p.position for p in poses]).reshape(-1, 3),
                    np.array([quat_matrix(p.orientation) for p in poses]).reshape(-1, 3, 3))
        rot, trans, _, _ = self._exp(qs)
        p_tcp, r_tcp = self._tcp_at_home()
        return rot @ p_tcp + trans, rot @ r_tcp

    def solve_path(self, poses_p: np.ndarray, poses_r: np.ndarray, guess: np.ndarray,
                   iterations: int = 12) -> tuple[np.ndarray, np.ndarray]:
        """Newton (damped least squares) for many TCP poses at once, each from its own guess: (q (N, n), converged
        (N,) bool: within 1e-7 m and 1e-7 rad, within the joint limits; none on an arm fk_many hands to pybullet)."""
        q = np.array(guess, dtype=float)
        if not self._numpy:
            return q, np.zeros(len(q), dtype=bool)
        p_tcp, r_tcp = self._tcp_at_home()
        ok = np.zeros(len(q), dtype=bool)
        for _ in range(iterations + 1):
            rot, trans, axes, points = self._exp(q, jacobian=True)
            x = rot @ p_tcp + trans
            r_err = poses_r @ np.swapaxes(rot @ r_tcp, 1, 2)
            vee = 0.5 * np.stack([r_err[:, 2, 1] - r_err[:, 1, 2], r_err[:, 0, 2] - r_err[:, 2, 0],
                                  r_err[:, 1, 0] - r_err[:, 0, 1]], axis=1)
            sin = np.linalg.norm(vee, axis=1)
            cos = (np.trace(r_err, axis1=1, axis2=2) - 1.0) / 2.0
            ang = np.arctan2(sin, cos)
            scale = np.where(sin > 1e-12, ang / np.maximum(sin, 1e-300), 1.0)
            err = np.concatenate([poses_p - x, vee * scale[:, None]], axis=1)
            ok = (np.linalg.norm(err[:, :3], axis=1) <= 1e-7) & (ang <= 1e-7)
            if ok.all():
                break
            lin = np.where(self._prismatic[None, :, None], axes, np.cross(axes, x[:, None, :] - points))
            ang_j = np.where(self._prismatic[None, :, None], 0.0, axes)
            jac = np.concatenate([lin, ang_j], axis=2).transpose(0, 2, 1)  # (N, 6, n)
            a = jac @ jac.transpose(0, 2, 1) + 1e-12 * np.eye(6)
            q = q + (jac.transpose(0, 2, 1) @ np.linalg.solve(a, err[:, :, None]))[:, :, 0]
        ok &= np.all((q >= self.lower - 1e-9) & (q <= self.upper + 1e-9), axis=1)
        return q, ok

    def close(self) -> None:
        try:
            self.client.disconnect()
        except pybullet.error:
            pass

    # -- forward kinematics ------------------------------------------------------------------------
    def _set(self, q: np.ndarray) -> None:
        for j, v in zip(self.joints, q):
            self.client.resetJointState(self.body, j, float(v), 0.0)

    def _flange(self) -> Pose:
        s = self.client.getLinkState(self.body, self.flange, computeForwardKinematics=True)
        return Pose(s[4], s[5])

    def flange_pose(self, q: Iterable[float]) -> Pose:
        self._set(self._as_q(q))
        return self._flange()

    def with_tool(self, tool: Pose) -> "ArmKinematics":
        """The same arm (and connection) with another TCP, e.g. a robot program's own tooldata."""
        other = copy.copy(self)
        other.tool, other._tool_inv = tool, tool.inverse()
        return other

    def fk(self, q: Iterable[float]) -> Pose:
        """The TCP pose (flange x tool) in the world for joint positions q (rad)."""
        return self.flange_pose(q) * self.tool

    def _as_q(self, q: Iterable[float]) -> np.ndarray:
        q = np.array([float(v) for v in q])
        if q.shape != (self.n,):
            raise ValueError(f"expected {self.n} joint values, got {q.shape[0] if q.ndim else 0}")
        return q

    # -- inverse kinematics ------------------------------------------------------------------------
    def check_limits(self, q: Iterable[float], target_name: str) -> None:
        """MotionError naming the target when a joint value is outside its range."""
        check_limits(self._as_q(q), self.limits, target_name)

    def ik(self, pose: Pose, seed_q: Iterable[float], target_name: str = "target", *, restarts: bool = True,
           max_iterations: int = 40) -> np.ndarray:
        """Joint positions that put the TCP at `pose`, near `seed_q`. Raises MotionError naming the target.

        When the solve from the seed fails and `restarts` is true, a few fixed seeds (arm turned towards
        the wrist centre, elbow and wrist in typical poses) are tried in order. Axes that turn more than
        a full turn (joint_4, joint_6) get the solution's turn nearest the seed.
        """
        seed = np.clip(self._as_q(seed_q), self.lower, self.upper)
        goal = pose * self._tool_inv
        q, err_p, err_o = self._solve(goal, seed, self.lower, self.upper, max_iterations)
        if err_p <= IK_FAIL_POS and err_o <= IK_FAIL_ORI:
            return self._nearest_turn(q, seed)
        if restarts:
            for start in self._restart_seeds(goal):
                q2, p2, o2 = self._solve(goal, start, self.lower, self.upper, RESTART_ITERATIONS)
                if p2 <= IK_FAIL_POS and o2 <= IK_FAIL_ORI:
                    return self._nearest_turn(q2, seed)
                if p2 + o2 < err_p + err_o:
                    q, err_p, err_o = q2, p2, o2
        # Out of reach, or only beyond a joint limit? Solve again without the limits to tell.
        wide = np.full(self.n, 4.0 * math.pi)
        q_free, fp, fo = self._solve(goal, seed, -wide, wide, max_iterations)
        if fp <= IK_FAIL_POS and fo <= IK_FAIL_ORI:
            self.check_limits(self._wrap(q_free), target_name)
        if err_p > IK_FAIL_POS:
            raise MotionError(target_name, f"cannot be reached: closest is {err_p * 1000:.1f} mm away")
        raise MotionError(target_name, f"cannot be reached: closest orientation is {math.degrees(err_o):.2f} deg away")

    def _restart_seeds(self, goal: Pose) -> list[np.ndarray]:
        wrist = self.base.inverse().transform(goal.transform(self._wrist_in_flange))
        j1 = math.atan2(float(wrist[1]), float(wrist[0]))
        seeds = [np.array([j1] + [math.radians(v) for v in rest]) for rest in RESTART_POSES]
        return [np.clip(s, self.lower, self.upper) for s in seeds]

    def _nearest_turn(self, q: np.ndarray, seed: np.ndarray) -> np.ndarray:
        """Each angle turned by whole turns, within its range, to lie nearest the seed."""
        out = q.copy()
        for i, lim in enumerate(self.limits):
            for k in (-2, -1, 1, 2):
                cand = q[i] + 2 * math.pi * k
                if lim.contains(cand) and abs(cand - seed[i]) < abs(out[i] - seed[i]):
                    out[i] = cand
        return out

    def _wrap(self, q: np.ndarray) -> np.ndarray:
        """Each angle turned by whole turns to lie in its joint's range, or else nearest the range's middle."""
        out = q.copy()
        for i, (lim, v) in enumerate(zip(self.limits, q)):
            mid = (lim.lower + lim.upper) / 2
            w = v - 2 * math.pi * round((v - mid) / (2 * math.pi))
            for cand in (v, w, w - 2 * math.pi, w + 2 * math.pi):
                if lim.contains(cand):
                    out[i] = cand
                    break
            else:
                out[i] = w
        return out

    def _error(self, goal: Pose) -> tuple[float, float, Pose]:
        f = self._flange()
        return f.distance(goal), f.angle(goal), f

    def _solve(self, goal: Pose, seed: np.ndarray, lower: np.ndarray, upper: np.ndarray,
               max_iterations: int) -> tuple[np.ndarray, float, float]:
        c = self.client
        ranges = upper - lower
        q = seed.copy()
        self._set(q)
        best_q, best_p, best_o = q.copy(), *self._error(goal)[:2]
        pos, orn = goal.position.tolist(), goal.orientation.tolist()
        for _ in range(max_iterations):
            if best_p < IK_TOL_POS and best_o < IK_TOL_ORI:
                break
            sol = c.calculateInverseKinematics(self.body, self.flange, pos, orn, lowerLimits=lower.tolist(),
                                               upperLimits=upper.tolist(), jointRanges=ranges.tolist(),
                                               restPoses=q.tolist(), maxNumIterations=20, residualThreshold=1e-6)
            q_new = np.clip(np.array(sol[:self.n]), lower, upper)
            q_new = self._polish(goal, q_new, lower, upper, 3)
            self._set(q_new)
            p, o, _ = self._error(goal)
            q = q_new
            if p + o < best_p + best_o:
                best_q, best_p, best_o = q.copy(), p, o
        if not (best_p < IK_TOL_POS and best_o < IK_TOL_ORI):
            q = self._polish(goal, best_q, lower, upper, 20)
            self._set(q)
            p, o, _ = self._error(goal)
            if p + o < best_p + best_o:
                best_q, best_p, best_o = q, p, o
        return best_q, best_p, best_o

    def _polish(self, goal: Pose, q: np.ndarray, lower: np.ndarray, upper: np.ndarray, steps: int) -> np.ndarray:
        """Damped least squares on pybullet's Jacobian of the flange (full 6-D error)."""
        c = self.client
        zeros = [0.0] * self.n
        for _ in range(steps):
            self._set(q)
            p, o, f = self._error(goal)
            if p < IK_TOL_POS * 0.1 and o < IK_TOL_ORI * 0.1:
                break
            dq_rot = quat_mul(goal.orientation, quat_conj(f.orientation))
            if dq_rot[3] < 0:
                dq_rot = -dq_rot
            s = math.sqrt(float(dq_rot[:3] @ dq_rot[:3]))
            w = (2.0 * math.atan2(s, dq_rot[3]) / s) * dq_rot[:3] if s > 1e-12 else 2.0 * dq_rot[:3]
            err = np.concatenate([goal.position - f.position, w])
            jl, ja = c.calculateJacobian(self.body, self.flange, self._flange_origin_in_com, q.tolist(), zeros, zeros)
            jac = np.vstack([np.array(jl), np.array(ja)])
            lam2 = 1e-6
            dq = jac.T @ np.linalg.solve(jac @ jac.T + lam2 * np.eye(6), err)
            q = np.clip(q + dq, lower, upper)
        return q
