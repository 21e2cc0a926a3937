"""`twin check STATION`: the station doctor. Is a new gripper ready for commissioning? Ask the physics.

For every target it finds, from the target's shape and the fingers' reach (a sweep of each finger's closing
drive over its range, distances taken on the nominal shapes), how the fingers can grip it: from outside, and
into the bore of a ring. It then grips it as a user would, through the simulation API: with a robot, the arm
brings the open gripper over the part and down (`Twin.move`); the drives close to the end of their range (so
they press with their full effort); the grip is held at rest; with a robot the part is lifted. Every measure is
judged against issue 18's thresholds (docs/check.md says why each one):

    status     2 (closing) / 1 (opening) within 10 steps of the grip closing (its last finger touching), and steady while pressing, `moving` off
    noise      the pressing joint's position spread while pressing <= 0.05 mm (0.001 rad)
    force      the finger's force = its drive's effort (the weakest in a chain of drives in series, shared over a
               mimic linkage) within 10 %
    penetration  how deep the nominal shapes overlap (into the part) <= 0.5 mm
    push       a centred part pushed < 0.5 mm by the closing grip
    creep      a resting part < 0.1 mm in the hold time (5 s); a held part < 0.2 mm relative to the gripper
    capacity   mu x sum of the normal forces >= 3 x the weight (below 1 x it cannot hold); a lift keeps it within 1 mm

Nothing here knows a station: every number comes from the station file, its URDFs and the physics.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

from twin.core.errors import MotionError
from twin.core.bullet import pybullet
from twin.core.geometry import Pose, cross
from twin.core.gripper import PAST_REACH
from twin.core.signal_table import IN_POSITION_TOLERANCE
from twin.core.world import STEEL_DENSITY as STEEL, link_volume

PASS, WARN, FAIL, INFO = "PASS", "WARN", "FAIL", "INFO"
STALL_STEPS = 10  # status 2/1 within this many steps of touching
NOISE = {"m": 0.05e-3, "rad": 0.001}  # stall noise: position spread while pressing
FORCE_TOLERANCE = 0.10  # force = effort within 10 %
PENETRATION = 0.5e-3  # m: deepest overlap of the nominal shapes at full effort
PUSH = 0.5e-3  # m: a closing grip moves a centred part less than this
CENTRED = 0.5e-3  # m: fingers whose gaps to the part agree within this close on a centred part
REST_CREEP = 0.1e-3  # m in the hold time: a part resting on its support
REST_SETTLE = 0.5  # s a part placed on its support is given to settle (sink into its contacts) before creep counts
HELD_CREEP = 0.2e-3  # m in the hold time: a held part relative to the gripper (the palm its fingers ride on)
CAPACITY = 3.0  # friction capacity / weight a grip needs to promise a lift
LIFT_SLIP = 1e-3  # m: such a grip lifts the part within this
LIFT = 0.1  # m: how far a robot lifts the part
LIFT_SPEED = 0.2  # m/s
APPROACH_SPEED = 0.1  # m/s: the last stretch down onto the part (MoveL)
TRAVEL_SPEED = 0.5  # m/s: to the approach pose (MoveJ)
SWEEP_SAMPLES = 400  # positions per range in the reach sweep (refined by bisection)
CLEARANCE = {"m": 0.01, "rad": 0.2}  # a pre-grip position stands this far off the part (or half the free room)
FAR = 1.0  # m: the reach sweep's query distance
DENSITY_LIMIT = 3 * STEEL  # a finger link denser than this (osmium, the densest metal, is 22600) has a wrong mass
PICTURE_PITCH = -15.0  # deg: the grip seen from a little above the part, the fingers in front of the gripper


@dataclass
class Check:
    level: str  # PASS, WARN, FAIL, INFO
    where: str  # "TARGET MODE" or "station"
    who: str  # a finger, or "grip"
    measure: str
    text: str

    def line(self) -> str:
        return f"{self.level:4}  {self.where}  {self.who} {self.measure}: {self.text}"


@dataclass
class FingerResult:
    finger: str
    drive: str  # the input that closes it
    unit: str  # of its pressing joint: m or rad
    contact_geometry: float | None = None  # the pressing joint's position at contact, from the reach sweep
    onset_step: int | None = None  # steps after the drives were told to close
    onset_time: float | None = None
    onset_position: float | None = None
    contact_lost: int = 0  # steps of the hold in which its contact flag was off
    status: list = field(default_factory=list)  # [[status, steps], ...] from the closing command on
    noise: float | None = None  # position spread while pressing (m or rad)
    position: float | None = None  # mean position of the pressing joint while pressing (m or rad)
    force: float | None = None  # mean force while pressing (N or N*m)
    force_range: tuple | None = None
    expected_force: float | None = None
    effort_share: float | None = None  # of that, the share of its drive's effort that reaches it (N or N m)
    weight_along: float = 0.0  # N: of that, the weight of what its drive moves, along its closing direction
    normal_force: float | None = None  # mean sum of the contact normal forces on the part (N)
    penetration: float | None = None  # m, >= 0: the deepest overlap of the nominal shapes while pressing (into the part)
    closest: float | None = None  # m: their smallest signed distance then (> 0: apart, < 0: overlapping by -closest)
    short_of_goal: float | None = None  # how far its drive stood short of its command (the range's end) while pressing


@dataclass
class GripResult:
    target: str
    mode: str  # outside or inside
    skipped: str = ""
    fingers: list = field(default_factory=list)
    centred: bool | None = None
    push: float | None = None  # m: the part moved while the fingers closed
    held_creep: float | None = None  # m: relative to the gripper's base over the hold
    capacity: float | None = None  # N: mu x sum of normal forces
    weight: float | None = None  # N
    gripped_step: int | None = None  # doGripped rose this many steps after the closing command
    lift_slip: float | None = None  # m: relative to the gripper's base over the lift
    lift_signal_slip: bool | None = None


@dataclass
class Report:
    station: str
    file: str
    hold: float
    rest_creep: dict = field(default_factory=dict)  # target -> m
    grips: list = field(default_factory=list)
    checks: list = field(default_factory=list)

    @property
    def failed(self) -> bool:
        return any(c.level == FAIL for c in self.checks)

    def as_dict(self) -> dict:
        d = asdict(self)
        d["verdict"] = FAIL if self.failed else PASS
        return d


class _Reach:
    """Where each finger meets a target, found by sweeping its closing drive over its range (no physics step:
    joints are set, the nominal shapes asked for their distance, and everything is put back)."""

    def __init__(self, twin):
        self.twin, self.g = twin, twin.gripper
        self.c, self.body = twin.world.client, twin.world.machine
        self.probe = getattr(self.g, "probe", None)

    def _set(self, name: str, q: float) -> None:
        c, g = self.c, self.g
        c.resetJointState(self.body, g.joint[name], q)
        for joint, master, mult, off in g.mimics:
            if master == name:
                c.resetJointState(self.body, joint, mult * q + off)

    def _saved(self):
        joints = list(self.g.joint.values()) + [j for j, *_ in self.g.mimics]
        return [(j, *self.c.getJointState(self.body, j)[:2]) for j in joints]

    def _restore(self, saved) -> None:
        for j, q, v in saved:
            self.c.resetJointState(self.body, j, q, v)

    def distance(self, finger: str, uid: int, placed=None) -> float | None:
        """The finger's closest distance to target `uid` on the nominal shapes (the target at `placed`, a pose
        in the world, or where it is); None when no link of the finger can be copied into the probe world."""
        probe = self.probe
        if probe is None:
            return None
        best = None
        for link in self.g.finger_links[finger]:
            if not probe.covers(link):
                continue
            if placed is None:
                d = probe.distance(link, uid, FAR)
            else:
                copy, correction = probe.links[link]
                state = self.c.getLinkState(self.body, link, computeForwardKinematics=True)
                pc = probe.client
                pc.resetBasePositionAndOrientation(copy, state[0], state[1])
                pc.resetBasePositionAndOrientation(probe.targets[uid], placed.position.tolist(),
                                                   placed.orientation.tolist())
                pts = pc.getClosestPoints(copy, probe.targets[uid], FAR + correction)
                d = min((pt[8] + correction for pt in pts), default=None)
            if d is not None and (best is None or d < best):
                best = d
        return best

    def closing_drive(self, finger: str) -> str | None:
        """The servo that closes the finger: of those that move it, the one that moves it furthest towards or
        away from the other fingers (a carriage, not the fine axis it carries; not a lift axis that carries every
        finger alike). A lone finger is measured against the gripper's base."""
        servos = self.g.finger_servos[finger]
        if len(servos) <= 1:
            return servos[0] if servos else None
        c, body = self.c, self.body

        def where(f):
            return c.getLinkState(body, self.g.finger_links[f][0], computeForwardKinematics=True)[4]

        def spread():
            others = [where(f) for f in self.g.finger_links if f != finger] or [c.getBasePositionAndOrientation(body)[0]]
            me = where(finger)
            return sum(math.dist(me, p) for p in others)

        saved = self._saved()
        travel = {}
        try:
            for name in servos:
                inp = self.twin.mechanism.input(name)
                ends = []
                for q in (inp.min, inp.max):
                    self._set(name, q)
                    ends.append(spread())
                self._restore(saved)
                travel[name] = abs(ends[1] - ends[0])
        finally:
            self._restore(saved)
        return max(servos, key=lambda n: travel[n])

    def lift_axis(self, closing: set, gravity) -> tuple[str, float] | None:
        """A prismatic input that moves every finger alike, against gravity (a gantry's lift): (its name, +1 or -1,
        the direction that lifts). None if there is none."""
        g = math.sqrt(sum(v * v for v in gravity))
        if not g:
            return None
        up = [-v / g for v in gravity]
        saved = self._saved()
        fingers = list(self.g.finger_links)
        try:
            for inp in self.twin.mechanism.inputs:
                if inp.name in closing or inp.unit != "m" or inp.max <= inp.min:
                    continue
                moves = []
                for q in (inp.min, inp.max):
                    self._set(inp.name, q)
                    moves.append([self.c.getLinkState(self.body, self.g.finger_links[f][0],
                                                      computeForwardKinematics=True)[4] for f in fingers])
                self._restore(saved)
                shifts = [[b[i] - a[i] for i in range(3)] for a, b in zip(*moves)]
                length = math.sqrt(sum(v * v for v in shifts[0]))
                alike = all(math.dist(s, shifts[0]) <= 1e-6 for s in shifts)
                vertical = length and abs(sum(a * b for a, b in zip(shifts[0], up))) >= 0.99 * length
                if alike and vertical:
                    return inp.name, (1.0 if sum(a * b for a, b in zip(shifts[0], up)) > 0 else -1.0)
        finally:
            self._restore(saved)
        return None

    def sweep(self, drive: str, fingers: list[str], uid: int, placed: Pose, here: float | None = None
              ) -> dict[str, dict]:
        """For each finger the drive moves: where it touches the part closing from the open end (`outside`),
        where it touches the bore's wall opening from inside (`inside`, with the free room `bore`), and its
        distance at the closed end; positions of the drive's joint.

        With `here` (no robot to bring the fingers anywhere else) the drive's joint can only move from where it
        stands: `outside` is then where the finger first meets the part closing from `here`, `inside` where it
        first meets it opening from `here` (a finger standing in a bore), each None when that way is free to the
        range's end, `bore` the free room opening, `min_gap` the closest it comes closing; `stuck` says it
        touches the part where it stands."""
        inp = self.twin.mechanism.input(drive)
        closing = self.g.closing[drive]  # the core's rule: the way the fingers' shapes come together
        open_end, closed_end = (inp.min, inp.max) if closing > 0 else (inp.max, inp.min)
        qs = [open_end + (closed_end - open_end) * k / SWEEP_SAMPLES for k in range(SWEEP_SAMPLES + 1)]
        saved = self._saved()
        try:
            def dists(q):
                self._set(drive, q)
                return {f: self.distance(f, uid, placed) for f in fingers}

            samples = [dists(q) for q in qs]

            def refine(f, a, b):  # a free, b touching (either order along the range)
                for _ in range(30):
                    m = (a + b) / 2
                    d = dists(m)[f]
                    if d is not None and d > 0:
                        a = m
                    else:
                        b = m
                return (a + b) / 2

            def first_touch(f, path):
                """Where the finger first touches the part along `path` [(q, d), ...] (its first entry free)."""
                k = next((k for k, (_, d) in enumerate(path) if d <= 0), None)
                return None if k is None else refine(f, path[k - 1][0], path[k][0])

            at_here = dists(here) if here is not None else None
            result = {}
            for f in fingers:
                d = [s[f] for s in samples]
                if any(v is None for v in d):
                    result[f] = {"measured": False}
                    continue
                ends = {"open_gap": d[0], "closed_gap": d[-1], "open_end": open_end, "closed_end": closed_end}
                if here is not None:
                    # the range seen from where the finger stands: closing on one side, opening on the other
                    side = [(q - here) * (1 if closed_end > open_end else -1) for q in qs]
                    path_close = [(here, at_here[f])] + [(q, v) for q, v, x in zip(qs, d, side) if x > 0]
                    path_open = [(here, at_here[f])] + [(q, v) for q, v, x in zip(qs, d, side) if x < 0][::-1]
                    stuck = at_here[f] <= 0
                    inside = None if stuck else first_touch(f, path_open)
                    result[f] = {"measured": True, "stuck": stuck, "here": here, "here_gap": at_here[f],
                                 "outside": None if stuck else first_touch(f, path_close), "inside": inside,
                                 "bore": abs(here - (inside if inside is not None else open_end)),
                                 "min_gap": min(v for _, v in path_close), **ends}
                    continue
                out = inside = None
                bore = 0.0
                first = next((k for k, v in enumerate(d) if v <= 0), None)
                if first is not None and first > 0:
                    out = refine(f, qs[first - 1], qs[first])
                if first is not None:
                    back = next((k for k in range(first, len(d)) if d[k] > 0), None)
                    if back is not None:
                        inside = refine(f, qs[back], qs[back - 1])
                        end = next((k for k in range(back, len(d)) if d[k] <= 0), len(d) - 1)
                        bore = abs(qs[end] - inside)
                result[f] = {"measured": True, "outside": out, "inside": inside, "bore": bore,
                             "min_gap": min(d), **ends}
            return result
        finally:
            self._restore(saved)


