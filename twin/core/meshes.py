"""Mesh collision shapes as pybullet would get them right: the mesh's own surface, not 1 mm proud of its hull.

pybullet turns a URDF's collision mesh into one convex hull with a 1 mm collision margin *outside* it, and neither
`changeDynamics(collisionMargin=...)` nor any load flag reaches that margin (measured: a mesh box 10 mm from a box
reads 9.0 mm, with or without `URDF_INITIALIZE_SAT_FEATURES`, `enableSAT` or a margin set afterwards). So a mesh finger
touches a part 1 mm before its surface does, and where the mesh is concave (pybullet_data's pr2_gripper finger has a
40 mm notch and a 9 mm groove on its inner side) the hull fills what is not there: contacts 1 to 5 mm off the mesh.

Instead, the world loads a rewritten mesh (an OBJ in its own folder, one object per piece; pybullet makes each
object of an OBJ one convex hull): every triangle becomes a flat piece whose corners are the rounding centres of its
vertices, each `HULL_MARGIN` under every face that meets that vertex (the least such move, solved per vertex; also
across a T-junction, where a vertex lies on the next triangle's edge). pybullet's margin round the pieces then
brings flat faces exactly back to the mesh and rounds its sharp edges and corners by the margin, as it rounds a box
(a right-angled edge met 0.41 mm late, a corner of three right angles 0.73 mm), never early. Flaps of no volume
(two triangles back to back over an edge) are left out. The pieces are 2 mm thick: a mesh wall thinner than that
stands proud on its far side.
Meshes this cannot read (a format other than STL and OBJ, more than MAX_PIECES triangles, or triangles whose
winding disagrees, so that no side is known to be outside) keep pybullet's hull; `prepared` tells which is which.
"""
from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

HULL_MARGIN = 0.001  # m: the margin pybullet puts round every convex hull it makes of a URDF mesh (fixed)
WINDING_SLACK = 0.02  # a mesh whose windings disagree on more of its edges than this share is not rewritten
MAX_PIECES = 5000  # a mesh of more triangles keeps pybullet's hull (a piece each: 2 ms a step for the PR2's 400 pieces)
MAX_DEPTH = 3.0  # a vertex's rounding centre lies at most this many margins inside it (a knife edge)
FOLD_COS = -0.9  # two triangles over one edge whose normals are further apart than this are a fold (left out)
SUFFIX = ".surface.obj"  # the rewritten mesh's name ends so: `prepared` knows it


def prepared(path: str | Path) -> bool:
    """Whether a collision mesh file is one this module wrote (its surface is exact: no margin to count off)."""
    return str(path).endswith(SUFFIX)


def read_mesh(path: Path) -> tuple[np.ndarray, np.ndarray] | None:
    """(vertices (n, 3), triangles (m, 3) of vertex indices) of an STL (binary or ASCII) or OBJ file; None for any
    other format."""
    suffix = path.suffix.lower()
    if suffix == ".stl":
        return _read_stl(path.read_bytes())
    if suffix == ".obj":
        return _read_obj(path.read_text(errors="replace"))
    return None


def _read_stl(data: bytes) -> tuple[np.ndarray, np.ndarray] | None:
    if len(data) >= 84:
        count = struct.unpack_from("<I", data, 80)[0]
        if 84 + 50 * count == len(data):  # binary: 80-byte header, count, 50 bytes per triangle
            rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                                count=count, offset=84)
            return _merge(rec["v"].reshape(-1, 3).astype(float))
    words = data.decode(errors="replace").split()
    points = [[float(words[i + 1]), float(words[i + 2]), float(words[i + 3])]
              for i, w in enumerate(words) if w == "vertex"]
    if not points or len(points) % 3:
        return None
    return _merge(np.asarray(points, dtype=float))


