"""The RAPID controller bound to a twin: the station's `[controller]` becomes the cell's robot controller.

Two small adapters, one per side of the controller:

- `TwinHost` is the controller's `Host`. Its I/O signals are the station's `[[controller.io]]`:
  an output with `drives` writes `scale * value + offset` to a twin input at once (`aoWidth` in mm
  drives `width` in m, as RobotStudio's expression blocks do); an input with `source` reads a twin output
  live, `(twin value - offset) / scale`; the others live in the controller's memory. Motions drive
  the station's robot through the twin's motion API and are done when the robot is in position.
- `ControllerDevice` is the twin's `Device`: it ticks the controller at the start of every simulation
  step (before the gripper and the robot act, so a `SetAO` takes effect in the same step), and adds the
  controller's signals to the twin's signal table, so the Modbus server publishes them. Its unwired inputs
  (DI, AI, GI) are written from outside (by the PLC); its outputs are read-only, unless marked `settable`
  (like RobotStudio's I/O simulator); wired signals are read-only mirrors.
  After them come the program's own: `rapid.start` / `rapid.stop` (rising edges restart the program from
  its entry routine or stop it), `rapid.running`, `rapid.error` and `rapid.line` (where it waits).

`attach_controller(twin)` does the wiring for a twin whose station has a `[controller]`.

The controller is ticked inside every 12 ms simulation step, so a busy RAPID loop must give the
step back quickly: the binding's loop budget is `STATION_LOOP_BUDGET` (200) time-less iterations
per tick, not the offline 10 000. Measured on the ring rig: a `WHILE di1 = 0 DO ENDWHILE`
iteration costs 2 to 3.5 us (10 000 of them: 20 to 35 ms, more than the step itself; 200: under
1 ms), and one turn of the thesis's Init loop with an empty Main 13 to 16 us (200: about 3 ms).
"""
from __future__ import annotations

import math
from typing import Callable, Sequence

from twin.core.errors import MotionError, TwinError
from twin.core.signal_table import (CONTROLLER_SIGNAL_TYPE as SIGNAL_TYPE, RAPID_ERROR as SIGNAL_ERROR,
                                    RAPID_LINE as SIGNAL_LINE, RAPID_RUNNING as SIGNAL_RUNNING,
                                    RAPID_START as SIGNAL_START, RAPID_STOP as SIGNAL_STOP, check_wiring,
                                    controller_signals)
from twin.core.signals import BOOL, INT
from twin.core.station import ControllerSpec

from .builtins import ERRORS
from .controller import ERROR, RUNNING, WAITING, Controller, load_program, load_task
from .errors import ExecError
from .host import MotionRequest, SignalInfo
from .interpreter import to_ns
from .robot_motion import conf_of, speed_of, zone_of
from .values import Record, record

STATION_LOOP_BUDGET = 200  # time-less loop iterations per simulation step (see the module docstring)


class HostError(ExecError):
    """A request the cell refuses (a setpoint out of range, an unreachable target)."""

    def __init__(self, message: str, errname: str):
        super().__init__(f"{message} ({errname})", None, ERRORS.get(errname, 0), errname)


def _pose(target: Record):
    from twin.core.geometry import Pose

    return Pose(*_pose_of(target))


def _tframe(tool: Record):
    """A tooldata's TCP in the flange frame (a Pose in m)."""
    return _pose(tool.fields["tframe"])


def _wobj_frame(wobj: Record):
    """A wobjdata's object frame in the world: uframe x oframe (a Pose in m)."""
    return _pose(wobj.fields["uframe"]) * _pose(wobj.fields["oframe"])


def _pose_of(target: Record) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """A robtarget or pose (mm, quaternion q1..q4 with q1 = w) as a position in m and an xyzw quaternion."""
    trans, rot = target.fields["trans"], target.fields["rot"]
    x, y, z = (float(v) / 1000.0 for v in trans.values())
    w, qx, qy, qz = (float(v) for v in rot.values())
    norm = math.sqrt(w * w + qx * qx + qy * qy + qz * qz) or 1.0
    return (x, y, z), (qx / norm, qy / norm, qz / norm, w / norm)


