"""What a front end sees of a running twin: a `Scene` (fixed geometry) and `Frame`s (the state after a step).

The view, the recorder and the pictures never step a twin and never call pybullet from their own
threads. They read frames taken by an `Observer`, which the stepping thread calls right after a step
(it is a twin device with no signals of its own, so the core needs to know nothing about it).

A frame holds every signal's value (SI units, in the signal table's order), the pose of every body
(each link of the robot-and-gripper multibody, each target and fixture: position and quaternion x, y,
z, w in the world frame) and the position of every movable joint. The links of the machine are rigid
bodies chained by revolute, prismatic and fixed joints, so their poses follow from the joints' positions:
the scene holds that chain (`Scene.links`, from pybullet's own joint frames) and `link_poses` computes
them, for all the rows of a recording at once; a recorder stores per step only the joints and the poses
of the bodies that move freely (targets, fixtures: `Scene.stored`). The scene describes, once, what
each body looks like: the URDF visuals as pybullet loaded them (boxes, cylinders, spheres, capsules,
meshes, planes; their colours and local frames), and for each finger its links, the chain of joints
that moves it (axis, type, which input drives it), so a front end can draw a finger where its setpoint
would put it. Both are plain data (`as_dict`/`from_dict`), stored with a recording.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from twin.core.device import ObservingDevice

GEOMETRY = {2: "sphere", 3: "box", 4: "cylinder", 5: "mesh", 6: "plane", 7: "capsule"}  # pybullet GEOM_*
POSE_FIELDS = ("x", "y", "z", "qx", "qy", "qz", "qw")


@dataclass(frozen=True)
class Visual:
    """One visual shape of a body, in its body's (link's) frame. Sizes in m."""

    body: str  # the body key (a link name, or a target's or fixture's name)
    shape: str  # box, cylinder, sphere, capsule, mesh, plane
    size: tuple[float, ...]  # box: full x, y, z; cylinder/capsule: length, radius; sphere: radius; mesh: scale
    mesh: str  # mesh file (absolute), "" for a primitive
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]  # x, y, z, w
    rgba: tuple[float, float, float, float]


@dataclass(frozen=True)
class ChainJoint:
    """A movable joint between a finger and the gripper's base, as seen from its child link."""

    name: str
    child: str  # body key of the joint's child link (its frame is the joint frame)
    type: str  # prismatic or revolute
    axis: tuple[float, float, float]  # in the child link's frame
    input: str  # the input (signal) whose setpoint drives it
    multiplier: float = 1.0  # q = multiplier * setpoint + offset (a mimic joint); 1, 0 for an input's own joint
    offset: float = 0.0


@dataclass(frozen=True)
class FingerView:
    name: str
    links: tuple[str, ...]  # body keys moving with the finger
    chain: tuple[ChainJoint, ...]  # from the finger's own joint up towards the base


@dataclass
class Scene:
    """The fixed description of a station's cell, as a front end draws it."""

    station: str  # station name
    station_file: str  # the station.toml it was loaded from
    dt: float
    bodies: list[str]  # body keys, in the order of a frame's poses
    joints: list[str]  # movable joint names, in the order of a frame's joint positions
    visuals: list[Visual]
    fingers: list[FingerView]
    targets: list[str]  # body keys of the targets (the parts a gripper can hold)
    fixtures: list[str]
    robot_targets: dict[str, list[float]] = field(default_factory=dict)  # name -> x, y, z, qx, qy, qz, qw
    signals: list[dict] = field(default_factory=list)  # name, direction, type, unit, min, max, group, choices
    # the machine's kinematic chain, parents first: body, parent (None: the world), joint, type (fixed,
    # revolute, prismatic), origin (the body's frame in its parent's at joint position 0: x y z qx qy qz qw),
    # axis (in the body's frame). A body listed here has its pose computed from the joints (`link_poses`).
    links: list[dict] = field(default_factory=list)

    @property
    def stored(self) -> list[str]:
        """The bodies whose poses a recording stores per step (the others follow from the joints)."""
        derived = {link["body"] for link in self.links}
        return [b for b in self.bodies if b not in derived]

    def as_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "Scene":
        d = dict(d)
        d["visuals"] = [Visual(**{k: tuple(v) if isinstance(v, list) else v for k, v in x.items()}) for x in d["visuals"]]
        d["fingers"] = [FingerView(f["name"], tuple(f["links"]), tuple(ChainJoint(**{k: tuple(v) if isinstance(v, list) else v
                                                                                     for k, v in c.items()}) for c in f["chain"]))
                        for f in d["fingers"]]
        return cls(**d)

    def signal(self, name: str) -> dict | None:
        return next((s for s in self.signals if s["name"] == name), None)


