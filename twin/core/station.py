"""Station files: a cell described in TOML, read with tomllib into a frozen `Station`.

Units are SI (m, kg, s, kg/m^3); angles carry their unit in the key (`rpy_deg`, `home_deg`). Paths are
relative to the station file. Every mistake stops with a StationError naming the file and the key
(e.g. `stations/x/station.toml: targets[0].inner_diameter: must be below outer_diameter (0.64)`).
Unknown keys are errors too, so a typo never goes unnoticed. The format is documented in
`docs/station-format.md`.
"""
from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .defaults import ARM_JOINTS, DEFAULT_STEP, SAFE_STATES
from .errors import MechanismError, StationError
from .mechanism import MOVABLE, FingerNameError, Mechanism, load_mechanism, read_links_and_joints

SHAPES = ("ring", "box", "cylinder", "plane")
MAX_RING_SEGMENTS = 16
IO_TYPES = ("DI", "DO", "AI", "AO", "GI", "GO")
GRIP_MODES = ("friction", "attach")
PYBULLET_DATA = "pybullet_data:"  # a path naming a model shipped with pybullet: pybullet_data:NAME.urdf


@dataclass(frozen=True)
class Placement:
    """A pose: position in m, orientation as roll-pitch-yaw in degrees (fixed axes x, y, z)."""

    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def rpy(self) -> tuple[float, float, float]:
        return tuple(math.radians(a) for a in self.rpy_deg)  # type: ignore[return-value]


@dataclass(frozen=True)
class Body:
    """A target object or a fixture: its shape, size, material and pose."""

    name: str
    shape: str
    pose: Placement
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)  # box
    radius: float = 0.0  # cylinder
    outer_diameter: float = 0.0  # ring
    inner_diameter: float = 0.0  # ring
    height: float = 0.0  # ring, cylinder
    segments: int = 12  # ring: the bore and the outside as regular polygons of this many faces
    density: float = 0.0  # kg/m^3; 0 = static (fixtures only)
    friction: float = 0.5
    color: tuple[float, float, float, float] = (0.6, 0.6, 0.65, 1.0)

    @property
    def dynamic(self) -> bool:
        return self.density > 0

    @property
    def volume(self) -> float:
        if self.shape == "box":
            return self.size[0] * self.size[1] * self.size[2]
        if self.shape == "cylinder":
            return math.pi * self.radius**2 * self.height
        if self.shape == "ring":
            return math.pi / 4 * (self.outer_diameter**2 - self.inner_diameter**2) * self.height
        return 0.0

    @property
    def mass(self) -> float:
        return self.density * self.volume


@dataclass(frozen=True)
class JointOverride:
    velocity: float | None = None
    effort: float | None = None
    stiffness: float | None = None  # N/m or N*m/rad: the drive's position-loop stiffness


@dataclass(frozen=True)
class GripperSpec:
    urdf: Path
    mount: Placement  # on the robot's flange, or in the world when the station has no robot
    tcp: Placement  # tool centre point relative to the flange (or to the mount in the world)
    always_active: bool = False
    fingers: tuple[str, ...] | None = None
    joints: dict[str, JointOverride] = field(default_factory=dict)
    contact_distance: float = 0.0  # m: a finger touches a target within this gap (0: only when they touch)
    friction: float = 0.8
    initial: dict[str, float] = field(default_factory=dict)  # initial setpoints by input name
    grip: str = "friction"  # "friction": held by contact friction alone; "attach": fixed while pressed
    grip_force: float | None = None  # N (N*m): doGripped's per-finger threshold; None: 10 % of the finger's effort
    attach_force: float | None = None  # N (N*m): attach mode's threshold; None: grip_force
    slip_distance: float = 0.005  # m: a gripped part moved this far relative to the base link has slipped
    force_rise_time: float | None = None  # s: a drive pressing on a part reaches its effort within this (None: 0.05)