def _rle(seq: list[int]) -> list[list[int]]:
    out: list[list[int]] = []
    for v in seq:
        if out and out[-1][0] == v:
            out[-1][1] += 1
        else:
            out.append([v, 1])
    return out


def _runs(status: list, most: int = 8) -> str:
    """A status sequence as runs (`0x12 2x95`: 12 steps of 0, then 95 of 2), the first `most` of them."""
    text = " ".join(f"{s}x{k}" for s, k in status[:most])
    return text + (f" ... ({len(status) - most} more runs)" if len(status) > most else "")


def _fmt_len(v: float | None, unit: str = "m", digits: int = 3) -> str:
    if v is None:
        return "-"
    return f"{v * 1000:.{digits}f} mm" if unit == "m" else f"{v * 1000:.{digits}f} mrad"


def _fmt_depth(r: FingerResult, short: bool = False) -> str:
    """A finger's penetration as a user reads it: how far into the part, or how far short of it."""
    if r.closest is None:
        return "-"
    if r.closest > 0:
        return f"0 ({_fmt_len(r.closest)} apart)" if short else \
            f"none: the shapes {_fmt_len(r.closest)} apart at the closest"
    return _fmt_len(r.penetration) + ("" if short else " into the part at the deepest")


def _fmt_pos(v: float | None, unit: str) -> str:
    if v is None:
        return "-"
    return f"{v * 1000:.2f} mm" if unit == "m" else f"{math.degrees(v):.2f} deg"


