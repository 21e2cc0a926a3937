"""The simulation API: a station's twin, stepped from outside.

`Twin` is what the Modbus server, the RAPID controller and the PLC wrap. Its contract is narrow:
`read`/`write` signals by name in SI units, `step(n)`, and queries of the physical state. It has no
sockets and no wall clock; its time is `step_count * dt`. Each step runs, in order: the gripper's servo
commands and the robot's trajectory (inputs written before the step take effect now), the physics
sub-steps, then sensing and the grip rule; outputs are then published as one snapshot, so a reader never
sees a half-updated state. The same station, inputs and step count give the same state, bit for bit.
"""
from __future__ import annotations

import math
from pathlib import Path

from .errors import MotionError, ObjectError, SignalError, StationError
from .gripper import Gripper
from .mechanism import Mechanism, load_mechanism
from .signal_table import IN_POSITION_TOLERANCE, twin_signals
from .device import Device
from .signals import INPUT, OUTPUT, SignalSpec
from .station import Station, load_station
from .world import ROBOT_PREFIX, World, quat



class Twin:
    """A running station: physics world, gripper logic and robot, with a signal table."""

    def __init__(self, station: Station):
        self.station = station
        self.mechanism: Mechanism = load_mechanism(station.gripper.urdf, station.gripper.fingers)
        self.devices: list[Device] = []
        self._own_signals = twin_signals(station, self.mechanism)
        self._index_signals()
        self.world: World | None = None
        self.reset()

    def _index_signals(self) -> None:
        signals = list(self._own_signals)
        self._owner: dict[str, Device | None] = {s.name: None for s in signals}
        for device in self.devices:
            for spec in device.signals:
                if spec.name in self._owner:
                    raise SignalError(spec.name, "is declared twice (by the station and by a device)")
                self._owner[spec.name] = device
                signals.append(spec)
        self.signals: tuple[SignalSpec, ...] = tuple(signals)
        self._spec = {s.name: s for s in signals}

    def add_device(self, device: Device) -> None:
        """Step `device` with the twin and add its signals at the end of the signal table."""
        self.devices.append(device)
        self._index_signals()

    @classmethod
    def from_station(cls, path: str | Path) -> "Twin":
        return cls(load_station(path))

    # -- life cycle -------------------------------------------------------------------------------
    def reset(self) -> None:
        """Rebuild the world from the station (never restored from a snapshot: see world.py)."""
        if self.world is not None:
            self.world.close()
        st = self.station
        self.world = World(st, self.mechanism.base_link)
        self.step_count = 0
        self.gripper = Gripper(self.world.client, self.world.machine, self.world.joint_index, self.world.link_index,
                               self.mechanism, st.gripper, {t.name: self.world.body_ids[t.name] for t in st.targets},
                               self.world.substep, self.world.contact_probe, self.world.substeps)
        if self.gripper.finger_forces:
            self.world.squeeze_tolerance_within(min(self.gripper.finger_forces.values()))
        self.world.iterations_for(self.gripper.mass_ratio, bool(self.gripper.rigid_linkages),
                                  self.gripper.spring_sweeps)
        self.robot = None
        if st.robot is not None:
            from .geometry import Pose
            from .kinematics import ArmKinematics
            from .robot import Robot

            # The station's base pose is the URDF base frame, where the world loaded the arm; pybullet's
            # getBasePositionAndOrientation would give the base link's centre of mass instead.
            base = Pose(st.robot.base.xyz, quat(st.robot.base))  # the very quaternion the world used
            tool = Pose.from_xyz_rpy(st.gripper.tcp.xyz, st.gripper.tcp.rpy)
            try:
                self.kinematics = ArmKinematics(st.robot.urdf, base.position, base.orientation,
                                                flange_link=st.robot.flange_link, tool=tool,
                                                joint_names=st.robot.joints)
            except MotionError as exc:  # load_station checks names; what is left is the joints' order
                raise StationError(str(st.file), "robot.joints", str(exc).split(": ", 1)[-1]) from None
            if st.robot.accel_deg is not None:
                import numpy as np

                self.kinematics.accel = np.radians(st.robot.accel_deg)
            self.robot = Robot(self.world.client, self.world.machine,
                               tuple(ROBOT_PREFIX + j for j in st.robot.joints), self.kinematics)
            self.robot.reset([math.radians(a) for a in st.robot.home_deg])
            self.gripper.read_along(self.robot.joints)  # the arm's joints read with the gripper's after a step
        self.world.check_overlaps()
        self._present = {f"{t.name}.present": True for t in st.targets}  # as written
        self._placed = dict(self._present)  # as applied to the world
        self._target_of = {f"{t.name}.present": t for t in st.targets}
        self._outputs: dict[str, object] = {}
        self._published: dict[str, object] = {}  # the last snapshot as published (before any override_outputs)
        self._published_fingers = None  # the fingers' states it shows
        self._index_outputs()
        self._publish()

    def close(self) -> None:
        if self.world is not None:
            self.world.close()
            self.world = None

    def __enter__(self) -> "Twin":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- time ---------------------------------------------------------------------------------------
    @property
    def dt(self) -> float:
        return self.station.step

    @property
    def time(self) -> float:
        return self.step_count * self.station.step

    def step(self, n: int = 1) -> None:
        """Advance n simulation steps."""
        for _ in range(n):
            for device in self.devices:
                device.before_step(self)
            if self._present != self._placed:  # (a `TARGET.present` written since: applied now)
                self._place_targets()
            # the drives and the arm are commanded at every physics substep: an arm command held for a whole
            # step moves the flange in bursts that shake a friction grip loose (measured-facts.md)
            t, gripper, robot, world = self.time, self.gripper, self.robot, self.world
            world.solve_for(gripper.pressing or bool(gripper.state.gripped or gripper.state.attached))
            substeps = world.substeps
            gripper.drive(0)
            arm = robot.commands(t, substeps) if robot is not None else None
            if arm is not None and arm[0] is not None:
                robot.send(arm[0])
            world.stasis.before_physics(self._machine_still)  # a cell at rest has its loose bodies frozen: thawed
            world.substep_physics()  # before anything may move them
            if gripper.quiet:
                # the drives keep the first substep's settings for the step's other substeps, and nothing is measured
                # until the last: the physics runs, and the arm's commands where it moves
                gripper.coast(substeps - 1)
                for k in range(1, substeps):
                    if arm is not None and arm[k] is not None:
                        robot.send(arm[k])
                    world.substep_physics()
                gripper.measure(True)
            else:
                gripper.measure(substeps == 1)
                for k in range(1, substeps):
                    gripper.drive(k)
                    if arm is not None and arm[k] is not None:
                        robot.send(arm[k])
                    world.substep_physics()
                    gripper.measure(k == substeps - 1)
            self.step_count += 1
            self.gripper.sense()
            self._publish(gripper.along)
            if world.rolling:  # (round parts in the cell: the targets' poses as the snapshot read them)
                world.free_rolling(gripper.touched_bodies(), dict(zip(self._target_ids, self._read[3])))
            world.stasis.after_step(self._machine_still)
            for device in self.devices:
                device.after_step(self)

    def _machine_still(self) -> bool:
        """The arm idle and every gripper drive standing at its goal, holding nothing (stasis.py)."""
        g = self.gripper
        return (g.quiet and not g.state.gripped and not g.state.attached
                and (self.robot is None or not self.robot.moving))

    # -- signals ------------------------------------------------------------------------------------
    def spec(self, name: str) -> SignalSpec:
        try:
            return self._spec[name]
        except KeyError:
            raise SignalError(name, "no such signal in station " + repr(self.station.name)) from None

    def read(self, name: str):
        """Present value of a signal: inputs as last written, outputs as of the last completed step."""
        spec = self.spec(name)
        device = self._owner[name]
        if device is not None:
            return device.read(name)
        if spec.direction == INPUT:
            if name == "Active":
                return self.gripper.active_input
            if name in self._present:
                return self._present[name]
            return self.gripper.setpoint[name]
        return self._outputs[name]

    def write(self, name: str, value) -> None:
        """Write an input. Takes effect at the next step. Checked by `SignalSpec.check` (SignalError for an
        output, SignalTypeError for a wrong type, SignalRangeError out of range): on error nothing changes."""
        value = self.spec(name).check(value)
        device = self._owner[name]
        if device is not None:
            device.write(name, value)
        elif name in self._present:
            self._present[name] = value
        elif name == "Active":
            self.gripper.set_active(value)
        else:
            self.gripper.set_setpoint(name, value)

    def set_drive_limits(self, name: str, velocity: float | None = None, effort: float | None = None) -> None:
        """Change input `name`'s velocity limit (m/s or rad/s) or effort limit (N or N*m) from the next step on
        (a drive that loses force; parameter studies). None keeps the present value."""
        self.spec(name)
        self.gripper.set_limits(name, velocity, effort)

    def drive_limits(self, name: str) -> tuple[float, float]:
        """Input `name`'s (velocity, effort) limits as the gripper applies them now."""
        self.spec(name)
        return self.gripper.limits[name]

    def override_outputs(self, values: dict) -> None:
        """Replace published output values until the next step publishes anew: a sensor reading that is stuck
        or offset, injected by a device in `after_step`. Readers (the PLC, the servers) see the replaced
        values; the gripper's own logic and the physics do not."""
        for name in values:
            if self.spec(name).direction != OUTPUT:
                raise SignalError(name, "is an input: only outputs (readings) can be overridden")
        self._outputs = {**self._outputs, **values}

    def _publish(self, arm_states=None) -> None:
        """The outputs as of now, as one new snapshot. `arm_states`: the arm's joints' states as the step read them
        after its last substep (else they are read here)."""
        g, setpoint, last = self.gripper.state, self.gripper.setpoint, self._published
        out = last.copy()  # (the step before's snapshot, as published: what did not change is not formed anew)
        out["doGripped"] = bool(g.gripped)
        out["GrippedPart"] = g.gripped
        out["slip"] = g.slip
        axes = g.axes
        for name, actual_key, in_position_key, moving_key, effort_key, tolerance in self._axis_keys:
            axis = axes[name]
            out[actual_key] = axis.actual
            out[in_position_key] = abs(axis.actual - setpoint[name]) <= tolerance
            out[moving_key] = axis.moving
            out[effort_key] = axis.effort
        fingers = g.fingers
        if fingers is not self._published_fingers:  # (the gripper keeps its fingers' states while they stand)
            for name, contact_key, force_key, status_key in self._finger_keys:
                finger = fingers[name]
                out[contact_key] = bool(finger.contacts)
                out[force_key] = finger.force
                out[status_key] = finger.status
            self._published_fingers = fingers
        arm = None
        if self.robot is not None:
            out["robot.busy"] = self.robot.busy(self.time)
            arm = [s[0] for s in arm_states] if arm_states else self.robot.positions()
            out.update(zip(self._robot_keys, arm))
        pose = self.world.client.getBasePositionAndOrientation
        poses = []
        for uid, x_key, y_key, z_key in self._target_keys:
            p = pose(uid)
            poses.append(p)
            out[x_key], out[y_key], out[z_key] = p[0]
        self._outputs = self._published = out
        self._read = (self.step_count, arm, self.gripper.step_positions, poses)

    def step_readings(self) -> tuple[list[int], list[float], list[int], list[tuple]] | None:
        """What the step read of the bodies anyway, for an observer that would otherwise ask pybullet again
        (a recorder, at every step): (machine joint indices, their positions: the arm's joints and the gripper
        inputs' joints; target body ids, their (position, orientation)), exactly as pybullet gave them after
        the step's last physics substep. None before the first step."""
        step, arm, grip, poses = self._read
        if step != self.step_count or not step:
            return None
        ids = self._read_ids
        if ids is None:
            ids = self._read_ids = ((self.robot.joints if arm is not None else [])
                                    + (self.gripper.joint_ids if grip is not None else []))
        return ids, (arm or []) + (grip or []), self._target_ids, poses

    def _index_outputs(self) -> None:
        """The output names published at every step, spelled out once (not formatted anew at every step)."""
        self._axis_keys = [(i.name, f"{i.name}.actual", f"{i.name}.in_position", f"{i.name}.moving",
                            f"{i.name}.effort", IN_POSITION_TOLERANCE[i.unit])
                           for i in self.mechanism.inputs]
        self._finger_keys = [(name, f"{name}.contact", f"{name}.force", f"{name}.status")
                             for name in self.gripper.state.fingers]
        self._robot_keys = ([f"robot.j{i}" for i in range(1, len(self.robot.joints) + 1)]
                            if self.robot is not None else [])
        self._target_keys = [(self.world.body_ids[t.name], f"{t.name}.x", f"{t.name}.y", f"{t.name}.z")
                             for t in self.station.targets]
        self._target_ids = [uid for uid, *_ in self._target_keys]
        self._read_ids: list[int] | None = None  # the joints `step_readings` gives, once known

    # -- robot motion -----------------------------------------------------------------------------
    def target(self, name: str):
        """A named robot target of the station, as a TCP Pose in the world frame."""
        from .geometry import Pose

        placement = self.station.robot_targets.get(name)
        if placement is None:
            known = ", ".join(self.station.robot_targets) or "none"
            raise MotionError(name, f"no such robot target in station {self.station.name!r} (targets: {known})")
        return Pose.from_xyz_rpy(placement.xyz, placement.rpy)

    def move(self, instr: str, target, speed=1.0, *, v_ori: float | None = None, via=None,
             name: str | None = None, tool=None, zone=None, conf=None) -> int:
        """Start a motion from where the robot is now; it runs over the next steps (see `robot_busy`).

        `instr` is MoveJ, MoveL, MoveC (through `via`) or MoveAbsJ (target: joint angles in rad). A
        target is a Pose or the name of a station target; `speed` is the TCP speed in m/s (or a
        `motion.Speed`), `v_ori` the reorientation speed in rad/s. `tool`: the TCP in the flange frame for
        this motion (a Pose; default the station's `tcp`). With a `zone` (planner.Zone) the motion is queued
        instead: it starts from the last queued motion's end, after it or blending out of its zone. The whole
        path is checked before the robot moves: a target it cannot reach raises MotionError naming the
        target (and, with `conf` = RAPID's (cf1, cf4, cf6), one it reaches in another configuration).
        Returns the motion's handle (`motion_ready`, `motion_done`).
        """
        from . import motion
        from .planner import plan_motion

        if self.robot is None:
            raise MotionError(name or str(target), f"station {self.station.name!r} has no robot")
        if isinstance(target, str):
            name = name or target
            target = self.target(target)
        if isinstance(via, str):
            via = self.target(via)
        name = name or instr
        if isinstance(speed, motion.Speed):
            speed_spec = speed
        else:
            speed_spec = motion.Speed(v_tcp=speed, v_ori=v_ori) if v_ori is not None else motion.Speed(v_tcp=speed)
        q0 = self.robot.q if zone is None else self.robot.plan_start(self.time)
        kin = self.kinematics if tool is None else self.kinematics.with_tool(tool)
        traj = plan_motion(kin, instr, q0, target, speed_spec, via, name, conf)
        handle = self.robot.start(traj, self.time) if zone is None else self.robot.queue(traj, zone, self.time)
        self._publish()
        return handle

    def motion_ready(self, handle: int) -> bool:
        """May a program go on past motion `handle` (a zone point's TCP in its largest zone, see planner.py)?"""
        return self.robot.ready(handle, self.time)

    def motion_done(self, handle: int) -> bool:
        """Is motion `handle` over (in position at its end, or gone on into the next motion)?"""
        return self.robot.done(handle, self.time)

    @property
    def robot_busy(self) -> bool:
        return self.robot is not None and self.robot.busy(self.time)

    @property
    def robot_q(self):
        return self.robot.q

    def tcp_pose(self, tool=None):
        """The TCP in the world: of the station's `tcp`, or of `tool` (a Pose in the flange frame)."""
        pose = self.robot.tcp_pose()
        return pose if tool is None else pose * self.kinematics.tool.inverse() * tool

    def run_motion(self, instr: str, target, speed: float = 1.0, *, max_time: float = 120.0, **kw) -> None:
        """Start a motion and step until the robot is in position. MotionError when it does not get there: still
        moving after `max_time`, or stopped short of its target (blocked: not in position `settle_timeout` after the
        motion's planned end; the arm then holds where it got to)."""
        self.move(instr, target, speed, **kw)
        limit = self.step_count + round(max_time / self.dt)
        while self.robot_busy:
            if self.step_count >= limit:
                raise MotionError(str(kw.get("name") or target), f"still moving after {max_time:g} s")
            self.step()
        if self.robot.failure is not None:
            raise self.robot.failure

    # -- physical state -----------------------------------------------------------------------------
    @property
    def gripped_part(self) -> str:
        return self.gripper.state.gripped

    def joint_positions(self) -> dict[str, float]:
        return {name: axis.actual for name, axis in self.gripper.state.axes.items()}

    def finger_contacts(self) -> dict[str, tuple[str, ...]]:
        return {name: f.contacts for name, f in self.gripper.state.fingers.items()}

    def finger_forces(self) -> dict[str, float]:
        return {name: f.force for name, f in self.gripper.state.fingers.items()}

    def object_pose(self, name: str) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """Position (m) and orientation (quaternion x, y, z, w) of a target or fixture."""
        if name not in self.world.body_ids:
            raise ObjectError(name, f"no such target or fixture in station {self.station.name!r} "
                                    f"(it has: {', '.join(sorted(self.world.body_ids)) or 'none'})")
        return self.world.pose(name)

    def remove_object(self, name: str) -> None:
        """Take a target out of the cell at once (a missed-grip scenario); `TARGET.present` does it at the
        next step, and writing it True puts the target back where the station placed it."""
        key = f"{name}.present"
        if key not in self._present:
            raise ObjectError(name, f"no such target in station {self.station.name!r}")
        self._present[key] = False
        self._place_targets()
        self._publish()

    def _place_targets(self) -> None:
        """Apply `TARGET.present` writes: a removed target is parked far below the cell, static; one put
        back returns to its station pose, at rest."""
        for key, want in self._present.items():
            if self._placed[key] == want:
                continue
            body = self._target_of[key]
            uid, c = self.world.body_ids[body.name], self.world.client
            self.world.stasis.thaw()  # (its mass is changed here)
            if not want:
                self.gripper.forget(body.name)
                c.resetBasePositionAndOrientation(uid, [0, 0, -100], [0, 0, 0, 1])
                c.changeDynamics(uid, -1, mass=0)
            else:
                c.changeDynamics(uid, -1, mass=body.mass)
                c.resetBasePositionAndOrientation(uid, body.pose.xyz, quat(body.pose))
                c.resetBaseVelocity(uid, [0, 0, 0], [0, 0, 0])
            self._placed[key] = want
