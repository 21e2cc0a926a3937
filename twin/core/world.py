"""The physics world: one private pybullet connection holding a station's bodies.

Each World owns its own DIRECT connection (pybullet_utils' BulletClient), so several twins can live in
one process. Every engine parameter is set explicitly after connecting, because pybullet's
`resetSimulation` silently resets gravity and solver settings (measured-facts.md). The world is rebuilt
from scratch rather than restored from a snapshot: `restoreState` is not exact once contacts exist.

The gripper URDF is merged into the robot URDF under the flange link, so arm and gripper are one
multibody: the gripper moves with the flange with no soft constraint in between. Robot link and joint
names get the prefix `robot/` so they cannot clash with the gripper's. Either way the world loads a
rewritten copy of the URDFs: mesh paths made absolute (`package://` resolved as ROS tools do) and
planar, floating and spherical gripper joints made fixed, as the mechanism treats them.
"""
from __future__ import annotations

import functools
import logging
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

from .bullet import BulletClient, pybullet

from .errors import StationError
from .mechanism import NOT_DRIVEN
from .station import Body, Placement, Station
from .native_output import quiet_native_output

ROBOT_PREFIX = "robot/"
COLLISION_MARGIN = 0.0001  # m: pybullet's default 1 mm margin rounds box corners (contact 0.4-0.7 mm late)
CYLINDER_MARGIN = 0.001  # m: pybullet's own, kept for cylinders (rims round by 0.41 mm; sides are exact)
ROLLING_RESISTANCE = 3e-4  # m: the rolling friction of a loose cylinder lying on its side that no finger touches
# (pybullet's, a lever: the torque that resists rolling is it times the normal force times the other body's friction,
# 0.03-0.3 mm on a support of friction 0.1-1, as plastic or wood rolls on steel). pybullet rolls a cylinder lying
# still on a flat support by itself (a 100 g, 40 mm one off a table within 2 s, from rest): a lever of 0.001-0.03 mm,
# depending on its size, holds it. A cylinder standing on its end cannot roll and has none; between fingers neither
# (there it would act at every finger's contact, 0.3 mm times their force, and change how a squeezed part settles)
LYING = math.cos(math.radians(45.0))  # a cylinder whose axis is nearer the horizontal than this lies on its side
OVERLAP_TOLERANCE = 0.0002  # m: a target resting on a fixture touches it; deeper than this it overlaps
SOLVER_ITERATIONS = 50  # pybullet solver iterations per substep, at most (20 holds the five test grippers and the ring
# rig within 2.6 % of statics and saves 25-40 % of the physics, but the PLC fault scenarios differ: kept at 50; more for
# heavy fingers and knuckles, `World.iterations_for`) ...
ITERATIONS_PER_RATIO = 3.5  # sweeps per unit of a finger's mass over the lightest part's: a part squeezed between
# fingers r times its mass converges by about (r - 1) / (r + 1) a sweep, so a thousandth takes ln(1000) r / 2
MAX_SOLVER_ITERATIONS = 500  # (a 10 g pin between 1 kg jaws: 350)
RIGID_LINKAGE_ITERATIONS = 300  # ... and at least this many where gears tie joints in series (a finger's knuckles)
SPRING_SWEEP_MARGIN = 2.0  # ... and at least this many times K h^2 / m_own for a finger's drive: a sweep adds at most its
# own links' mass times the speed its motor asks (e / h) to the motor's impulse, so its spring's force K e is built in
# K h^2 / m_own sweeps, large where light fingers squeeze a heavy part (K derived for both): 20 g jaws at 300 N on a 4 kg
# block (101) pressed 145 N each with 50, and pushed an off-centre block 7 mm on through the grip with 100
RESIDUAL_SHARE = 2e-3  # ... fewer once converged while fingers press on a part: the solver stops when no contact's or
# drive's impulse changes by more than this share of the lightest loose body's weight over a substep in one sweep
PYBULLET_RESIDUAL = 1e-7  # pybullet's own threshold (its measure: an impulse's change squared), kept at every other time


def _mm(xyz) -> str:
    return "(" + ", ".join(f"{v * 1000:.0f}" for v in xyz) + ")"


def quat(p: Placement) -> tuple[float, float, float, float]:
    return tuple(pybullet.getQuaternionFromEuler(p.rpy))  # type: ignore[return-value]


MESH_TAGS = ("mesh", "texture")  # the URDF elements whose `filename` is a file to load