class Doctor:
    """Runs the checks on one twin (fresh from its station) and gathers a Report."""

    def __init__(self, twin, hold: float = 5.0, picture: bool = False, log=None):
        self.twin, self.hold = twin, hold
        self.c, self.body = twin.world.client, twin.world.machine
        self.reach = _Reach(twin)
        self.report = Report(twin.station.name, str(twin.station.file), hold)
        self.want_picture = picture
        self.pictures: list = []
        self._gripped_at = None  # the part relative to the gripper when doGripped rose
        self.carrier = twin.world.link_index[twin.mechanism.base_link]  # the palm: see `relative`
        self.lift_axis: tuple[str, float] | None = None  # without a robot: an axis that lifts every finger alike
        self.log = log or (lambda text: None)
        st = twin.station
        self.g = twin.gripper
        self.mech = twin.mechanism
        self.fingers = list(self.g.finger_links)
        self.spec = {t.name: t for t in st.targets}
        self.unit = {i.name: i.unit for i in self.mech.inputs}

    # -- helpers ----------------------------------------------------------------------------------
    def check(self, level, where, who, measure, text) -> None:
        c = Check(level, where, who, measure, text)
        self.report.checks.append(c)
        self.log(c.line())

    def steps(self, seconds: float) -> int:
        return max(1, round(seconds / self.twin.dt))

    def part_pose(self, name: str) -> Pose:
        return Pose(*self.twin.object_pose(name))

    def relative(self, name: str):
        """The part's position in the frame of the link that carries the fingers' drives (the palm: the gripper's
        base, or what a gantry's lift moves): what a part that stays put in the grip keeps."""
        j = self.carrier
        if j < 0:
            p, o = self.c.getBasePositionAndOrientation(self.body)
        else:
            p, o = self.c.getLinkState(self.body, j, computeForwardKinematics=True)[4:6]
        return (Pose(p, o).inverse() * self.part_pose(name)).position

    def tcp(self) -> Pose:
        if self.twin.robot is not None:
            return self.twin.tcp_pose()
        st = self.twin.station
        mount = Pose.from_xyz_rpy(st.gripper.mount.xyz, st.gripper.mount.rpy)
        return mount * Pose.from_xyz_rpy(st.gripper.tcp.xyz, st.gripper.tcp.rpy)

    def grip_pose(self, name: str) -> Pose:
        """Where the TCP grips the part: the station's robot target at the part's placement (its author's height
        and orientation; within half the part's height), moved and turned with the part since; else the
        part's centre with the TCP's present orientation. Without a robot, where the gripper is."""
        here = self.tcp()
        if self.twin.robot is None:
            return here
        body = self.spec[name]
        placed_pose = Pose.from_xyz_rpy(body.pose.xyz, body.pose.rpy)
        placed, now = placed_pose.position, self.part_pose(name).position
        lo, hi = self.c.getAABB(self.twin.world.body_ids[name])
        tolerance = max(0.01, (hi[2] - lo[2]) / 2)
        best = None
        for tname in self.twin.station.robot_targets:
            pose = self.twin.target(tname)
            d = float(sum((pose.position - placed) ** 2) ** 0.5)
            if d <= tolerance and (best is None or d < best[0]):
                best = (d, pose)
        if best is None:
            return Pose(now, here.orientation)
        return self.part_pose(name) * placed_pose.inverse() * best[1]  # moved and turned as the part was

    def backed_off(self, pose: Pose, distance: float) -> Pose:
        """`pose` moved back along its tool axis (z) by `distance`: out of the part, the way it came in."""
        return pose * Pose((0.0, 0.0, -distance))

    def approach_distance(self, name: str) -> float:
        lo, hi = self.c.getAABB(self.twin.world.body_ids[name])
        return min(0.3, max(0.05, math.dist(lo, hi)))

    def weight(self, name: str) -> float:
        gx, gy, gz = self.twin.station.gravity
        return self.spec[name].mass * math.sqrt(gx * gx + gy * gy + gz * gz)

    def pressing_joint(self, finger: str, drive: str) -> int:
        """The joint whose position shows how the finger stands: its own when it is the drive's or mimics it,
        else the drive's (a carriage)."""
        own = self.twin.world.joint_index[next(f.joint for f in self.mech.fingers if f.name == finger)]
        if own == self.g.joint[drive] or any(j == own and m == drive for j, m, _, _ in self.g.mimics):
            return own
        return self.g.joint[drive]

    def linkage_share(self, finger: str, drive: str, fingers: list[str]) -> float:
        """The share of the drive's effort that reaches this finger (docs/check.md, `force`): on a mimic linkage the
        effort E balances sum(|m_k| Q_k) over the coupled fingers (virtual work, m_k = 1 for the master), and a free
        part between them takes equal forces Q_k, so each presses with E / sum |m_k|."""
        mult = {}
        for f in fingers:
            own = self.twin.world.joint_index[next(x.joint for x in self.mech.fingers if x.name == f)]
            if own == self.g.joint[drive]:
                mult[f] = 1.0
            for j, m, mul, _ in self.g.mimics:
                if j == own and m == drive:
                    mult[f] = abs(mul)
        if finger not in mult:
            return 1.0
        return 1.0 / sum(mult.values())  # each coupled finger alike, whatever its own multiplier

    def knuckle_force(self, finger: str, drive: str, target: str, effort: float) -> float | None:
        """What a finger on a linkage of joints in series (knuckles tied by gears) reads in statics where it touches
        the part now: by virtual work the drive's effort E balances the contacts' normal forces through the speed of
        each contact point along its normal for a unit speed of the linkage (every joint of it that carries the
        finger turning at its multiplier), sum(N_i n_i . v_i) = E; the finger reads the torque of those forces about
        its own joint (a prismatic finger: their sum). None without a contact."""
        g, c = self.g, self.c
        own = self.twin.world.joint_index[next(x.joint for x in self.mech.fingers if x.name == finger)]
        gear = {g.joint[drive]: 1.0} | {j: mult for j, m, mult, _ in g.mimics if m == drive}
        moving = [(j, gear[j]) for j in g._chain(own) if j in gear]
        frames = {j: g._joint_frame(j) for j, _ in moving}
        revolute = {j: g._joint_kind(j)[0] == pybullet.JOINT_REVOLUTE for j, _ in moving}
        own_origin, own_axis = frames[own] if own in frames else g._joint_frame(own)
        own_revolute = revolute.get(own, g._joint_kind(own)[0] == pybullet.JOINT_REVOLUTE)
        work = read = 0.0
        for link in g.finger_links[finger]:
            for pt in c.getContactPoints(self.body, self.twin.world.body_ids[target], linkIndexA=link):
                p, n, fn = pt[5], pt[7], pt[9]  # (n: on the part, towards the finger: the part pushes it along n)
                if fn <= 0.0:
                    continue
                speed = [0.0, 0.0, 0.0]
                for j, mult in moving:
                    origin, axis = frames[j]
                    v = cross(axis, [p[i] - origin[i] for i in range(3)]) if revolute[j] else axis
                    speed = [speed[i] + mult * v[i] for i in range(3)]
                work += fn * abs(sum(n[i] * speed[i] for i in range(3)))
                arm = cross([p[i] - own_origin[i] for i in range(3)], n) if own_revolute else n
                read += fn * abs(sum(arm[i] * own_axis[i] for i in range(3)))
        return effort * read / work if work > 0.0 else None

    def carried(self, finger: str) -> list[str]:
        """The other fingers whose links hang from this finger's links: it is a carriage (a lift, a slide), not a
        finger, when it carries all of them."""
        mine = set(self.g.finger_links[finger])
        out = []
        for f, links in self.g.finger_links.items():
            j = links[0] if f != finger else -1
            while j >= 0 and j not in mine:
                j = self.c.getJointInfo(self.body, j)[16]  # the parent link
            if j >= 0:
                out.append(f)
        return out

    def carriage_hint(self, finger: str) -> str:
        """How to fix a reach failure of a carriage taken for a finger (detection counts any moving link with
        collision shapes): name the fingers in the station."""
        carried = self.carried(finger)
        if not carried:
            return ""
        names = ", ".join(f'"{f}"' for f in self.fingers if f != finger and f in carried)
        return (f"; {finger} carries {', '.join(carried)}: if it is a carriage, not a finger, name the fingers in "
                f"station.toml: [gripper] fingers = [{names}]")

    def wait_in_position(self, drives, limit_s: float) -> None:
        for _ in range(self.steps(limit_s)):
            self.twin.step()  # (outputs are those of the last step: a setpoint just written shows after one)
            if all(self.twin.read(f"{d}.in_position") for d in drives):
                return

    # -- the run ----------------------------------------------------------------------------------
    def run(self) -> Report:
        st = self.twin.station
        if not st.targets:
            self.check(FAIL, "station", "grip", "targets", "the station has no target to grip")
            return self.report
        if not self.twin.read("Active"):
            self.twin.write("Active", True)  # a gripper that is not always active follows its setpoints once told to
        for what, note in self.g.limit_notes:  # a drive limit the URDF leaves out, or a placeholder effort (the force
            self.check(WARN, "station", "drive", what, note)  # check below cannot pass, and says so)
        for link, measure, note in self.twin.world.urdf_fixes:  # URDF data replaced: the real values are wanted
            self.check(WARN, "station", link, measure, note)
        self.rest()
        self.densities()
        drive_of = {f: self.reach.closing_drive(f) for f in self.fingers}
        first = next((d for d in drive_of.values() if d is not None), None)
        if first is not None:  # the link the (first) closing drive's joint sits on
            self.carrier = self.c.getJointInfo(self.body, self.g.joint[first])[16]
        if self.twin.robot is None:
            self.lift_axis = self.reach.lift_axis(set(drive_of.values()), self.twin.station.gravity)
        self.home = {d: self.twin.read(d) for d in dict.fromkeys(d for d in drive_of.values() if d is not None)}
        for body in st.targets:
            for mode in ("outside", "inside"):
                plans = self.plan(body.name, drive_of)  # where the part is now (an earlier grip may have moved it)
                result = GripResult(body.name, mode)
                self.report.grips.append(result)
                try:
                    self.grip(body.name, mode, plans, drive_of, result)
                except MotionError as exc:  # the arm cannot get there: the grip is not possible as placed
                    result.skipped = result.skipped or "the robot cannot get there"
                    self.check(FAIL, f"{body.name} {mode}", "robot", "motion", str(exc))
                    return self.report
        if all(g.skipped for g in self.report.grips) and not self.report.failed:
            # nothing was gripped, so nothing is known: a station the doctor could not try is not ready
            why = "; ".join(dict.fromkeys(f"{g.target} {g.mode}: {g.skipped}" for g in self.report.grips))
            self.check(FAIL, "station", "grip", "tried", f"no grip could be tried on any target ({why})")
        return self.report

    def densities(self) -> None:
        """A WARN per finger link whose mass does not fit its size: denser than DENSITY_LIMIT over the volume of
        its collision shapes (a mesh counted by its link's bounding box, so its density is never overstated).
        A typo (2000 for 2 kg) tunes the drives for a mass the finger does not have."""
        c, body = self.c, self.body
        names = self.twin.world.link_name
        for f in self.fingers:
            for link in self.g.finger_links[f]:
                mass = c.getDynamicsInfo(body, link)[0]
                volume = link_volume(c, body, link)
                if mass <= 0 or not volume:
                    continue
                density = mass / volume
                if density > DENSITY_LIMIT:
                    self.check(WARN, "station", names.get(link, f), "mass",
                               f"{mass:.4g} kg in {volume * 1e6:.4g} cm^3 of collision shapes is {density:.3g} "
                               f"kg/m^3, {density / STEEL:.0f}x steel's {STEEL:g}: a typo in the URDF's <mass>? (the "
                               "drives are tuned for it)")

    def rest(self) -> None:
        """Every target left alone for the hold time: how far does it creep on its support?"""
        names = [t.name for t in self.twin.station.targets]
        self.twin.step(self.steps(REST_SETTLE))
        before = {n: self.part_pose(n).position for n in names}
        self.twin.step(self.steps(self.hold))
        for n in names:
            creep = float(sum((self.part_pose(n).position - before[n]) ** 2) ** 0.5)
            self.report.rest_creep[n] = creep
            level = PASS if creep < REST_CREEP else FAIL
            self.check(level, f"{n} resting", "part", "creep",
                       f"{_fmt_len(creep)} in {self.hold:g} s on its support (< {_fmt_len(REST_CREEP, digits=1)})")

    def plan(self, name: str, drive_of: dict) -> dict:
        """The reach sweep of every closing drive, with the gripper at the grip pose; without a robot, from where
        each drive's joint stands (nothing can bring the fingers to the part's other side of their range)."""
        placed_rel = self.grip_pose(name).inverse() * self.part_pose(name)  # the part as the TCP will see it
        placed = self.tcp() * placed_rel  # ...placed in the world relative to where the gripper is now
        uid = self.twin.world.body_ids[name]
        by_drive: dict[str, list[str]] = {}
        for f, d in drive_of.items():
            if d is not None:
                by_drive.setdefault(d, []).append(f)
        plans = {}
        for d, fingers in by_drive.items():
            here = None if self.twin.robot is not None else self.c.getJointState(self.body, self.g.joint[d])[0]
            plans.update(self.reach.sweep(d, fingers, uid, placed, here))
        return plans

    def grip(self, name: str, mode: str, plans: dict, drive_of: dict, result: GripResult) -> None:
        where = f"{name} {mode}"
        tw, shape = self.twin, self.spec[name].shape
        fingers = self.fingers
        unmovable = [f for f in fingers if drive_of[f] is None]
        if unmovable:
            result.skipped = "fingers without a drive: " + ", ".join(unmovable)
            self.check(FAIL, where, ", ".join(unmovable), "drive", "no input moves this finger")
            return
        unmeasured = [f for f in fingers if not plans[f]["measured"]]
        if unmeasured:
            result.skipped = "no nominal shape for " + ", ".join(unmeasured)
            self.check(WARN, where, ", ".join(unmeasured), "reach", "the finger's shapes cannot be measured: not checked")
            return
        robot = tw.robot is not None
        if mode == "inside" and shape != "ring":
            result.skipped = f"a {shape} has no bore"
            return
        stuck = [f for f in fingers if plans[f].get("stuck")]
        if stuck:  # without a robot: a finger standing on (or in) the part can start no grip
            result.skipped = "the fingers touch it where they stand"
            for f in stuck:
                self.check(WARN, where, f, "reach", f"touches {name} where it stands (gap "
                           f"{_fmt_len(plans[f]['here_gap'])}): start it free of the part (the station's `initial`)")
            return
        if mode == "inside":
            missing = [f for f in fingers if plans[f]["inside"] is None]
            if missing:
                result.skipped = ("the fingers do not fit into the bore" if robot else
                                  "the fingers stand outside the bore, and there is no robot to bring them in")
                self.check(INFO, where, ", ".join(missing), "reach",
                           ("cannot open against the bore from inside" if robot else
                            "opening from where it stands meets no bore") + ": no inside grip checked")
                return
        else:
            missing = [f for f in fingers if plans[f]["outside"] is None]
            # a ring the fingers can only hold from inside (or, without a robot, whose bore they stand in): no
            # outside grip is no failure
            bore_only = shape == "ring" and all(plans[f]["inside"] is not None for f in fingers)
            if missing:
                for f in missing:
                    p = plans[f]
                    if not robot and bore_only:
                        self.check(INFO, where, f, "reach", f"stands in the bore of {name}: closing from there meets "
                                   "nothing (its inside grip is checked)")
                        continue
                    if not robot:
                        why = (f"closing from where it stands ({_fmt_pos(p['here'], self.unit[drive_of[f]])}) it comes "
                               f"no closer than {_fmt_len(p['min_gap'])}")
                    elif p["open_gap"] <= 0:
                        why = f"touches it already when fully open (gap {_fmt_len(p['open_gap'])})"
                    else:
                        why = f"closest {_fmt_len(p['min_gap'])} away over its whole travel"
                    self.check(INFO if bore_only else FAIL, where, f, "reach", f"cannot reach {name}: {why}"
                               + (" (it grips the bore)" if bore_only else self.carriage_hint(f)))
                result.skipped = "the fingers grip it from inside only" if bore_only else "out of reach"
                return
        drives = sorted({drive_of[f] for f in fingers}, key=list(self.g.joint).index)
        # where each drive starts (free of the part) and where it is told to go (the range's end past the part)
        start, goal = {}, {}
        for d in drives:
            mine = [f for f in fingers if drive_of[f] == d]
            p = [plans[f] for f in mine]
            unit = self.unit[d]
            goal[d] = p[0]["closed_end"] if mode == "outside" else p[0]["open_end"]
            if not robot:  # where it stands: free of the part, which lies ahead of it (the sweep from there says)
                start[d] = self.home[d]
                continue
            if mode == "outside":
                touch = p[0]["open_end"] + min((x["outside"] - x["open_end"] for x in p), key=abs)
                room = touch - p[0]["open_end"]
            else:
                touch = p[0]["open_end"] + max((x["inside"] - x["open_end"] for x in p), key=abs)
                room = -min(x["bore"] for x in p) * (1 if p[0]["closed_end"] > p[0]["open_end"] else -1)
            # room: signed, from the touching position into the free space the finger starts from
            start[d] = touch + math.copysign(min(CLEARANCE[unit], abs(room) / 2), -room)
        # bring the open gripper to the part
        if robot:
            back = self.approach_distance(name)
            pose = self.grip_pose(name)
            here = tw.tcp_pose()
            if here.distance(pose) < 2 * back:
                tw.run_motion("MoveL", self.backed_off(here, back), APPROACH_SPEED * 2, name="back off")
            tw.run_motion("MoveJ", self.backed_off(pose, back), TRAVEL_SPEED, name=f"over {name}")
        for d in drives:
            tw.write(d, start[d])
        self.wait_in_position(drives, 10.0)
        if robot:
            tw.run_motion("MoveL", pose, APPROACH_SPEED, name=f"onto {name}")
        tw.step(3)
        self.close_and_hold(name, mode, where, drives, drive_of, plans, goal, result)
        # let go and leave
        if (robot or self.lift_axis) and result.capacity is not None:
            self.lift(name, where, pose if robot else None, result)
        for d in drives:
            tw.write(d, start[d])
        self.wait_in_position(drives, 10.0)
        if robot:
            tw.run_motion("MoveL", self.backed_off(tw.tcp_pose(), back), APPROACH_SPEED * 2, name="away")
        else:  # back where the station put them: the next grip is planned from there
            for d, q in self.home.items():
                tw.write(d, q)
            self.wait_in_position(list(self.home), 10.0)
        tw.step(self.steps(0.5))

    def close_and_hold(self, name, mode, where, drives, drive_of, plans, goal, result) -> None:
        tw, g = self.twin, self.g
        uid = tw.world.body_ids[name]
        fingers = self.fingers
        want = 2 if mode == "outside" else 1
        gaps = {f: self.reach.distance(f, uid) for f in fingers}
        speeds = {g.drives[d].velocity for d in drives}
        result.centred = (len(speeds) == 1 and all(v is not None for v in gaps.values())
                          and max(gaps.values()) - min(gaps.values()) <= CENTRED)
        before = self.part_pose(name).position
        self._gripped_at = None
        joints = {f: self.pressing_joint(f, drive_of[f]) for f in fingers}
        units = {f: ("rad" if self.c.getJointInfo(self.body, joints[f])[2] == 0 else "m") for f in fingers}
        res = {f: FingerResult(f, drive_of[f], units[f]) for f in fingers}
        for f in fingers:
            key = "outside" if mode == "outside" else "inside"
            q = plans[f][key]
            if q is not None and joints[f] != g.joint[drive_of[f]]:  # a mimic finger: its own joint's value
                q = next(m * q + o for j, m_name, m, o in g.mimics if j == joints[f])
            res[f].contact_geometry = q
        result.fingers = list(res.values())
        travel = max(abs(goal[d] - tw.read(d)) / g.drives[d].velocity for d in drives)
        for d in drives:
            tw.write(d, goal[d])
        status = {f: [] for f in fingers}
        t0 = tw.step_count
        limit = self.steps(travel + 1.0)
        while True:
            tw.step()
            k = tw.step_count - t0
            for f in fingers:
                status[f].append(int(tw.read(f"{f}.status")))
                if res[f].onset_step is None and tw.read(f"{f}.contact"):
                    res[f].onset_step, res[f].onset_time = k, k * tw.dt
                    res[f].onset_position = self.c.getJointState(self.body, joints[f])[0]
            if result.gripped_step is None and tw.read("GrippedPart") == name:
                result.gripped_step = k
                self._gripped_at = self.relative(name)
            if all(r.onset_step is not None for r in res.values()) or k >= limit:
                break
        for _ in range(STALL_STEPS):  # the steps a touching finger has to settle in: their status counts
            tw.step()
            for f in fingers:
                status[f].append(int(tw.read(f"{f}.status")))
        # the hold: every step's positions, forces, overlap, status; the part relative to the gripper
        n = self.steps(self.hold)
        pos = {f: [] for f in fingers}
        force = {f: [] for f in fingers}
        normal = {f: [] for f in fingers}
        pen = {f: None for f in fingers}
        moving = {d: 0 for d in drives}
        rel0 = self.relative(name)
        result.push = float(sum((self.part_pose(name).position - before) ** 2) ** 0.5)
        links = {link: f for f in fingers for link in g.finger_links[f]}
        for i in range(n):
            tw.step()
            if result.gripped_step is None and tw.read("GrippedPart") == name:
                result.gripped_step = tw.step_count - t0
                self._gripped_at = self.relative(name)
            for f in fingers:
                status[f].append(int(tw.read(f"{f}.status")))
                pos[f].append(self.c.getJointState(self.body, joints[f])[0])
                force[f].append(float(tw.read(f"{f}.force")))
                d = self.reach.distance(f, uid)
                if d is not None and (pen[f] is None or d < pen[f]):
                    pen[f] = d
            for d in drives:
                moving[d] += bool(tw.read(f"{d}.moving"))
            for f in fingers:
                res[f].contact_lost += not tw.read(f"{f}.contact")
            sums = {f: 0.0 for f in fingers}
            for pt in self.c.getContactPoints(self.body, uid):
                f = links.get(pt[3])
                if f is not None:
                    sums[f] += pt[9]
            for f in fingers:
                normal[f].append(sums[f])
            if i == n // 2 and self.want_picture:
                from .picture import render

                self.pictures.append((where, render(tw, width=480, height=360, focus=name, highlight=name,
                                                        pitch=PICTURE_PITCH)))
        result.held_creep = float(sum((self.relative(name) - rel0) ** 2) ** 0.5)
        spec = self.spec[name]
        mu = g.spec.friction * spec.friction
        for f in fingers:
            r = res[f]
            r.status = _rle(status[f])
            r.noise = max(pos[f]) - min(pos[f])
            r.position = sum(pos[f]) / n
            r.force = sum(force[f]) / n
            r.force_range = (min(force[f]), max(force[f]))
            r.normal_force = sum(normal[f]) / n
            r.closest = pen[f]
            r.penetration = None if pen[f] is None else max(0.0, -pen[f])
            d = drive_of[f]
            r.effort_share = g.chain_effort(d) * self.linkage_share(f, d, fingers)  # the weakest in its chain
            r.expected_force = r.effort_share
            if d in g.rigid_linkages:  # knuckles in series: what reaches the finger depends on where it touches
                r.expected_force = self.knuckle_force(f, d, name, g.chain_effort(d)) or r.expected_force
            r.weight_along = self.weight_along(f, d)
            r.expected_force += r.weight_along
            r.short_of_goal = abs(goal[d] - float(tw.read(f"{d}.actual")))
        result.weight = self.weight(name)
        result.capacity = mu * sum(r.normal_force for r in res.values())
        self.judge(where, want, status, res, moving, result, mu)
        self.judge_slip(name, where, "the hold")

    def weight_along(self, finger: str, drive: str) -> float:
        """The weight of what a prismatic finger's own drive moves, along its closing direction (N): a ram pressing
        down adds its weight to its drive's effort (statics); 0 where the drive moves more than this finger (a
        linkage, a lift) or turns it."""
        g, c, body = self.g, self.c, self.body
        movers = g._link_mover.get(drive, {})
        others = set().union(*(set(g.finger_links[f]) for f in g.finger_links if f != finger))
        if self.unit[drive] != "m" or not movers or others & set(movers) or any(m != 1.0 for _, m in movers.values()):
            return 0.0
        mass = sum(c.getDynamicsInfo(body, link)[0] for link in movers)
        _, axis = g._joint_frame(g.joint[drive])
        along = mass * g.closing[drive] * sum(a * v for a, v in zip(axis, self.twin.station.gravity))
        return along if abs(along) > 1e-6 * g.drives[drive].effort else 0.0  # (a level drive: none)

    @staticmethod
    def weight_note(r: FingerResult, unit: str) -> str:
        if not r.weight_along:
            return ""
        return (f" ({r.expected_force - r.weight_along:.4g} {unit} of its drive's, "
                f"{'and' if r.weight_along > 0 else 'less'} {abs(r.weight_along):.4g} {unit} of the weight it moves)")

    def range_hint(self, r: FingerResult) -> str:
        """Why a finger presses short of its effort where its drive's spring is too soft for its range: a stalled drive
        presses with its stiffness times how far its command lies past where it stands, and its holding force
        (docs/station-format.md, the drive model); the doctor commands the range's end, and only a drive whose
        full-force error is within PAST_REACH times its range presses past it with its whole effort."""
        drive = self.g.drives[r.drive]
        if r.short_of_goal is None or drive.rigid:
            return ""
        most = drive.stiffness * r.short_of_goal + drive.hold
        effort = self.g.chain_effort(r.drive)
        if most >= (1 - FORCE_TOLERANCE) * effort:
            return ""
        unit, inp = self.unit[r.drive], self.mech.input(r.drive)
        span = inp.max - inp.min
        spring, u, k = ((f"{drive.stiffness / 1000:.4g} N/mm", "N", "N/m") if unit == "m"
                        else (f"{drive.stiffness / 1000:.4g} N m/mrad", "N m", "N m/rad"))
        return (f": its range ends only {_fmt_len(r.short_of_goal, unit)} past where {r.drive} stands on the part, "
                f"and its drive's spring ({spring}) presses with at most {most:.4g} {u} there (with its "
                f"{drive.hold:.3g} {u} holding force); its full-force error, {_fmt_len(effort / drive.stiffness, unit)}, "
                f"is more than {PAST_REACH:g} times its range ({_fmt_len(span, unit)}), so it does not press past its "
                f"range's end: a stiffer drive ([gripper.joints.{r.drive}] stiffness, at least "
                f"{effort / (PAST_REACH * span):.4g} {k}) or a range of {_fmt_len(effort / drive.stiffness / PAST_REACH, unit)} "
                "gives the whole effort")

    def judge(self, where, want, status, res, moving, result, mu) -> None:
        # the grip closes when its last finger touches: one that touched first pushes an off-centre part over to the
        # others, moving (status 0), and stalls only once they hold it
        closed = max((r.onset_step for r in res.values() if r.onset_step is not None), default=None)
        unbalanced = self.unbalanced(res)
        for f, r in res.items():
            if r.onset_step is None:
                self.check(FAIL, where, f, "contact", f"never touched the part (geometry: contact at "
                           f"{_fmt_pos(r.contact_geometry, r.unit)})")
                continue
            # status: the wanted value within STALL_STEPS of the grip closing, and from then on for good
            seq = status[f]
            settled = next((k for k in range(closed - 1, len(seq)) if all(s == want for s in seq[k:])), None)
            late = None if settled is None else settled + 1 - closed
            runs = _runs(r.status)
            since = "touching" if closed == r.onset_step else f"the grip closing (every finger touching, step {closed})"
            if late is not None and late <= STALL_STEPS:
                self.check(PASS, where, f, "status", f"{want} within {max(late, 0)} steps of {since}, steady to "
                           f"the end ({runs})")
            else:
                flips = len(r.status) - 1
                self.check(FAIL, where, f, "status", f"not a steady {want} from {STALL_STEPS} steps after {since} "
                           f"(sequence {runs}; {flips} changes)")
            lim = NOISE[r.unit]
            self.check(PASS if r.noise <= lim else FAIL, where, f, "noise",
                       f"position spread {_fmt_len(r.noise, r.unit)} while pressing (<= {_fmt_len(lim, r.unit, 2)})")
            u = "N m" if f in self.g.revolute_fingers else "N"
            ratio = r.force / r.expected_force if r.expected_force else float("nan")
            ok = abs(ratio - 1) <= FORCE_TOLERANCE
            self.check(PASS if ok else FAIL, where, f, "force",
                       f"{r.force:.4g} {u} (from {r.force_range[0]:.4g} to {r.force_range[1]:.4g}) against "
                       f"{r.expected_force:.4g} {u} of effort{self.weight_note(r, u)}: {ratio:.3f} (within "
                       f"{FORCE_TOLERANCE:.0%})"
                       + ("" if ok or ratio > 1 or unbalanced else self.range_hint(r)))
            if r.penetration is None:
                self.check(WARN, where, f, "penetration", "not measured (the finger's shapes)")
            else:
                ok = r.penetration <= PENETRATION
                self.check(PASS if ok else FAIL, where, f, "penetration", f"{_fmt_depth(r)} while pressing (<= "
                           f"{_fmt_len(PENETRATION, digits=1)})")
        for f, r in res.items():
            if r.onset_step is not None and r.contact_lost:
                self.check(FAIL, where, f, "contact", f"contact flag off in {r.contact_lost} of the hold's "
                           f"{self.steps(self.hold)} steps while pressing")
        for d, k in moving.items():
            if k:
                self.check(FAIL, where, d, "moving", f"{d}.moving on in {k} of the hold's steps while pressing")
        if result.centred:
            self.check(PASS if result.push < PUSH else FAIL, where, "grip", "push",
                       f"part moved {_fmt_len(result.push)} while the fingers closed (centred: < "
                       f"{_fmt_len(PUSH, digits=1)})")
        else:
            self.check(INFO, where, "grip", "push", f"part moved {_fmt_len(result.push)} while the fingers closed "
                       "(not centred between the fingers: no limit)")
        self.check(PASS if result.held_creep < HELD_CREEP else FAIL, where, "grip", "creep",
                   f"{_fmt_len(result.held_creep)} relative to the gripper in {self.hold:g} s held at rest "
                   f"(< {_fmt_len(HELD_CREEP, digits=1)})")
        ratio = result.capacity / result.weight if result.weight else float("inf")
        fingers = ", ".join(f"{f} {r.normal_force:.4g} N" for f, r in res.items())
        text = (f"mu {mu:.3g} x {sum(r.normal_force for r in res.values()):.4g} N ({fingers}) = "
                f"{result.capacity:.4g} N, {ratio:.2f}x the weight {result.weight:.4g} N")
        if self.g.spec.grip == "attach":
            self.check(INFO, where, "grip", "capacity", text + " (grip = \"attach\": held by the attachment)")
        elif ratio >= CAPACITY:
            self.check(PASS, where, "grip", "capacity", text + f" (>= {CAPACITY:g}x)")
        elif ratio >= 1.0:
            self.check(WARN, where, "grip", "capacity", text + f" (< {CAPACITY:g}x: a lift may slip)")
        else:
            self.check(FAIL, where, "grip", "capacity", text + " (< 1x: cannot hold it)")
        if result.gripped_step is None:
            self.check(WARN, where, "grip", "doGripped", "never reported the part gripped")
        self.judge_balance(where, res, result)

    def unbalanced(self, res: dict) -> dict:
        """The fingers' efforts (finger -> N or N m) where they differ by more than the force tolerance, else {}."""
        expected = {f: r.effort_share for f, r in res.items() if r.effort_share is not None}
        if not expected or max(expected.values()) <= (1 + FORCE_TOLERANCE) * min(expected.values()):
            return {}
        return expected

    def judge_balance(self, where: str, res: dict, result) -> None:
        """A FAIL where the drives' efforts do not balance across the part and it walks in the grip, or a finger stands
        at an end of its range while pressing: the stronger push the part, and the weaker, until a stop holds a finger
        (why the grip's status, noise, push and creep lines fail, and a force reads what the others push)."""
        tw, at_end = self.twin, []
        expected = self.unbalanced(res)
        if not expected:
            return
        for f, r in res.items():
            d = r.drive
            if r.onset_step is None or d is None:
                continue
            inp, way, q = self.mech.input(d), self.g.closing[d], float(tw.read(f"{d}.actual"))
            for end, which in ((inp.min, "open" if way > 0 else "closed"), (inp.max, "closed" if way > 0 else "open")):
                if abs(q - end) <= IN_POSITION_TOLERANCE[inp.unit]:
                    at_end.append(f"{f} stands at its range's {which} end")
        walked = [] if result.held_creep is None or result.held_creep < HELD_CREEP else [
            f"the part walked {_fmt_len(result.held_creep)} in the hold"]
        if at_end or walked:
            unit = {f: "N m" if f in self.g.revolute_fingers else "N" for f in expected}
            efforts = ", ".join(f"{f} {e:.4g} {unit[f]}" for f, e in expected.items())
            self.check(FAIL, where, "grip", "balance",
                       f"the drives' efforts do not balance across the part ({efforts}): the stronger push it, and the "
                       f"weaker, until a stop holds a finger ({'; '.join(at_end + walked)})")

    def judge_slip(self, name: str, where: str, when: str) -> None:
        """`slip` must say whether the part moved more than slip_distance relative to the gripper since the grip
        (docs/station-format.md): a WARN when it says otherwise (1 mm either side is left to the physics)."""
        if self._gripped_at is None:
            return
        moved = float(sum((self.relative(name) - self._gripped_at) ** 2) ** 0.5)
        raised, limit = bool(self.twin.read("slip")), self.g.spec.slip_distance
        if raised and moved < limit - 1e-3:
            self.check(WARN, where, "grip", "slip", f"raised at the end of {when}, the part {_fmt_len(moved)} from "
                       f"where it was gripped (slip_distance {_fmt_len(limit, digits=1)})")
        elif not raised and moved > limit + 1e-3:
            self.check(WARN, where, "grip", "slip", f"low at the end of {when}, the part {_fmt_len(moved)} from "
                       f"where it was gripped (slip_distance {_fmt_len(limit, digits=1)})")

    def lift(self, name, where, pose, result) -> None:
        tw = self.twin
        rel0 = self.relative(name)
        if pose is not None:
            tw.run_motion("MoveL", self.backed_off(pose, LIFT), LIFT_SPEED, name="lift")
            height = LIFT
        else:  # the gripper's own lift axis
            axis, up = self.lift_axis
            inp, here = self.mech.input(axis), tw.read(axis)
            goal = min(max(here + up * LIFT, inp.min), inp.max)  # (in m: a lift axis is prismatic)
            height = abs(goal - here)
            tw.write(axis, goal)
            self.wait_in_position([axis], height / self.g.drives[axis].velocity + 2.0)
        tw.step(self.steps(1.0))
        result.lift_slip = float(sum((self.relative(name) - rel0) ** 2) ** 0.5)
        result.lift_signal_slip = bool(tw.read("slip"))
        ratio = result.capacity / result.weight if result.weight else float("inf")
        text = (f"part moved {_fmt_len(result.lift_slip)} relative to the gripper in a {height * 1000:.0f} mm lift and "
                f"1 s hanging (slip {'raised' if result.lift_signal_slip else 'low'})")
        if ratio >= CAPACITY or self.g.spec.grip == "attach":
            self.check(PASS if result.lift_slip <= LIFT_SLIP else FAIL, where, "grip", "lift",
                       text + f" (<= {_fmt_len(LIFT_SLIP, digits=1)})")
        else:
            self.check(WARN if result.lift_slip > LIFT_SLIP else INFO, where, "grip", "lift", text)
        self.judge_slip(name, where, "the lift")
        if pose is not None:
            tw.run_motion("MoveL", pose, APPROACH_SPEED, name="set down")
        else:
            tw.write(axis, here)
            self.wait_in_position([axis], height / self.g.drives[axis].velocity + 2.0)
        tw.step(3)


