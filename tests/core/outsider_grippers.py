"""Four grippers written from the docs alone by outsiders (tests/grippers/{tri_120_60n,heavy_800n,scissor_mimic,
tiny_2n}), in numbers of their own: where each finger's working face lies for a joint position, from the URDFs as
written (not from the twin), how far a part's nominal shape reaches towards it, and what statics says each finger
presses with; `run` drives one through the simulation API (rest, close past the part, press) and records each step."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from twin.core import Twin

GRIPPERS = Path(__file__).resolve().parents[1] / "grippers"
G = 9.81


def rot(quat) -> np.ndarray:
    x, y, z, w = quat
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def box_reach(pose, half, u) -> float:
    """How far a box (centre, quaternion; half sizes) reaches along the unit direction u from the origin."""
    c, q = np.array(pose[0]), pose[1]
    r = rot(q)
    return float(c @ u + sum(abs(r[:, i] @ u) * half[i] for i in range(3)))


def cylinder_reach(pose, radius, height, u) -> float:
    c, q = np.array(pose[0]), pose[1]
    a = rot(q)[:, 2]
    au = float(a @ u)
    return float(c @ u + radius * math.sqrt(max(0.0, 1 - au * au)) + height / 2 * abs(au))


@dataclass
class Gripper:
    """One outsider gripper: its inputs' closing ends, each finger's penetration into the part (m, > 0 overlap)
    as a function of the joint positions and the part's pose, and the force statics gives each finger."""

    name: str
    part: str
    inputs: dict            # input -> setpoint at the closed end of its range (past the part)
    fingers: tuple          # finger signal names
    expected: dict          # finger -> N (N m for a revolute finger): what statics says it presses with
    weight: float           # the part's weight, N
    floor_mu: float         # friction coefficient part-floor (0.5 x 0.5)
    penetration: object = field(repr=False)   # (joint positions dict, part pose) -> {finger: m}
    normals: object = field(repr=False, default=None)   # finger -> unit vector of its push on the part (prismatic)
    revolute: bool = False

    @property
    def station(self) -> Path:
        return GRIPPERS / self.name


# --- a) three 60 N fingers at 120 degrees, a 50 mm aluminium cylinder (r 25 mm, h 60 mm) at the origin ----------
_TRI_DIRS = {f"f{k + 1}": np.array([math.cos(a), math.sin(a), 0.0])
             for k, a in enumerate((0.0, 2 * math.pi / 3, -2 * math.pi / 3))}


def _tri_pen(q, pose):
    return {f: cylinder_reach(pose, 0.025, 0.06, u) - q[f] for f, u in _TRI_DIRS.items()}


TRI = Gripper("tri_120_60n", "can", {"f1": 0.012, "f2": 0.012, "f3": 0.012}, ("f1", "f2", "f3"),
              {"f1": 60.0, "f2": 60.0, "f3": 60.0}, math.pi * 0.025 ** 2 * 0.06 * 2700 * G, 0.25, _tri_pen,
              {f: -u for f, u in _TRI_DIRS.items()})

# --- b) 800 N jaws of 2 kg; a steel block 80 x 100 x 80 mm at the origin; jaw faces at x = -0.12 + qa, 0.12 - qb --
_X = np.array([1.0, 0.0, 0.0])


def _heavy_pen(q, pose):
    half = (0.04, 0.05, 0.04)
    return {"jaw_a": (-0.12 + q["jaw_a"]) + box_reach(pose, half, -_X),
            "jaw_b": box_reach(pose, half, _X) - (0.12 - q["jaw_b"])}


HEAVY = Gripper("heavy_800n", "block", {"jaw_a": 0.11, "jaw_b": 0.11}, ("jaw_a", "jaw_b"),
                {"jaw_a": 800.0, "jaw_b": 800.0}, 0.08 * 0.1 * 0.08 * 7850 * G, 0.25, _heavy_pen,
                {"jaw_a": _X, "jaw_b": -_X})

# --- d) 2 N fingers of 5 g; a 10 mm cube of 2 g at the origin; finger faces at x = -0.03 + qa, 0.03 - qb ------------


def _tiny_pen(q, pose):
    half = (0.005, 0.005, 0.005)
    return {"finger_a": (-0.03 + q["finger_a"]) + box_reach(pose, half, -_X),
            "finger_b": box_reach(pose, half, _X) - (0.03 - q["finger_b"])}


TINY = Gripper("tiny_2n", "cube", {"finger_a": 0.03, "finger_b": 0.03}, ("finger_a", "finger_b"),
               {"finger_a": 2.0, "finger_b": 2.0}, 1e-6 * 2000 * G, 0.25, _tiny_pen,
               {"finger_a": _X, "finger_b": -_X})

# --- c) scissor: levers 8 x 20 x 100 mm hanging from pivots (+-0.02, 0, 0.12) about y, lever_a = -lever_b;
#        an ABS cylinder r 12 mm, h 42 mm, standing at the origin. By virtual work the 1 N m drive gives each
#        lever E / (|m_b| + |m_a|) = 0.5 N m.
PIVOT_Z = 0.12


