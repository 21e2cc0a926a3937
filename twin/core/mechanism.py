"""Mechanism discovery: what a gripper URDF offers to control, and which of its links are fingers.

This is the open counterpart of the SmartComponent's *Tool* property. It reads the URDF itself (the
kinematic tree, joint limits and `<mimic>` tags, which pybullet ignores) and derives:

- one analogue *input* per independent movable joint (prismatic, revolute, continuous), named after
  the joint's child link, with the joint's range and unit (m or rad);
- the *mimic* joints, each following its master (never an input of its own);
- the *base link* (the tree's root), where a gripped part is attached;
- the *fingers*: a movable joint's child link together with the links rigidly fixed to it, counted as
  a finger when that rigid group has collision geometry (or as named by the station: any link of the
  group names its finger, which keeps the movable link's name).

Planar and floating joints (and pybullet's spherical ones) are no inputs: they are treated as rigid,
and the world loads them as fixed joints (`Mechanism.rigid_joints` lists them). A continuous
joint's input gets the range -pi to pi. A mimic follower must stay within its own URDF limits, so the
master's input range is narrowed to what every follower allows (`JointInput.note` says so).

It needs no physics connection, so `twin info` works on any URDF in milliseconds.
"""
from __future__ import annotations

import functools
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from .errors import MechanismError


class FingerNameError(MechanismError):
    """The names given for the fingers do not fit the URDF (they come from the station, not the URDF)."""

MOVABLE = ("prismatic", "revolute", "continuous")
NOT_DRIVEN = ("planar", "floating", "spherical")  # spherical: pybullet's extension; the twin makes these fixed
RIGID = ("fixed",) + NOT_DRIVEN
#: The twin's own signal names: a link named so would give a second signal of the same name.
RESERVED_NAMES = ("Active", "doGripped", "GrippedPart")  # the twin's own signals (twin.Twin._signal_table)


@dataclass(frozen=True)
class JointInput:
    """An analogue input generated for one independent movable joint."""

    name: str  # the joint's child link
    joint: str
    type: str  # "prismatic" or "revolute" (continuous joints are revolute with a +-pi range)
    min: float
    max: float
    unit: str  # "m" or "rad"
    velocity: float  # URDF velocity limit (m/s or rad/s), 0 if the URDF gives none
    effort: float  # URDF effort limit (N or N*m), 0 if the URDF gives none
    note: str = ""  # where the range does not come straight from the URDF's limits, why


@dataclass(frozen=True)
class Mimic:
    """A joint that follows `master`: q = multiplier * q_master + offset."""

    joint: str
    master: str
    multiplier: float
    offset: float


@dataclass(frozen=True)
class Finger:
    """A movable link and the links rigidly fixed to it; `joint` is the joint that drives it."""

    name: str
    joint: str
    links: tuple[str, ...]

    @property
    def label(self) -> str:
        """Its name, with the links fixed to it: `finger_a (+finger_a_tip)`."""
        return self.name + (f" (+{', '.join(self.links[1:])})" if len(self.links) > 1 else "")


@dataclass(frozen=True)
class Mechanism:
    urdf: Path
    robot_name: str
    base_link: str
    inputs: tuple[JointInput, ...]
    mimics: tuple[Mimic, ...]
    fingers: tuple[Finger, ...]
    rigid_joints: tuple[tuple[str, str], ...] = ()  # (joint, type) of planar, floating, spherical joints

    def input(self, name: str) -> JointInput:
        for inp in self.inputs:
            if inp.name == name:
                return inp
        raise KeyError(name)

    def as_dict(self) -> dict:
        """The `twin info --json` shape."""
        return {
            "base_link": self.base_link,
            "inputs": [
                {"name": i.name, "joint": i.joint, "type": i.type, "min": i.min, "max": i.max, "unit": i.unit}
                for i in self.inputs
            ],
            "fingers": [f.name for f in self.fingers],
        }


@dataclass(frozen=True)
class _Joint:
    name: str
    type: str
    parent: str
    child: str
    lower: float
    upper: float
    velocity: float
    effort: float
    mimic: tuple[str, float, float] | None
    has_range: bool  # the URDF gives lower or upper (a mimic follower's range is checked only then)


def _float(elem: ET.Element, attr: str, default: float, where: str) -> float:
    text = elem.get(attr)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        raise MechanismError(f"{where}: attribute {attr}={text!r} is not a number") from None
    if not math.isfinite(value):
        raise MechanismError(f"{where}: attribute {attr}={text!r} is not a finite number")
    return value


