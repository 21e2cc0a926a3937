"""The robot in the physics world: drives an arm's joints along a trajectory, step by step.

`Robot.commands(t, n)` gives the commands for a step's n physics substeps, `send` sends each before its substep
from t to t + dt (`update(t)`: one substep's, sent at once). Each commands pybullet's
POSITION_CONTROL towards where the planned motion will be at the end of the step (`q(t + dt)`, with
`qd(t + dt)` as the velocity feed-forward), with the axes' URDF efforts as force limits. The planned motion is
a `MotionQueue` (planner.py): `start` replaces it with one motion, `queue` appends one that starts after the
last (or blends out of its zone). After the last one's planned end the robot keeps commanding the end point
and stays busy until the TCP has settled there (within `settle_distance` and `settle_angle`), or
`settle_timeout` has passed.
When idle it holds its last commanded position. The arm's joints are looked up by name, so the body may
carry more joints (a gripper merged under the flange).
"""
from __future__ import annotations

import math
from typing import Iterable, Sequence

import numpy as np
from .bullet import pybullet

from .errors import MotionError
from .geometry import Pose
from .kinematics import ARM_JOINTS, ArmKinematics
from .motion import Trajectory
from .planner import (FINE, REGAIN_DISTANCE, MotionQueue, PathClock, Zone, restart_on_path, stand_time,
                      stop_on_path)


