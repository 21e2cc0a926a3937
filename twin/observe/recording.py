"""Recordings: every signal at every step, and the pose of every body, in a columnar file; a flight recorder.

    from twin.core import Twin
    from twin.observe.recording import record, Recording

    with Twin.from_station("stations/my_cell") as twin, record(twin, "run.parquet"):
        twin.write("jaw", 0.011)
        twin.step(100)
    rec = Recording.open("run.parquet")     # or pandas.read_parquet / polars.read_parquet
    rec.column("jaw.actual"), rec.time

`twin serve STATION --record FILE` and `plc demo --record FILE` write the same file. One row per step,
the first row the state before the first step (step 0), in the format described in docs/recording.md:
`step`, `time` (s), one column per signal of the station in SI units (bool, float64, int64, or the
text of an enumeration), then `pose:BODY:x|y|z|qx|qy|qz|qw` for every body (each robot and gripper
link, each target and fixture; world frame, m, quaternion x y z w) and `joint:NAME` for every movable
joint (m or rad). The file's metadata (`gripper_twin` key, JSON) holds the scene: the station, the step,
each signal's unit and range, each body's visuals, the fingers, the machine's kinematic chain.

The links' poses follow from the joints' positions (rigid links chained by revolute, prismatic and fixed
joints), so a row stores the joints and only the poses of the bodies that move freely (targets, fixtures:
`Scene.stored`); they are computed from the joints with pybullet's own joint frames (`twin.observe.scene.link_poses`)
when the file is read (`Recording`) and when a Parquet file is finished, which then has every pose column.
A CSV file keeps the stored columns only (`stored_columns`).

Parquet (the default, any name but `.csv`) needs pyarrow (`pip install 'gripper-twin[view]'`): typed
columns, compressed, read by pandas, polars, DuckDB, Excel's Power Query. A `.csv` file (one header row,
then one line per step; the scene goes beside it as FILE.csv.json) is written with Arrow's CSV formatting
when pyarrow is there, else with Python's. Either way the file depends only on the station and the
inputs, step by step: a lockstep replay of the same inputs writes the same bytes (no wall time, no host
name, no random ids).

A flight recorder: what was recorded survives the crash it should explain. Rows are buffered in groups
of less than `FLUSH_S` (0.5 s) of simulated time; a full group goes at once to the recorder's writer process
(started, and set up, before the first step), which appends it to the file with one system call within
milliseconds, so after a SIGKILL of the simulation's process the file holds every step up to less than 1 s
before it (the group being filled, and at most the one the writer is still writing): the writer, in a
session of its own, writes what it received and exits (`wait_for_writer`: then only the group being filled
is missing). A CSV file gets its lines
directly. A Parquet file's footer is written only when it is finished, so while recording the file is an
Arrow IPC stream (self-delimiting record batches, each readable on its own; narrow: the floats of a row in
one fixed-size list, so a group costs a few buffers, not one per column) and closing converts it into
Parquet in place (`finish`). After a crash the file is still that stream: `Recording.open` (so `twin plot`,
`twin view --replay`, `twin snapshot`) reads every complete group of it, `finish(path)` turns it into
Parquet. A graceful stop keeps every step.

The recorder is a device of the twin (stepped with it, adding no signals), or, in a served cell, a
subscriber of the exchange that takes the signals' values from the snapshot already published (`exchange`):
the core imports nothing of it. What a step costs the simulation's process: no pybullet call (the joints
and targets the step read itself are taken from the twin, `Twin.step_readings`; the links' poses are not
read), the row kept as the tuples read, and once per group a pickle of them into a pipe (about a
microsecond a row). Encoding (Arrow record batches; CSV numbers formatted by Arrow once per run of equal
values down a column) and writing happen in the writer process (issue 21's rule: what would cost the step
runs in a process of its own). See `python -m bench record`.
"""
from __future__ import annotations

import contextlib
import csv
import io
import itertools
import json
import math
import os
import pickle
from itertools import islice
from pathlib import Path

import numpy as np

from twin.core.errors import TwinError
from .scene import POSE_FIELDS, Frame, Observer, Scene, attach, detach, link_poses
from twin.core.device import ObservingDevice

