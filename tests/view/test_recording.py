"""Recordings: every signal at every step, every body's pose, and the same bytes for the same inputs."""
from __future__ import annotations

import math
import time

import numpy as np
import pytest

from plc_client.testing import twin_server
from tests.conftest import STATIONS
from twin.core import Twin
from twin.observe.recording import Recorder, Recording, RecordingError, record, wait_for_writer

SMART = STATIONS / "smart_gripper"
RING = STATIONS / "ring_rig_plc"


def script(twin, steps: int = 120) -> list[dict]:
    """Drive the smart gripper (close on the cube, then open) and note what the API reads after each step."""
    seen = [{s.name: twin.read(s.name) for s in twin.signals}]
    for k in range(steps):
        if k == 10:
            twin.write("jaw_left", twin.spec("jaw_left").min)
        if k == 80:
            twin.write("jaw_left", twin.spec("jaw_left").max)
        twin.step()
        seen.append({s.name: twin.read(s.name) for s in twin.signals})
    return seen


@pytest.mark.parametrize("suffix", ["parquet", "csv"])
def test_every_signal_at_every_step(tmp_path, suffix):
    if suffix == "parquet":
        pytest.importorskip("pyarrow")
    path = tmp_path / f"run.{suffix}"
    with Twin.from_station(SMART) as twin, record(twin, path):
        seen = script(twin)
        bodies = {t.name: twin.world.pose(t.name) for t in twin.station.targets}
    rec = Recording.open(path)
    assert len(rec) == len(seen)  # the start, then one row per step
    assert list(rec.column("step")) == list(range(len(seen)))
    assert rec.column("time")[-1] == pytest.approx(120 * twin.dt)
    names = [s.name for s in twin.signals]
    assert rec.signal_names == names
    for name in names:  # what the API read after each step, row by row (floats to the bit)
        col = rec.column(name)
        for k, row in enumerate(seen):
            v = row[name]
            assert col[k] == v or (isinstance(v, float) and math.isnan(v) and math.isnan(col[k])), (name, k)
    for target, (pos, orn) in bodies.items():  # the last row holds where the world has each target
        last = rec.frame(len(rec) - 1)
        k = rec.scene.bodies.index(target)
        assert tuple(last.poses[k]) == (*pos, *orn)
    # the grip happened and is in the file
    assert rec.column("doGripped").any() and not rec.column("doGripped")[0]


def test_two_lockstep_runs_write_identical_files(tmp_path):
    pytest.importorskip("pyarrow")
    for k in (1, 2):
        with Twin.from_station(SMART) as twin, record(twin, tmp_path / f"run{k}.parquet", flush_s=0.3):
            script(twin)
    assert (tmp_path / "run1.parquet").read_bytes() == (tmp_path / "run2.parquet").read_bytes()


def test_served_recording_is_byte_identical_across_lockstep_replays(tmp_path):
    """`twin serve --lockstep --record FILE`: the same Modbus writes and advances give the same file."""
    pytest.importorskip("pyarrow")
    for k in (1, 2):
        with twin_server(RING, lockstep=True, extra_args=["--record", str(tmp_path / f"served{k}.parquet")]) as server:
            with server.client() as plc:
                plc.advance(20)
                plc.write(L2=330.0, L3=330.0)
                plc.advance(60)
    a, b = (tmp_path / "served1.parquet").read_bytes(), (tmp_path / "served2.parquet").read_bytes()
    assert a == b
    rec = Recording.open(tmp_path / "served1.parquet")
    assert len(rec) == 81 and rec.column("L2")[-1] == pytest.approx(0.33)
    assert "goCycle" in rec.signal_names  # the controller's signals are recorded too
    # every robot link's pose is there, and the flange moved with the arm's joints (not constant)
    assert any(b.startswith("robot/") for b in rec.scene.bodies)
    assert np.all(np.isfinite(rec.column("pose:L2:x")))


def test_a_file_that_is_no_recording_is_named(tmp_path):
    bad = tmp_path / "bad.parquet"
    bad.write_text("not parquet")
    with pytest.raises(RecordingError, match="bad.parquet"):
        Recording.open(bad)