@dataclass(frozen=True)
class Frame:
    """The state of the cell after one step (see the module docstring)."""

    step: int
    time: float
    values: tuple  # signal values, in Scene.signals' order
    poses: np.ndarray  # (len(bodies), 7): x, y, z, qx, qy, qz, qw
    joints: np.ndarray  # (len(joints),)

    def as_signals(self, scene: Scene) -> dict:
        return {s["name"]: v for s, v in zip(scene.signals, self.values)}


def _signal_dict(spec) -> dict:
    return {"name": spec.name, "direction": spec.direction, "type": spec.type, "unit": spec.unit, "min": spec.min,
            "max": spec.max, "group": spec.group, "choices": list(spec.choices), "description": spec.description}


class Observer:
    """Takes frames of a twin. Call `frame()` only from the thread that steps the twin."""

    signals: tuple = ()  # as a twin device: it adds no signals

    def __init__(self, twin):
        self.twin = twin
        world, c = twin.world, twin.world.client
        self._c, self._machine = c, world.machine
        base_name = c.getBodyInfo(world.machine)[0].decode()
        self._links: list[tuple[str, int]] = sorted(((n, i) for n, i in world.link_index.items() if i >= 0), key=lambda t: t[1])
        self._link_indices = [i for _, i in self._links]
        self._others = [(name, uid) for name, uid in world.body_ids.items()]
        bodies = [base_name] + [n for n, _ in self._links] + [n for n, _ in self._others]
        joint_info = [c.getJointInfo(world.machine, j) for j in range(c.getNumJoints(world.machine))]
        movable = [info for info in joint_info if info[2] in (0, 1)]  # JOINT_REVOLUTE, JOINT_PRISMATIC
        self._joint_indices = [info[0] for info in movable]
        st = twin.station
        # the machine's base is fixed: its URDF frame is its centre-of-mass frame less the inertial offset
        com_pos, com_orn = c.getBasePositionAndOrientation(world.machine)
        inert_pos, inert_orn = c.getDynamicsInfo(world.machine, -1)[3:5]
        inv_pos, inv_orn = c.invertTransform(inert_pos, inert_orn)
        self._base_pose = np.array([*c.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)[0],
                                    *c.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)[1]])
        visuals = []
        link_name = {-1: base_name, **{i: n for n, i in self._links}}
        for v in c.getVisualShapeData(world.machine):
            visuals.append(self._visual(link_name[v[1]], v))
        for name, uid in self._others:
            for v in c.getVisualShapeData(uid):
                visuals.append(self._visual(name, v))
        self.scene = Scene(
            station=st.name, station_file=str(st.file), dt=twin.dt, bodies=bodies,
            joints=[info[1].decode() for info in movable], visuals=visuals,
            fingers=self._fingers(twin, joint_info, link_name), targets=[t.name for t in st.targets],
            fixtures=[f.name for f in st.fixtures],
            robot_targets={n: [*p.xyz, *c.getQuaternionFromEuler(p.rpy)] for n, p in st.robot_targets.items()},
            signals=[_signal_dict(s) for s in twin.signals])
        self.scene.links = self._kinematics(c, world.machine, joint_info, link_name, self._base_pose)
        self._names = [s.name for s in twin.signals]
        self._base_pose_t = tuple(float(v) for v in self._base_pose)
        # a fixture of mass 0 is static in pybullet (nothing moves it; only targets are placed and displaced):
        # its pose is read once, not at every frame
        fixtures = {f.name for f in st.fixtures}
        self._static_pose = {uid: (*c.getBasePositionAndOrientation(uid)[0], *c.getBasePositionAndOrientation(uid)[1])
                             for name, uid in self._others if name in fixtures and c.getDynamicsInfo(uid, -1)[0] == 0}
        self._other_ids = [uid for _, uid in self._others]
        self._cid = c._client  # the connection's id (BulletClient keeps it here)
        from twin.core.bullet import pybullet

        self._pb = pybullet

    @staticmethod
    def _visual(body: str, v) -> Visual:
        shape = GEOMETRY.get(v[2], "box")
        mesh = v[4].decode(errors="replace") if shape == "mesh" else ""
        size = tuple(float(x) for x in v[3])
        if shape == "sphere":
            size = size[:1]
        elif shape in ("cylinder", "capsule"):
            size = size[:2]
        return Visual(body, shape, size, mesh, tuple(v[5]), tuple(v[6]), tuple(float(x) for x in v[7]))

    @staticmethod
    def _kinematics(c, machine: int, joint_info, link_name, base_pose) -> list[dict]:
        """The machine's chain as `Scene.links` lists it, from pybullet's model: a link's centre-of-mass frame
        is its parent's, moved to the joint and turned by the joint's frame (getJointInfo gives the inverse
        rotation), then moved along or turned about the axis (given in the child's centre-of-mass frame); a
        link's own frame is its centre-of-mass frame less its inertial offset. Here both are expressed from link
        frame to link frame. (The world loads every joint as revolute, prismatic or fixed: `twin.core.mechanism`
        makes planar, floating and spherical ones rigid.)"""
        links = [{"body": link_name[-1], "parent": None, "joint": "", "type": "fixed",
                  "origin": [float(v) for v in base_pose], "axis": [0.0, 0.0, 0.0]}]
        kinds = {0: "revolute", 1: "prismatic", 4: "fixed"}
        for info in joint_info:  # pybullet numbers a link after its parent
            j, parent = info[0], info[16]
            inertial_pos, inertial_orn = c.getDynamicsInfo(machine, parent)[3:5]
            ix, iy, iz, iw = c.getDynamicsInfo(machine, j)[4]
            fx, fy, fz, fw = info[15]
            orn = quat_multiply(quat_multiply(inertial_orn, (-fx, -fy, -fz, fw)), (-ix, -iy, -iz, iw))
            pos = np.asarray(inertial_pos, dtype=float) + quat_to_matrix(inertial_orn) @ np.asarray(info[14], dtype=float)
            axis = quat_to_matrix((ix, iy, iz, iw)) @ np.asarray(info[13], dtype=float)
            links.append({"body": link_name[j], "parent": link_name[parent], "joint": info[1].decode(),
                          "type": kinds[info[2]], "origin": [*(float(v) for v in pos), *(float(v) for v in orn)],
                          "axis": [float(a) for a in axis]})
        return links

    @staticmethod
    def _fingers(twin, joint_info, link_name) -> list[FingerView]:
        mech = twin.mechanism
        parent_joint = {}  # child link name -> joint info
        for info in joint_info:
            parent_joint[info[12].decode()] = info
        driver = {inp.joint: (inp.name, 1.0, 0.0) for inp in mech.inputs}
        input_of_joint = {inp.joint: inp.name for inp in mech.inputs}
        for m in mech.mimics:
            master = input_of_joint.get(m.master)
            if master is not None:
                driver[m.joint] = (master, m.multiplier, m.offset)
        fingers = []
        for f in mech.fingers:
            chain, link = [], f.links[0] if f.links else f.name
            while link in parent_joint:
                info = parent_joint[link]
                jname = info[1].decode()
                if info[2] in (0, 1) and jname in driver:
                    inp, mult, off = driver[jname]
                    chain.append(ChainJoint(jname, link, "revolute" if info[2] == 0 else "prismatic",
                                            tuple(float(a) for a in info[13]), inp, mult, off))
                parent = info[16]
                link = link_name.get(parent)
                if parent < 0 or link is None:
                    break
            fingers.append(FingerView(f.name, tuple(f.links), tuple(chain)))
        return fingers

    def raw(self, values: tuple | None = None) -> tuple:
        """What a recorder keeps of the state now: (step, time, values, the poses of `scene.stored` flat (x y z
        qx qy qz qw per body), joints) as plain sequences.

        `values`: the signals' values in `scene.signals`' order when the caller has them already (a published
        snapshot). What the step itself read (the joints' positions, the targets' poses: `Twin.step_readings`)
        is taken from it, not asked of pybullet again: the same numbers, bit for bit, for a fraction of the
        cost. The links' poses are not read (they follow from the joints: `link_poses`)."""
        twin, cid, pybullet = self.twin, self._cid, self._pb
        if values is None:
            read = twin.read
            values = tuple([read(n) for n in self._names])
        readings = twin.step_readings() if twin.step_count else None
        poses = self._other_poses(readings)
        if not self._joint_indices:
            joints = ()
        elif readings is not None and readings[0] == self._joint_indices:
            joints = tuple(readings[1])
        else:
            have = dict(zip(readings[0], readings[1])) if readings is not None else {}
            missing = [j for j in self._joint_indices if j not in have]
            if missing:
                have.update(zip(missing, (s[0] for s in pybullet.getJointStates(self._machine, missing,
                                                                                   physicsClientId=cid))))
            joints = tuple([have[j] for j in self._joint_indices])
        return twin.step_count, twin.time, values, poses, joints

    def _link_states(self, indices: list[int]) -> list[float]:
        """The links' frames where the joints put them now (x y z qx qy qz qw each, flat): what a recording
        computes from its joints (pybullet's cached frames lag the joints by the step's last substep;
        computing them changes nothing in the simulation)."""
        # pybullet's functions called directly with the connection's id: BulletClient's per-call wrapper
        # costs more than the calls themselves
        poses = []
        for s in self._pb.getLinkStates(self._machine, indices, computeForwardKinematics=True,
                                        physicsClientId=self._cid):
            poses += s[4]
            poses += s[5]
        return poses

    def _other_poses(self, readings) -> list[float]:
        poses, static = [], self._static_pose
        known = dict(zip(readings[2], readings[3])) if readings is not None else {}
        for uid in self._other_ids:
            if uid in static:
                poses += static[uid]
                continue
            pose = known.get(uid)
            if pose is None:
                pose = self._pb.getBasePositionAndOrientation(uid, physicsClientId=self._cid)
            poses += pose[0]
            poses += pose[1]
        return poses

    def frame(self) -> Frame:
        """The state now with every body's pose (the live page's picture), read from pybullet."""
        step, t, values, stored, joints = self.raw()
        poses = list(self._base_pose_t)
        if self._link_indices:
            poses += self._link_states(self._link_indices)
        poses += stored
        return Frame(step, t, values, np.asarray(poses, dtype=float).reshape(len(self.scene.bodies), 7),
                     np.asarray(joints, dtype=float))