FORMAT_VERSION = 2  # 2: the links' poses are computed from the joints on reading (1: stored per step)
META_KEY = "gripper_twin"
# a group holds less than this much simulated time before it goes to the writer process; a crash loses the group
# being filled and, read at once, at most the one the writer is still writing: less than 1 s together
FLUSH_S = 0.5
START_TIMEOUT = 60.0  # s the writer process may take to start (python, numpy, pyarrow)
STREAM_MAGIC = b"\xff\xff\xff\xff"  # an Arrow IPC stream's first message starts so; a Parquet file with b"PAR1"
STREAM_END = b"\xff\xff\xff\xff\x00\x00\x00\x00"  # the end-of-stream mark (written by `close` only)
PARQUET_ROW_GROUP = 65536


class RecordingError(TwinError):
    """A recording cannot be written or read (names the file)."""


def columns_of(scene: Scene, bodies: list[str] | None = None) -> list[tuple[str, str]]:
    """(column name, type) of a recording of `scene`, in file order; type: int64, float64, bool, string.
    With every body's pose (a finished Parquet file, `Recording`), or those of `bodies` (`stored_columns`)."""
    cols = [("step", "int64"), ("time", "float64")]
    kinds = {"bool": "bool", "float": "float64", "int": "int64", "enum": "string"}
    cols += [(s["name"], kinds.get(s["type"], "float64")) for s in scene.signals]
    cols += [(f"pose:{b}:{f}", "float64") for b in (scene.bodies if bodies is None else bodies) for f in POSE_FIELDS]
    cols += [(f"joint:{j}", "float64") for j in scene.joints]
    return cols


def stored_columns(scene: Scene) -> list[tuple[str, str]]:
    """The columns a row holds while recording (a CSV file, a Parquet recording's stream): the poses only of
    the bodies the joints do not place (`Scene.stored`)."""
    return columns_of(scene, scene.stored)


