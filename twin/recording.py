"""Recordings: every signal at every step, and the pose of every body, in a columnar file.

    from twin.core import Twin
    from twin.recording import record, Recording

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
each signal's unit and range, each body's visuals, the fingers.

Parquet (the default, any name but `.csv`) needs pyarrow (`pip install 'gripper-twin[view]'`): typed
columns, compressed, read by pandas, polars, DuckDB, Excel's Power Query. A `.csv` file needs nothing
(one header row, then one line per step; the scene goes beside it as FILE.csv.json). Either way the
file depends only on the station and the inputs, step by step: a lockstep replay of the same inputs
writes the same bytes (rows are written in groups of a fixed number of steps, no wall time, no host
name, no random ids).

The recorder is a device of the twin (stepped with it, adding no signals): the core imports nothing of
it. Rows are buffered and written in groups by one background thread, so a real-time server does not
wait on the disk.
"""
from __future__ import annotations

import contextlib
import csv
import json
import math
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from .core.errors import TwinError
from .observe import POSE_FIELDS, Frame, Observer, Scene, attach, detach
from .core.device import ObservingDevice

FORMAT_VERSION = 1
META_KEY = "gripper_twin"
ROWS_PER_GROUP = 1024


class RecordingError(TwinError):
    """A recording cannot be written or read (names the file)."""


def columns_of(scene: Scene) -> list[tuple[str, str]]:
    """(column name, type) of a recording of `scene`, in file order; type: int64, float64, bool, string."""
    cols = [("step", "int64"), ("time", "float64")]
    kinds = {"bool": "bool", "float": "float64", "int": "int64", "enum": "string"}
    cols += [(s["name"], kinds.get(s["type"], "float64")) for s in scene.signals]
    cols += [(f"pose:{b}:{f}", "float64") for b in scene.bodies for f in POSE_FIELDS]
    cols += [(f"joint:{j}", "float64") for j in scene.joints]
    return cols


def is_parquet(path: str | Path) -> bool:
    return Path(path).suffix.lower() != ".csv"


def _meta(scene: Scene) -> str:
    return json.dumps({"format": FORMAT_VERSION, "scene": scene.as_dict()}, sort_keys=True)


