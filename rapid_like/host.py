"""The host protocol: what the controller needs from the world it runs in, and an in-memory host.

The controller never touches physics or sockets. Everything it observes or does to the cell goes
through a `Host`:

    signals()                      the configured I/O signals (name as configured, type DI/DO/AI/AO/GI/GO)
    read_signal(name) -> float     a signal's present value, read each time RAPID evaluates it
    write_signal(name, value)      SetDO/Set/Reset/SetAO/SetGO/PulseDO edges (outputs only)
    start_motion(request) -> h     begin a MoveJ/MoveL/MoveC/MoveAbsJ; returns any handle
    motion_done(h) -> bool         asked every tick until True; then the program goes on
    (optional) motion_ready(h)     a host that plans ahead: may the program go on past zone point h (its TCP
                                   has reached the largest zone)? The program pointer runs one motion ahead
    (optional) motion_wake(h, what) -> ns | None  when h is "ready" or its plan "end"s, for event-driven runs
    (optional) corner_failure(h)   did zone point h become a stop point (its next motion came too late)?
    current_robtarget(tool, wobj)  for CRobT: the TCP of `tool` in `wobj`, a robtarget Record
    current_jointtarget()          for CJointT
    tp_write(text)                 a line for the FlexPendant (TPWrite)

Names passed to read/write are the configured spelling. Values are RAPID nums (digital 0/1, analog
in the controller's unit, e.g. mm). `InMemoryHost` is the offline host: signals live in a dict and a
motion is complete as soon as it starts (the robot is at its target at once).

CRobT (`current_robtarget(tool, wobj)`): the TCP of `tool` in `wobj`; as in RAPID, an omitted
\\Tool or \\WObj (None) means the one that is active, i.e. the tool and work object of the last
motion instruction (tool0 and wobj0 before the first one). Offline, the flange pose is kept from
the last MoveJ/MoveL/MoveC as `wobj frame * target * inverse(tool.tframe)`, so CRobT with the
active tool and wobj returns that target exactly as written and any other tool or wobj sees the
same flange through its own frames. A MoveAbsJ has no kinematics offline: it makes its tool and
wobj the active ones but leaves the flange where the last Cartesian motion put it (CJointT reports
its joints).

Notes for a station binding (item 5):
- `signals()` comes from the station file's controller I/O section (name, type, wiring). The
  controller reads outputs too (`aoWidth<=440` reads the AO's present value), so `read_signal`
  must answer for every configured signal, outputs included (the last value written).
- Wiring is the binding's job: `write_signal("aoWidth", 331)` in mm becomes the gripper input `width` =
  0.331 m, the way RobotStudio's expression blocks divide by 1000; a DI such as diPartHeld reads the
  twin's grip output. The controller never scales anything.
- `start_motion` receives targets in mm and quaternions [q1..q4] (q1 = w), in `request.wobj`'s
  user/object frame, for the TCP of `request.tool` (tframe in the flange frame); `motion_done` is
  polled on every tick. A host with `motion_ready` queues the motion behind the ones under way and
  blends zones (twin.core.planner); one without completes every motion (like `fine`).
- Time: call `Controller.tick(now)` once per control step after applying the step's inputs; the
  program sees signal values as they are at `now`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, Sequence, runtime_checkable

from .builtins import Pose, _clean, pose_inv, pose_mul, pose_of, predefined_data, tool_frame, wobj_frame
from .values import Record, default_value, record

SIGNAL_KINDS = ("DI", "DO", "AI", "AO", "GI", "GO")
OUTPUT_KINDS = ("DO", "AO", "GO")


@dataclass(frozen=True)
class SignalInfo:
    """A configured I/O signal: its name as configured and its type (DI, DO, AI, AO, GI, GO)."""

    name: str
    kind: str


@dataclass(frozen=True)
class MotionRequest:
    """One motion instruction, with values (records in mm / quaternions) and the identifiers written.

    `target` is a robtarget Record for MoveJ/MoveL/MoveC and a jointtarget Record for MoveAbsJ;
    `via` is MoveC's circle point (None otherwise). `*_name` are the argument texts as written in
    the program (`Target_PickOutside`, `v1000`, `fine`, `tcpGripper`, `wobj0` when \\WObj is absent).
    """

    instr: str
    target: Record
    speed: Record
    zone: Record
    tool: Record
    wobj: Record
    via: Record | None = None
    target_name: str = ""
    via_name: str = ""
    speed_name: str = ""
    zone_name: str = ""
    tool_name: str = ""
    wobj_name: str = "wobj0"
    line: int = 0
    # how the controller plans it (docs/rapid.md, "Motion"): \T (s, after VelSet), AccSet's (acc, ramp) in %,
    # a stop point (fine or \Inpos), \Z (mm) instead of the zone's pzone_tcp, the payload's mass (kg: the
    # tool's load and GripLoad, or \TLoad), configuration monitoring on (ConfJ\On for MoveJ, ConfL\On for
    # MoveL/MoveC), PathAccLim's TCP acceleration limit (m/s^2)
    time: float | None = None
    acc: tuple[float, float] = (100.0, 100.0)
    stop_point: bool = True
    zone_size: float | None = None
    load_kg: float = 0.0
    conf: bool = False
    path_acc: float | None = None
    span: object = None  # where the instruction is (FILE:LINE:COL), for notes about it


@runtime_checkable
class Host(Protocol):
    def signals(self) -> Sequence[SignalInfo]: ...

    def read_signal(self, name: str) -> float: ...

    def write_signal(self, name: str, value: float) -> None: ...

    def start_motion(self, request: MotionRequest) -> object: ...

    def motion_done(self, handle: object) -> bool: ...

    def current_robtarget(self, tool: Record | None, wobj: Record | None) -> Record: ...

    def current_jointtarget(self) -> Record: ...

    def tp_write(self, text: str) -> None: ...


HOME_ROBTARGET = [[0, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0], [9e9] * 6]


@dataclass
class InMemoryHost:
    """Offline host: signals in a dict (all start at 0), motions complete at once."""

    config: list[SignalInfo]
    values: dict[str, float] = field(default_factory=dict)
    printed: list[str] = field(default_factory=list)
    moves: list[MotionRequest] = field(default_factory=list)
    position: Record = field(default_factory=lambda: record("robtarget", *HOME_ROBTARGET))  # last target
    joints: Record = field(default_factory=lambda: default_value("jointtarget"))  # type: ignore[assignment]
    tool: Record = field(default_factory=lambda: predefined_data()["tool0"][1])  # type: ignore[assignment]
    wobj: Record = field(default_factory=lambda: predefined_data()["wobj0"][1])  # type: ignore[assignment]

    def __post_init__(self) -> None:
        for s in self.config:
            self.values.setdefault(s.name, 0.0)
        # the flange in the world, and the (tool, wobj) for which CRobT returns `position` as written
        self.flange = _flange(self.wobj, self.position, self.tool)
        self.active = (self.tool.copy(), self.wobj.copy())

    def signals(self) -> Sequence[SignalInfo]:
        return self.config

    def read_signal(self, name: str) -> float:
        return self.values[name]

    def write_signal(self, name: str, value: float) -> None:
        self.values[name] = float(value)

    def set_input(self, name: str, value: float) -> None:
        """Change any signal from outside (what `--set` does)."""
        self.values[name] = float(value)

    def start_motion(self, request: MotionRequest) -> object:
        self.moves.append(request)
        if request.instr == "MoveAbsJ":
            self.joints = request.target.copy()
        else:
            self.position = request.target.copy()
            self.flange = _flange(request.wobj, request.target, request.tool)
            self.active = (request.tool.copy(), request.wobj.copy())
        self.tool, self.wobj = request.tool.copy(), request.wobj.copy()  # the active tool and wobj
        return len(self.moves)

    def motion_done(self, handle: object) -> bool:
        return True

    def current_robtarget(self, tool: Record | None, wobj: Record | None) -> Record:
        tool = tool or self.tool
        wobj = wobj or self.wobj
        out = self.position.copy()
        if tool == self.active[0] and wobj == self.active[1]:
            return out  # the last Cartesian target, as written
        trans, rot = pose_mul(pose_mul(pose_inv(wobj_frame(wobj)), self.flange), tool_frame(tool))
        t, r = out.fields["trans"].fields, out.fields["rot"].fields  # type: ignore[union-attr]
        t["x"], t["y"], t["z"] = (_clean(v) for v in trans)
        r["q1"], r["q2"], r["q3"], r["q4"] = (_clean(v) for v in rot)
        return out

    def current_jointtarget(self) -> Record:
        return self.joints.copy()

    def tp_write(self, text: str) -> None:
        self.printed.append(text)


def _flange(wobj: Record, target: Record, tool: Record) -> Pose:
    """The flange in the world for `target` (a robtarget in `wobj`) reached with `tool`:
    wobj frame * target * inverse(tool.tframe)."""
    return pose_mul(pose_mul(wobj_frame(wobj), pose_of(target)), pose_inv(tool_frame(tool)))