def _complete(scene: Scene, columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Stored columns -> every column of `columns_of(scene)`: the links' poses computed from the joints."""
    if scene.links and f"pose:{scene.links[0]['body']}:x" not in columns:
        n = len(columns["step"])
        joints = np.stack([columns[f"joint:{j}"] for j in scene.joints], axis=1) if scene.joints else np.empty((n, 0))
        derived = link_poses(scene, joints)
        columns = dict(columns)
        for k, link in enumerate(scene.links):
            for f, field in enumerate(POSE_FIELDS):
                columns[f"pose:{link['body']}:{field}"] = np.ascontiguousarray(derived[:, k, f])
    return {name: columns[name] for name, _ in columns_of(scene) if name in columns}


def is_parquet(path: str | Path) -> bool:
    return Path(path).suffix.lower() != ".csv"


def _meta(scene: Scene) -> str:
    return json.dumps({"format": FORMAT_VERSION, "scene": scene.as_dict()}, sort_keys=True)


class _Layout:
    """Where each signal of a scene goes in a stream's narrow record batch: by kind, in the scene's order."""

    KINDS = ("float64", "bool", "int64", "string")
    DTYPES = {"float64": np.dtype("<f8"), "bool": np.dtype(bool), "int64": np.dtype("<i8")}

    def __init__(self, scene: Scene):
        self.columns = stored_columns(scene)
        kinds = [t for _, t in self.columns[2:2 + len(scene.signals)]]
        self.index = {k: [i for i, t in enumerate(kinds) if t == k] for k in self.KINDS}
        self.n_poses, self.n_joints = 7 * len(scene.stored), len(scene.joints)
        # a CSV line's columns, as the whole-number block, the float block and the text block hold them
        signal = [2 + i for i in range(len(kinds))]
        after = list(range(2 + len(kinds), len(self.columns)))
        self.csv_order = ([0] + [signal[i] for k in ("bool", "int64") for i in self.index[k]],
                          [1] + [signal[i] for i in self.index["float64"]] + after,
                          [signal[i] for i in self.index["string"]])

    def schema(self, pa, metadata: dict | None = None):
        types = {"float64": pa.float64(), "bool": pa.bool_(), "int64": pa.int64(), "string": pa.string()}
        fields = [("step", pa.int64()), ("time", pa.float64())]
        fields += [(f"signals:{k}", pa.list_(types[k], len(self.index[k]))) for k in self.KINDS if self.index[k]]
        fields += [(key, pa.list_(pa.float64(), width)) for key, width in (("poses", self.n_poses), ("joints", self.n_joints))
                   if width]
        return pa.schema(fields, metadata=metadata)

    def blocks(self, group: "_Group") -> dict:
        """A group's rows as numpy blocks: step, time, one (rows, width) block per kind of signal, poses, joints.
        (The rows' value tuples become one object array, cut by kind and converted column block by column
        block: a few numpy calls per group, no Python work per row.)"""
        n = group.n
        values = np.array(group.values, dtype=object).reshape(n, -1)
        out = {"step": np.array(group.steps, dtype=np.int64), "time": np.array(group.times, dtype=float)}
        for kind in self.KINDS:
            if self.index[kind]:
                block = values[:, self.index[kind]]
                out[kind] = block if kind == "string" else block.astype(self.DTYPES[kind])
        out["poses"] = np.array(group.poses, dtype=float).reshape(n, self.n_poses)
        out["joints"] = np.array(group.joints, dtype=float).reshape(n, self.n_joints)
        return out

    def batch(self, pa, schema, group: "_Group"):
        """A group of rows -> one narrow record batch (a handful of buffers whatever the column count)."""
        b = self.blocks(group)
        arrays = [pa.array(b["step"]), pa.array(b["time"])]
        for kind in self.KINDS:
            if self.index[kind]:
                flat = [str(v) for v in b[kind].ravel()] if kind == "string" else b[kind].ravel()
                arrays.append(pa.FixedSizeListArray.from_arrays(
                    pa.array(flat, schema.field(f"signals:{kind}").type.value_type), len(self.index[kind])))
        for key, width in (("poses", self.n_poses), ("joints", self.n_joints)):
            if width:
                arrays.append(pa.FixedSizeListArray.from_arrays(pa.array(b[key].ravel()), width))
        return pa.RecordBatch.from_arrays(arrays, schema=schema)

    def wide(self, pa, narrow) -> dict:
        """A narrow table or batch -> {column name: numpy array}, in file order."""
        n = narrow.num_rows

        def block(key: str, width: int) -> np.ndarray:
            col = narrow.column(key)
            col = col.combine_chunks() if hasattr(col, "combine_chunks") else col
            flat = col.flatten()
            flat = flat.to_numpy(zero_copy_only=False)
            return flat.reshape(n, width).T

        names = [name for name, _ in self.columns]
        out = {"step": narrow.column("step").to_numpy(), "time": narrow.column("time").to_numpy()}
        signals = [None] * sum(len(v) for v in self.index.values())
        for kind in self.KINDS:
            if self.index[kind]:
                for row, i in zip(block(f"signals:{kind}", len(self.index[kind])), self.index[kind]):
                    signals[i] = row
        for name, col in zip(names[2:], signals):
            out[name] = col
        rest = names[2 + len(signals):]
        for key, width, cols in (("poses", self.n_poses, rest[:self.n_poses]), ("joints", self.n_joints, rest[self.n_poses:])):
            if width:
                for name, col in zip(cols, block(key, width)):
                    out[name] = np.ascontiguousarray(col)
        return out


class _Group:
    """Rows being buffered: a row costs five list appends (the tuples `Observer.raw` made, kept as they are);
    the group becomes arrays once, when it is written."""

    def __init__(self, layout: _Layout, capacity: int):
        self.n, self.t0, self.capacity = 0, None, capacity
        self.steps, self.times, self.values, self.poses, self.joints = [], [], [], [], []

    def add(self, row: tuple) -> bool:
        """Store an Observer.raw row; False when full."""
        if self.n == self.capacity:
            return False
        step, t, values, poses, joints = row
        self.steps.append(step)
        self.times.append(t)
        self.values.append(values)
        self.poses.append(poses)
        self.joints.append(joints)
        self.n += 1
        if self.t0 is None:
            self.t0 = t
        return True

    def rows(self):
        """The rows again as (step, time, values, poses, joints) tuples (the CSV writer without pyarrow)."""
        return zip(self.steps, self.times, self.values, self.poses, self.joints)


class Recorder(ObservingDevice):
    """Records a twin at every step into `path` (see the module docstring). Close it to finish the file."""

    signals: tuple = ()  # a device of the twin with no signals of its own

    def __init__(self, twin, path: str | Path, *, observer: Observer | None = None, exchange=None,
                 flush_s: float = FLUSH_S):
        """`exchange` (a served cell's `twin.runtime.exchange.Exchange`): record each published snapshot (its values
        are already read) instead of stepping with the twin."""
        self.path = Path(path)
        self._parquet = is_parquet(self.path)
        self.observer = observer or Observer(twin)
        self.scene = self.observer.scene
        self.columns = stored_columns(self.scene)  # what a row holds
        self.layout = _Layout(self.scene)
        self.flush_s = flush_s
        self._dt = twin.dt
        self._capacity = max(16, int(math.ceil(flush_s / twin.dt)) + 2)  # rows of one group (FLUSH_S of steps)
        self._group = _Group(self.layout, self._capacity)
        self._fd = None
        self.rows = 0
        self.twin = twin
        self._closed = False
        self._last_step = None
        self._n_signals = len(self.scene.signals)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._open()
        except OSError as exc:
            raise RecordingError(f"{self.path}: cannot write a recording: {exc.strerror or exc}") from None
        self._writer = _WriterProcess(self.path, self._fd, self.scene)  # it holds the file from here on
        self._fd = None
        self.capture()  # step 0, or wherever the twin is now
        names = [sig["name"] for sig in self.scene.signals]
        if exchange is not None and list(islice(exchange.snapshot.values, len(names))) != names:
            exchange = None  # its snapshot does not list the signals first, in order: read them here
        self._exchange = exchange
        if exchange is not None:
            self._unsubscribe = exchange.subscribe(on_snapshot=self._on_snapshot)
        else:
            attach(twin, self)

    # -- the twin's side (as a device, or as the exchange's subscriber) ----------------------------------------
    def after_step(self, twin) -> None:
        self.capture()

    def _on_snapshot(self, snapshot) -> None:
        if snapshot.step != self._last_step:  # a snapshot taken again at the same step is not a new row
            self.capture(tuple(islice(snapshot.values.values(), self._n_signals)))

    def capture(self, values: tuple | None = None) -> None:
        """Add the twin's present state as a row (the device does this after every step)."""
        row = self.observer.raw(values)
        group = self._group
        if not group.add(row):
            self._flush()
            group = self._group
            group.add(row)
        self._last_step = row[0]
        self.rows += 1
        if row[1] + self._dt - group.t0 >= self.flush_s - 1e-9:  # the next row would make it span flush_s
            self._flush()

    # -- the file --------------------------------------------------------------------------------------------
    def _open(self) -> None:
        try:
            import pyarrow as pa
        except ImportError:
            pa = None
        self._pa = pa
        if is_parquet(self.path):
            if pa is None:
                raise RecordingError(f"{self.path}: a Parquet recording needs pyarrow (pip install 'gripper-twin[view]'); "
                                     "or record to a .csv file")
            self._schema = self.layout.schema(pa, {META_KEY: _meta(self.scene)})
            head = pa.BufferOutputStream()
            with pa.ipc.new_stream(head, self._schema):  # the schema message (and an end mark, cut off)
                pass
            self._stream_head = head.getvalue().to_pybytes()
            if self._stream_head.endswith(STREAM_END):
                self._stream_head = self._stream_head[:-len(STREAM_END)]
            self._fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            _write_all(self._fd, self._stream_head)
        else:
            Path(str(self.path) + ".json").write_text(_meta(self.scene) + "\n", encoding="utf-8")
            self._fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            header = io.StringIO()
            csv.writer(header, lineterminator="\n").writerow([n for n, _ in self.columns])
            _write_all(self._fd, header.getvalue().encode("utf-8"))

    def _flush(self) -> None:
        """Hand the buffered group to the writer process now (a pickle of the rows as they are: about a
        microsecond per row, where encoding them here would cost ten to twenty)."""
        rows, self._group = self._group, _Group(self.layout, self._capacity)
        if rows.n:
            self._writer.send_group(("group", rows.steps, rows.times, rows.values, rows.poses, rows.joints))

    def close(self) -> None:
        """Write what is buffered and finish the file (a Parquet file: the stream becomes Parquet); returns
        when the file is complete."""
        if self._closed:
            return
        self._closed = True
        if self._exchange is not None:
            self._unsubscribe()
        else:
            detach(self.twin, self)
        try:
            self._flush()
        finally:
            self._writer.close()

    def __enter__(self) -> "Recorder":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class _WriterProcess:
    """The recorder's other half, a process of its own (issue 21's rule: a front end that would cost the step
    runs beside it): it turns each group of rows into the file's bytes and appends them with one system call.
    It inherits the open file (header written) and reads the groups from a pipe. When the simulation's process
    dies, the pipe ends and it writes what it received and exits (in its own session, so a Ctrl-C or a signal
    to the server's process group leaves it to finish); after a graceful `close` it also finishes the file. It
    holds an exclusive `flock` on the file while it lives: whoever must read all a crashed run wrote takes a
    shared one first."""

    def __init__(self, path: Path, fd: int, scene: Scene):
        import subprocess
        import sys

        self.path = path
        read, self._pipe = os.pipe()
        ready, told = os.pipe()
        try:
            import fcntl

            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # (held by the file's description: the writer's from now)
            fcntl.fcntl(self._pipe, getattr(fcntl, "F_SETPIPE_SZ", 1031), 1 << 20)  # room for every group in flight
        except OSError:
            pass
        package = str(Path(__file__).resolve().parents[__name__.count(".")])  # the folder `twin` is imported from
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([package] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
        try:
            self.process = subprocess.Popen(
                [sys.executable, "-P", "-c", f"from {__name__} import _writer_main; _writer_main()", str(read), str(fd),
                 str(told), str(path)], pass_fds=(read, fd, told), stdin=subprocess.DEVNULL, env=env,
                start_new_session=True)
        except OSError as exc:
            os.close(self._pipe)
            os.close(ready)
            raise RecordingError(f"{path}: cannot start the recorder's process: {exc.strerror or exc}") from None
        finally:
            for end in (read, fd, told):
                os.close(end)
        self._acks, self._in_flight = ready, 0  # the writer says b"w" for each group it has written
        try:
            self.send(("scene", scene.as_dict()))
            self._wait_ready(ready)
        except RecordingError:
            self.process.kill()
            self.process.wait()
            os.close(self._pipe)
            os.close(ready)
            raise

    def _wait_ready(self, ready: int) -> None:
        """Wait (before the first step) until it has set itself up: from then on it writes a group within
        milliseconds of receiving it, so what a crash leaves is on disk almost at once."""
        import select

        if not select.select([ready], [], [], START_TIMEOUT)[0] or os.read(ready, 1) != b"r":
            raise RecordingError(f"{self.path}: the recorder's process did not start (exit status "
                                 f"{self.process.poll()}); see the message it left on stderr")

    def send_group(self, message: tuple) -> None:
        """Hand a group over once the one before it is on disk: at most one group is ever in flight, so a
        crash loses at most that one and the group being filled, whatever the load (a writer that has fallen
        behind makes the step wait instead of the file falling further behind)."""
        import select

        while self._in_flight:
            if not select.select([self._acks], [], [], START_TIMEOUT)[0]:
                raise RecordingError(f"{self.path}: the recorder's process has not written a group for "
                                     f"{START_TIMEOUT} s (exit status {self.process.poll()})")
            got = os.read(self._acks, 64)
            if not got:
                raise RecordingError(f"{self.path}: the recorder's process stopped (exit status "
                                     f"{self.process.poll()}); see the message it left on stderr")
            self._in_flight -= len(got)
        self.send(message)
        self._in_flight += 1

    def send(self, message: tuple) -> None:
        try:
            _write_all(self._pipe, pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL))
        except OSError:
            raise RecordingError(f"{self.path}: the recorder's process stopped (exit status "
                                 f"{self.process.poll()}); see the message it left on stderr") from None

    def close(self) -> None:
        """Tell it to finish the file, and wait until it has."""
        try:
            self.send(("close",))
        finally:
            os.close(self._pipe)
            status = self.process.wait()
            os.close(self._acks)
        if status != 0:
            raise RecordingError(f"{self.path}: the recorder's process failed (exit status {status}); "
                                 "see the message it left on stderr")


class _FileWriter:
    """In the writer process: a group of rows -> one record batch (a Parquet recording's stream) or lines (CSV),
    appended with one system call."""

    def __init__(self, fd: int, path: Path, scene: Scene):
        try:
            import pyarrow as pa
        except ImportError:
            pa = None
        self.fd, self.path, self.pa = fd, path, pa
        self.parquet = is_parquet(path)
        if pa is not None:
            import pyarrow.compute  # noqa: F401  (set up now, not at the first group)
        self.layout = _Layout(scene)
        self.schema = self.layout.schema(pa, {META_KEY: _meta(scene)}) if pa is not None and self.parquet else None

    def write(self, rows: _Group) -> None:
        _write_all(self.fd, self.encode(rows))

    def encode(self, rows: _Group):
        """The group as the bytes to write (or a buffer holding them)."""
        if self.parquet:  # one stream message: what the stream writer would put after the schema
            return memoryview(self.layout.batch(self.pa, self.schema, rows).serialize())
        if self.pa is not None:
            return _csv_lines(self.pa, self.layout, rows)
        return _csv_lines_plain(self.layout, rows.rows())


def _writer_main() -> None:
    """The writer process (`_WriterProcess`): argv = the pipe it reads, the file, the pipe it says ready on, the
    file's path."""
    import signal
    import sys

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # it ends when its pipe does
    read, fd, told, path = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), Path(sys.argv[4])
    closing = False
    with os.fdopen(read, "rb") as pipe:
        writer = None
        while True:
            try:
                message = pickle.load(pipe)
            except (EOFError, pickle.UnpicklingError):  # the simulation's process is gone
                break
            if message[0] == "scene":
                writer = _FileWriter(fd, path, Scene.from_dict(message[1]))
                os.write(told, b"r")
            elif message[0] == "group":
                rows = _Group(writer.layout, len(message[1]))
                rows.steps, rows.times, rows.values, rows.poses, rows.joints = message[1:]
                rows.n = len(rows.steps)
                writer.write(rows)
                try:
                    os.write(told, b"w")  # on disk: the simulation may hand over the next group
                except OSError:  # the simulation's process is gone: write on what it sent
                    pass
            elif message[0] == "close":
                closing = True
                break
    os.close(fd)
    if closing and is_parquet(path):
        finish(path)