def format_report(report: Report) -> str:
    """The report as `twin check` prints it: per grip a table of the fingers, then the verdict lines."""
    lines = [f"twin check {report.file} (station {report.station}, hold {report.hold:g} s)"]
    by_where: dict[str, list[Check]] = {}
    for c in report.checks:
        by_where.setdefault(c.where, []).append(c)
    lines += [c.line() for c in by_where.pop("station", [])]
    for name, creep in report.rest_creep.items():
        lines += [f"{name}: resting on its support"] + ["  " + c.line() for c in by_where.pop(f"{name} resting", [])]
    for grip in report.grips:
        where = f"{grip.target} {grip.mode}"
        checks = by_where.pop(where, [])
        if grip.skipped and not checks:
            lines.append(f"{where} grip: not checked ({grip.skipped})")
            continue
        lines.append(f"{where} grip" + (f": not checked ({grip.skipped})" if grip.skipped else ""))
        if grip.fingers:
            rows = [("finger", "drive", "contact (geometry)", "onset", "status", "noise", "penetration",
                     "force / effort", "normal")]
            for r in grip.fingers:
                onset = ("never" if r.onset_step is None else
                         f"step {r.onset_step} ({r.onset_time:.3f} s) at {_fmt_pos(r.onset_position, r.unit)}")
                u = "N" if r.unit == "m" else "N m"
                force = "-" if r.force is None else f"{r.force:.4g} / {r.expected_force:.4g} {u}"
                rows.append((r.finger, r.drive, _fmt_pos(r.contact_geometry, r.unit), onset,
                             _runs(r.status, 4), _fmt_len(r.noise, r.unit),
                             _fmt_depth(r, short=True), force,
                             "-" if r.normal_force is None else f"{r.normal_force:.4g} N"))
            widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
            for row in rows:
                lines.append("  " + "  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
        lines += ["  " + c.line() for c in checks]
    for rest in by_where.values():
        lines += [c.line() for c in rest]
    n_fail = sum(c.level == FAIL for c in report.checks)
    n_warn = sum(c.level == WARN for c in report.checks)
    n_pass = sum(c.level == PASS for c in report.checks)
    lines.append(f"verdict: {'FAIL' if n_fail else 'PASS'} ({n_pass} pass, {n_warn} warn, {n_fail} fail)")
    failed: dict[str, dict[str, list[str]]] = {}  # where -> who -> measures
    for c in report.checks:
        if c.level == FAIL:
            failed.setdefault(c.where, {}).setdefault(c.who, []).append(c.measure)
    for where, whos in failed.items():
        lines.append(f"  failed in {where}: " + "; ".join(f"{who} {', '.join(dict.fromkeys(m))}"
                                                            for who, m in whos.items()))
    return "\n".join(lines)


def save_pictures(pictures: list, path) -> Path:
    """The grips side by side in one PNG (twin.observe.picture draws each, headless)."""
    import numpy as np
    from PIL import Image, ImageDraw

    from .picture import save_png

    labelled = []
    for where, img in pictures:
        im = Image.fromarray(img)
        draw = ImageDraw.Draw(im)
        draw.rectangle([0, 0, 8 + 7 * len(where), 18], fill=(255, 255, 255))
        draw.text((4, 3), where, fill=(0, 0, 0))
        labelled.append(np.asarray(im))
    return save_png(np.concatenate(labelled, axis=1), path)


def check_station(path, hold: float = 5.0, picture: bool = False, log=None):
    """Load the station, run the doctor, return (report, pictures)."""
    from twin.core import Twin

    with Twin.from_station(path) as twin:
        doctor = Doctor(twin, hold=hold, picture=picture, log=log)
        report = doctor.run()
        return report, doctor.pictures