class FramePublisher(ObservingDevice):
    """A twin device that publishes the latest frame for front ends in other threads.

    Taking a frame costs pybullet calls, so it takes one only when some reader has asked for one
    (`request()`, e.g. a page wanting its next picture) or when `every_step` is set. `latest` is
    replaced as a whole: a reader in another thread always sees one complete frame.
    """

    signals: tuple = ()

    def __init__(self, twin, observer: Observer | None = None):
        self.observer = observer or Observer(twin)
        self.scene = self.observer.scene
        self.latest: Frame = self.observer.frame()
        self.stale = False  # a step ran since `latest` was taken
        self._wanted = False
        self.listeners: list = []  # called with each new frame, in the stepping thread

    def request(self) -> None:
        self._wanted = True

    def after_step(self, twin) -> None:
        self.stale = True
        if self._wanted or self.listeners:
            self._wanted = False
            self.refresh()

    def refresh_if_stale(self) -> None:
        """Take a frame if a step ran since the last one (call it in the stepping thread, e.g. via the event
        loop): after a burst of steps the last one is shown, not one from the middle of the burst."""
        if self.stale:
            self.refresh()

    def refresh(self) -> Frame:
        frame = self.observer.frame()
        self.latest = frame
        self.stale = False
        for listener in self.listeners:
            listener(frame)
        return frame