def wait_for_writer(path: str | Path, timeout: float = 10.0) -> bool:
    """Wait until no recorder's process writes `path` any more (after a crash it writes what it had received,
    in milliseconds, then exits): True when it is done, False after `timeout` s (it is still recording)."""
    import fcntl
    import time

    deadline = time.monotonic() + timeout
    with open(path, "rb") as f:
        while True:
            try:
                fcntl.flock(f, fcntl.LOCK_SH | fcntl.LOCK_NB)
                fcntl.flock(f, fcntl.LOCK_UN)
                return True
            except BlockingIOError:
                if time.monotonic() > deadline:
                    return False
                time.sleep(0.01)


def _write_all(fd: int, data: bytes) -> None:
    while data:
        data = data[os.write(fd, data):]


def _csv_lines(pa, layout: _Layout, group: _Group):
    """A group as CSV lines (no header), as one buffer, formatted by Arrow in a dozen vectorised calls whatever
    the column and row count. The whole numbers (step, bools as 1/0, integers) make one block, the floats (time,
    signals, poses, joints) another; a number is formatted once per run of equal values down its column (most
    signals and the bodies at rest keep theirs from step to step): only the values that changed are cast to
    text (floats in their shortest form that reads back bit for bit) and given the separator that follows them;
    one take puts every cell's text in place, and the taken texts, laid end to end, are the lines."""
    import pyarrow.compute as pc

    b = layout.blocks(group)
    n = group.n
    whole = np.hstack([b["step"].reshape(n, 1)] + [b[k].astype(np.int64) for k in ("bool", "int64") if layout.index[k]])
    floats = np.hstack([b["time"].reshape(n, 1)] + [b[k] for k in ("float64", "poses", "joints") if k in b and b[k].size])
    parts, places, total = [], [], 0  # texts to concatenate; per block, each cell's index into them
    for block in (whole, floats):
        changed, where = _runs(block)
        parts.append(pa.array(block[changed]).cast(pa.string()))
        places.append(where + total)
        total += len(parts[-1])
    if layout.index["string"]:
        parts.append(pa.array([_csv_field(str(v)) for v in b["string"].ravel()], pa.string()))
        places.append(np.arange(b["string"].size, dtype=np.int64).reshape(n, -1) + total)
        total += len(parts[-1])
    take = np.empty((n, len(layout.columns)), dtype=np.int64)
    for columns, where in zip(layout.csv_order, places):
        take[:, columns] = where
    texts = pa.concat_arrays(parts)
    # every text with a comma after it; the last column's cells with the line's end instead
    ends = pc.binary_join_element_wise(pc.take(texts, pa.array(take[:, -1])), "\n", "")
    texts = pa.concat_arrays([pc.binary_join_element_wise(texts, ",", ""), ends])
    take[:, -1] = total + np.arange(n)
    cells = pc.take(texts, pa.array(take.ravel()))
    offsets = np.frombuffer(cells.buffers()[1], dtype=np.int32)[cells.offset:cells.offset + len(cells) + 1]
    return memoryview(cells.buffers()[2])[offsets[0]:offsets[-1]]


