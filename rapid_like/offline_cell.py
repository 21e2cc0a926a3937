"""A station's robot without physics, for `rapid run --station DIR`: the offline run moves the station's arm with
the same planner as the cell (twin.core.planner), on the controller's clock.

`KinematicCell` answers what `station_host.TwinHost` asks of a twin (move, motion_ready, motion_done, tcp_pose,
robot_q, read, write), so the offline host is the cell's host: the station's I/O configuration, its arm, tool,
start pose (home_deg), joint and acceleration limits. The robot is exactly where the plan says (it follows
the plan perfectly and is in position the instant the plan ends; in the cell the physics settles within a
step of it). The gripper is not simulated: a setpoint written by the program reads back as written, a
reading of the gripper (an input wired to a twin output) reads 0 unless `--set` gives it.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from twin.core.geometry import Pose
from twin.core.kinematics import ArmKinematics
from twin.core.motion import Speed
from twin.core.planner import FINE, KinematicRobot, plan_motion
from twin.core.station import IOSignal, Station

from .station_host import TwinHost


class KinematicCell:
    """The station's arm as a plan on a clock; see the module docstring."""

    def __init__(self, station: Station):
        st = station.robot
        if st is None:
            raise ValueError(f"station {station.name!r} has no [robot]")
        self.station = station
        self.clock: Callable[[], float] = lambda: 0.0
        base = Pose.from_xyz_rpy(st.base.xyz, st.base.rpy)
        tool = Pose.from_xyz_rpy(station.gripper.tcp.xyz, station.gripper.tcp.rpy)
        self.kinematics = ArmKinematics(st.urdf, base.position, base.orientation, flange_link=st.flange_link,
                                        tool=tool, joint_names=st.joints)
        if st.accel_deg is not None:
            self.kinematics.accel = np.radians(st.accel_deg)
        self.robot = KinematicRobot(self.kinematics, np.radians(st.home_deg))
        self.values: dict[str, float] = {k: float(v) for k, v in station.gripper.initial.items()}

    @property
    def time(self) -> float:
        return self.clock()

    def move(self, instr: str, target, speed: Speed, *, via=None, name: str | None = None, tool=None, zone=None,
             conf=None) -> int:
        kin = self.kinematics if tool is None else self.kinematics.with_tool(tool)
        q0 = self.robot.plan_start(self.time)
        traj = plan_motion(kin, instr, q0, target, speed, via, name or instr, conf)
        return self.robot.queue(traj, zone or FINE, self.time)

    def motion_ready(self, handle: int) -> bool:
        return self.robot.ready(handle, self.time)

    def motion_done(self, handle: int) -> bool:
        return self.robot.done(handle, self.time)

    @property
    def robot_q(self) -> np.ndarray:
        return self.robot.q_at(self.time)

    def tcp_pose(self, tool: Pose | None = None) -> Pose:
        pose = self.kinematics.fk(self.robot_q)
        return pose if tool is None else pose * self.kinematics.tool.inverse() * tool

    def read(self, name: str) -> float:
        return self.values.get(name, 0.0)

    def write(self, name: str, value: float) -> None:
        self.values[name] = float(value)

    def close(self) -> None:
        self.kinematics.close()


class OfflineStationHost(TwinHost):
    """The cell's host on a `KinematicCell`; `--set` writes a gripper reading (a wired input) in the cell's units."""

    def __init__(self, station: Station, extra: list = ()):
        """`extra`: signals configured beyond the station's (`--io`), kept in the controller's memory."""
        if station.controller is None:
            raise ValueError(f"station {station.name!r} has no [controller] (its I/O configuration)")
        self.cell = KinematicCell(station)
        spec = station.controller
        spec = replace(spec, io=spec.io + tuple(IOSignal(s.name, s.kind) for s in extra))
        super().__init__(self.cell, spec)

    def bind_clock(self, clock: Callable[[], float]) -> None:
        self.cell.clock = clock

    def set_input(self, name: str, value: float) -> None:
        sig = self.io[name]
        wired = sig.source or sig.drives
        if wired:
            self.cell.write(wired, sig.scale * float(value) + sig.offset)
        else:
            self.memory[name] = float(value)

    @property
    def values(self) -> dict[str, float]:
        return {s.name: self.read_signal(s.name) for s in self.config}


def station_signals(station: Station) -> list:
    """The station's controller I/O configuration as the checker takes it."""
    from .host import SignalInfo

    return [SignalInfo(s.name, s.type) for s in station.controller.io] if station.controller else []

