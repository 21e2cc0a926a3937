"""What the view draws, checked against the simulation itself: meshes load, and a finger's setpoint ghost
is where the finger really goes."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import PYBULLET_DATA, STATIONS
from tests.core.test_foreign_models import robot_station
from twin.core import Twin
from twin.observe.scene import Observer, pose_matrix, setpoint_motion


def test_the_ghost_of_a_finger_is_where_the_finger_goes():
    with Twin.from_station(STATIONS / "ring_rig") as twin:
        obs = Observer(twin)
        scene, start = obs.scene, obs.frame()
        twin.write("L2", 0.40)   # outwards from 350 mm: free travel, nothing in the way
        twin.write("L5", 0.006)  # the fine axis on finger L4's carriage: a chain of two joints
        twin.write("L4", 0.38)
        setpoints = {s["name"]: twin.read(s["name"]) for s in scene.signals if s["direction"] == "input" and s["type"] == "float"}
        for _ in range(400):
            twin.step()
            if all(twin.read(f"{a}.in_position") for a in ("L2", "L4", "L5")):
                break
        end = obs.frame()
    k = {b: i for i, b in enumerate(scene.bodies)}
    for finger in scene.fingers:
        link = finger.links[0]
        ghost = setpoint_motion(finger, scene, start, setpoints) @ pose_matrix(start.poses[k[link]])
        real = pose_matrix(end.poses[k[link]])
        assert np.linalg.norm(ghost[:3, 3] - real[:3, 3]) < 0.0006, finger.name  # within the in-position band
        assert np.allclose(ghost[:3, :3], real[:3, :3], atol=1e-3)


def test_mesh_visuals_are_found_and_load(tmp_path):
    pytest.importorskip("trimesh")
    from twin.frontends.view.page import _load_mesh

    path = robot_station(tmp_path, gripper=PYBULLET_DATA / "franka_panda" / "panda.urdf")  # under the arm
    with Twin.from_station(path) as twin:
        scene = Observer(twin).scene
    meshes = [v for v in scene.visuals if v.shape == "mesh"]
    assert meshes, "the panda's links are meshes"
    for v in meshes[:3]:
        vertices, faces = _load_mesh(v.mesh)
        assert len(vertices) > 10 and len(faces) > 10 and faces.max() < len(vertices)