@dataclass(frozen=True)
class RobotSpec:
    urdf: Path
    base: Placement
    home_deg: tuple[float, ...]
    flange_link: str = "flange"
    joints: tuple[str, ...] = ARM_JOINTS
    accel_deg: tuple[float, ...] | None = None  # each axis's acceleration limit, deg/s^2 (None: kinematics' default)
    payload_kg: float | None = None  # the rated payload: a load of this mass halves the accelerations
    # configuration monitoring at the program's start (RAPID's ConfJ\On, ConfL\On, the controller's default); off
    # for an arm model whose axis zeros differ from the robot the program's confdata were taught on
    conf_monitoring: bool = True


@dataclass(frozen=True)
class IOSignal:
    """A robot-controller signal and its wiring: `drives` a twin input or reads a twin output (`source`)."""

    name: str
    type: str
    drives: str | None = None
    source: str | None = None
    scale: float = 1.0  # twin value = scale * controller value + offset (and back for `source`)
    offset: float = 0.0
    unit: str = ""  # the controller's unit of an analogue signal (e.g. mm), for the register map
    settable: bool = False  # an output the outside may set too (RobotStudio's I/O simulator)


@dataclass(frozen=True)
class ControllerSpec:
    program: Path
    entry: str
    io: tuple[IOSignal, ...]
    modules: tuple[Path, ...] = ()  # more modules of the task (system modules, station data)
    answers: tuple[str, ...] = ()  # answers to the program's FlexPendant dialogs, in order


@dataclass(frozen=True)
class WatchdogSpec:
    """`[watchdog]`: the comm-loss watchdog (twin.runtime.watchdog): seconds of silence, and the safe state."""

    timeout: float | None = None  # s; None: off unless `twin serve --watchdog S`
    safe_state: str = "hold"  # hold, open or stop
    open: dict[str, float] = field(default_factory=dict)  # open setpoints by input name (default: gripper.initial)




@dataclass(frozen=True)
class Station:
    file: Path
    name: str
    step: float  # s, one simulation step
    substeps: int  # physics steps inside one simulation step
    gravity: tuple[float, float, float]
    gripper: GripperSpec
    robot: RobotSpec | None
    targets: tuple[Body, ...]
    fixtures: tuple[Body, ...]
    robot_targets: dict[str, Placement]
    controller: ControllerSpec | None
    watchdog: WatchdogSpec | None = None
    profile: dict | None = None  # the raw `[profile]` table: read and checked by twin.devices, not the core
    plugins: dict[str, str] = field(default_factory=dict)  # `[plugins]`: station code by reference (twin_app.plugins)

    @property
    def folder(self) -> Path:
        return self.file.parent


_TYPE_NAMES = {float: "number", str: "string", int: "integer", bool: "bool", list: "list", dict: "table"}

MIN_SUBSTEPS = 4  # physics substeps per step at the least, by default ...
MAX_SUBSTEP = 0.003  # s: ... and more where the step is longer than 4 of these: the stiffest drive a substep keeps
# stable for a finger's mass falls as 1 / substep^2, and a slow step's soft drives fall short of their effort (at a
# 20 ms step in 4 substeps a 25 N finger of 25 g reached its effort 35 mm past the part, and pressed 12 N where its
# range ended 15 mm past it)


def default_substeps(step: float) -> int:
    """The physics substeps of a step when the station does not say: at least MIN_SUBSTEPS, none longer than
    MAX_SUBSTEP (12 ms: 4; 20 ms: 7), at most the 100 a station may give."""
    return min(100, max(MIN_SUBSTEPS, math.ceil(step / MAX_SUBSTEP - 1e-9)))


def _all_numbers(values: list) -> bool:
    """Every value a finite number (TOML has nan and inf: they would poison the physics)."""
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in values)