def _parse(urdf: Path) -> tuple[str, dict[str, bool], list[_Joint]]:
    try:
        root = ET.parse(urdf).getroot()
    except FileNotFoundError:
        raise MechanismError(f"{urdf}: no such file") from None
    except IsADirectoryError:
        raise MechanismError(f"{urdf}: is a folder, not a URDF file") from None
    except OSError as exc:
        raise MechanismError(f"{urdf}: cannot be read: {exc.strerror or exc}") from None
    except ET.ParseError as exc:
        raise MechanismError(f"{urdf}: not valid XML: {exc}") from None
    if root.tag != "robot":
        raise MechanismError(f"{urdf}: the root element is <{root.tag}>, a URDF needs <robot>")
    links = {}
    for link in root.findall("link"):
        name = link.get("name")
        if not name:
            raise MechanismError(f"{urdf}: a <link> has no name")
        links[name] = link.find("collision") is not None
    joints = []
    for j in root.findall("joint"):  # direct children only: <transmission> also holds <joint> tags
        name, jtype = j.get("name"), j.get("type")
        where = f"{urdf}: joint {name!r}"
        parent, child = j.find("parent"), j.find("child")
        if not name or not jtype or parent is None or child is None:
            raise MechanismError(f"{where}: needs name, type, <parent> and <child>")
        if jtype not in MOVABLE + RIGID:
            raise MechanismError(f"{where}: type {jtype!r} is not a URDF joint type ({', '.join(MOVABLE + RIGID)})")
        limit = j.find("limit")
        lower = upper = velocity = effort = 0.0
        if limit is not None:
            lower = _float(limit, "lower", 0.0, where)
            upper = _float(limit, "upper", 0.0, where)
            velocity = _float(limit, "velocity", 0.0, where)
            effort = _float(limit, "effort", 0.0, where)
        has_range = limit is not None and (limit.get("lower") is not None or limit.get("upper") is not None)
        if jtype == "continuous":
            lower, upper, has_range = -math.pi, math.pi, False
        elif jtype in MOVABLE and limit is None:
            raise MechanismError(f"{where}: a {jtype} joint needs a <limit> with lower and upper")
        if jtype in MOVABLE and lower > upper:
            raise MechanismError(f"{where}: limit lower {lower} is above upper {upper}")
        mimic = None
        m = j.find("mimic")
        if m is not None and jtype in MOVABLE:
            mimic = (m.get("joint", ""), _float(m, "multiplier", 1.0, where), _float(m, "offset", 0.0, where))
        joints.append(_Joint(name, jtype, parent.get("link", ""), child.get("link", ""),
                             lower, upper, velocity, effort, mimic, has_range))
    return root.get("name", urdf.stem), links, joints


def load_mechanism(urdf: str | Path, finger_names: tuple[str, ...] | None = None) -> Mechanism:
    """Read a gripper URDF into a Mechanism. `finger_names` overrides finger detection.

    A Mechanism is immutable and a pure function of the file and the names, so a file read before and
    unchanged since (same modification time and size) is not parsed again: loading a station, checking it
    and building its twin all ask for the same one."""
    urdf = Path(urdf)
    names = None if finger_names is None else tuple(finger_names)
    try:
        st = urdf.stat()
    except OSError:
        return _load_mechanism(urdf, names)  # the parse reports what is wrong with the path
    return _load_unchanged(urdf, urdf.resolve(), st.st_mtime_ns, st.st_size, names)


@functools.lru_cache(maxsize=32)
def _load_unchanged(urdf: Path, resolved: Path, mtime_ns: int, size: int,
                    finger_names: tuple[str, ...] | None) -> Mechanism:
    return _load_mechanism(urdf, finger_names)  # messages name the file as the caller gave it


