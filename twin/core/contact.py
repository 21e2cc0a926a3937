"""Exact contact queries: the finger links' and targets' nominal shapes in a world of their own.

pybullet rounds every convex shape by its collision margin (1 mm for shapes loaded from a URDF, and
`changeDynamics(collisionMargin=...)` does not reach them): a box finger's corner meets a flat face 0.73 mm
late, an edge 0.41 mm late. The physics keeps those shapes; the contact flag asks this separate world instead,
where copies of the finger links' collision shapes and of the targets carry a 0.01 mm margin. Before a query
each copy is put where its original is. The physics world is not touched (bodies that never touch anything
still change a pybullet world's results), so replays stay bit-identical.
"""
from __future__ import annotations

from .bullet import BulletClient, pybullet

from .meshes import HULL_MARGIN, prepared
from .native_output import quiet_native_output

PROBE_MARGIN = 0.00001  # m: the copies' margin (a hull's lies outside it and is counted off)


class ContactProbe:
    """Finger-link and target copies for exact closest-distance queries."""

    def __init__(self, physics, body: int, finger_links: dict[str, list[int]], targets: dict[str, int],
                 make_target):
        """`make_target(client, name) -> body id` builds a target's shape in the probe world (as the world did)."""
        self.physics, self.body = physics, body
        with quiet_native_output():
            self.client = BulletClient(connection_mode=pybullet.DIRECT)
        from .world import bind_calls

        bind_calls(self.client)
        c = self.client
        self.links: dict[int, tuple[int, float]] = {}  # physics link -> (probe body, distance correction)
        for links in finger_links.values():
            for link in links:
                made = self._copy_link(link)
                if made is not None:
                    self.links[link] = made
        self.targets: dict[int, int] = {}  # physics body -> probe body
        for name, uid in targets.items():
            copy = make_target(c, name)
            c.changeDynamics(copy, -1, collisionMargin=PROBE_MARGIN)
            self.targets[uid] = copy

    def _copy_link(self, link: int):
        c, p = self.client, self.physics
        shapes = p.getCollisionShapeData(self.body, link)
        types, kw = [], {"halfExtents": [], "radii": [], "lengths": [], "fileNames": [], "meshScales": [],
                         "collisionFramePositions": [], "collisionFrameOrientations": []}
        correction = 0.0
        for s in shapes:
            kind, dims = s[2], s[3]
            if kind not in (pybullet.GEOM_BOX, pybullet.GEOM_SPHERE, pybullet.GEOM_CYLINDER, pybullet.GEOM_CAPSULE,
                            pybullet.GEOM_MESH):
                return None
            types.append(kind)
            kw["halfExtents"].append([v / 2 for v in dims] if kind == pybullet.GEOM_BOX else [0, 0, 0])
            kw["radii"].append(dims[0] if kind == pybullet.GEOM_SPHERE else dims[1] if kind != pybullet.GEOM_BOX else 0)
            kw["lengths"].append(dims[0] if kind in (pybullet.GEOM_CYLINDER, pybullet.GEOM_CAPSULE) else 0)
            kw["fileNames"].append(s[4].decode() if kind == pybullet.GEOM_MESH else "")
            kw["meshScales"].append(list(dims) if kind == pybullet.GEOM_MESH else [1, 1, 1])
            kw["collisionFramePositions"].append(list(s[5]))
            kw["collisionFrameOrientations"].append(list(s[6]))
            if kind == pybullet.GEOM_MESH and not prepared(s[4].decode()):
                correction = HULL_MARGIN  # pybullet's hull of a mesh stands this far outside it: distances read short
        if not types:
            return None
        try:
            shape = c.createCollisionShapeArray(types, **kw)
        except pybullet.error:
            return None
        copy = c.createMultiBody(0, shape)
        # a rewritten mesh's pieces need pybullet's own hull margin round them to be the mesh's surface (meshes.py)
        exact_mesh = any(s[2] == pybullet.GEOM_MESH and prepared(s[4].decode()) for s in shapes)
        c.changeDynamics(copy, -1, collisionMargin=HULL_MARGIN if exact_mesh else PROBE_MARGIN)
        return copy, correction

    def covers(self, link: int) -> bool:
        return link in self.links

    def distance(self, link: int, target: int, within: float) -> float | None:
        """The closest distance of a finger link's nominal shape to a target's, or None beyond `within`."""
        c, p = self.client, self.physics
        copy, correction = self.links[link]
        state = p.getLinkState(self.body, link, computeForwardKinematics=True)
        c.resetBasePositionAndOrientation(copy, state[0], state[1])  # the link's inertial frame
        pos, orn = p.getBasePositionAndOrientation(target)
        c.resetBasePositionAndOrientation(self.targets[target], pos, orn)
        points = c.getClosestPoints(copy, self.targets[target], within + correction)
        return min((pt[8] + correction for pt in points), default=None)

    def close(self) -> None:
        try:
            self.client.disconnect()
        except pybullet.error:
            pass