class _Reader:
    """Reads one TOML table, checking types and reporting bad keys with their full path."""

    def __init__(self, file: Path, table: dict[str, Any], path: str):
        self.file, self.table, self.path = file, table, path
        self.used: set[str] = set()

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def error(self, name: str, message: str) -> StationError:
        return StationError(str(self.file), self.key(name), message)

    def missing(self, name: str, what: str = "") -> StationError:
        """A required key not given; a key given here that reads like it is named (`densty` for `density`)."""
        unknown = [k for k in self.table if k not in self.used]
        like = difflib.get_close_matches(name, unknown, n=1, cutoff=0.75)
        return self.error(name, f"is required{what}" + (f" (is {like[0]!r} a misspelling of it?)" if like else ""))

    def has(self, name: str) -> bool:
        return name in self.table

    def get(self, name: str, kind: type | tuple, default: Any = ..., *, check=None) -> Any:
        self.used.add(name)
        if name not in self.table:
            if default is ...:
                raise self.missing(name)
            return default
        value = self.table[name]
        kinds = kind if isinstance(kind, tuple) else (kind,)
        if float in kinds and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if not isinstance(value, kinds) or (isinstance(value, bool) and bool not in kinds):
            names = " or ".join(_TYPE_NAMES.get(k, k.__name__) for k in kinds)
            raise self.error(name, f"must be {'an' if names[0] in 'aeiou' else 'a'} {names}, not {value!r}")
        if isinstance(value, float) and not math.isfinite(value):
            raise self.error(name, f"must be a finite number, not {value!r}")
        if check is not None:
            problem = check(value)
            if problem:
                raise self.error(name, problem)
        return value

    def number(self, name: str, default: Any = ..., *, positive=False, nonnegative=False) -> float:
        def check(v):
            if positive and v <= 0:
                return f"must be greater than 0, not {v:g}"
            if nonnegative and v < 0:
                return f"must not be negative, not {v:g}"
            return None
        return self.get(name, float, default, check=check)

    def vector(self, name: str, n: int, default: Any = ...) -> tuple[float, ...]:
        value = self.get(name, list, default)
        if value is default:
            return value
        if len(value) != n or not _all_numbers(value):
            raise self.error(name, f"must be a list of {n} finite numbers, not {value!r}")
        return tuple(float(v) for v in value)

    def sub(self, name: str, required=True) -> "_Reader | None":
        self.used.add(name)
        if name not in self.table:
            if required:
                raise self.missing(name, " (a table)")
            return None
        value = self.table[name]
        if not isinstance(value, dict):
            raise self.error(name, "must be a table")
        return _Reader(self.file, value, self.key(name))

    def items(self, name: str) -> list["_Reader"]:
        self.used.add(name)
        value = self.table.get(name, [])
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise self.error(name, "must be an array of tables ([[" + self.key(name) + "]])")
        return [_Reader(self.file, v, f"{self.key(name)}[{i}]") for i, v in enumerate(value)]

    def path_to(self, name: str) -> Path:
        text = self.get(name, str)
        if text.startswith(PYBULLET_DATA):
            import pybullet_data

            path = (Path(pybullet_data.getDataPath()) / text[len(PYBULLET_DATA):]).resolve()
            if not path.is_file():
                raise self.error(name, f"pybullet ships no {text[len(PYBULLET_DATA):]!r} (looked at {path})")
            return path
        path = (self.file.parent / text).resolve()
        if not path.exists():
            raise self.error(name, f"file {text!r} not found (looked at {path})")
        if not path.is_file():
            raise self.error(name, f"{text!r} is a folder, not a file (looked at {path})")
        return path

    def done(self) -> None:
        unknown = [k for k in self.table if k not in self.used]
        if unknown:
            raise self.error(unknown[0], "is not a known key here")


def _placement(r: _Reader) -> Placement:
    p = Placement(r.vector("xyz", 3, (0.0, 0.0, 0.0)), r.vector("rpy_deg", 3, (0.0, 0.0, 0.0)))
    r.done()
    return p


def _placement_key(r: _Reader, name: str) -> Placement:
    sub = r.sub(name, required=False)
    return _placement(sub) if sub is not None else Placement()