@pytest.mark.parametrize("suffix", ["parquet", "csv"])
def test_a_sigkilled_server_leaves_every_step_but_the_last_second_readable(tmp_path, suffix):
    """`twin serve --lockstep --record FILE`, killed with SIGKILL (no chance to finish the file): the file is
    read back at once and holds the steps 0..k in order, k at most 1 s of simulated time short of the last
    step the client saw done, with the values the client wrote and read at those steps; once the recorder's
    writer process has written what it had received, only the group being filled is missing (< 0.5 s)."""
    pytest.importorskip("pyarrow")
    import signal

    from twin.observe.recording import finish, wait_for_writer

    path = tmp_path / f"crash.{suffix}"
    with twin_server(RING, lockstep=True, extra_args=["--record", str(path)]) as server:
        with server.client() as plc:
            plc.advance(20)
            plc.write(L2=330.0)
            plc.advance(230)
            seen = plc.read("sim.step", "sim.time_ms", "L2.actual")
        server.process.send_signal(signal.SIGKILL)
        server.process.wait(10)
    at_once = Recording.open(path)
    assert (seen["sim.step"] - int(at_once.steps[-1])) * at_once.scene.dt <= 1.0  # at most 1 s of simulated time lost
    assert wait_for_writer(path)  # the recorder's own process writes what it had received, and ends
    rec = Recording.open(path)
    dt = rec.scene.dt
    last = int(rec.steps[-1])
    assert list(rec.steps) == list(range(last + 1))  # every step from the start, none twice, in order
    assert last <= seen["sim.step"] and (seen["sim.step"] - last) * dt <= 0.5  # the group being filled at most
    assert last * dt > 1.0  # (and something was written while it ran)
    assert rec.column("L2")[20] != pytest.approx(0.33) and rec.column("L2")[21] == pytest.approx(0.33)
    if last == seen["sim.step"]:
        assert rec.column("L2.actual")[-1] * 1000 == pytest.approx(seen["L2.actual"], abs=0.01)
    if suffix == "parquet":  # a crashed Parquet recording is its stream: finish it into the Parquet file it would be
        import pyarrow.parquet as pq

        finish(path)
        table = pq.read_table(path)
        assert table.num_rows == last + 1 and table.column("step").to_pylist() == list(range(last + 1))
        assert Recording.open(path).column("pose:L2:x").tolist() == rec.column("pose:L2:x").tolist()


def test_a_recorder_whose_writer_process_died_says_so_naming_the_file(tmp_path):
    """The writer is a process of its own: if it is killed, the next second's group is refused with the
    file's name (nothing silently dropped), and what it wrote before stays readable."""
    path = tmp_path / "run.csv"
    with Twin.from_station(SMART) as twin:
        rec = Recorder(twin, path)
        twin.step(round(1.5 / twin.dt))  # one group handed over
        assert wait_for_writer(path, timeout=0.1) is False  # (it is still recording)
        deadline = time.monotonic() + 10
        while len(path.read_text().splitlines()) < 2 and time.monotonic() < deadline:
            time.sleep(0.02)  # (written once the process has started)
        rec._writer.process.kill()
        rec._writer.process.wait()
        with pytest.raises(RecordingError, match="run.csv.*recorder's process"):
            twin.step(round(1.0 / twin.dt))
    assert len(Recording.open(path)) >= round(1.0 / twin.dt)


def test_a_line_cut_short_at_the_end_of_a_csv_recording_is_not_a_row(tmp_path):
    path = tmp_path / "run.csv"
    with Twin.from_station(SMART) as twin, record(twin, path):
        script(twin, steps=30)
    whole = Recording.open(path)
    text = path.read_text()
    path.write_text(text + text.splitlines()[-1][:25])  # a crash in the middle of a line
    cut = Recording.open(path)
    assert len(cut) == len(whole) == 31 and cut.column("time").tolist() == whole.column("time").tolist()


CHUCK = STATIONS.parent / "tests" / "core" / "data" / "chuck3"
UNTUNED = STATIONS.parent / "tests" / "grippers"
FLOAT32 = 2.0 ** -23  # pybullet hands link frames over in single precision: one step of it at 1 m