def _merge(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shared vertices from a triangle soup (STL repeats each vertex in every triangle)."""
    vertices, index = np.unique(corners, axis=0, return_inverse=True)
    return vertices, index.reshape(-1, 3)


def _read_obj(text: str) -> tuple[np.ndarray, np.ndarray] | None:
    vertices, faces = [], []
    for line in text.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v" and len(parts) >= 4:
            vertices.append([float(x) for x in parts[1:4]])
        elif parts[0] == "f" and len(parts) >= 4:
            idx = [int(p.split("/")[0]) for p in parts[1:]]
            idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
            faces += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]  # a polygon as a fan
    if not vertices or not faces:
        return None
    return np.asarray(vertices, dtype=float), np.asarray(faces, dtype=int)


def surface_pieces(vertices: np.ndarray, faces: np.ndarray, margin: float = HULL_MARGIN) -> list[np.ndarray] | None:
    """The flat triangles (3 points each) whose union, each rounded by `margin`, is the mesh's surface (module
    docstring). None when the triangles' winding disagrees (no side is known to be outside), or when there are more
    than MAX_PIECES of them."""
    if len(faces) > MAX_PIECES:
        return None  # as many hulls would cost more physics than a finger is worth: pybullet's hull stays
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = np.linalg.norm(normal, axis=1)
    keep = area > 1e-14
    faces, tri, normal, area = faces[keep], tri[keep], normal[keep] / area[keep, None], area[keep]
    edges: set[tuple[int, int]] = set()
    clashes = 0
    for a, b, c in faces:
        for e in ((a, b), (b, c), (c, a)):
            clashes += e in edges  # two triangles run along one edge the same way: there the windings disagree
            edges.add(e)
    if clashes > WINDING_SLACK * len(edges):
        return None  # no side is known to be outside
    if np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() < 0.0:  # wound inwards: turn round
        faces, tri, normal = faces[:, ::-1], tri[:, ::-1], -normal
    # a fold (two triangles back to back over an edge, a flap of no volume) has no outside: left out
    by_edge: dict[tuple[int, int], list[int]] = {}
    for k, (a, b, c) in enumerate(faces):
        for e in ((a, b), (b, c), (c, a)):
            by_edge.setdefault((min(e), max(e)), []).append(k)
    fold = np.zeros(len(faces), dtype=bool)
    for ks in by_edge.values():
        for i in ks:
            for j in ks:
                if normal[i] @ normal[j] < FOLD_COS:
                    fold[i] = fold[j] = True
    faces, tri, normal, area = faces[~fold], tri[~fold], normal[~fold], area[~fold]
    # each vertex's rounding centre: `margin` under every face that meets it (also across a T-junction: a face whose
    # edge it lies on), so the margin brings the faces back exactly and rounds edges and corners off by it, as
    # pybullet rounds a box's (contact at a right-angled edge 0.41 mm late, at a corner of three right angles 0.73 mm), never early
    touching = _faces_at_vertices(vertices, faces, tri)
    centre = np.empty_like(vertices)
    for v, fs in enumerate(touching):
        if not len(fs):  # on no triangle (a stray point): not part of any piece
            centre[v] = vertices[v]
            continue
        ns = normal[fs]
        x = np.linalg.lstsq(ns, np.full(len(fs), margin), rcond=1e-6)[0]  # the least move with x . n = margin
        low = ns @ x
        if (low < margin * (1 - 1e-9)).any():  # more than three ways at once: deeper, so that it is under each
            x *= margin / max(low.min(), margin / MAX_DEPTH)
        if np.linalg.norm(x) > MAX_DEPTH * margin:  # a knife edge: no deeper than this
            x *= MAX_DEPTH * margin / np.linalg.norm(x)
        centre[v] = vertices[v] - x
    return [centre[ids] for ids in faces]


def _faces_at_vertices(vertices: np.ndarray, faces: np.ndarray, tri: np.ndarray,
                       tolerance: float = 1e-7) -> list[np.ndarray]:
    """Per vertex, the triangles it lies on: those it is a corner of and, for a vertex on an open edge (a T-junction:
    the next triangles' edge runs past it), those whose edge or face it lies on within `tolerance`."""
    at: list[list[int]] = [[] for _ in range(len(vertices))]
    edges: set[tuple[int, int]] = set()
    for k, (a, b, c) in enumerate(faces):
        at[a].append(k)
        at[b].append(k)
        at[c].append(k)
        edges.update(((a, b), (b, c), (c, a)))
    open_ends = {v for a, b in edges if (b, a) not in edges for v in (a, b)}
    for v in sorted(open_ends):
        near = np.nonzero(_point_triangle_distance(vertices[v], tri[:, 0], tri[:, 1], tri[:, 2]) <= tolerance)[0]
        at[v] = sorted(set(at[v]) | set(near.tolist()))
    return [np.asarray(fs, dtype=int) for fs in at]


def _point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The distance from point p to each triangle (a[i], b[i], c[i]): to its plane inside it, else to its edges."""
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    plane = np.abs(np.einsum("ij,ij->i", p - a, n))
    inside = np.ones(len(a), dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, p - u), n) >= 0.0
    edge = np.full(len(a), np.inf)
    for u, v in ((a, b), (b, c), (c, a)):
        e = v - u
        t = np.clip(np.einsum("ij,ij->i", p - u, e) / np.maximum(np.einsum("ij,ij->i", e, e), 1e-30), 0.0, 1.0)
        edge = np.minimum(edge, np.linalg.norm(p - (u + t[:, None] * e), axis=1))
    return np.where(inside, plane, edge)


def write_pieces(pieces: list[np.ndarray], path: Path) -> None:
    """One OBJ object per piece (pybullet makes each one convex hull)."""
    lines = []
    for k, piece in enumerate(pieces):
        lines.append(f"o piece_{k}")
        lines += [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in piece]
        lines.append("f " + " ".join(str(3 * k + i) for i in (1, 2, 3)))
    path.write_text("\n".join(lines) + "\n")


CYLINDER_SIDES = 48  # a URDF cylinder's surface prism: its sides lie at most 0.2 % of its radius inside the circle


def surface_cylinder(radius: float, length: float, out_dir: Path, name: str) -> Path | None:
    """Write a URDF collision cylinder (its axis along z, centred) as its surface for pybullet: one convex prism of
    CYLINDER_SIDES sides whose corners lie HULL_MARGIN inside the cylinder's side and ends, which pybullet's margin
    round its hull brings back out to them (never early: a side's middle 0.2 % of the radius late). pybullet itself
    makes a URDF cylinder a hull 1 mm proud of it (a round pad touches a part 1 mm early). None when the cylinder is
    too thin for that (the caller keeps pybullet's hull)."""
    r, h = radius - HULL_MARGIN, length / 2 - HULL_MARGIN
    if r <= 0.0 or h <= 0.0:
        return None
    n = CYLINDER_SIDES
    ring = [(r * np.cos(2 * np.pi * k / n), r * np.sin(2 * np.pi * k / n)) for k in range(n)]
    lines = [f"o {name}"] + [f"v {float(x)!r} {float(y)!r} {z!r}" for z in (-h, h) for x, y in ring]
    lines += ["f " + " ".join(str(k) for k in range(n, 0, -1)), "f " + " ".join(str(n + k) for k in range(1, n + 1))]
    lines += [f"f {k + 1} {(k + 1) % n + 1} {n + (k + 1) % n + 1} {n + k + 1}" for k in range(n)]
    out = out_dir / (name + SUFFIX)
    out.write_text("\n".join(lines) + "\n")
    return out


def surface_mesh(source: Path, scale: tuple[float, float, float], out_dir: Path, name: str) -> Path | None:
    """Write the mesh file `source` (scaled) as surface prisms into `out_dir` (`name` + SUFFIX); None when it cannot
    be read (the caller keeps the original)."""
    try:
        mesh = read_mesh(source)
    except (OSError, ValueError, struct.error):
        return None
    if mesh is None:
        return None
    vertices, faces = mesh
    pieces = surface_pieces(vertices * np.asarray(scale, dtype=float), faces)
    if not pieces:
        return None
    out = out_dir / (name + SUFFIX)
    write_pieces(pieces, out)
    return out