def _body(r: _Reader, is_target: bool) -> Body:
    name = r.get("name", str)
    shape = r.get("shape", str, check=lambda v: None if v in SHAPES else f"must be one of {', '.join(SHAPES)}, not {v!r}")
    if is_target and shape == "plane":
        raise r.error("shape", "a target cannot be a plane")
    pose = Placement(r.vector("xyz", 3, (0.0, 0.0, 0.0)), r.vector("rpy_deg", 3, (0.0, 0.0, 0.0)))
    kw: dict[str, Any] = {}
    if shape == "box":
        kw["size"] = r.vector("size", 3)
        if min(kw["size"]) <= 0:
            raise r.error("size", "every side must be greater than 0")
    elif shape == "cylinder":
        kw["radius"] = r.number("radius", positive=True)
        kw["height"] = r.number("height", positive=True)
    elif shape == "ring":
        kw["outer_diameter"] = od = r.number("outer_diameter", positive=True)
        kw["inner_diameter"] = r.get(
            "inner_diameter", float,
            check=lambda v: None if 0 < v < od else f"must be between 0 and outer_diameter ({od:g}), not {v:g}")
        kw["height"] = r.number("height", positive=True)
        kw["segments"] = r.get("segments", int, 12, check=lambda v: None if 6 <= v <= MAX_RING_SEGMENTS else
                               f"must be between 6 and {MAX_RING_SEGMENTS} (a pybullet compound shape holds at most 16 boxes)")
    if is_target:
        kw["density"] = r.number("density", positive=True)
    else:
        kw["density"] = r.number("density", 0.0, nonnegative=True)
    kw["friction"] = r.number("friction", 0.5, nonnegative=True)
    color = r.vector("color", 4, None)
    if color is not None:
        kw["color"] = color
    r.done()
    return Body(name=name, shape=shape, pose=pose, **kw)


