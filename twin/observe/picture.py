"""`twin snapshot STATION|FILE [--at T] [-o cell.png]`: a picture of the cell, headless.

pybullet's TinyRenderer (a software rasteriser in DIRECT mode) draws the very bodies the physics
simulates, in the station's colours, with no GPU and no display. For a recording, the station it was
made from is loaded and every body put where the recording has it at time T (every movable joint of
the robot and gripper, every target's pose), so the picture shows the recorded moment; the gripped part
is drawn in a highlight colour.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from twin.core.errors import TwinError

HIGHLIGHT = (0.16, 0.86, 0.35, 1.0)


def _is_recording(path: Path) -> bool:
    return path.is_file() and path.suffix.lower() in (".parquet", ".csv", ".pq")


def camera(twin, focus: str | None = None, *, width: int, height: int, distance: float | None = None,
           yaw: float = 35.0, pitch: float = -28.0):
    """View and projection matrices that show the cell (or the body `focus`, closer)."""
    c, world = twin.world.client, twin.world
    if focus is not None:
        target = _body_position(twin, focus)
        size = 0.3
        if focus in world.body_ids:
            lo, hi = c.getAABB(world.body_ids[focus])
            size = float(np.linalg.norm(np.subtract(hi, lo)))
        dist = distance or max(0.25, 3.7 * size)  # the part and the fingers around it fill the picture
    else:
        pts = []
        for name, uid in world.body_ids.items():
            if c.getVisualShapeData(uid) and c.getVisualShapeData(uid)[0][2] == 6:  # a plane: no extent
                continue
            lo, hi = c.getAABB(uid)
            pts += [lo, hi]
        for j in range(-1, c.getNumJoints(world.machine)):
            lo, hi = c.getAABB(world.machine, j)
            pts += [lo, hi]
        a = np.array(pts, dtype=float)
        lo, hi = a.min(axis=0), a.max(axis=0)
        target = (lo + hi) / 2
        dist = distance or float(np.linalg.norm(hi - lo)) * 1.25
    view = c.computeViewMatrixFromYawPitchRoll(cameraTargetPosition=[float(v) for v in target], distance=dist,
                                               yaw=yaw, pitch=pitch, roll=0.0, upAxisIndex=2)
    proj = c.computeProjectionMatrixFOV(fov=45.0, aspect=width / height, nearVal=0.05, farVal=100.0)
    return view, proj


def _body_position(twin, key: str):
    c, world = twin.world.client, twin.world
    if key in world.body_ids:
        return c.getBasePositionAndOrientation(world.body_ids[key])[0]
    if key in world.link_index:
        j = world.link_index[key]
        return c.getBasePositionAndOrientation(world.machine)[0] if j < 0 else c.getLinkState(world.machine, j)[4]
    raise TwinError(f"no body {key!r} to look at")


def render(twin, *, width: int = 960, height: int = 720, focus: str | None = None, highlight: str = "",
           distance: float | None = None, yaw: float = 35.0, pitch: float = -28.0) -> np.ndarray:
    """An RGB picture (height x width x 3, uint8) of the twin's world as it is now."""
    from twin.core.bullet import pybullet

    c = twin.world.client
    restore = []
    if highlight and highlight in twin.world.body_ids:
        uid = twin.world.body_ids[highlight]
        for v in c.getVisualShapeData(uid):
            restore.append((uid, v[1], v[7]))
        c.changeVisualShape(uid, -1, rgbaColor=HIGHLIGHT)
    try:
        view, proj = camera(twin, focus, width=width, height=height, distance=distance, yaw=yaw, pitch=pitch)
        _, _, rgba, _, _ = c.getCameraImage(width, height, viewMatrix=view, projectionMatrix=proj,
                                            renderer=pybullet.ER_TINY_RENDERER, shadow=1,
                                            lightDirection=[-1.0, -2.0, 4.0], lightAmbientCoeff=0.55,
                                            lightDiffuseCoeff=0.5, lightSpecularCoeff=0.1)
    finally:
        for uid, link, colour in restore:
            c.changeVisualShape(uid, link, rgbaColor=colour)
    img = np.reshape(np.asarray(rgba, dtype=np.uint8), (height, width, 4))
    return img[:, :, :3].copy()


def pose_like(twin, rec, i: int) -> None:
    """Put every body of `twin` where row `i` of the recording `rec` has it (joints, targets)."""
    c, world = twin.world.client, twin.world
    frame = rec.frame(i)
    joint_index = {c.getJointInfo(world.machine, j)[1].decode(): j for j in range(c.getNumJoints(world.machine))}
    for name, q in zip(rec.scene.joints, frame.joints):
        if name in joint_index:
            c.resetJointState(world.machine, joint_index[name], float(q))
    for k, key in enumerate(rec.scene.bodies):
        if key in world.body_ids:
            p = frame.poses[k]
            c.resetBasePositionAndOrientation(world.body_ids[key], [float(v) for v in p[:3]], [float(v) for v in p[3:7]])


class RecordingCamera:
    """Pictures of a recording's moments: the station loaded once, its bodies posed per picture."""

    def __init__(self, rec):
        from twin.core import Twin

        station = Path(rec.scene.station_file)
        if not station.is_file():
            raise TwinError(f"{rec.path}: recorded from {station}, which is not there: a picture needs the station")
        self.rec = rec
        self.twin = Twin.from_station(station)

    def picture(self, t: float, **kw) -> np.ndarray:
        i = self.rec.index_at(t)
        pose_like(self.twin, self.rec, i)
        frame = self.rec.frame(i)
        gripped = frame.as_signals(self.rec.scene).get("GrippedPart") or ""
        return render(self.twin, highlight=gripped, **kw)

    def close(self) -> None:
        self.twin.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def save_png(img: np.ndarray, path: str | Path) -> Path:
    from PIL import Image

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(img).save(path)
    return path


def cmd_snapshot(args, open_cell) -> int:
    """`twin snapshot`; `open_cell(station)` (the application's) gives a station's cell."""
    out = Path(args.output)
    if out.suffix.lower() != ".png":
        raise TwinError(f"{out}: twin snapshot writes a .png")
    try:
        import PIL  # noqa: F401
    except ImportError:
        raise TwinError("twin snapshot needs Pillow (it comes with matplotlib): pip install 'gripper-twin[view]'") from None
    source = Path(args.source)
    size = dict(width=args.width, height=args.height)
    if _is_recording(source):
        from .recording import Recording

        rec = Recording.open(source)
        t = rec.time[-1] if args.at is None else args.at
        if not rec.time[0] - 1e-9 <= t <= rec.time[-1] + 1e-9:
            raise TwinError(f"{source}: --at {t:g} s is outside the recording ({rec.time[0]:g} to {rec.time[-1]:g} s)")
        with RecordingCamera(rec) as cam:
            img = cam.picture(t, **size)
    else:
        cell = open_cell(source)
        try:
            if args.at:
                if args.at < 0 or math.isnan(args.at):
                    raise TwinError(f"--at {args.at:g}: a time in s, at least 0")
                cell.step(round(args.at / cell.dt))
            img = render(cell.twin, highlight=cell.read("GrippedPart") or "", **size)
        finally:
            cell.close()
    print(save_png(img, out))
    return 0