def resolve_package_path(fname: str, folder: Path) -> tuple[Path | None, list[Path]]:
    """Where a mesh path of a URDF in `folder` points, as ROS tools resolve it; and the places tried.

    `package://PKG/rest` is looked up in the nearest folder upwards that is named PKG or holds a folder
    PKG (a ROS package or a workspace), then in the URDF's folder and its parent (URDFs copied out of
    their package, such as pybullet_data's). A relative path is relative to the URDF's folder.
    """
    if fname.startswith("file://"):
        fname = fname[len("file://"):]
    if not fname.startswith("package://"):
        path = Path(fname) if Path(fname).is_absolute() else (folder / fname)
        return (path.resolve() if path.is_file() else None), [path]
    pkg, _, rest = fname[len("package://"):].partition("/")
    tried: list[Path] = []
    if rest:
        for d in (folder, *folder.parents):
            for base in ((d,) if d.name == pkg else ()) + (d / pkg,):
                tried.append(base / rest)
                if tried[-1].is_file():
                    return tried[-1].resolve(), tried
    rest = rest or pkg
    for base in (folder, folder.parent):
        tried.append(base / rest)
        if tried[-1].is_file():
            return tried[-1].resolve(), tried
    return None, tried


def _absolutize_meshes(root: ET.Element, urdf: Path, file: Path, key: str) -> None:
    """Make every mesh path absolute, so the URDF can be written anywhere; a missing mesh is a StationError."""
    folder = urdf.parent
    for elem in root.iter():
        fname = elem.get("filename")
        if fname is None or elem.tag not in MESH_TAGS:
            continue
        path, tried = resolve_package_path(fname, folder)
        if path is None:
            looked = ", ".join(os.path.normpath(p) for p in tried[:4]) + (", ..." if len(tried) > 4 else "")
            raise StationError(str(file), key, f"{urdf}: mesh {fname!r} not found (looked at {looked})")
        elem.set("filename", str(path))


def _rigid_for_pybullet(root: ET.Element) -> None:
    """Planar, floating and spherical joints are no inputs: make them fixed, as the mechanism treats them."""
    for joint in root.findall("joint"):
        if joint.get("type") in NOT_DRIVEN:
            joint.set("type", "fixed")


def _unit_axes(root: ET.Element, urdf: Path, file: Path) -> list[tuple[str, str, str]]:
    """Every moving joint's <axis> made a unit vector, as URDF means it: pybullet takes it as written, so a prismatic
    joint along "1 1 0" travels 1.41 m for a metre of its setpoint and presses with 0.71 times its effort. Returns
    (joint, "axis", warning) for each axis it scaled; StationError for an axis of no length."""
    fixes = []
    for joint in root.findall("joint"):
        axis = joint.find("axis")
        if joint.get("type") in ("fixed", None) or axis is None:
            continue
        try:
            xyz = [float(v) for v in (axis.get("xyz") or "1 0 0").split()]
        except ValueError:
            continue  # (pybullet's own loader says what is wrong with it)
        length = math.sqrt(sum(v * v for v in xyz)) if len(xyz) == 3 else 1.0
        if length == 0.0:
            raise StationError(str(file), "gripper.urdf", f"{urdf}: joint {joint.get('name')}: axis \"{axis.get('xyz')}\" "
                               "has no direction (a joint's axis must be a unit vector)")
        if abs(length - 1.0) > 1e-3:  # (an axis written to a few digits, 0.866 0.5 0, is left as it is: 0.1 % at most)
            unit = [v / length for v in xyz]
            axis.set("xyz", " ".join(repr(v) for v in unit))
            name = joint.get("name", "")
            note = (f"{urdf}: joint {name}: axis \"{' '.join(f'{v:g}' for v in xyz)}\" is {length:.4g} long; using the "
                    f"unit vector {' '.join(f'{v:.4g}' for v in unit)} (a URDF axis is a direction: as written it "
                    "would scale the joint's travel and force)")
            fixes.append((name, "axis", note))
            warn_once(str(urdf), "joint " + name, note)
    return fixes


def _read(urdf: Path, file: Path, key: str) -> ET.Element:
    try:
        return ET.parse(urdf).getroot()
    except (OSError, ET.ParseError) as exc:
        raise StationError(str(file), key, f"{urdf}: cannot be read as a URDF: {exc}") from None