class Robot:
    """An arm living in a physics world, driven along trajectories in simulated time."""

    def __init__(self, client, body_id: int, joint_names: Sequence[str] = ARM_JOINTS,
                 kinematics: ArmKinematics | None = None, *, dt: float | None = None,
                 position_gain: float = 0.3, velocity_gain: float = 1.0,
                 settle_distance: float = 2e-4, settle_angle: float = math.radians(0.02),
                 settle_timeout: float = 2.0):
        self.client = client
        self.body = body_id
        self.kinematics = kinematics
        index: dict[str, int] = {}
        for j in range(client.getNumJoints(body_id)):
            index[client.getJointInfo(body_id, j)[1].decode()] = j
        missing = [n for n in joint_names if n not in index]
        if missing:
            raise MotionError(missing[0], f"the robot body has no joint {missing[0]!r}")
        self.joint_names = tuple(joint_names)
        self.joints = [index[n] for n in joint_names]
        self.forces = [float(client.getJointInfo(body_id, j)[10]) for j in self.joints]
        if dt is None:
            dt = float(client.getPhysicsEngineParameters()["fixedTimeStep"])
        self.dt = dt
        self.position_gain, self.velocity_gain = position_gain, velocity_gain
        self.settle_distance, self.settle_angle, self.settle_timeout = settle_distance, settle_angle, settle_timeout
        self._traj: Trajectory | None = None  # the last motion of the queue
        self._queue: MotionQueue | None = None
        self._handles = 0
        self._corner_failures: set[int] = set()  # zone points that became stop points (their next motion late)
        #: why the last motion ended without arriving (e.g. blocked by a collision), else None
        self.failure: MotionError | None = None
        self._clock: PathClock | None = PathClock(0.0)  # the motions' time (None: from the next update)
        self._stored = None  # StorePath: the stopped path and its clock, while a temporary path runs
        self._end_tcp: Pose | None = None
        self._settled = True
        self._held = None
        self._motors = client.setJointMotorControlArray  # bound once: called at every physics substep
        self._gains = ([position_gain] * len(self.joints), [velocity_gain] * len(self.joints))
        self._joint_states = client.getJointStates
        self._hold = self.q
        self._hold_for: Trajectory | None = None  # the last motion whose end self._hold is
        self._paused: np.ndarray | None = None  # while paused: where the arm holds

    # -- state --------------------------------------------------------------------------------------
    @property
    def q(self) -> np.ndarray:
        """Actual joint positions (rad)."""
        return np.array([s[0] for s in self.client.getJointStates(self.body, self.joints)])

    def positions(self) -> list[float]:
        """Actual joint positions (rad) as floats: `q` without the array, for publishing at every step."""
        return [s[0] for s in self._joint_states(self.body, self.joints)]

    @property
    def qd(self) -> np.ndarray:
        """Actual joint velocities (rad/s)."""
        return np.array([s[1] for s in self.client.getJointStates(self.body, self.joints)])

    def motor_torque(self, axis: int) -> float:
        """The torque (N m) the physics applied at axis `axis` (1-based) in the last (sub)step."""
        return float(self.client.getJointState(self.body, self.joints[axis - 1])[3])

    @property
    def trajectory(self) -> Trajectory | None:
        return self._traj

    def tcp_pose(self) -> Pose:
        """The TCP of the actual joint positions, in the world (through the kinematics' own connection)."""
        if self.kinematics is None:
            raise MotionError("tcp", "the robot has no kinematics")
        return self.kinematics.fk(self.q)

    # -- commands -----------------------------------------------------------------------------------
    def reset(self, q: Iterable[float]) -> None:
        """Teleport the arm to q (rad) at rest and hold it there (at load time, not during a motion)."""
        q = np.array([float(v) for v in q])
        if q.shape != (len(self.joints),):
            raise ValueError(f"expected {len(self.joints)} joint values")
        for j, v in zip(self.joints, q):
            self.client.resetJointState(self.body, j, float(v), 0.0)
        self._traj, self._queue, self._settled, self._hold, self.failure = None, None, True, q, None
        self.send(self._command(q, np.zeros_like(q)))
        self.check_kinematics()

    def check_kinematics(self, tolerance: float = 1e-4) -> None:
        """MotionError unless the kinematics' last arm link is where the physics body's is, for the actual q.

        Catches a kinematics placed at the wrong base frame (pybullet's getBasePositionAndOrientation gives
        the base's centre of mass, which is the URDF base frame only when the base's inertial origin is 0).
        """
        if self.kinematics is None:
            return
        kin = self.kinematics
        s = self.client.getLinkState(self.body, self.joints[-1], computeForwardKinematics=True)
        physics = Pose(s[4], s[5])
        kin._set(self.q)
        k = kin.client.getLinkState(kin.body, kin.joints[-1], computeForwardKinematics=True)
        planned = Pose(k[4], k[5])
        if physics.distance(planned) > tolerance or physics.angle(planned) > tolerance:
            d = (physics.position - planned.position) * 1000
            raise MotionError("robot", f"the kinematics do not match the physics body: {self.joint_names[-1]}'s link is "
                                       f"off by ({d[0]:.1f}, {d[1]:.1f}, {d[2]:.1f}) mm and "
                                       f"{math.degrees(physics.angle(planned)):.2f} deg (wrong base frame?)")

    def start(self, trajectory: Trajectory, t: float | None = None) -> int:
        """Run `trajectory` from simulated time t (s), or from the next `update` when t is None.

        It replaces any motion under way; build it from `robot.q` when the robot is at rest (a motion
        started while another runs begins from standstill). Returns the motion's handle.
        """
        self._queue = MotionQueue(trajectory.q_start)
        self._clock = None if t is None else PathClock(t)
        return self._append(trajectory, FINE, 0.0)

    def queue(self, trajectory: Trajectory, zone: Zone, t: float) -> int:
        """Append `trajectory` (planned from `plan_start()`) to the motions under way at simulated time t: it
        starts when the last one ends, or blends out of its zone (planner.py). Returns the motion's handle."""
        if self._queue is None or self._clock is None or not self.busy(t):
            last = self._queue.last if self._queue is not None else None
            if last is not None and not last.zone.fine:  # it ran out of motions at a zone point: a stop point
                self._corner_failures.add(last.handle)
            self._queue = MotionQueue(trajectory.q_start)
            self._clock = PathClock(t)
            return self._append(trajectory, zone, 0.0)
        return self._append(trajectory, zone, self._clock.tau(t))

    def _append(self, trajectory: Trajectory, zone: Zone, now: float) -> int:
        self._handles += 1
        prev = self._queue.last
        self._queue.add(trajectory, zone, now, self._handles)
        if prev is not None and prev.corner_failure:
            self._corner_failures.add(prev.handle)
        self._traj, self._settled, self.failure = trajectory, False, None
        self._end_tcp = self.kinematics.fk(trajectory.q_end) if self.kinematics is not None else None
        return self._handles

    def plan_start(self, t: float) -> np.ndarray:
        """Where the next motion starts: the last queued motion's end while the robot is busy, else where it is."""
        return self._queue.q_end if self._queue is not None and self.busy(t) else self.q

    def _segment(self, handle: int):
        return self._queue.find(handle) if self._queue is not None else None

    def ready(self, handle: int, t: float) -> bool:
        """May the program go on past motion `handle`: a zone point's TCP in its largest zone (planner.py)?"""
        seg = self._segment(handle)
        return seg is None or (self._clock is not None and self._clock.tau(t) >= seg.ready - 1e-9)

    def done(self, handle: int, t: float) -> bool:
        """Is motion `handle` over: the robot in position at its end, or gone on into the next motion?"""
        seg = self._segment(handle)
        if seg is None:
            return True
        if seg is self._queue.last:
            return not self.busy(t)
        return self._clock is not None and self._clock.tau(t) >= seg.end

    def corner_failure(self, handle: int) -> bool:
        """Did zone point `handle` become a stop point because its next motion came too late?"""
        return handle in self._corner_failures

    def ready_time(self, handle: int) -> float | None:
        """The simulated time the program may go on past motion `handle` (`ready`), None if unknown."""
        seg = self._segment(handle)
        return None if seg is None or self._clock is None else self._clock.t_of(seg.ready)

    def end_time(self, handle: int) -> float | None:
        """The simulated time motion `handle`'s plan ends, None if unknown."""
        seg = self._segment(handle)
        return None if seg is None or self._clock is None else self._clock.t_of(seg.end)

    def stop(self) -> None:
        """Stop following the trajectory and hold where the arm is now."""
        self._traj, self._queue, self._settled, self._hold = None, None, True, self.q

    # -- path control (RAPID StopMove, StartMove, ClearPath, StorePath, RestoPath) ---------------------------
    def stop_path(self, t: float, quick: bool = False, at_end: bool = False) -> None:
        """StopMove: decelerate on the planned path and stand (planner.PathClock; `quick`: at the axes' full
        acceleration limits, else half). `at_end`: stand at the end of the motion under way instead."""
        if self._queue is not None and self._clock is not None and self.busy(t):
            stop_on_path(self.kinematics, self._queue, self._clock, t, quick, at_end)

    def path_standing(self, t: float) -> bool:
        """Is the robot standing still on its path (stopped by `stop_path`, the ramp over) or idle?"""
        if self._queue is None or self._clock is None or not self.busy(t):
            return True
        return self._clock.stopping and self._clock.rate(t) == 0.0 and self._clock.tau(t) == self._clock.tau(t + 1.0)

    def stand_time(self, t: float) -> float | None:
        """When the path will stand (t if it does or the robot is idle), None if not stopping."""
        return stand_time(self.path_standing(t), self._clock, t)

    def start_path(self, t: float) -> None:
        """StartMove: the rest of the stopped path, speeding up as it slowed down."""
        if self._queue is not None and self._clock is not None and self._clock.stopping:
            restart_on_path(self.kinematics, self._queue, self._clock, t)

    def _stand(self, t: float) -> np.ndarray:
        """Where the path stands at t (its planned joints), the robot then idle there with no path."""
        q = self._queue.q(min(self._clock.tau(t), self._queue.end)) if self._queue is not None and self._clock else self.q
        self._traj, self._queue, self._settled, self._hold, self._clock = None, None, True, q, PathClock(t)
        return q

    def clear_path(self, t: float) -> None:
        """ClearPath: the motions handed over and not yet done are dropped (done, as far as the program is
        concerned); the robot holds where its path stands."""
        self._stand(t)

    def store_path(self, t: float) -> None:
        """StorePath: keep the (standing) path aside; new motions run from where it stands until `restore_path`."""
        stored = (self._queue, self._clock, self._traj, self._end_tcp)
        self._stored = (*stored, self._stand(t))

    def restore_path(self, t: float) -> None:
        """RestoPath: the stored path back, standing (StartMove resumes it). MotionError if none is stored."""
        if self._stored is None:
            raise MotionError("RestoPath", "no path is stored (StorePath first)")
        self._queue, self._clock, self._traj, self._end_tcp, stand = self._stored
        self._stored = None
        self._settled = self._traj is None
        if self.kinematics is not None and self._traj is not None:
            off = self.kinematics.fk(self.q).distance(self.kinematics.fk(stand))
            if off > REGAIN_DISTANCE:
                self._traj, self._queue, self._settled, self._hold = None, None, True, self.q
                raise MotionError("RestoPath", f"the robot is {off * 1000:.1f} mm from where the stored path stands "
                                               f"(at most {REGAIN_DISTANCE * 1000:g} mm): move it back there first")

    def pause(self, paused: bool = True) -> None:
        """A robot stop (protective stop, feed hold): the arm holds where it is and a motion under way waits,
        its time frozen, busy all along; `pause(False)` lets it go on along its path."""
        self._paused = self.q if paused else None

    @property
    def moving(self) -> bool:
        """A motion runs or has not yet settled, and the arm is not paused (unlike `busy`, no side effects)."""
        return self._traj is not None and not self._settled and self._paused is None

    @property
    def holding(self) -> bool:
        """Idle and holding its last commanded position, commanded already: `update` would do nothing."""
        return self._traj is None and self._paused is None and self._held is self._hold

    @property
    def paused(self) -> bool:
        return self._paused is not None

    @property
    def fault(self) -> str | None:
        """`failure` as text ("target 'NAME': not reached ..."), else None."""
        return None if self.failure is None else str(self.failure)

    def busy(self, t: float) -> bool:
        """True while a motion runs or has not yet settled at its end point.

        The end of a motion latches: once in position the robot is idle until the next `start`. If it is
        not in position `settle_timeout` after the planned end, it sets `failure` and holds where it is.
        """
        if self._traj is None or self._settled:
            return False
        if self._clock is None:
            return True
        tau = self._clock.tau(t)
        end = self._queue.end
        if tau < end:
            return True
        if self._in_position():
            self._settled = True
        elif tau >= end + self.settle_timeout:
            self._settled = True
            off = self.tcp_pose().distance(self._end_tcp) * 1000 if self.kinematics is not None else float("nan")
            self.failure = MotionError(self._traj.name, f"not reached {self.settle_timeout:g} s after the motion's end "
                                                        f"(TCP {off:.1f} mm away; blocked?)")
            self._traj, self._queue, self._hold = None, None, self.q  # stop pushing: hold where it got to
        return not self._settled

    def _in_position(self) -> bool:
        if self.kinematics is None:
            return bool(np.max(np.abs(self.q - self._traj.q_end)) < 1e-4)
        actual, planned = self.kinematics.fk(self.q), self._end_tcp
        return actual.distance(planned) <= self.settle_distance and actual.angle(planned) <= self.settle_angle

    def update(self, t: float) -> None:
        """Command the arm for the substep from t to t + dt (call once per substep, before it runs)."""
        command = self._next(t)
        if command is not None:
            self.send(command)

    def commands(self, t: float, n: int) -> list[tuple | None] | None:
        """The arm's commands for the n substeps from t on, worked out at once (the same as `update` at each of them
        would send: None where it would send nothing): the step sends each before its substep with `send`, and the
        arm's Python runs once a step, not between substeps, where pybullet has just left the caches cold. None: it
        holds, commanded already (`holding`), and sends nothing."""
        if self.holding:
            return None
        return [self._next(t + k * self.dt) for k in range(n)]

    def send(self, command: tuple) -> None:
        """The arm's position motors to q at qd (`commands`' Python floats), with their forces and gains."""
        self._motors(self.body, self.joints, pybullet.POSITION_CONTROL, targetPositions=command[0],
                     targetVelocities=command[1], forces=self.forces, positionGains=self._gains[0],
                     velocityGains=self._gains[1])

    def _next(self, t: float) -> tuple | None:
        """What `update(t)` sends: (q, qd) as lists of floats, or None (the hold is commanded already)."""
        traj = self._traj
        if self._paused is not None:
            if traj is not None and self._clock is not None:
                self._clock.shift(self.dt)  # the motion's clock stands still
            return self._command(self._paused, np.zeros(len(self.joints)))
        if traj is None:
            return self._command_hold(self._hold)
        if self._clock is None:
            self._clock = PathClock(t)
        tau, rate = self._clock.at(t + self.dt)
        queue = self._queue
        if tau >= queue.end:
            if self._hold_for is not traj:
                self._hold, self._hold_for = queue.q(queue.end), traj
            return self._command_hold(self._hold)
        self._held = None
        if rate == 1.0:
            return queue.command(tau)  # (lists of floats already: no conversion)
        q, qd = queue.state(tau)  # StopMove / StartMove: on the path, at the clock's rate
        return self._command(q, qd * rate)

    def _command_hold(self, q: np.ndarray) -> tuple | None:
        """Hold q: commanded once (the motors keep their command), not again at every substep."""
        if self._held is q:
            return None
        command = self._command(q, np.zeros(len(self.joints)))
        self._held = q
        return command

    def _command(self, q: np.ndarray, qd: np.ndarray) -> tuple:
        self._held = None
        return _floats(q), _floats(qd)


def _floats(values) -> list[float]:
    """Python floats for pybullet (an array's `tolist` gives the very same values, without a loop in Python)."""
    return values.tolist() if isinstance(values, np.ndarray) else [float(v) for v in values]