def load_station(path: str | Path) -> Station:
    """Read a station from its TOML file, or from a folder holding `station.toml`."""
    path = Path(path)
    file = path / "station.toml" if path.is_dir() else path
    if not file.exists():
        raise StationError(str(file), "", "no such station file")
    if file.is_dir():
        raise StationError(str(file), "", "is a folder, not a station file")
    try:
        data = tomllib.loads(file.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise StationError(str(file), "", f"not valid TOML: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise StationError(str(file), "", f"cannot be read: {exc}") from None
    top = _Reader(file.resolve(), data, "")
    file = top.file

    st = top.sub("station")
    name = st.get("name", str, file.parent.name)
    step = st.number("step", DEFAULT_STEP, positive=True)
    substeps = st.get("substeps", int, default_substeps(step),
                      check=lambda v: None if 1 <= v <= 100 else "must be between 1 and 100")
    gravity = st.vector("gravity", 3, (0.0, 0.0, -9.81))
    st.done()

    g = top.sub("gripper")
    joints: dict[str, JointOverride] = {}
    jt = g.sub("joints", required=False)
    if jt is not None:
        for jname in list(jt.table):
            jr = jt.sub(jname)
            joints[jname] = JointOverride(jr.number("velocity", None, positive=True), jr.number("effort", None, positive=True),
                                          jr.number("stiffness", None, positive=True))
            jr.done()
        jt.done()
    fingers = g.get("fingers", list, None)
    if fingers is not None and (not fingers or not all(isinstance(f, str) for f in fingers)):
        raise g.error("fingers", f"must be a list of one or more link names, not {fingers!r}")
    initial_r = g.sub("initial", required=False)
    initial: dict[str, float] = {}
    if initial_r is not None:
        for key in list(initial_r.table):
            initial[key] = initial_r.number(key)
        initial_r.done()
    gripper = GripperSpec(
        urdf=g.path_to("urdf"),
        mount=_placement_key(g, "mount"),
        tcp=_placement_key(g, "tcp"),
        always_active=g.get("always_active", bool, False),
        fingers=tuple(fingers) if fingers is not None else None,
        joints=joints,
        contact_distance=g.number("contact_distance", 0.0, nonnegative=True),
        friction=g.number("friction", 0.8, nonnegative=True),
        initial=initial,
        grip=g.get("grip", str, "friction", check=lambda v: None if v in GRIP_MODES else
                   f"must be one of {', '.join(repr(m) for m in GRIP_MODES)}, not {v!r}"),
        grip_force=g.number("grip_force", None, positive=True),
        attach_force=g.number("attach_force", None, positive=True),
        slip_distance=g.number("slip_distance", 0.005, positive=True),
        force_rise_time=g.number("force_rise_time", None, positive=True),
    )
    g.done()

    robot = None
    rr = top.sub("robot", required=False)
    robot_targets: dict[str, Placement] = {}
    if rr is not None:
        home = rr.get("home_deg", list, [0.0] * 6)
        if not _all_numbers(home):
            raise rr.error("home_deg", f"must be a list of finite numbers (degrees), not {home!r}")
        jn = rr.get("joints", list, list(RobotSpec.joints))
        if not jn or not all(isinstance(n, str) for n in jn):
            raise rr.error("joints", f"must be a list of joint names (strings), not {jn!r}")
        if len(set(jn)) != len(jn):
            raise rr.error("joints", f"names a joint twice: {jn!r}")
        accel = rr.get("accel_deg", list, None)
        if accel is not None and (not _all_numbers(accel) or any(v <= 0 for v in accel)):
            raise rr.error("accel_deg", f"must be a list of positive numbers (deg/s^2), not {accel!r}")
        robot = RobotSpec(rr.path_to("urdf"), _placement_key(rr, "base"), tuple(float(v) for v in home),
                          rr.get("flange_link", str, "flange"), tuple(jn),
                          None if accel is None else tuple(float(v) for v in accel),
                          rr.number("payload_kg", None, positive=True), rr.get("conf_monitoring", bool, True))
        if len(robot.home_deg) != len(robot.joints):
            raise rr.error("home_deg", f"needs one value per joint ({len(robot.joints)}), has {len(robot.home_deg)}")
        if robot.accel_deg is not None and len(robot.accel_deg) != len(robot.joints):
            raise rr.error("accel_deg", f"needs one value per joint ({len(robot.joints)}), has {len(robot.accel_deg)}")
        _check_robot_urdf(file, robot, given=rr.has("joints"))
        tr = rr.sub("targets", required=False)
        if tr is not None:
            for tname in list(tr.table):
                robot_targets[tname] = _placement(tr.sub(tname))
            tr.done()
        rr.done()

    targets = tuple(_body(r, True) for r in top.items("targets"))
    fixtures = tuple(_body(r, False) for r in top.items("fixtures"))
    seen: dict[str, str] = {}
    for kind, bodies in (("targets", targets), ("fixtures", fixtures)):
        for i, b in enumerate(bodies):
            if b.name in seen:
                raise StationError(str(file), f"{kind}[{i}].name", f"{b.name!r} is already the name of a {seen[b.name]}")
            seen[b.name] = kind[:-1]

    controller = None
    cr = top.sub("controller", required=False)
    if cr is not None:
        io = []
        for r in cr.items("io"):
            sig = IOSignal(
                name=r.get("name", str),
                type=r.get("type", str, check=lambda v: None if v in IO_TYPES else f"must be one of {', '.join(IO_TYPES)}"),
                drives=r.get("drives", str, None),
                source=r.get("source", str, None),
                scale=r.number("scale", 1.0),
                offset=r.number("offset", 0.0),
                unit=r.get("unit", str, ""),
                settable=r.get("settable", bool, False),
            )
            if sig.settable and (sig.type not in ("DO", "AO", "GO") or sig.drives):
                raise r.error("settable", f"only an output that drives nothing can be settable from outside; "
                                          f"{sig.name} is {'wired' if sig.drives else 'an input, always settable'}")
            if sig.drives and sig.type not in ("DO", "AO", "GO"):
                raise r.error("drives", f"only an output (DO, AO, GO) can drive a twin input; {sig.name} is {sig.type}")
            if sig.source and sig.type not in ("DI", "AI", "GI"):
                raise r.error("source", f"only an input (DI, AI, GI) can read a twin output; {sig.name} is {sig.type}")
            r.done()
            io.append(sig)
        modules = []
        for i, text in enumerate(cr.get("modules", list, [])):
            path = (file.parent / str(text)).resolve()
            if not path.is_file():
                raise cr.error(f"modules[{i}]", f"file {text!r} not found (looked at {path})")
            modules.append(path)
        answers = tuple(str(a) for a in cr.get("answers", list, []))
        controller = ControllerSpec(cr.path_to("program"), cr.get("entry", str, "main"), tuple(io), tuple(modules),
                                    answers)
        cr.done()
    watchdog = None
    wr = top.sub("watchdog", required=False)
    if wr is not None:
        opened: dict[str, float] = {}
        orr = wr.sub("open", required=False)
        if orr is not None:
            for key in list(orr.table):
                opened[key] = orr.number(key)
            orr.done()
        watchdog = WatchdogSpec(wr.number("timeout", None, positive=True),
                                wr.get("safe_state", str, "hold",
                                       check=lambda v: None if v in SAFE_STATES else f"must be one of {', '.join(SAFE_STATES)}"),
                                opened)
        wr.done()
    profile = top.get("profile", dict, None)  # a device profile's mapping (twin.devices checks it)
    plugins = _plugins(top)
    top.done()
    station = Station(file, name, step, substeps, gravity, gripper, robot, targets, fixtures, robot_targets, controller,
                      watchdog, profile, plugins)
    gripper_mechanism(station)  # the gripper's URDF and what the station says about it must agree
    return station


PLUGIN_KEYS = ("twin_demo", "plc_demo", "plc_logic")  # what each one is: twin_app.plugins


def _plugins(top: _Reader) -> dict[str, str]:
    """`[plugins]`: references to the station's own code, checked for form only (loading is twin_app.plugins's)."""
    pr = top.sub("plugins", required=False)
    if pr is None:
        return {}
    plugins = {}
    for key in PLUGIN_KEYS:
        ref = pr.get(key, str, None, check=lambda v: None if v.strip() and " " not in v.strip() else
                     'must be "package.module", "file.py", or either with ":name"')
        if ref is not None:
            plugins[key] = ref.strip()
    pr.done()
    return plugins


def _check_robot_urdf(file: Path, robot: RobotSpec, given: bool) -> None:
    """The robot's joints and flange must be in its URDF (else pybullet fails later, with no names)."""
    try:
        links, joints = read_links_and_joints(robot.urdf)
    except MechanismError as exc:
        raise StationError(str(file), "robot.urdf", str(exc)) from None
    movable = [n for n, t in joints.items() if t in MOVABLE]
    hint = "" if given else f" (the default is {', '.join(RobotSpec.joints)}; name the arm's joints with robot.joints)"
    for n in robot.joints:
        if n not in joints:
            raise StationError(str(file), "robot.joints", f"{robot.urdf.name} has no joint {n!r}{hint}; "
                                                          f"its movable joints: {', '.join(movable) or 'none'}")
        if joints[n] not in MOVABLE:
            raise StationError(str(file), "robot.joints", f"joint {n!r} of {robot.urdf.name} is {joints[n]}, not movable")
    extra = [n for n in movable if n not in robot.joints]
    if extra:
        raise StationError(str(file), "robot.joints", f"{robot.urdf.name} has movable joints that are not named here: "
                                                      f"{', '.join(extra)} (the arm's joints must be all of them)")
    if robot.flange_link not in links:
        raise StationError(str(file), "robot.flange_link", f"{robot.urdf.name} has no link {robot.flange_link!r} "
                                                           f"(its links: {', '.join(links)})")


def gripper_mechanism(station: Station) -> Mechanism:
    """The station's gripper mechanism, checked against the station (initial values, overrides, fingers).

    Every problem is a StationError naming the station file and the key, so it reads as a station mistake.
    """
    g, file = station.gripper, str(station.file)
    try:
        mech = load_mechanism(g.urdf, g.fingers)
    except FingerNameError as exc:  # the URDF is fine; the station's finger names are not
        raise StationError(file, "gripper.fingers", str(exc)) from None
    except MechanismError as exc:
        raise StationError(file, "gripper.urdf", str(exc)) from None
    if g.fingers is None and not mech.fingers:
        raise StationError(file, "gripper.urdf", f"{g.urdf.name} has no finger: no movable link (with the links fixed "
                                                 "to it) has collision geometry, so nothing could ever grip; name the "
                                                 "fingers with gripper.fingers")
    names = [i.name for i in mech.inputs]
    for key, table in (("initial", g.initial), ("joints", g.joints)):
        for name in table:
            if name not in names:
                raise StationError(file, f"gripper.{key}.{name}", f"{g.urdf.name} has no input {name!r} "
                                                                  f"(its inputs: {', '.join(names)})")
    for name, value in g.initial.items():
        inp = mech.input(name)
        if not inp.min <= value <= inp.max:
            raise StationError(file, f"gripper.initial.{name}", f"{value:g} {inp.unit} is outside the input's range "
                                                                f"{inp.min:g} to {inp.max:g} {inp.unit}")
    return mech