def _load_mechanism(urdf: Path, finger_names: tuple[str, ...] | None) -> Mechanism:
    robot_name, links, joints = _parse(urdf)
    by_name = {j.name: j for j in joints}
    children = {j.child for j in joints}
    roots = [name for name in links if name not in children]
    if len(roots) != 1:
        raise MechanismError(f"{urdf}: expected one root link, found {len(roots)}: {', '.join(roots) or 'none'}")
    for j in joints:
        for end in (j.parent, j.child):
            if end not in links:
                raise MechanismError(f"{urdf}: joint {j.name!r} names link {end!r}, which is not defined")
    if not any(j.type in MOVABLE for j in joints):
        raise MechanismError(f"{urdf}: has no movable joint (prismatic or revolute): nothing to drive")

    def root_master(j: _Joint) -> _Joint:
        seen = {j.name}
        while j.mimic is not None:
            master = by_name.get(j.mimic[0])
            if master is None or master.type not in MOVABLE:
                raise MechanismError(f"{urdf}: joint {j.name!r} mimics {j.mimic[0]!r}, which is not a movable joint")
            if master.name in seen:
                raise MechanismError(f"{urdf}: joint {j.name!r} is part of a mimic cycle")
            seen.add(master.name)
            j = master
        return j

    ranges: dict[str, tuple[float, float]] = {}
    notes: dict[str, list[str]] = {}
    mimics = []
    for j in joints:
        if j.type not in MOVABLE:
            continue
        if j.mimic is None:
            ranges[j.name] = (j.lower, j.upper)
            if j.type == "continuous":
                notes.setdefault(j.name, []).append("continuous joint: range -pi to pi")
        else:
            # Compose chained mimics so every follower refers to an independent joint.
            master, mult, off = root_master(j), j.mimic[1], j.mimic[2]
            k = by_name[j.mimic[0]]
            while k.mimic is not None:
                mult, off = mult * k.mimic[1], mult * k.mimic[2] + off
                k = by_name[k.mimic[0]]
            mimics.append(Mimic(j.name, master.name, mult, off))
    for m in mimics:
        _narrow_for_follower(urdf, by_name[m.joint], m, ranges, notes)

    inputs = []
    for j in joints:
        if j.type in MOVABLE and j.mimic is None:
            kind = "prismatic" if j.type == "prismatic" else "revolute"
            lo, hi = ranges[j.name]
            inputs.append(JointInput(j.child, j.name, kind, lo, hi, "m" if kind == "prismatic" else "rad",
                                     j.velocity, j.effort, "; ".join(notes.get(j.name, []))))
    for inp in inputs:
        if inp.name in RESERVED_NAMES:
            raise MechanismError(f"{urdf}: link {inp.name!r} (moved by joint {inp.joint!r}) would be an input named "
                                 f"{inp.name!r}, which is one of the twin's own signals ({', '.join(RESERVED_NAMES)}); "
                                 "rename the link")

    rigid_children: dict[str, list[str]] = {}
    for j in joints:
        if j.type not in MOVABLE:
            rigid_children.setdefault(j.parent, []).append(j.child)

    def rigid_group(link: str) -> list[str]:
        group, todo = [], [link]
        while todo:
            name = todo.pop(0)
            group.append(name)
            todo.extend(rigid_children.get(name, []))
        return group

    candidates = tuple(Finger(j.child, j.name, tuple(rigid_group(j.child))) for j in joints if j.type in MOVABLE)
    if finger_names is None:
        fingers = tuple(f for f in candidates if any(links[name] for name in f.links))
    else:
        fingers = _named_fingers(urdf, finger_names, candidates)
    rigid = tuple((j.name, j.type) for j in joints if j.type in NOT_DRIVEN)
    return Mechanism(urdf, robot_name, roots[0], tuple(inputs), tuple(mimics), fingers, rigid)


def _narrow_for_follower(urdf: Path, follower: _Joint, m: Mimic, ranges: dict[str, tuple[float, float]],
                         notes: dict[str, list[str]]) -> None:
    """Narrow the master's range so that the follower stays within its own URDF limits."""
    if not follower.has_range:
        return
    lo, hi = ranges[m.master]
    if m.multiplier == 0:
        if not follower.lower <= m.offset <= follower.upper:
            raise MechanismError(f"{urdf}: mimic joint {m.joint!r} sits at {m.offset:g}, outside its limits "
                                 f"{follower.lower:g} to {follower.upper:g}")
        return
    a, b = sorted(((follower.lower - m.offset) / m.multiplier, (follower.upper - m.offset) / m.multiplier))
    eps = 1e-9 * max(1.0, abs(lo), abs(hi))  # rounding of the division is no reason to narrow
    new_lo, new_hi = (a if a > lo + eps else lo), (b if b < hi - eps else hi)
    if new_lo > new_hi:
        raise MechanismError(f"{urdf}: mimic joint {m.joint!r} (= {m.multiplier:g} x {m.master} {m.offset:+g}) "
                             f"cannot stay within its limits {follower.lower:g} to {follower.upper:g} for any value "
                             f"of {m.master!r} in {lo:g} to {hi:g}")
    if (new_lo, new_hi) != (lo, hi):
        ranges[m.master] = (new_lo, new_hi)
        notes.setdefault(m.master, []).append(
            f"range narrowed from the URDF's {lo:g} to {hi:g} so that mimic joint {m.joint} stays within "
            f"its limits {follower.lower:g} to {follower.upper:g}")


def _named_fingers(urdf: Path, names: tuple[str, ...], candidates: tuple[Finger, ...]) -> tuple[Finger, ...]:
    """The fingers a station names: any link of a finger's rigid group stands for that finger."""
    owner = {}
    for f in candidates:
        for link in f.links:
            owner.setdefault(link, f)
    fingers: list[Finger] = []
    for name in names:
        finger = owner.get(name)
        if finger is None:
            known = ", ".join(f.label for f in candidates)
            raise FingerNameError(f"{urdf}: finger {name!r} is not a link of a finger, i.e. a movable joint's child "
                                 f"link or a link fixed to one (fingers: {known or 'none'})")
        if finger in fingers:
            raise FingerNameError(f"{urdf}: finger {name!r} is finger {finger.name!r}, which is already named")
        fingers.append(finger)
    return tuple(fingers)


def read_links_and_joints(urdf: str | Path) -> tuple[tuple[str, ...], dict[str, str]]:
    """The link names and the joint types (by joint name) of any URDF, e.g. to check a station's robot."""
    _, links, joints = _parse(Path(urdf))
    return tuple(links), {j.name: j.type for j in joints}