def _surface_meshes(root: ET.Element, out_dir: Path) -> None:
    """Every collision mesh (paths already absolute) and cylinder as its own surface (twin/core/meshes.py): pybullet's
    hull of either stands 1 mm proud (and fills a mesh's hollows). One that cannot be rewritten keeps pybullet's
    hull."""
    from .meshes import surface_cylinder, surface_mesh

    done: dict[tuple, str] = {}
    for collision in root.iter("collision"):
        geometry = collision.find("geometry")
        cylinder = geometry.find("cylinder") if geometry is not None else None
        if cylinder is not None:
            try:
                radius, length = float(cylinder.get("radius", "")), float(cylinder.get("length", ""))
            except ValueError:
                continue  # (pybullet's own loader says what is wrong with it)
            key = ("cylinder", radius, length)
            if key not in done:
                out = surface_cylinder(radius, length, out_dir, f"cylinder{len(done)}")
                done[key] = str(out) if out is not None else ""
            if done[key]:
                geometry.remove(cylinder)
                ET.SubElement(geometry, "mesh", {"filename": done[key]})
            continue
        for mesh in collision.iter("mesh"):
            scale = tuple(float(v) for v in (mesh.get("scale") or "1 1 1").split())
            key = (mesh.get("filename"), scale)
            if key not in done:
                out = surface_mesh(Path(key[0]), scale if len(scale) == 3 else (scale[0],) * 3, out_dir,
                                   f"mesh{len(done)}")
                done[key] = str(out) if out is not None else ""
            if done[key]:
                mesh.set("filename", done[key])
                mesh.attrib.pop("scale", None)


def _gripper_for_pybullet(gripper_urdf: Path, file: Path, out_dir: Path | None = None) -> ET.Element:
    """The gripper's URDF as the world loads it: absolute mesh paths, joints that are not inputs rigid, collision
    meshes as their surface (written into `out_dir`)."""
    gripper = _read(gripper_urdf, file, "gripper.urdf")
    _absolutize_meshes(gripper, gripper_urdf, file, "gripper.urdf")
    _rigid_for_pybullet(gripper)
    if out_dir is not None:
        _surface_meshes(gripper, out_dir)
    return gripper


def write_gripper(gripper: ET.Element, out_dir: Path) -> Path:
    """The gripper's URDF (`_gripper_for_pybullet`'s) as the world loads it when there is no robot."""
    out = out_dir / "gripper.urdf"
    ET.ElementTree(gripper).write(out)
    return out


def merge_gripper_into_robot(robot_urdf: Path, flange_link: str, gripper: ET.Element, gripper_root: str,
                             mount: Placement, out_dir: Path, file: Path) -> Path:
    """Write one URDF where the gripper's root link (`gripper`: `_gripper_for_pybullet`'s URDF) hangs off the
    robot's flange by a fixed joint."""
    robot = _read(robot_urdf, file, "robot.urdf")
    _absolutize_meshes(robot, robot_urdf, file, "robot.urdf")
    for elem in robot:
        if elem.tag in ("link", "joint"):
            elem.set("name", ROBOT_PREFIX + elem.get("name", ""))
        if elem.tag == "joint":
            for end in ("parent", "child"):
                e = elem.find(end)
                e.set("link", ROBOT_PREFIX + e.get("link", ""))
            mimic = elem.find("mimic")
            if mimic is not None:
                mimic.set("joint", ROBOT_PREFIX + mimic.get("joint", ""))
    merged = ET.Element("robot", {"name": f"{robot.get('name', 'robot')}+{gripper.get('name', 'gripper')}"})
    for elem in list(robot) + list(gripper):
        if elem.tag in ("link", "joint", "material"):
            merged.append(elem)
    mount_joint = ET.SubElement(merged, "joint", {"name": "gripper_mount", "type": "fixed"})
    ET.SubElement(mount_joint, "parent", {"link": ROBOT_PREFIX + flange_link})
    ET.SubElement(mount_joint, "child", {"link": gripper_root})
    ET.SubElement(mount_joint, "origin", {"xyz": " ".join(f"{v!r}" for v in mount.xyz),
                                          "rpy": " ".join(f"{v!r}" for v in mount.rpy)})
    out = out_dir / "robot_with_gripper.urdf"
    ET.ElementTree(merged).write(out)
    return out