def lever_corner(theta: float, side: int) -> np.ndarray:
    """The inner bottom corner of a lever in the xz plane (side +1: lever_b at x = +0.02, -1: lever_a at -0.02).
    Rotation by t about +y takes (x, z) to (x cos t + z sin t, -x sin t + z cos t)."""
    t = theta if side > 0 else -theta          # lever_a turns by -theta_b
    lx, lz = -0.004 * side, -0.1
    return np.array([side * 0.02 + lx * math.cos(t) + lz * math.sin(t), PIVOT_Z - lx * math.sin(t) + lz * math.cos(t)])


def _scissor_pen(q, pose):
    c = np.array(pose[0])
    out = {}
    for name, side in (("lever_b", 1), ("lever_a", -1)):
        x, z = lever_corner(q["lever_b"], side)
        assert 0.0 <= z <= 0.042 + 1e-3, z     # the corner is what meets the peg's side
        out[name] = (c[0] + side * 0.012 - x) * side
    return out


SCISSOR = Gripper("scissor_mimic", "peg", {"lever_b": 0.35}, ("lever_b", "lever_a"),
                  {"lever_b": 0.5, "lever_a": 0.5}, math.pi * 0.012 ** 2 * 0.042 * 1050 * G, 0.25, _scissor_pen,
                  revolute=True)

ALL = (TRI, HEAVY, SCISSOR, TINY)


def run(g, rest_steps: int, press_steps: int) -> dict:
    """Rest for rest_steps with the fingers open, then command every input to its closed end and step
    press_steps more. Per step: joint positions, statuses, moving flags, forces, efforts, slip, part pose."""
    rec = {k: [] for k in ("q", "status", "moving", "force", "effort", "slip", "gripped", "pose", "actual_in_range")}
    with Twin.from_station(g.station) as twin:
        specs = {s.name: s for s in twin.signals}
        start = twin.object_pose(g.part)

        def sample():
            q = {i: twin.read(f"{i}.actual") for i in g.inputs}
            rec["q"].append(q)
            rec["actual_in_range"].append(all(specs[i].min <= q[i] <= specs[i].max for i in g.inputs))
            rec["status"].append({f: twin.read(f"{f}.status") for f in g.fingers})
            rec["moving"].append({i: twin.read(f"{i}.moving") for i in g.inputs})
            rec["force"].append({f: twin.read(f"{f}.force") for f in g.fingers})
            rec["effort"].append({i: twin.read(f"{i}.effort") for i in g.inputs})
            rec["slip"].append(twin.read("slip"))
            rec["gripped"].append(twin.read("doGripped"))
            rec["pose"].append(twin.object_pose(g.part))

        for _ in range(rest_steps):
            twin.step()
            sample()
        for name, value in g.inputs.items():
            twin.write(name, value)
        for _ in range(press_steps):
            twin.step()
            sample()
        rec["dt"] = twin.dt
    rec["start"] = start
    rec["rest_steps"] = rest_steps
    return rec


def penetrations(g, rec) -> list[dict]:
    return [g.penetration(q, pose) for q, pose in zip(rec["q"], rec["pose"])]


def first_touch(g, rec, pen) -> dict:
    """Per finger, the first step index (after the closing command) where the geometry says it touches
    (overlap above -0.05 mm, the contact flag's tolerance)."""
    out = {}
    for f in g.fingers:
        out[f] = next(k for k in range(rec["rest_steps"], len(pen)) if pen[k][f] > -0.05e-3)
    return out


def displacement(a, b) -> float:
    return float(np.linalg.norm(np.array(a[0]) - np.array(b[0])))


def tri_in_a_bore(folder: Path) -> Path:
    """tri_120_60n standing in the bore of an aluminium ring (60 mm bore flat to flat, 90 mm outside, 30 mm tall,
    12 faces, one facing each finger): its fingers' outer faces, at a radius of q + 10 mm, meet the bore at
    q = 20 mm; opening them is an inside grip. Returns the station file written into `folder`."""
    urdf = (GRIPPERS / "tri_120_60n" / "gripper.urdf").as_posix()
    path = folder / "station.toml"
    path.write_text(f"""[station]
name = "tri_120_60n_bore"

[gripper]
urdf = "{urdf}"
mount = {{ xyz = [0.0, 0.0, 0.15], rpy_deg = [0.0, 0.0, 0.0] }}
always_active = true
initial = {{ f1 = 0.012, f2 = 0.012, f3 = 0.012 }}

[[targets]]
name = "ring"
shape = "ring"
xyz = [0.0, 0.0, 0.015]
outer_diameter = 0.09
inner_diameter = 0.06
height = 0.03
density = 2700.0

[[fixtures]]
name = "floor"
shape = "plane"
xyz = [0.0, 0.0, 0.0]
""")
    return path


def scissor_at(folder: Path, multiplier: float) -> Path:
    """scissor_mimic with its mimic lever at another multiplier (its limits hold for -0.5 .. -1); the station
    file written into `folder`."""
    src = GRIPPERS / "scissor_mimic"
    (folder / "gripper.urdf").write_text((src / "gripper.urdf").read_text()
                                         .replace('multiplier="-1"', f'multiplier="{multiplier}"'))
    (folder / "station.toml").write_text((src / "station.toml").read_text())
    return folder / "station.toml"
