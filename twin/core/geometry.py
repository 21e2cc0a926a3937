"""Rigid-body poses in numpy: position in m, orientation as a unit quaternion (x, y, z, w) as pybullet's.

Pure functions of their inputs (no pybullet connection needed), so the same inputs give the same bits.
Roll-pitch-yaw follows pybullet's `getQuaternionFromEuler`: fixed axes, roll about x first, then pitch
about y, then yaw about z (R = Rz(yaw) Ry(pitch) Rx(roll)).
"""
from __future__ import annotations

import math
from typing import Iterable

import numpy as np


def cross(a, b) -> tuple[float, float, float]:
    """a x b of two 3-vectors as plain floats (per contact point: numpy costs more than the arithmetic there)."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a*b of quaternions (x, y, z, w): rotate by b, then by a."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz])


def quat_conj(q: np.ndarray) -> np.ndarray:
    return np.array([-q[0], -q[1], -q[2], q[3]])


def quat_normalize(q: Iterable[float]) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    n = math.sqrt(float(q @ q))
    if n == 0.0:
        raise ValueError("a zero quaternion has no orientation")
    return q / n


def quat_rotate(q: np.ndarray, v: Iterable[float]) -> np.ndarray:
    """Rotate vector v by the unit quaternion q."""
    return quat_matrix(q) @ np.asarray(v, dtype=float)


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """3x3 rotation matrix of the unit quaternion q (x, y, z, w)."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def quat_matrices(qs: np.ndarray) -> np.ndarray:
    """`quat_matrix` of many unit quaternions (N, 4) at once: (N, 3, 3)."""
    x, y, z, w = (qs[:, i] for i in range(4))
    m = np.empty((len(qs), 3, 3))
    m[:, 0, 0], m[:, 0, 1], m[:, 0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)
    m[:, 1, 0], m[:, 1, 1], m[:, 1, 2] = 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    m[:, 2, 0], m[:, 2, 1], m[:, 2, 2] = 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)
    return m


def slerp_many(a: np.ndarray, b: np.ndarray, s: np.ndarray) -> np.ndarray:
    """`slerp` at many parameters s (N,) at once: (N, 4)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    s = np.asarray(s, dtype=float)[:, None]
    d = float(np.dot(a, b))
    if d < 0.0:
        b, d = -b, -d
    if d > 0.9995:
        out = a + s * (b - a)
        return out / np.linalg.norm(out, axis=1, keepdims=True)
    theta = math.acos(d)
    sin_t = math.sin(theta)
    return (np.sin((1.0 - s) * theta) / sin_t) * a + (np.sin(s * theta) / sin_t) * b


def quat_from_matrix(m: np.ndarray) -> np.ndarray:
    """The unit quaternion (x, y, z, w) of a 3x3 rotation matrix (inverse of `quat_matrix`, w >= 0)."""
    t = float(np.trace(m))
    if t > 0:
        s = 2.0 * math.sqrt(1.0 + t)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(max(1.0 + m[i, i] - m[j, j] - m[k, k], 1e-300))
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i], q[j], q[k] = 0.25 * s, (m[j, i] + m[i, j]) / s, (m[k, i] + m[i, k]) / s
        if q[3] < 0:
            q = [-v for v in q]
    return quat_normalize(q)


def rotation_angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation angles (rad, 0 to pi) between rotation matrices a and b ((N, 3, 3) each, or one of them (3, 3))."""
    rel = np.swapaxes(a, -1, -2) @ b
    vee = np.stack([rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0], rel[..., 1, 0] - rel[..., 0, 1]],
                   axis=-1)
    return np.arctan2(0.5 * np.linalg.norm(vee, axis=-1), (np.trace(rel, axis1=-2, axis2=-1) - 1.0) / 2.0)


def quat_from_rpy(rpy: Iterable[float]) -> np.ndarray:
    """Quaternion of roll-pitch-yaw in rad, as pybullet's getQuaternionFromEuler."""
    r, p, y = (float(v) for v in rpy)
    cr, sr = math.cos(r / 2), math.sin(r / 2)
    cp, sp = math.cos(p / 2), math.sin(p / 2)
    cy, sy = math.cos(y / 2), math.sin(y / 2)
    return np.array([sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy,
                     cr * cp * sy - sr * sp * cy,
                     cr * cp * cy + sr * sp * sy])


