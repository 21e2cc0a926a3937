"""What a front end sees of a running twin: a `Scene` (fixed geometry) and `Frame`s (the state after a step).

The view, the recorder and the pictures never step a twin and never call pybullet from their own
threads. They read frames taken by an `Observer`, which the stepping thread calls right after a step
(it is a twin device with no signals of its own, so the core needs to know nothing about it).

A frame holds every signal's value (SI units, in the signal table's order), the pose of every body
(each link of the robot-and-gripper multibody, each target and fixture: position and quaternion x, y,
z, w in the world frame) and the position of every movable joint. The scene describes, once, what
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
        """The state now as plain sequences: (step, time, values, poses flat (x y z qx qy qz qw per body), joints).

        The cheap form a recorder keeps for every step; `frame()` makes a `Frame` of it. `values`: the
        signals' values in `scene.signals`' order when the caller has them already (a published snapshot).
        What the step itself read (the joints' positions, the targets' poses: `Twin.step_readings`) is taken
        from it, not asked of pybullet again: the same numbers, bit for bit, for a fraction of the cost."""
        twin, cid, pybullet = self.twin, self._cid, self._pb
        if values is None:
            read = twin.read
            values = tuple([read(n) for n in self._names])
        readings = twin.step_readings() if twin.step_count else None
        poses = list(self._base_pose_t)
        # pybullet's functions called directly with the connection's id: BulletClient's per-call wrapper
        # costs more than the calls themselves
        if self._link_indices:
            # after a step pybullet's link frames are current; before the first one, compute them
            states = pybullet.getLinkStates(self._machine, self._link_indices,
                                            computeForwardKinematics=not twin.step_count, physicsClientId=cid)
            for s in states:
                poses += s[4]
                poses += s[5]
        static = self._static_pose
        known = dict(zip(readings[2], readings[3])) if readings is not None else {}
        for uid in self._other_ids:
            if uid in static:
                poses += static[uid]
                continue
            pose = known.get(uid)
            if pose is None:
                pose = pybullet.getBasePositionAndOrientation(uid, physicsClientId=cid)
            poses += pose[0]
            poses += pose[1]
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

    def frame(self, raw: tuple | None = None) -> Frame:
        step, t, values, poses, joints = raw if raw is not None else self.raw()
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