def _runs(block: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For a (rows, columns) block of numbers: which cells differ (bit for bit) from the cell above (the
    first row always), and for every cell the index, among those cells in row-major order, of the one that
    starts its run."""
    n, w = block.shape
    bits = np.ascontiguousarray(block).view(f"i{block.dtype.itemsize}")
    changed = np.ones((n, w), dtype=bool)
    changed[1:] = bits[1:] != bits[:-1]
    rank = np.cumsum(changed.ravel()) - 1
    start = np.maximum.accumulate(np.where(changed, np.arange(n)[:, None], 0), axis=0)
    return changed, rank[start * w + np.arange(w)]


def _csv_field(text: str) -> str:
    """A text as one CSV field (quoted when empty or when it holds a separator, a quote or a line break)."""
    if not text or any(c in text for c in ',"\r\n'):
        return '"' + text.replace('"', '""') + '"'
    return text


def _csv_lines_plain(layout: _Layout, rows) -> bytes:
    """The same lines without pyarrow (Python's csv module)."""
    kinds = [t for _, t in layout.columns[2:]]
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    for step, t, values, poses, joints in rows:
        w.writerow([step, repr(t), *(_csv_text(v, k) for v, k in zip(values, kinds)),
                    *(repr(float(v)) for v in poses), *(repr(float(v)) for v in joints)])
    return out.getvalue().encode("utf-8")


def _read_stream(path: Path):
    """Every complete record batch of an Arrow IPC stream (a recording cut short: up to the last whole one)."""
    import pyarrow as pa

    data = pa.memory_map(str(path)) if path.stat().st_size else None
    if data is None:
        raise RecordingError(f"{path}: empty")
    reader = pa.ipc.open_stream(data)
    batches = []
    while True:
        try:
            batches.append(reader.read_next_batch())
        except StopIteration:
            break
        except (pa.ArrowInvalid, OSError, EOFError):  # the group being written when the process died
            break
    return reader.schema, pa.Table.from_batches(batches, schema=reader.schema)


def finish(path: str | Path) -> Path:
    """Turn a recording's Arrow IPC stream (a Parquet recording while it is written, or after a crash) into
    the Parquet file it would have been, in place. A file that is Parquet already is left as it is."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = Path(path)
    with open(path, "rb") as f:
        if f.read(4) != STREAM_MAGIC:
            return path
    schema, narrow = _read_stream(path)
    meta = (schema.metadata or {}).get(META_KEY.encode())
    if meta is None:
        raise RecordingError(f"{path}: an Arrow stream without gripper-twin metadata: not a recording")
    scene = Scene.from_dict(json.loads(meta)["scene"])
    layout = _Layout(scene)
    wide = _complete(scene, layout.wide(pa, narrow))
    types = {"int64": pa.int64(), "float64": pa.float64(), "bool": pa.bool_(), "string": pa.string()}
    full = columns_of(scene)
    out_schema = pa.schema([(n, types[t]) for n, t in full], metadata={META_KEY: meta})
    table = pa.Table.from_arrays([pa.array(wide[n], types[t]) for n, t in full], schema=out_schema)
    tmp = path.with_name(path.name + ".finishing")
    pq.write_table(table, str(tmp), compression="zstd", row_group_size=PARQUET_ROW_GROUP)
    os.replace(tmp, path)
    return path


def _csv_text(v, kind: str) -> str:
    if kind == "bool":
        return "1" if v else "0"
    if kind == "int64":
        return str(int(v))
    if kind == "string":
        return str(v)
    return repr(float(v))


@contextlib.contextmanager
def record(twin, path: str | Path, **kw):
    """Record `twin` into `path` while the block runs (every step it takes, and its state at the start)."""
    rec = Recorder(twin, path, **kw)
    try:
        yield rec
    finally:
        rec.close()


# -- reading ---------------------------------------------------------------------------------------------------
class Recording:
    """A recording read back: columns as numpy arrays, and frames to replay."""

    def __init__(self, path: Path, scene: Scene, columns: dict[str, np.ndarray]):
        self.path, self.scene, self._columns = path, scene, columns
        self.time = columns["time"]
        self.steps = columns["step"]
        self._poses = np.stack([columns[f"pose:{b}:{f}"] for b in scene.bodies for f in POSE_FIELDS], axis=1) \
            if scene.bodies else np.empty((len(self.time), 0))
        self._joints = np.stack([columns[f"joint:{j}"] for j in scene.joints], axis=1) if scene.joints \
            else np.empty((len(self.time), 0))

    def __len__(self) -> int:
        return len(self.time)

    @property
    def names(self) -> list[str]:
        return list(self._columns)

    @property
    def signal_names(self) -> list[str]:
        return [s["name"] for s in self.scene.signals]

    def column(self, name: str) -> np.ndarray:
        try:
            return self._columns[name]
        except KeyError:
            raise RecordingError(f"{self.path}: no column {name!r} (signals: {', '.join(self.signal_names)})") from None

    def index_at(self, t: float) -> int:
        """The row at simulated time t (the last step at or before it; the first row before the start)."""
        i = int(np.searchsorted(self.time, t + 1e-9, side="right")) - 1
        return max(0, min(i, len(self.time) - 1))

    def frame(self, i: int) -> Frame:
        values = tuple(_py(self._columns[s["name"]][i]) for s in self.scene.signals)
        n = len(self.scene.bodies)
        return Frame(int(self.steps[i]), float(self.time[i]), values, self._poses[i].reshape(n, 7), self._joints[i])

    @classmethod
    def open(cls, path: str | Path) -> "Recording":
        path = Path(path)
        if not path.is_file():
            raise RecordingError(f"{path}: no such recording")
        if is_parquet(path):
            try:
                import pyarrow.parquet as pq
            except ImportError:
                raise RecordingError(f"{path}: reading Parquet needs pyarrow (pip install 'gripper-twin[view]')") from None
            with open(path, "rb") as f:
                stream = f.read(4) == STREAM_MAGIC  # still being written, or cut short by a crash
            try:
                table = _read_stream(path)[1] if stream else pq.read_table(str(path))
            except RecordingError:
                raise
            except Exception as exc:  # pyarrow's errors are of several kinds; all mean "not a readable file"
                raise RecordingError(f"{path}: not a readable Parquet recording ({exc})") from None
            meta = (table.schema.metadata or {}).get(META_KEY.encode())
            if meta is None:
                raise RecordingError(f"{path}: a Parquet file without gripper-twin metadata: not a recording")
            scene = Scene.from_dict(json.loads(meta)["scene"])
            if stream:
                import pyarrow as pa

                columns = _complete(scene, _Layout(scene).wide(pa, table))
            else:
                columns = {name: table.column(name).to_numpy(zero_copy_only=False) for name in table.column_names}
        else:
            meta_path = Path(str(path) + ".json")
            if not meta_path.is_file():
                raise RecordingError(f"{path}: its scene file {meta_path.name} is missing beside it")
            scene = Scene.from_dict(json.loads(meta_path.read_text(encoding="utf-8"))["scene"])
            kinds = dict(stored_columns(scene))
            with open(path, newline="", encoding="utf-8") as f:
                text = f.read()
            text = text[:text.rfind("\n") + 1]  # a line cut short by a crash is not a row
            rows = list(csv.reader(io.StringIO(text, newline="")))
            if not rows:
                raise RecordingError(f"{path}: empty")
            header, body = rows[0], rows[1:]
            columns = {}
            for k, name in enumerate(header):
                col = [r[k] for r in body]
                kind = kinds.get(name, "float64")
                if kind == "bool":
                    columns[name] = np.array([v == "1" for v in col], dtype=bool)
                elif kind == "int64":
                    columns[name] = np.array([int(v) for v in col], dtype=np.int64)
                elif kind == "string":
                    columns[name] = np.array(col, dtype=object)
                else:
                    columns[name] = np.array([float(v) for v in col], dtype=float)
            columns = _complete(scene, columns)
        missing = [n for n, _ in columns_of(scene) if n not in columns]
        if missing:
            raise RecordingError(f"{path}: columns missing: {', '.join(missing[:5])}")
        return cls(path, scene, columns)


def _py(v):
    if isinstance(v, np.bool_):
        return bool(v)
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, np.floating):
        return float(v) if not math.isnan(v) else v
    return v