class Recorder(ObservingDevice):
    """Records a twin at every step into `path` (see the module docstring). Close it to finish the file."""

    signals: tuple = ()  # a device of the twin with no signals of its own

    def __init__(self, twin, path: str | Path, *, observer: Observer | None = None, rows_per_group: int = ROWS_PER_GROUP):
        self.path = Path(path)
        self.observer = observer or Observer(twin)
        self.scene = self.observer.scene
        self.columns = columns_of(self.scene)
        self.rows_per_group = rows_per_group
        self._rows: list[tuple] = []
        self._writer = None
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="recorder")
        self._pending = None
        self.rows = 0
        self.twin = twin
        self._closed = False
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._open()
        except OSError as exc:
            self._pool.shutdown()
            raise RecordingError(f"{self.path}: cannot write a recording: {exc.strerror or exc}") from None
        self.capture()  # step 0, or wherever the twin is now
        attach(twin, self)

    # -- the twin's side (as a device) --------------------------------------------------------------------
    def after_step(self, twin) -> None:
        self.capture()

    def capture(self) -> None:
        """Add the twin's present state as a row (the device does this after every step)."""
        self._rows.append(self.observer.raw())
        self.rows += 1
        if len(self._rows) >= self.rows_per_group:
            self._flush()

    # -- the file --------------------------------------------------------------------------------------------
    def _open(self) -> None:
        if is_parquet(self.path):
            try:
                import pyarrow as pa
                import pyarrow.parquet as pq
            except ImportError:
                raise RecordingError(f"{self.path}: a Parquet recording needs pyarrow (pip install 'gripper-twin[view]'); "
                                     "or record to a .csv file") from None
            types = {"int64": pa.int64(), "float64": pa.float64(), "bool": pa.bool_(), "string": pa.string()}
            self._schema = pa.schema([(n, types[t]) for n, t in self.columns], metadata={META_KEY: _meta(self.scene)})
            self._writer = pq.ParquetWriter(str(self.path), self._schema, compression="zstd")
        else:
            self._file = open(self.path, "w", newline="", encoding="utf-8")
            self._csv = csv.writer(self._file, lineterminator="\n")
            self._csv.writerow([n for n, _ in self.columns])
            Path(str(self.path) + ".json").write_text(_meta(self.scene) + "\n", encoding="utf-8")

    def _flush(self) -> None:
        rows, self._rows = self._rows, []
        if not rows:
            return
        if self._pending is not None:
            self._pending.result()  # one group at a time, in order; raises what the last write raised
        self._pending = self._pool.submit(self._write_group, rows)

    def _write_group(self, rows: list[tuple]) -> None:
        """Rows (Observer.raw tuples) -> one row group (Parquet) or lines (CSV). Runs in the writer thread."""
        n_sig = len(self.scene.signals)
        steps, times, values, poses, joints = zip(*rows)
        values = list(zip(*values)) if n_sig else []
        poses = np.array(poses, dtype=float).reshape(len(rows), -1)
        joints = np.array(joints, dtype=float).reshape(len(rows), -1)
        kinds = [t for _, t in self.columns[2:2 + n_sig]]
        if self._writer is not None:
            import pyarrow as pa

            arrays = [pa.array(steps, pa.int64()), pa.array(times, pa.float64())]
            for col, kind in zip(values, kinds):
                arrays.append(_arrow_column(pa, col, kind))
            arrays += [pa.array(poses[:, k]) for k in range(poses.shape[1])]
            arrays += [pa.array(joints[:, k]) for k in range(joints.shape[1])]
            self._writer.write_table(pa.Table.from_arrays(arrays, schema=self._schema))
        else:
            cols = [steps, [repr(t) for t in times]]
            for col, kind in zip(values, kinds):
                cols.append([_csv_text(v, kind) for v in col])
            cols += [[repr(float(v)) for v in poses[:, k]] for k in range(poses.shape[1])]
            cols += [[repr(float(v)) for v in joints[:, k]] for k in range(joints.shape[1])]
            self._csv.writerows(zip(*cols))

    def close(self) -> None:
        """Write what is buffered and finish the file (a Parquet file is unreadable until then)."""
        if self._closed:
            return
        self._closed = True
        detach(self.twin, self)
        try:
            self._flush()
            if self._pending is not None:
                self._pending.result()
        finally:
            self._pool.shutdown()
            if self._writer is not None:
                self._writer.close()
            else:
                self._file.close()

    def __enter__(self) -> "Recorder":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


_ARROW_TYPES = {"bool": "bool_", "int64": "int64", "string": "string", "float64": "float64"}


def _arrow_column(pa, col, kind):
    typ = getattr(pa, _ARROW_TYPES[kind])()
    try:
        return pa.array(col, typ)
    except (pa.ArrowInvalid, pa.ArrowTypeError, TypeError):  # e.g. numpy scalars or ints among floats
        conv = {"bool": bool, "int64": int, "string": str, "float64": float}[kind]
        return pa.array([conv(v) for v in col], typ)


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
            try:
                table = pq.read_table(str(path))
            except Exception as exc:  # pyarrow's errors are of several kinds; all mean "not a readable file"
                raise RecordingError(f"{path}: not a readable Parquet recording ({exc})") from None
            meta = (table.schema.metadata or {}).get(META_KEY.encode())
            if meta is None:
                raise RecordingError(f"{path}: a Parquet file without gripper-twin metadata: not a recording")
            scene = Scene.from_dict(json.loads(meta)["scene"])
            columns = {name: table.column(name).to_numpy(zero_copy_only=False) for name in table.column_names}
        else:
            meta_path = Path(str(path) + ".json")
            if not meta_path.is_file():
                raise RecordingError(f"{path}: its scene file {meta_path.name} is missing beside it")
            scene = Scene.from_dict(json.loads(meta_path.read_text(encoding="utf-8"))["scene"])
            kinds = dict(columns_of(scene))
            with open(path, newline="", encoding="utf-8") as f:
                rows = list(csv.reader(f))
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
