"""Mechanism discovery: what a gripper URDF offers to control, and which of its links are fingers.

This is the open counterpart of the SmartComponent's *Tool* property. It reads the URDF itself (the
kinematic tree, joint limits and `<mimic>` tags, which pybullet ignores) and derives:

- one analogue *input* per independent movable joint (prismatic, revolute, continuous), named after
  the joint's child link, with the joint's range and unit (m or rad);
- the *mimic* joints, each following its master (never an input of its own);
- the *base link* (the tree's root), where a gripped part is attached;
- the *fingers*: a movable joint's child link together with the links rigidly fixed to it, counted as
  a finger when that rigid group has collision geometry (or as named by the station).

It needs no physics connection, so `twin info` works on any URDF in milliseconds.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from .errors import MechanismError

MOVABLE = ("prismatic", "revolute", "continuous")


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


@dataclass(frozen=True)
class Mechanism:
    urdf: Path
    robot_name: str
    base_link: str
    inputs: tuple[JointInput, ...]
    mimics: tuple[Mimic, ...]
    fingers: tuple[Finger, ...]

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


def _float(elem: ET.Element, attr: str, default: float, where: str) -> float:
    text = elem.get(attr)
    if text is None:
        return default
    try:
        return float(text)
    except ValueError:
        raise MechanismError(f"{where}: attribute {attr}={text!r} is not a number") from None


def _parse(urdf: Path) -> tuple[str, dict[str, bool], list[_Joint]]:
    try:
        root = ET.parse(urdf).getroot()
    except FileNotFoundError:
        raise MechanismError(f"{urdf}: no such file") from None
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
        limit = j.find("limit")
        lower = upper = velocity = effort = 0.0
        if limit is not None:
            lower = _float(limit, "lower", 0.0, where)
            upper = _float(limit, "upper", 0.0, where)
            velocity = _float(limit, "velocity", 0.0, where)
            effort = _float(limit, "effort", 0.0, where)
        if jtype == "continuous":
            lower, upper = -math.pi, math.pi
        elif jtype in MOVABLE and limit is None:
            raise MechanismError(f"{where}: a {jtype} joint needs a <limit> with lower and upper")
        if jtype in MOVABLE and lower > upper:
            raise MechanismError(f"{where}: limit lower {lower} is above upper {upper}")
        mimic = None
        m = j.find("mimic")
        if m is not None and jtype in MOVABLE:
            mimic = (m.get("joint", ""), _float(m, "multiplier", 1.0, where), _float(m, "offset", 0.0, where))
        joints.append(_Joint(name, jtype, parent.get("link", ""), child.get("link", ""),
                             lower, upper, velocity, effort, mimic))
    return root.get("name", urdf.stem), links, joints


def load_mechanism(urdf: str | Path, finger_names: tuple[str, ...] | None = None) -> Mechanism:
    """Read a gripper URDF into a Mechanism. `finger_names` overrides finger detection."""
    urdf = Path(urdf)
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

    inputs, mimics = [], []
    for j in joints:
        if j.type not in MOVABLE:
            continue
        if j.mimic is None:
            kind = "prismatic" if j.type == "prismatic" else "revolute"
            inputs.append(JointInput(j.child, j.name, kind, j.lower, j.upper,
                                     "m" if kind == "prismatic" else "rad", j.velocity, j.effort))
        else:
            # Compose chained mimics so every follower refers to an independent joint.
            master, mult, off = root_master(j), j.mimic[1], j.mimic[2]
            k = by_name[j.mimic[0]]
            while k.mimic is not None:
                mult, off = mult * k.mimic[1], mult * k.mimic[2] + off
                k = by_name[k.mimic[0]]
            mimics.append(Mimic(j.name, master.name, mult, off))

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

    candidates = [Finger(j.child, j.name, tuple(rigid_group(j.child))) for j in joints if j.type in MOVABLE]
    if finger_names is None:
        fingers = tuple(f for f in candidates if any(links[name] for name in f.links))
    else:
        known = {f.name: f for f in candidates}
        missing = [n for n in finger_names if n not in known]
        if missing:
            raise MechanismError(
                f"{urdf}: finger {missing[0]!r} is not the child link of a movable joint "
                f"(movable links: {', '.join(known) or 'none'})")
        fingers = tuple(known[n] for n in finger_names)
    return Mechanism(urdf, robot_name, roots[0], tuple(inputs), tuple(mimics), fingers)