def create_body(c, body: Body) -> int:
    """Build a target or fixture as a pybullet body in client `c`."""
    color = list(body.color)
    if body.shape == "plane":
        col = c.createCollisionShape(pybullet.GEOM_PLANE)
        vis = c.createVisualShape(pybullet.GEOM_PLANE, rgbaColor=color)
    elif body.shape == "box":
        half = [s / 2 for s in body.size]
        col = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
        vis = c.createVisualShape(pybullet.GEOM_BOX, halfExtents=half, rgbaColor=color)
    elif body.shape == "cylinder":
        col = c.createCollisionShape(pybullet.GEOM_CYLINDER, radius=body.radius, height=body.height)
        vis = c.createVisualShape(pybullet.GEOM_CYLINDER, radius=body.radius, length=body.height, rgbaColor=color)
    else:  # ring: a compound of boxes; the outside is a regular polygon whose apothem is the outer radius
        n = body.segments
        r_out, r_in = body.outer_diameter / 2, body.inner_diameter / 2
        width = 2 * r_out * math.tan(math.pi / n)
        half = [(r_out - r_in) / 2, width / 2, body.height / 2]
        angles = [2 * math.pi * k / n for k in range(n)]
        positions = [[(r_in + r_out) / 2 * math.cos(a), (r_in + r_out) / 2 * math.sin(a), 0.0] for a in angles]
        orns = [list(pybullet.getQuaternionFromEuler([0, 0, a])) for a in angles]
        col = c.createCollisionShapeArray([pybullet.GEOM_BOX] * n, halfExtents=[half] * n,
                                          collisionFramePositions=positions, collisionFrameOrientations=orns)
        vis = c.createVisualShapeArray([pybullet.GEOM_BOX] * n, halfExtents=[half] * n,
                                       visualFramePositions=positions, visualFrameOrientations=orns)
    uid = c.createMultiBody(baseMass=body.mass, baseCollisionShapeIndex=col, baseVisualShapeIndex=vis,
                            basePosition=body.pose.xyz, baseOrientation=quat(body.pose))
    c.changeDynamics(uid, -1, lateralFriction=body.friction, restitution=0.0)
    if body.mass > 0:  # friction anchors: a part held or resting by friction stays where friction holds it (without
        c.changeDynamics(uid, -1, frictionAnchor=1)  # them the solver's friction drifts: a squeezed box walks)
    if body.shape in ("box", "ring"):  # sharp corners; a cylinder keeps pybullet's margin (a thin one makes a
        c.changeDynamics(uid, -1, collisionMargin=COLLISION_MARGIN)  # squeezed one creep; its rims err 0.4 mm)
    return uid


STEEL_DENSITY = 7850.0  # kg/m^3: what a gripper link with no <inertial> weighs, over its collision shapes' volume
INERTIA_SLACK = 10.0  # a link's inertia more than this many times that of the solid box of its collision shapes (or
# less than its inverse squared) does not fit its mass and size: an exported placeholder (1 kg m^2 on a 50 g finger)
_warned: set[tuple[str, str]] = set()  # (URDF, link or joint): each warned of once per process


def warn_once(source: str, what: str, note: str) -> None:
    """Log `note` as the twin's warning, once per process for `what` of URDF `source`."""
    if (source, what) not in _warned:
        _warned.add((source, what))
        logging.getLogger("twin").warning("warning: %s", note)