def tilted(name: str, folder):
    """Test gripper `name` with the frames a CAD export gives: every link's centre of mass off its link frame
    and its inertial frame turned, every joint axis of length 2."""
    import re
    import shutil

    shutil.copytree(UNTUNED / name, folder)
    for urdf in folder.glob("*.urdf"):
        text = re.sub(r'<inertial><origin xyz="(\S+) (\S+) (\S+)" rpy="0 0 0"/>',
                      lambda m: f'<inertial><origin xyz="{float(m[1]) + 0.003} {float(m[2]) - 0.002} {m[3]}" '
                                f'rpy="0.3 -0.5 0.7"/>', urdf.read_text())
        text = re.sub(r'<axis xyz="(\S+) (\S+) (\S+)"/>',
                      lambda m: '<axis xyz="' + " ".join(str(2 * float(v)) for v in m.groups()) + '"/>', text)
        urdf.write_text(text)
    return folder


@pytest.mark.parametrize("station, inputs", [(CHUCK, {"jaw_1": 0.02}), (RING, {"L2": 0.3, "L5": 0.01}),
                                             ("revolute_chuck", {"jaw_1": -0.3, "jaw_2": 0.2}),
                                             ("parallel_200n", {"jaw_a": 0.01})])
@pytest.mark.parametrize("suffix", ["parquet", "csv"])
def test_every_pose_is_what_pybullet_gives_after_the_step(tmp_path, station, inputs, suffix):
    """Each row's joint positions and free bodies' poses are, to the bit, what pybullet answers after that
    step (the recorder takes what the step read already); the links' poses, computed on reading from the
    joints, are where pybullet's forward kinematics puts them for those joints (within the single precision
    it hands them over in). On a mimic-coupled chuck (follower joints the step does not read), an arm with a
    gripper, and revolute levers and a mimic-coupled parallel gripper with turned inertial frames and axes not of
    unit length."""
    if suffix == "parquet":
        pytest.importorskip("pyarrow")
    if isinstance(station, str):
        station = tilted(station, tmp_path / station)
    path = tmp_path / f"run.{suffix}"
    truth = []
    with Twin.from_station(station) as twin, record(twin, path) as rec:
        c, body, scene = twin.world.client, twin.world.machine, rec.scene
        links = {n: i for n, i in twin.world.link_index.items() if i >= 0}
        joints = {c.getJointInfo(body, j)[1].decode(): j for j in range(c.getNumJoints(body))}
        for name, value in inputs.items():
            twin.write(name, value)
        if twin.robot is not None:
            twin.move("MoveJ", "app_right")
        for _ in range(40):
            twin.step()
            free = []
            for b in scene.bodies[1 + len(links):]:  # targets and fixtures
                free += [*(v for part in c.getBasePositionAndOrientation(twin.world.body_ids[b]) for v in part)]
            # (asking pybullet to compute the links' frames changes nothing in the simulation)
            frames = [c.getLinkState(body, links[b], computeForwardKinematics=True)[4:6] for b in scene.bodies[1:1 + len(links)]]
            truth.append((free, np.array([[*pos, *orn] for pos, orn in frames]),
                          [c.getJointState(body, joints[j])[0] for j in scene.joints]))
    assert len(links) and scene.bodies[1:1 + len(links)] == list(links)
    got = Recording.open(path)
    for k, (free, frames, qs) in enumerate(truth, start=1):
        frame = got.frame(k)
        assert frame.joints.tolist() == qs, k
        assert frame.poses[1 + len(links):].ravel().tolist() == free, k
        computed = frame.poses[1:1 + len(links)]
        assert np.abs(computed[:, :3] - frames[:, :3]).max() <= 4 * FLOAT32, k  # positions (m, within 2 m)
        turn = np.minimum(np.abs(computed[:, 3:] - frames[:, 3:]), np.abs(computed[:, 3:] + frames[:, 3:]))
        assert turn.max() <= 4 * FLOAT32, k  # orientations (a quaternion and its negative are one turn)