def attach(twin, device) -> None:
    """Step `device` with the twin (after the twin's own devices, so it sees their outputs too)."""
    twin.add_device(device)


def detach(twin, device) -> None:
    """Stop stepping `device` (it has no signals, so the signal table does not change)."""
    if device in twin.devices:
        twin.devices.remove(device)


# -- pose arithmetic for front ends (numpy, quaternions x, y, z, w) ---------------------------------------------
def quat_multiply(a, b) -> tuple[float, float, float, float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def link_poses(scene: Scene, joints: np.ndarray) -> np.ndarray:
    """The pose of each body of `scene.links` for each row of joint positions (rows, len(scene.joints)):
    (rows, len(scene.links), 7), x y z qx qy qz qw in the world frame; all rows at once."""
    joints = np.asarray(joints, dtype=float).reshape(-1, len(scene.joints))
    n = joints.shape[0]
    column = {name: k for k, name in enumerate(scene.joints)}
    frames: dict[str, tuple[np.ndarray, np.ndarray]] = {}  # body -> (rotations (n, 3, 3), positions (n, 3))
    out = np.empty((n, len(scene.links), 7))
    for k, link in enumerate(scene.links):
        origin = np.asarray(link["origin"], dtype=float)
        turn = quat_to_matrix(origin[3:])
        rot, pos = np.broadcast_to(turn, (n, 3, 3)), np.broadcast_to(origin[:3], (n, 3))
        if link["type"] != "fixed":
            axis = np.asarray(link["axis"], dtype=float)
            q = joints[:, column[link["joint"]]]
            if link["type"] == "prismatic":  # (as pybullet moves it: by the axis as long as it is given)
                pos = pos + (turn @ axis) * q[:, None]
            else:
                rot = rot @ _rotations(axis / np.linalg.norm(axis), q)
        if link["parent"] is not None:
            parent_rot, parent_pos = frames[link["parent"]]
            pos = parent_pos + np.einsum("nij,nj->ni", parent_rot, pos)
            rot = parent_rot @ rot
        frames[link["body"]] = (rot, pos)
        out[:, k, :3] = pos
        out[:, k, 3:] = matrices_to_quats(rot)
    return out


def _rotations(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations by each angle about a unit axis (Rodrigues)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    s, c = np.sin(angles)[:, None, None], np.cos(angles)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def matrices_to_quats(m: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations -> (n, 4) quaternions x y z w, the sign chosen as Bullet chooses it (so a computed
    pose reads like one pybullet gives)."""
    n = m.shape[0]
    q = np.empty((n, 4))
    trace = m[:, 0, 0] + m[:, 1, 1] + m[:, 2, 2]
    pos = trace > 0
    if pos.any():
        a = m[pos]
        s = np.sqrt(trace[pos] + 1.0)
        q[pos, 3] = 0.5 * s
        s = 0.5 / s
        q[pos, 0] = (a[:, 2, 1] - a[:, 1, 2]) * s
        q[pos, 1] = (a[:, 0, 2] - a[:, 2, 0]) * s
        q[pos, 2] = (a[:, 1, 0] - a[:, 0, 1]) * s
    d0, d1, d2 = m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]
    big = np.where(d0 < d1, np.where(d1 < d2, 2, 1), np.where(d0 < d2, 2, 0))
    for i in range(3):
        sel = ~pos & (big == i)
        if not sel.any():
            continue
        j, k = (i + 1) % 3, (i + 2) % 3
        a = m[sel]
        s = np.sqrt(a[:, i, i] - a[:, j, j] - a[:, k, k] + 1.0)
        q[sel, i] = 0.5 * s
        s = 0.5 / s
        q[sel, 3] = (a[:, k, j] - a[:, j, k]) * s
        q[sel, j] = (a[:, j, i] + a[:, i, j]) * s
        q[sel, k] = (a[:, k, i] + a[:, i, k]) * s
    return q


def quat_to_matrix(q) -> np.ndarray:
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def matrix_to_quat(m: np.ndarray) -> tuple[float, float, float, float]:
    t = m[0, 0] + m[1, 1] + m[2, 2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s)
    i = int(np.argmax([m[0, 0], m[1, 1], m[2, 2]]))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k]) * 2
    q = [0.0, 0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (m[j, i] + m[i, j]) / s
    q[k] = (m[k, i] + m[i, k]) / s
    q[3] = (m[k, j] - m[j, k]) / s
    return tuple(q)  # type: ignore[return-value]


def pose_matrix(pose) -> np.ndarray:
    """4x4 from x, y, z, qx, qy, qz, qw."""
    T = np.eye(4)
    T[:3, :3] = quat_to_matrix(pose[3:7])
    T[:3, 3] = pose[:3]
    return T


def axis_motion(kind: str, axis, delta: float) -> np.ndarray:
    """4x4 of a joint moving by `delta` along/about `axis` (in the joint's frame)."""
    a = np.asarray(axis, dtype=float)
    n = np.linalg.norm(a)
    a = a / n if n else a
    T = np.eye(4)
    if kind == "prismatic":
        T[:3, 3] = a * delta
    else:
        x, y, z = a
        c, s, C = math.cos(delta), math.sin(delta), 1 - math.cos(delta)
        T[:3, :3] = [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]
    return T


def setpoint_motion(finger: FingerView, scene: Scene, frame: Frame, setpoints: dict) -> np.ndarray:
    """World 4x4 that carries the finger's links from where they are to where its setpoints put them."""
    index = {b: k for k, b in enumerate(scene.bodies)}
    jindex = {j: k for k, j in enumerate(scene.joints)}
    G = np.eye(4)
    for cj in finger.chain:  # leaf first: each motion is computed in the current configuration
        if cj.input not in setpoints or cj.name not in jindex or cj.child not in index:
            continue
        q_now = float(frame.joints[jindex[cj.name]])
        delta = cj.multiplier * float(setpoints[cj.input]) + cj.offset - q_now
        F = pose_matrix(frame.poses[index[cj.child]])
        G = F @ axis_motion(cj.type, cj.axis, delta) @ np.linalg.inv(F) @ G
    return G