def quat_to_rpy(q: np.ndarray) -> np.ndarray:
    """Roll-pitch-yaw in rad of a unit quaternion (inverse of `quat_from_rpy`)."""
    x, y, z, w = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.array([roll, pitch, yaw])


def quat_angle(a: np.ndarray, b: np.ndarray) -> float:
    """The rotation angle in rad (0 to pi) between two orientations."""
    d = abs(float(np.dot(a, b)))
    return 2.0 * math.acos(min(1.0, d))


def slerp(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Spherical linear interpolation from a (s=0) to b (s=1), along the shorter way."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    d = float(np.dot(a, b))
    if d < 0.0:
        b, d = -b, -d
    if d > 0.9995:
        return quat_normalize(a + s * (b - a))
    theta = math.acos(d)
    sin_t = math.sin(theta)
    return (math.sin((1.0 - s) * theta) / sin_t) * a + (math.sin(s * theta) / sin_t) * b


class Pose:
    """A frame: `position` (m, shape 3) and `orientation` (unit quaternion x, y, z, w, shape 4).

    `a * b` composes (b expressed in a), `a.inverse()` inverts, `a * point` is not defined: use
    `a.transform(point)`.
    """

    __slots__ = ("position", "orientation")

    def __init__(self, position: Iterable[float] = (0.0, 0.0, 0.0), orientation: Iterable[float] = (0.0, 0.0, 0.0, 1.0)):
        self.position = np.array([float(v) for v in position])
        self.orientation = quat_normalize([float(v) for v in orientation])
        if self.position.shape != (3,) or self.orientation.shape != (4,):
            raise ValueError("a Pose needs 3 position values and 4 quaternion values (x, y, z, w)")

    @classmethod
    def identity(cls) -> "Pose":
        return cls()

    @classmethod
    def from_xyz_rpy(cls, xyz: Iterable[float], rpy: Iterable[float] = (0.0, 0.0, 0.0)) -> "Pose":
        """From a position in m and roll-pitch-yaw in rad (pybullet's convention)."""
        return cls(xyz, quat_from_rpy(rpy))

    @property
    def rpy(self) -> np.ndarray:
        return quat_to_rpy(self.orientation)

    @property
    def matrix(self) -> np.ndarray:
        """4x4 homogeneous transform."""
        m = np.eye(4)
        m[:3, :3] = quat_matrix(self.orientation)
        m[:3, 3] = self.position
        return m

    def __mul__(self, other: "Pose") -> "Pose":
        if not isinstance(other, Pose):
            return NotImplemented
        return Pose(self.position + quat_rotate(self.orientation, other.position),
                    quat_mul(self.orientation, other.orientation))

    def inverse(self) -> "Pose":
        qi = quat_conj(self.orientation)
        return Pose(-quat_rotate(qi, self.position), qi)

    def transform(self, point: Iterable[float]) -> np.ndarray:
        """A point given in this frame, expressed in the parent frame."""
        return self.position + quat_rotate(self.orientation, point)

    def distance(self, other: "Pose") -> float:
        """Distance between the two positions in m."""
        return float(np.linalg.norm(self.position - other.position))

    def angle(self, other: "Pose") -> float:
        """Rotation angle between the two orientations in rad."""
        return quat_angle(self.orientation, other.orientation)

    def interpolate(self, other: "Pose", s: float) -> "Pose":
        """Straight line between the positions, slerp between the orientations."""
        return Pose(self.position + s * (other.position - self.position), slerp(self.orientation, other.orientation, s))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Pose):
            return NotImplemented
        return bool(np.array_equal(self.position, other.position) and np.array_equal(self.orientation, other.orientation))

    def __repr__(self) -> str:
        p = ", ".join(f"{v:.4f}" for v in self.position)
        q = ", ".join(f"{v:.4f}" for v in self.orientation)
        return f"Pose(position=[{p}], orientation=[{q}])"