class TwinHost:
    """The controller's view of the cell: wired signals, memory signals and the robot."""

    def __init__(self, twin, spec: ControllerSpec):
        self.twin, self.spec = twin, spec
        self.config = [SignalInfo(s.name, s.type) for s in spec.io]
        self.io = {s.name: s for s in spec.io}
        self.memory: dict[str, float] = {s.name: 0.0 for s in spec.io if not (s.drives or s.source)}
        self.outputs: dict[str, float] = {s.name: 0.0 for s in spec.io if s.drives}
        self.printed: list[str] = []
        self._active: tuple[Record | None, Record | None] = (None, None)  # tooldata, wobjdata of the last motion
        robot = twin.station.robot
        self.conf_monitoring = robot.conf_monitoring if robot is not None else True  # at the program's start

    # -- signals --------------------------------------------------------------------------------------
    def signals(self) -> Sequence[SignalInfo]:
        return self.config

    def read_signal(self, name: str) -> float:
        sig = self.io[name]
        if sig.source:
            value = self.twin.read(sig.source)
            if isinstance(value, str):  # an enum output (GrippedPart): its index, 0 for none
                value = self.twin.spec(sig.source).choices.index(value)
            return (float(value) - sig.offset) / sig.scale
        if sig.drives:  # a wired output reads what it drives (aoWidth mirrors width, whoever wrote it last)
            value = self.twin.read(sig.drives)
            return (float(value) - sig.offset) / sig.scale
        return self.memory[name]

    def write_signal(self, name: str, value: float) -> None:
        sig = self.io[name]
        if sig.drives:
            try:
                self.twin.write(sig.drives, sig.scale * value + sig.offset)
            except TwinError as exc:
                errname = {"AO": "ERR_AO_LIM", "GO": "ERR_GO_LIM"}.get(sig.type, "ERR_ARGVALERR")
                raise HostError(f"{name} = {value:g} drives {exc}", errname) from None
            self.outputs[name] = float(value)
        else:
            self.memory[name] = float(value)

    # -- robot ----------------------------------------------------------------------------------------
    def start_motion(self, request: MotionRequest) -> object:
        """Queue the motion with the robot's planner: the target is for the program's tooldata (its tframe) in its
        wobjdata; it starts after the motion under way, or blends out of its zone (twin.core.planner)."""
        twin = self.twin
        name = request.target_name or request.instr
        robot = twin.station.robot
        speed = speed_of(request, robot.payload_kg if robot is not None else None)
        zone = zone_of(request)
        try:
            if request.instr == "MoveAbsJ":
                q = [math.radians(float(v)) for v in request.target.fields["robax"].values()]
                handle = twin.move("MoveAbsJ", q, speed, name=name, zone=zone)
            else:
                frame = _wobj_frame(request.wobj)
                target = frame * _pose(request.target)
                via = frame * _pose(request.via) if request.via is not None else None
                handle = twin.move(request.instr, target, speed, via=via, name=name, tool=_tframe(request.tool),
                                   zone=zone, conf=conf_of(request))
        except MotionError as exc:
            raise HostError(str(exc), "ERR_ROBLIMIT") from None
        self._active = (request.tool, request.wobj)
        return handle

    def motion_done(self, handle: object) -> bool:
        return self.twin.motion_done(handle)

    def motion_ready(self, handle: object) -> bool:
        return self.twin.motion_ready(handle)

    def corner_failure(self, handle: object) -> bool:
        return self.twin.robot.corner_failure(handle)

    def motion_wake(self, handle: object, what: str) -> int | None:
        """When the program may go on past motion `handle` ("ready") or it ends ("end") on the plan (ns), for runners that jump from event to event."""
        robot = self.twin.robot
        t = robot.ready_time(handle) if what == "ready" else robot.end_time(handle)
        return None if t is None else to_ns(t)

    # -- path control: StopMove, StartMove, ClearPath, StorePath, RestoPath (twin.core.planner.PathClock) ----
    def stop_path(self, quick: bool, at_end: bool = False) -> None:
        self.twin.robot.stop_path(self.twin.time, quick, at_end)

    def path_standing(self) -> bool:
        return self.twin.robot.path_standing(self.twin.time)

    def stand_time(self) -> int | None:
        """When the robot will stand on its path (ns), for runners that jump from event to event."""
        t = self.twin.robot.stand_time(self.twin.time)
        return None if t is None else to_ns(t)

    def start_path(self) -> None:
        self.twin.robot.start_path(self.twin.time)

    def clear_path(self) -> None:
        self.twin.robot.clear_path(self.twin.time)

    def store_path(self) -> None:
        self.twin.robot.store_path(self.twin.time)

    def restore_path(self) -> None:
        try:
            self.twin.robot.restore_path(self.twin.time)
        except MotionError as exc:
            raise HostError(str(exc), "ERR_PATHDIST") from None

    def motor_torque(self, axis: int) -> float:
        """GetMotorTorque: the physics arm's axis torque (N m); 0 without physics (an offline run)."""
        torque = getattr(self.twin.robot, "motor_torque", None)
        return torque(axis) if torque is not None else 0.0

    def current_robtarget(self, tool: Record | None, wobj: Record | None) -> Record:
        """CRobT: the TCP of `tool` in `wobj`; without them, those of the last motion (the active ones), or
        before any motion the station's tcp in the world (wobj0)."""
        active_tool, active_wobj = self._active
        tool, wobj = tool or active_tool, wobj or active_wobj
        pose = self.twin.tcp_pose(_tframe(tool) if tool is not None else None)
        if wobj is not None:
            pose = _wobj_frame(wobj).inverse() * pose
        x, y, z = (float(v) * 1000.0 for v in pose.position)
        qx, qy, qz, w = (float(v) for v in pose.orientation)
        return record("robtarget", [x, y, z], [w, qx, qy, qz], [0, 0, 0, 0], [9e9] * 6)

    def current_jointtarget(self) -> Record:
        q = [math.degrees(float(v)) for v in self.twin.robot_q]
        return record("jointtarget", q, [9e9] * 6)

    def tp_write(self, text: str) -> None:
        self.printed.append(text)