def fix_inertias(c, body: int, link_name: dict[int, str], source: str, no_inertial: frozenset = frozenset()
                 ) -> list[tuple[str, str, str]]:
    """Replace the inertia of every gripper link whose URDF inertia does not fit its mass and collision shapes by
    that of the solid box around those shapes (about its centre of mass, in its inertial frame; a mesh by the box
    around its link); one warning line per link, naming it. A link with no collision shape keeps what the URDF
    says. `no_inertial`: the gripper links whose URDF has no <inertial> at all: pybullet makes them 1 kg (a 30 g
    jaw's drive then moves 30 times its mass, and rocks a light part it squeezes for a second); they weigh their
    collision shapes' volume in steel instead (STEEL_DENSITY, `link_volume`), with that box's inertia, and their
    warning says so. Returns (link, "mass" or "inertia", warning) for each."""
    notes = []
    for link, name in sorted(link_name.items()):
        if name.startswith(ROBOT_PREFIX):
            continue
        info = c.getDynamicsInfo(body, link)
        mass, given = info[0], info[2]
        shapes = c.getCollisionShapeData(body, link)
        if mass <= 0.0 or not shapes:
            continue
        corners = []
        for shape in shapes:
            half = _half_extents(shape[2], shape[3])
            if half is None:  # a mesh: the corners of the link's bounding box, in its inertial frame
                lo, hi = c.getAABB(body, link)
                com, orn = c.getLinkState(body, link, computeForwardKinematics=True)[:2]
                inv_pos, inv_orn = pybullet.invertTransform(com, orn)
                corners += [pybullet.multiplyTransforms(inv_pos, inv_orn, (x, y, z), (0, 0, 0, 1))[0]
                            for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
                continue
            pos, orn = shape[5], shape[6]
            for sx in (-1, 1):
                for sy in (-1, 1):
                    for sz in (-1, 1):
                        p, _ = pybullet.multiplyTransforms(pos, orn, (sx * half[0], sy * half[1], sz * half[2]),
                                                           (0, 0, 0, 1))
                        corners.append(p)
        if corners:
            lo = [min(p[i] for p in corners) for i in range(3)]
            hi = [max(p[i] for p in corners) for i in range(3)]
            size = [hi[i] - lo[i] for i in range(3)]
            mid = [(hi[i] + lo[i]) / 2 for i in range(3)]
            bare = name in no_inertial
            if bare:
                volume = link_volume(c, body, link)
                mass = STEEL_DENSITY * volume
            box = [mass / 12 * (size[(i + 1) % 3] ** 2 + size[(i + 2) % 3] ** 2)
                   + mass * (mid[(i + 1) % 3] ** 2 + mid[(i + 2) % 3] ** 2) for i in range(3)]
            fits = all(b > 0 and b / INERTIA_SLACK ** 2 <= g <= b * INERTIA_SLACK for g, b in zip(given, box))
            if fits and not bare:
                continue
            if bare:
                c.changeDynamics(body, link, mass=mass, localInertiaDiagonal=box)
                note = (f"{source}: link {name} has no <inertial> (pybullet would make it 1 kg): using {mass:.3g} kg, "
                        f"its collision shapes' {volume * 1e6:.3g} cm^3 in steel, and an inertia of "
                        f"{' '.join(f'{b:.3g}' for b in box)} kg m^2 (the solid box around them at that mass): give "
                        "the link's real mass and inertia")
            else:
                c.changeDynamics(body, link, localInertiaDiagonal=box)
                note = (f"{source}: link {name}: inertia {' '.join(f'{g:.3g}' for g in given)} kg m^2 does not fit "
                        f"its {mass:g} kg and collision shapes; using {' '.join(f'{b:.3g}' for b in box)} kg m^2 (the "
                        f"solid box around them)")
            notes.append((name, "mass" if bare else "inertia", note))
            warn_once(source, name, note)
    return notes


def link_volume(c, body: int, link: int) -> float:
    """m^3: the summed volume of a link's collision shapes (a mesh: its link's bounding box, at least as much)."""
    total = 0.0
    for shape in c.getCollisionShapeData(body, link):
        kind, dims = shape[2], shape[3]
        if kind == pybullet.GEOM_BOX:
            total += dims[0] * dims[1] * dims[2]
        elif kind == pybullet.GEOM_SPHERE:
            total += 4 / 3 * math.pi * dims[0] ** 3
        elif kind in (pybullet.GEOM_CYLINDER, pybullet.GEOM_CAPSULE):
            r, length = dims[1], dims[0]
            total += math.pi * r * r * length + (4 / 3 * math.pi * r ** 3 if kind == pybullet.GEOM_CAPSULE else 0.0)
        else:
            lo, hi = c.getAABB(body, link)
            return math.prod(h - l for l, h in zip(lo, hi))  # covers every shape of the link
    return total


def _half_extents(kind: int, dims) -> tuple[float, float, float] | None:
    """Half the size of a collision shape's bounding box in its own frame (None: a mesh, measured by its link's
    bounding box instead)."""
    if kind == pybullet.GEOM_BOX:
        return dims[0] / 2, dims[1] / 2, dims[2] / 2
    if kind == pybullet.GEOM_SPHERE:
        return dims[0], dims[0], dims[0]
    if kind in (pybullet.GEOM_CYLINDER, pybullet.GEOM_CAPSULE):
        r, length = dims[1], dims[0]
        return r, r, length / 2 + (r if kind == pybullet.GEOM_CAPSULE else 0.0)
    return None


HOT_CALLS = ("stepSimulation", "getJointStates", "getJointState", "setJointMotorControlArray", "getContactPoints",
             "getClosestPoints", "getAABB", "getOverlappingObjects", "getLinkState", "getBasePositionAndOrientation",
             "resetBasePositionAndOrientation", "invertTransform", "multiplyTransforms", "getJointInfo",
             "resetJointState", "getBaseVelocity", "resetBaseVelocity")


def bind_calls(client: BulletClient) -> None:
    """Bind the calls made at every step to the client once: pybullet_utils' client looks each function up
    anew (and inspects it) on every call, which costs as much as the call itself."""
    for name in HOT_CALLS:
        setattr(client, name, functools.partial(getattr(pybullet, name), physicsClientId=client._client))


def solver_tolerance(station: Station, substep: float) -> float | None:
    """N s: the change of impulse per sweep below which the solver has converged on a squeeze: RESIDUAL_SHARE of the
    lightest loose body's weight over a substep (a held part's statics hold to that share). None: no loose body under
    gravity to scale by: pybullet's own threshold stays."""
    g = math.sqrt(sum(v * v for v in station.gravity))
    masses = [b.mass for b in (*station.fixtures, *station.targets) if b.dynamic]
    if not masses or g == 0.0:
        return None
    return RESIDUAL_SHARE * min(masses) * g * substep


class World:
    """A pybullet world built from a station. Owns the connection; `close()` releases it."""

    def __init__(self, station: Station, gripper_root: str):
        self.station = station
        self.substeps = station.substeps
        self.substep = station.step / station.substeps  # s: one physics step
        self._tmp = tempfile.TemporaryDirectory(prefix="gripper-twin-")
        with quiet_native_output():  # pybullet's argv[0] lines would corrupt `--json` output
            self.client = BulletClient(connection_mode=pybullet.DIRECT)
            self._build(station, gripper_root)
        bind_calls(self.client)
        # one physics substep (a simulation step is `substeps` of them): pybullet's call itself, bound once (a
        # method around it would cost a Python call at every substep)
        self.substep_physics = self.client.stepSimulation
        from .stasis import Stasis

        loose = [self.body_ids[b.name] for b in (*station.fixtures, *station.targets) if b.dynamic]
        self.stasis = Stasis(self.client, self.machine, loose)  # loose bodies frozen while the cell rests
        # loose cylinders (targets): their rolling friction as it is now (ROLLING_RESISTANCE while lying untouched)
        self.rolling = {self.body_ids[b.name]: 0.0 for b in station.targets if b.dynamic and b.shape == "cylinder"}
        g = math.sqrt(sum(v * v for v in station.gravity))
        self._down = tuple(v / g for v in station.gravity) if g else (0.0, 0.0, -1.0)
        self.free_rolling(set(), {uid: self.client.getBasePositionAndOrientation(uid) for uid in self.rolling})

    def free_rolling(self, touched: set[int], poses: dict) -> None:
        """Loose cylinders lying on their side that no finger touches resist rolling (ROLLING_RESISTANCE): one lying
        still stays where it lies. Standing on an end, or between fingers (`touched`, body ids), they have no rolling
        friction: nothing for it to do there but change how a squeezed part settles. `poses`: body id -> (position,
        orientation), as the step read them. Applied from the next step."""
        dx, dy, dz = self._down
        for uid, now in self.rolling.items():
            want = 0.0
            if uid not in touched:
                x, y, z, w = poses[uid][1]  # the cylinder's axis (its local z) in the world, against the vertical
                if abs(2 * (x * z + w * y) * dx + 2 * (y * z - w * x) * dy + (1 - 2 * (x * x + y * y)) * dz) < LYING:
                    want = ROLLING_RESISTANCE
            if want != now:
                self.client.changeDynamics(uid, -1, rollingFriction=want)
                self.rolling[uid] = want

    def _build(self, station: Station, gripper_root: str) -> None:
        self.body_ids: dict[str, int] = {}
        self._configure()
        for fixture in station.fixtures:
            self.body_ids[fixture.name] = self._create_body(fixture)
        flags = pybullet.URDF_USE_INERTIA_FROM_FILE
        gripper = _gripper_for_pybullet(station.gripper.urdf, station.file, Path(self._tmp.name))
        axis_fixes = _unit_axes(gripper, station.gripper.urdf, station.file)
        bare = frozenset(link.get("name", "") for link in gripper.iter("link")
                         if link.find("inertial") is None)  # (pybullet makes such a link 1 kg)
        if station.robot is not None:
            urdf = merge_gripper_into_robot(station.robot.urdf, station.robot.flange_link, gripper, gripper_root,
                                            station.gripper.mount, Path(self._tmp.name), station.file)
            base, key, source = station.robot.base, "robot.urdf", f"{station.robot.urdf} with the gripper"
        else:
            urdf = write_gripper(gripper, Path(self._tmp.name))
            base, key, source = station.gripper.mount, "gripper.urdf", str(station.gripper.urdf)
        try:
            self.machine = self.client.loadURDF(str(urdf), base.xyz, quat(base), useFixedBase=True, flags=flags)
        except pybullet.error as exc:  # pybullet says only "Cannot load URDF file."; name what was loaded
            raise StationError(str(station.file), key, f"pybullet cannot load {source}: {exc}") from None
        self.joint_index: dict[str, int] = {}
        self.link_index: dict[str, int] = {self.client.getBodyInfo(self.machine)[0].decode(): -1}
        for j in range(self.client.getNumJoints(self.machine)):
            info = self.client.getJointInfo(self.machine, j)
            self.joint_index[info[1].decode()] = j
            self.link_index[info[12].decode()] = j
        self.link_name = {j: name for name, j in self.link_index.items()}
        # (link or joint, "mass", "inertia" or "axis", warning) per piece of the gripper's URDF data replaced
        self.urdf_fixes = axis_fixes + fix_inertias(self.client, self.machine, self.link_name,
                                                    str(station.gripper.urdf), bare)
        for target in station.targets:
            self.body_ids[target.name] = self._create_body(target)

    def _configure(self) -> None:
        c, st = self.client, self.station
        c.resetSimulation()
        c.setGravity(*st.gravity)
        # substeps by hand: pybullet's numSubSteps applies a motor's limit in every substep with the whole step's
        # impulse and reports only the last substep's contact impulse (measured-facts.md); one stepSimulation per
        # substep keeps both true, and lets the robot and the drives be commanded at every substep
        c.setPhysicsEngineParameter(fixedTimeStep=self.substep, numSubSteps=1, numSolverIterations=SOLVER_ITERATIONS,
                                    deterministicOverlappingPairs=1)
        self.iterations = SOLVER_ITERATIONS  # (`iterations_for`)
        tolerance = solver_tolerance(st, self.substep)
        # (the solver's measure is the largest squared change of an impulse in a sweep)
        self._residuals = (PYBULLET_RESIDUAL, PYBULLET_RESIDUAL if tolerance is None
                           else max(PYBULLET_RESIDUAL, tolerance ** 2))  # never finer than pybullet's own
        self._pressing = False
        c.setPhysicsEngineParameter(solverResidualThreshold=PYBULLET_RESIDUAL)

    def _create_body(self, body: Body) -> int:
        return create_body(self.client, body)

    def contact_probe(self, finger_links: dict[str, list[int]], targets: dict[str, int]):
        """The exact-contact probe for these finger links and targets (closed with the world)."""
        from .contact import ContactProbe

        spec = {t.name: t for t in self.station.targets}
        self.probe = ContactProbe(self.client, self.machine, finger_links, targets,
                                  lambda client, name: create_body(client, spec[name]))
        return self.probe

    def iterations_for(self, mass_ratio: float, rigid_linkage: bool = False, spring_sweeps: float = 0.0) -> int:
        """Let the solver sweep a substep's contacts and drives up to ITERATIONS_PER_RATIO times `mass_ratio` times
        (how many times the lightest part's mass a finger's drive moves: `Gripper.mass_ratio`), at least
        SOLVER_ITERATIONS (RIGID_LINKAGE_ITERATIONS with a `rigid_linkage`: gears in series) and SPRING_SWEEP_MARGIN
        times `spring_sweeps` (the most K h^2 / m_own of a finger's drive: `Gripper.spring_sweeps`), at most
        MAX_SOLVER_ITERATIONS; the solver stops sooner where it converges. Heavy fingers on a light part need them: a
        50 g can between 2 kg jaws at 100 N was pressed 0.7 mm deep by one jaw, which read `moving` for 12 steps after
        touching, with 50; so do light fingers on a heavy part (SPRING_SWEEP_MARGIN); and a chain of gears: a
        two-knuckle finger's distal joint lagged its master by 40-50 mrad under load with 50 to 150 (the grip walked
        its can 3.6 mm), not with 200 or more. Returns the iterations."""
        least = max(RIGID_LINKAGE_ITERATIONS if rigid_linkage else SOLVER_ITERATIONS,
                    math.ceil(SPRING_SWEEP_MARGIN * spring_sweeps))
        iterations = min(MAX_SOLVER_ITERATIONS, max(least, math.ceil(ITERATIONS_PER_RATIO * mass_ratio)))
        if iterations != SOLVER_ITERATIONS:
            self.client.setPhysicsEngineParameter(numSolverIterations=iterations)
        self.iterations = iterations
        return iterations

    def squeeze_tolerance_within(self, force: float) -> None:
        """Keep the squeeze's tolerance within RESIDUAL_SHARE of `force` (N, the weakest finger's) over a substep too:
        a weak drive on a heavy part is solved as finely as its own force needs."""
        if force > 0.0:
            finest = max(PYBULLET_RESIDUAL, (RESIDUAL_SHARE * force * self.substep) ** 2)
            self._residuals = (PYBULLET_RESIDUAL, min(self._residuals[1], finest))

    def solve_for(self, pressing: bool) -> None:
        """The solver's tolerance for the next step: `solver_tolerance` while fingers press on a part (a squeeze's
        statics hold to it, and it costs half the iterations), pybullet's own otherwise (a drive standing at its goal
        settles exactly, and the cell at rest freezes: stasis.py)."""
        if pressing != self._pressing:
            self._pressing = pressing
            self.client.setPhysicsEngineParameter(solverResidualThreshold=self._residuals[pressing])

    def check_overlaps(self, tolerance: float = OVERLAP_TOLERANCE) -> None:
        """StationError when a target starts inside the gripper, the arm, a fixture or another target: physics
        would shove it away (and fingers embedded in a part would grip it from step 0); or when the gripper starts
        inside a fixture: the fixture would throw its links, against their drives, from step 0. Names both bodies."""
        c, st = self.client, self.station
        names = {uid: name for name, uid in self.body_ids.items()}
        for i, fixture in enumerate(st.fixtures):
            points = [pt for pt in c.getClosestPoints(self.machine, self.body_ids[fixture.name], 0.0)
                      if not self.link_name.get(pt[3], "").startswith(ROBOT_PREFIX)]  # (the arm stands where it stands)
            deepest = min(points, key=lambda pt: pt[8], default=None)
            if deepest is not None and deepest[8] < -tolerance:
                raise StationError(str(st.file), f"fixtures[{i}]", f"the gripper's link "
                                   f"{self.link_name.get(deepest[3], 'base')!r} overlaps fixture {fixture.name!r} by "
                                   f"{-deepest[8] * 1000:.1f} mm at the start (at {_mm(deepest[5])} mm): move the "
                                   "fixture, the gripper's mount or its initial setpoints")
        done: set[frozenset] = set()
        for i, target in enumerate(st.targets):
            uid = self.body_ids[target.name]
            for other in [self.machine, *self.body_ids.values()]:
                if other == uid or frozenset((uid, other)) in done:
                    continue
                done.add(frozenset((uid, other)))
                points = c.getClosestPoints(uid, other, 0.0)
                deepest = min(points, key=lambda pt: pt[8], default=None)
                if deepest is None or deepest[8] >= -tolerance:
                    continue
                if other == self.machine:
                    link = self.link_name.get(deepest[4], "base")
                    what = (f"the robot's link {link[len(ROBOT_PREFIX):]!r}" if link.startswith(ROBOT_PREFIX)
                            else f"the gripper's link {link!r}")
                else:
                    kind = "target" if any(t.name == names[other] for t in st.targets) else "fixture"
                    what = f"{kind} {names[other]!r}"
                raise StationError(str(st.file), f"targets[{i}]", f"target {target.name!r} overlaps {what} by "
                                   f"{-deepest[8] * 1000:.1f} mm at the start (at {_mm(deepest[5])} mm): "
                                   "move the target, the robot's home or the gripper's initial setpoints")

    def pose(self, name: str) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """A target's or fixture's frame (built here with no inertial offset, so its centre of mass is its frame)."""
        pos, orn = self.client.getBasePositionAndOrientation(self.body_ids[name])
        return tuple(pos), tuple(orn)

    def close(self) -> None:
        if getattr(self, "probe", None) is not None:
            self.probe.close()
            self.probe = None
        try:
            self.client.disconnect()
        except pybullet.error:
            pass
        self._tmp.cleanup()