class ControllerDevice:
    """Steps the controller with the twin and publishes the controller's signals in the signal table."""

    def __init__(self, host: TwinHost, controller: Controller):
        self.host, self.controller = host, controller
        self.signals = controller_signals(host.spec)
        self._requests = {SIGNAL_START: False, SIGNAL_STOP: False}  # as written
        self._seen = dict(self._requests)  # as acted on

    def read(self, name: str):
        if name in self._requests:
            return self._requests[name]
        state = self.controller.state
        if name == SIGNAL_RUNNING:
            return state in (RUNNING, WAITING)
        if name == SIGNAL_ERROR:
            return state == ERROR
        if name == SIGNAL_LINE:
            wait = self.controller.wait
            return wait.span.line if wait is not None and wait.span is not None and state == WAITING else 0
        value = self.host.read_signal(name)
        kind = SIGNAL_TYPE[self.host.io[name].type]
        return bool(value) if kind == BOOL else int(value) if kind == INT else value

    def write(self, name: str, value) -> None:
        if name in self._requests:
            self._requests[name] = bool(value)
        else:
            self.host.memory[name] = float(value)

    def before_step(self, twin) -> None:
        """Act on program requests written since the last step (rising edges), then run the program."""
        for name, value in self._requests.items():
            if value and not self._seen[name]:
                self.controller.stop() if name == SIGNAL_STOP else self.controller.start()
            self._seen[name] = value
        self.controller.tick(twin.time)

    def after_step(self, twin) -> None:
        pass


def attach_controller(twin, on_event: Callable[[dict], None] | None = None, autostart: bool = True,
                      entry: str | None = None) -> Controller:
    """Load the station's RAPID program and make it the twin's robot controller.

    `entry` overrides the station's entry routine (e.g. `Path_FullAutoRun` for one cycle)."""
    spec = twin.station.controller
    if spec is None:
        raise TwinError(f"station {twin.station.name!r} has no [controller]")
    check_wiring(twin.station, twin.signals)
    host = TwinHost(twin, spec)
    program = load_task([spec.program, *spec.modules]) if spec.modules else load_program(spec.program)
    controller = Controller(program, host, entry=entry or spec.entry, on_event=on_event, autostart=autostart,
                            loop_budget=STATION_LOOP_BUDGET, answers=list(spec.answers))
    controller.interp.io_wall_wait = 0.0  # a socket wait never stalls the simulation step
    twin.add_device(ControllerDevice(host, controller))
    return controller
