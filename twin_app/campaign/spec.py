"""Campaign files: a TOML file read into a checked `Campaign` with its list of scenarios.

The format is documented in docs/campaigns.md. Every mistake is a `SpecError` naming the file, the key and,
where it belongs to one, the scenario: `campaign.toml: matrix.ring.offset_x_mm: must be a list of values`.
Unknown keys are errors, with the nearest known key suggested. Nothing here starts physics: the station is
read (its file, the gripper's URDF) to check the names of targets and inputs.
"""
from __future__ import annotations

import difflib
import hashlib
import itertools
import json
import math
import random
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from twin.core.errors import TwinError

from .expressions import Expression, ExpressionError

# -- the vocabulary -----------------------------------------------------------------------------------------
TARGET_KEYS = {  # parameter TARGET.KEY: what it changes (see docs/campaigns.md)
    "offset_x_mm", "offset_y_mm", "offset_z_mm", "roll_deg", "pitch_deg", "yaw_deg",
    "outer_diameter_mm", "inner_diameter_mm", "height_mm", "radius_mm", "size_x_mm", "size_y_mm", "size_z_mm",
    "mass_kg", "density", "friction", "present",
}
INPUT_KEYS = {"effort", "velocity_mm_s", "velocity_deg_s"}
GRIPPER_KEYS = {"effort", "velocity_mm_s", "velocity_deg_s", "friction"}
SIM_KEYS = {"step", "substeps"}
FAULT_KINDS = {  # kind: (required keys, optional keys)
    "part_missing": ({"target"}, {"at", "duration"}),
    "part_displaced": ({"target"}, {"at", "offset_mm", "yaw_deg"}),
    "finger_jammed": ({"input"}, {"at", "duration", "position_mm", "position_deg"}),
    "finger_force_lost": ({"input"}, {"at", "duration", "effort"}),
    "force_stuck": (set(), {"finger", "signal", "at", "duration", "value"}),
    "force_offset": ({"offset"}, {"finger", "signal", "at", "duration"}),
    "reading_stuck": ({"signal"}, {"at", "duration", "value"}),
    "reading_offset": ({"signal", "offset"}, {"at", "duration"}),
    "link_lost": ({"duration"}, {"at"}),
    "link_latency": (set(), {"latency", "jitter", "seed", "at"}),
    "robot_stopped": (set(), {"at", "duration"}),
}
LINK_KINDS = {"link_lost", "link_latency"}
EXPECT_KEYS = {"outcome", "fault", "grip", "grips", "misses", "cycle_time_max", "part", "part_at_mm",
               "part_tolerance_mm", "part_present", "max_finger_force", "slip", "plc_fault", "values"}
OUTCOMES = ("completed", "stopped", "timeout", "error")
GRIP_OUTCOMES = ("confirmed", "missed", "retried", "none")
DEFAULT_TIMEOUT = 300.0  # s of wall time one scenario may take
DEFAULT_MAX_TIME = 60.0  # s of simulated time


class SpecError(TwinError):
    """A mistake in a campaign file: names the file, the key and (where it applies) the scenario."""

    def __init__(self, file: str | Path, key: str, message: str, scenario: str | None = None):
        self.file, self.key, self.message, self.scenario = str(file), key, message, scenario
        where = f"{self.file}: {key}: " if key else f"{self.file}: "
        super().__init__(where + message + (f" (scenario {scenario})" if scenario else ""))


@dataclass
class Driver:
    kind: str  # "plc", "rapid" or "check"
    ref: str = ""  # plc/check: "module:name" or "file.py:name"; rapid: a program file or "" (the station's)
    entry: str | None = None  # rapid: the entry routine (default: the station's)
    scan: float = 0.010  # plc: the scan cycle, s
    base: Path = Path(".")  # where a file reference is relative to


@dataclass
class FaultSpec:
    name: str
    kind: str
    keys: dict


@dataclass
class Scenario:
    index: int
    name: str
    params: dict  # every parameter of the scenario (the campaign's base values and its own)
    own: tuple[str, ...]  # the keys that make it this scenario (its name)
    expect: dict  # the scenario's own expectation overrides
    origin: str  # "matrix", "scenarios[2]", "sample"

    @property
    def key(self) -> str:
        """Identity for --resume: the name and a digest of the parameters and expectations."""
        blob = json.dumps([self.name, self.params, self.expect], sort_keys=True, default=str)
        return f"{self.index}:{hashlib.sha1(blob.encode()).hexdigest()[:12]}"


@dataclass
class Campaign:
    file: Path
    name: str
    station: Path
    driver: Driver
    start: dict  # signal -> value written before the first step (map units)
    max_time: float
    done_when: Expression | None
    stop_when: dict  # name -> Expression
    timeout: float
    faults: dict  # name -> FaultSpec
    expect: dict
    when: list  # [(Expression, dict)]
    measure: dict
    scenarios: list[Scenario] = field(default_factory=list)
    watchdog: float | None = None  # s: the comm-loss watchdog's time (default: the station's [watchdog])
    record: tuple[str, ...] = ()  # signals traced for failing scenarios

    def scenario(self, index: int) -> Scenario:
        return self.scenarios[index]


# -- reading ----------------------------------------------------------------------------------------------
def flatten(table: dict, prefix: str = "") -> dict:
    """TOML's dotted keys make nested tables: `ring.offset_x_mm = 1` is {"ring": {"offset_x_mm": 1}}.
    Parameters are named by their dotted path again. (Fault-level tables are kept whole where asked.)"""
    out = {}
    for k, v in table.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict) and not _is_leaf_table(v):
            out.update(flatten(v, name + "."))
        else:
            out[name] = v
    return out


def _is_leaf_table(v: dict) -> bool:
    """A distribution ({uniform = [..]}) is a value, not a nesting level."""
    return bool(v) and set(v) <= {"uniform", "choice", "normal", "integers", "round"}


def _suggest(word: str, known) -> str:
    near = difflib.get_close_matches(word, list(known), n=1, cutoff=0.6)
    return f" (did you mean {near[0]!r}?)" if near else ""


def _number(file, key, value, *, positive=False, nonnegative=False, scenario=None) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise SpecError(file, key, f"must be a finite number, not {value!r}", scenario)
    if positive and value <= 0:
        raise SpecError(file, key, f"must be greater than 0, not {value!r}", scenario)
    if nonnegative and value < 0:
        raise SpecError(file, key, f"must not be negative, not {value!r}", scenario)
    return float(value)


class _Station:
    """The names a campaign may use from its station (read without physics)."""

    def __init__(self, file: Path, path: Path):
        from twin.core.errors import TwinError
        from twin.core.station import gripper_mechanism, load_station

        try:
            self.station = load_station(path)
            mech = gripper_mechanism(self.station)
        except TwinError as exc:
            raise SpecError(file, "campaign.station", f"cannot be loaded: {exc}") from None
        self.targets = {t.name: t for t in self.station.targets}
        self.inputs = {i.name: i for i in mech.inputs}
        self.fingers = [f.name for f in mech.fingers]


def read_toml(file: Path) -> dict:
    """A campaign or faults file's tables; a file that cannot be read or parsed is a SpecError naming it."""
    try:
        return tomllib.loads(file.read_text())
    except OSError as exc:
        raise SpecError(file, "", f"cannot be read: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(file, "", f"is not valid TOML: {exc}") from None


def load_campaign(path: str | Path) -> Campaign:
    """Read and check a campaign file; its scenarios are expanded (matrix, list, samples) in order."""
    file = Path(path)
    data = read_toml(file)
    known = {"campaign", "driver", "start", "run", "parameters", "matrix", "scenarios", "sample", "faults",
             "expect", "measure"}
    for k in data:
        if k not in known:
            raise SpecError(file, k, "is not a section of a campaign file" + _suggest(k, known))
    head = _table(file, data, "campaign", required=True)
    _only(file, "campaign", head, {"name", "station", "description", "record"})
    if "station" not in head:
        raise SpecError(file, "campaign.station", "is required (the station folder or station.toml, relative to this file)")
    if not isinstance(head["station"], str):
        raise SpecError(file, "campaign.station", f"must be a path (a string), not {head['station']!r}")
    station_path = (file.parent / head["station"]).resolve()
    st = _Station(file, station_path)
    name = head.get("name", file.stem)
    record = head.get("record", [])
    if not (isinstance(record, list) and all(isinstance(s, str) for s in record)):
        raise SpecError(file, "campaign.record", f"must be a list of signal names, not {record!r}")

    driver = _driver(file, _table(file, data, "driver", required=True))
    start = _table(file, data, "start")
    for k, v in flatten(start).items():
        if not isinstance(v, (bool, int, float)):
            raise SpecError(file, f"start.{k}", f"must be a number or true/false, not {v!r}")
    start = flatten(start)

    run = _table(file, data, "run")
    _only(file, "run", run, {"max_time", "done_when", "stop_when", "timeout", "watchdog"})
    watchdog = _number(file, "run.watchdog", run["watchdog"], positive=True) if "watchdog" in run else None
    max_time = _number(file, "run.max_time", run.get("max_time", DEFAULT_MAX_TIME), positive=True)
    timeout = _number(file, "run.timeout", run.get("timeout", DEFAULT_TIMEOUT), positive=True)
    done_when = _expr(file, "run.done_when", run["done_when"]) if "done_when" in run else None
    stop = run.get("stop_when", {})
    if not isinstance(stop, dict):
        raise SpecError(file, "run.stop_when", "must be a table of named conditions: { cycle_fault = \"cycle_fault_bit\" }")
    stop_when = {k: _expr(file, f"run.stop_when.{k}", v) for k, v in stop.items()}

    faults = {}
    for fname, ftable in _table(file, data, "faults").items():
        faults[fname] = _fault(file, fname, ftable, st)

    measure = _table(file, data, "measure")
    _only(file, "measure", measure, {"grip", "miss", "part"})
    for k, v in measure.items():
        if not isinstance(v, str):
            raise SpecError(file, f"measure.{k}", f"must be a name (a string), not {v!r}")
    if "part" in measure and measure["part"] not in st.targets:
        raise SpecError(file, "measure.part", f"no target {measure['part']!r} in the station" + _suggest(measure["part"], st.targets))

    expect_table = dict(_table(file, data, "expect"))
    when_list = expect_table.pop("when", [])
    if not isinstance(when_list, list) or not all(isinstance(w, dict) for w in when_list):
        raise SpecError(file, "expect.when", "must be a list of tables ([[expect.when]] with an `if` and expectations)")
    expect = _expectations(file, "expect", expect_table, st)
    when = []
    for i, w in enumerate(when_list):
        w = dict(w)
        if "if" not in w:
            raise SpecError(file, f"expect.when[{i}].if", "is required: the condition on the scenario's parameters")
        cond = _expr(file, f"expect.when[{i}].if", w.pop("if"))
        when.append((cond, _expectations(file, f"expect.when[{i}]", w, st)))

    campaign = Campaign(file=file, name=str(name), station=station_path, driver=driver, start=start, max_time=max_time,
                        done_when=done_when, stop_when=stop_when, timeout=timeout, faults=faults, expect=expect,
                        when=when, measure=measure, record=tuple(record), watchdog=watchdog)
    base = flatten(_table(file, data, "parameters"))
    for k, v in base.items():
        _check_param(file, f"parameters.{k}", k, v, st, faults, driver)
    campaign.scenarios = _expand(file, data, base, st, faults, driver)
    for sc in campaign.scenarios:  # every parameter a `when` reads must exist in every scenario
        for i, (cond, _) in enumerate(when):
            missing = [n for n in cond.names if n not in _condition_values(sc)]
            if missing:
                raise SpecError(file, f"expect.when[{i}].if", f"reads {missing[0]!r}, which scenario {sc.name!r} "
                                f"does not set (parameters: {', '.join(sorted(sc.params)) or 'none'}, fault)", sc.name)
    return campaign


def _condition_values(sc: Scenario) -> dict:
    values = dict(sc.params)
    values.setdefault("fault", "none")
    if isinstance(values["fault"], list):
        values["fault"] = "+".join(values["fault"]) or "none"
    values["index"] = sc.index
    return values


def scenario_values(sc: Scenario) -> dict:
    """What an `[[expect.when]]` condition can read: the parameters, `fault` and `index`."""
    return _condition_values(sc)


def _table(file, data, key, required=False) -> dict:
    if key not in data:
        if required:
            raise SpecError(file, key, "is required")
        return {}
    if not isinstance(data[key], dict):
        raise SpecError(file, key, "must be a table")
    return data[key]


def _only(file, prefix, table, allowed) -> None:
    for k in table:
        if k not in allowed:
            raise SpecError(file, f"{prefix}.{k}", "is not a known key" + _suggest(k, allowed))


def _expr(file, key, text) -> Expression:
    try:
        return Expression(text)
    except ExpressionError as exc:
        raise SpecError(file, key, str(exc)) from None


def st_files(ref) -> list[str]:
    """A PLC driver given as Structured Text files ("gripper.st io.st", or a list of them), else []."""
    names = ref.split() if isinstance(ref, str) else ref if isinstance(ref, list) else []
    ok = names and all(isinstance(n, str) and n.lower().endswith(".st") for n in names)
    return list(names) if ok else []


def _driver(file, d: dict) -> Driver:
    kinds = [k for k in ("plc", "rapid", "check") if k in d]
    if len(kinds) != 1:
        raise SpecError(file, "driver", "needs exactly one of plc = \"module:logic\", rapid = true (or a program "
                                         "file) or check = \"module:function\"")
    kind = kinds[0]
    _only(file, "driver", d, {kind, "scan", "entry"})
    ref = d[kind]
    if kind == "rapid":
        if ref is True:
            ref = ""
        elif not isinstance(ref, str) or not ref:
            raise SpecError(file, "driver.rapid", f"must be true (the station's program) or a program file, not {ref!r}")
    elif kind == "plc" and st_files(ref):
        for name in st_files(ref):  # a Structured Text PLC: its files, beside the campaign file
            if not (file.parent / name).is_file():
                raise SpecError(file, "driver.plc", f"{name}: no such file (beside {file.name})")
        ref = " ".join(st_files(ref))
    elif not isinstance(ref, str) or ":" not in ref:
        raise SpecError(file, f"driver.{kind}", f"must be \"module:name\", \"file.py:name\" or Structured Text "
                                                f"files (\"gripper.st io.st\"), not {ref!r}")
    scan = _number(file, "driver.scan", d.get("scan", 0.010), positive=True)
    entry = d.get("entry")
    if entry is not None and not isinstance(entry, str):
        raise SpecError(file, "driver.entry", f"must be a routine name, not {entry!r}")
    driver = Driver(kind, ref, entry, scan, file.parent.resolve())
    if kind != "rapid" and not st_files(ref):
        from twin_app.plugins import LoadError, load_object

        try:
            load_object(ref, driver.base)
        except LoadError as exc:
            raise SpecError(file, f"driver.{kind}", str(exc)) from None
    return driver


def _fault(file, name, table, st: _Station) -> FaultSpec:
    key = f"faults.{name}"
    if not isinstance(table, dict):
        raise SpecError(file, key, "must be a table with a `kind`")
    kind = table.get("kind")
    if kind not in FAULT_KINDS:
        raise SpecError(file, f"{key}.kind", f"must be one of {', '.join(FAULT_KINDS)}, not {kind!r}"
                        + (_suggest(kind, FAULT_KINDS) if isinstance(kind, str) else ""))
    required, optional = FAULT_KINDS[kind]
    keys = {k: v for k, v in table.items() if k != "kind"}
    for k in keys:
        if k not in required | optional:
            raise SpecError(file, f"{key}.{k}", f"is not a key of a {kind} fault" + _suggest(k, required | optional))
    for k in required:
        if k not in keys:
            raise SpecError(file, f"{key}.{k}", f"is required for a {kind} fault")
    _check_fault_keys(file, key, kind, keys, st)
    return FaultSpec(name, kind, keys)


def _check_fault_keys(file, key, kind, keys, st: _Station, scenario=None) -> None:
    for k in ("at", "duration", "latency", "jitter", "effort"):
        if k in keys:
            _number(file, f"{key}.{k}", keys[k], nonnegative=True, scenario=scenario)
    if "duration" in keys and keys["duration"] <= 0:
        raise SpecError(file, f"{key}.duration", "must be greater than 0 s", scenario)
    for k in ("offset", "value", "yaw_deg", "position_mm", "position_deg"):
        if k in keys and not isinstance(keys[k], bool):
            _number(file, f"{key}.{k}", keys[k], scenario=scenario)
    if "seed" in keys and (isinstance(keys["seed"], bool) or not isinstance(keys["seed"], int)):
        raise SpecError(file, f"{key}.seed", f"must be a whole number, not {keys['seed']!r}", scenario)
    if "offset_mm" in keys:
        v = keys["offset_mm"]
        if not (isinstance(v, list) and len(v) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)):
            raise SpecError(file, f"{key}.offset_mm", f"must be [x, y, z] in mm, not {v!r}", scenario)
    if "target" in keys and keys["target"] not in st.targets:
        raise SpecError(file, f"{key}.target", f"no target {keys['target']!r} in the station (targets: "
                        f"{', '.join(st.targets) or 'none'})" + _suggest(str(keys['target']), st.targets), scenario)
    if "input" in keys and keys["input"] not in st.inputs:
        raise SpecError(file, f"{key}.input", f"no gripper input {keys['input']!r} (inputs: {', '.join(st.inputs)})"
                        + _suggest(str(keys["input"]), st.inputs), scenario)
    if "finger" in keys and keys["finger"] not in st.fingers:
        raise SpecError(file, f"{key}.finger", f"no finger {keys['finger']!r} (fingers: {', '.join(st.fingers)})"
                        + _suggest(str(keys["finger"]), st.fingers), scenario)
    if kind in ("force_stuck", "force_offset") and ("finger" in keys) == ("signal" in keys):
        raise SpecError(file, key, f"a {kind} fault names either a finger or a signal", scenario)


def _expectations(file, key, table: dict, st: _Station) -> dict:
    out = {}
    for k, v in table.items():
        where = f"{key}.{k}"
        if k not in EXPECT_KEYS:
            raise SpecError(file, where, "is not a known expectation" + _suggest(k, EXPECT_KEYS))
        if k == "outcome":
            vals = v if isinstance(v, list) else [v]
            if not vals or any(x not in OUTCOMES for x in vals):
                raise SpecError(file, where, f"must be one of {', '.join(OUTCOMES)} (or a list of them), not {v!r}")
        elif k == "grip":
            if v not in GRIP_OUTCOMES:
                raise SpecError(file, where, f"must be one of {', '.join(GRIP_OUTCOMES)}, not {v!r}")
        elif k in ("fault", "plc_fault"):
            if not isinstance(v, str):
                raise SpecError(file, where, f"must be a name (\"none\" for no fault), not {v!r}")
        elif k in ("grips", "misses"):
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise SpecError(file, where, f"must be a whole number >= 0, not {v!r}")
        elif k in ("cycle_time_max", "part_tolerance_mm", "max_finger_force"):
            _number(file, where, v, positive=True)
        elif k in ("slip", "part_present"):
            if not isinstance(v, bool):
                raise SpecError(file, where, f"must be true or false, not {v!r}")
        elif k == "part":
            if v not in st.targets:
                raise SpecError(file, where, f"no target {v!r} in the station" + _suggest(str(v), st.targets))
        elif k == "part_at_mm":
            if not (isinstance(v, list) and len(v) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)):
                raise SpecError(file, where, f"must be [x, y, z] in mm, not {v!r}")
        elif k == "values":
            if not isinstance(v, dict):
                raise SpecError(file, where, "must be a table: name = value or { min = .., max = .. }")
            for name, want in v.items():
                if isinstance(want, dict):
                    _only(file, f"{where}.{name}", want, {"min", "max", "equal"})
                    for b in want:
                        if b != "equal":
                            _number(file, f"{where}.{name}.{b}", want[b])
        out[k] = v
    return out


def _check_param(file, key, name, value, st: _Station, faults, driver: Driver, scenario=None) -> None:
    """A parameter's name must mean something, and its value fit it."""
    parts = name.split(".")
    head = parts[0]

    def number(**kw):
        if isinstance(value, dict):  # a distribution: checked when sampled
            return
        _number(file, key, value, scenario=scenario, **kw)

    if name == "fault":
        names = value if isinstance(value, list) else [value]
        for n in names:
            if not isinstance(n, str) or (n != "none" and n not in faults):
                raise SpecError(file, key, f"no fault {n!r} in [faults] (faults: {', '.join(faults) or 'none'}; "
                                "\"none\" for no fault)" + (_suggest(n, faults) if isinstance(n, str) else ""), scenario)
        return
    if head in st.targets and len(parts) == 2:
        if parts[1] not in TARGET_KEYS:
            raise SpecError(file, key, f"{parts[1]!r} is not a target parameter" + _suggest(parts[1], TARGET_KEYS), scenario)
        if parts[1] == "present":
            if not isinstance(value, bool):
                raise SpecError(file, key, f"must be true or false, not {value!r}", scenario)
            return
        number(positive=parts[1] in ("mass_kg", "density", "outer_diameter_mm", "inner_diameter_mm", "height_mm",
                                     "radius_mm", "size_x_mm", "size_y_mm", "size_z_mm"),
               nonnegative=parts[1] == "friction")
        return
    if head == "gripper":
        if len(parts) == 2 and parts[1] in GRIPPER_KEYS:
            return number(positive=parts[1] != "friction", nonnegative=True)
        if len(parts) == 3 and parts[1] in st.inputs:
            if parts[2] not in INPUT_KEYS:
                raise SpecError(file, key, f"{parts[2]!r} is not a drive parameter" + _suggest(parts[2], INPUT_KEYS), scenario)
            return number(positive=True)
        raise SpecError(file, key, f"gripper parameters are gripper.{{{', '.join(sorted(GRIPPER_KEYS))}}} or "
                        f"gripper.INPUT.{{{', '.join(sorted(INPUT_KEYS))}}} with INPUT one of {', '.join(st.inputs)}", scenario)
    if head == "sim":
        if len(parts) != 2 or parts[1] not in SIM_KEYS:
            raise SpecError(file, key, "simulation parameters are sim.step (s) and sim.substeps", scenario)
        if parts[1] == "substeps":
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise SpecError(file, key, f"must be a whole number >= 1, not {value!r}", scenario)
            return
        return number(positive=True)
    if head == "plc":
        if driver.kind != "plc":
            raise SpecError(file, key, "plc.* parameters need a PLC driver (driver.plc)", scenario)
        if len(parts) != 2:
            raise SpecError(file, key, "a PLC parameter is plc.NAME (an argument of the logic)", scenario)
        return
    if head == "start":
        if len(parts) < 2 or not isinstance(value, (bool, int, float)):
            raise SpecError(file, key, "start.SIGNAL = a number or true/false", scenario)
        return
    if head == "faults":
        if len(parts) != 3 or parts[1] not in faults:
            raise SpecError(file, key, f"a fault parameter is faults.NAME.KEY with NAME one of {', '.join(faults) or '(none)'}", scenario)
        f = faults[parts[1]]
        required, optional = FAULT_KINDS[f.kind]
        if parts[2] not in required | optional:
            raise SpecError(file, key, f"{parts[2]!r} is not a key of a {f.kind} fault" + _suggest(parts[2], required | optional), scenario)
        if not isinstance(value, dict):
            _check_fault_keys(file, key.rsplit(".", 1)[0], f.kind, {parts[2]: value}, st, scenario)
        return
    if head == "var":
        return
    raise SpecError(file, key, f"unknown parameter {name!r}: parameters are TARGET.KEY (targets: "
                    f"{', '.join(st.targets) or 'none'}), gripper.*, sim.*, plc.*, start.*, faults.NAME.KEY, var.* "
                    "or fault" + _suggest(name, [f"{t}.{k}" for t in st.targets for k in TARGET_KEYS] + ["fault"]),
                    scenario)


# -- scenarios ----------------------------------------------------------------------------------------------
def _fmt(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, list):
        return "+".join(_fmt(x) for x in v)
    return str(v)


def scenario_name(params: dict, own: tuple[str, ...]) -> str:
    return ", ".join(f"{k}={_fmt(params[k])}" for k in own) or "base"


def _expand(file, data, base, st, faults, driver) -> list[Scenario]:
    rows: list[tuple[dict, tuple, dict, str, str | None]] = []  # (own params, own keys, expect, origin, name)
    matrix = flatten(_table(file, data, "matrix"))
    if matrix:
        for k, values in matrix.items():
            if not isinstance(values, list) or not values:
                raise SpecError(file, f"matrix.{k}", f"must be a non-empty list of values, not {values!r}")
            for v in values:
                _check_param(file, f"matrix.{k}", k, v, st, faults, driver)
        keys = tuple(matrix)
        for combo in itertools.product(*(matrix[k] for k in keys)):
            rows.append((dict(zip(keys, combo)), keys, {}, "matrix", None))
    listed = data.get("scenarios", [])
    if not isinstance(listed, list) or not all(isinstance(s, dict) for s in listed):
        raise SpecError(file, "scenarios", "must be a list of tables ([[scenarios]])")
    for i, table in enumerate(listed):
        table = dict(table)
        label = table.pop("name", None)
        if label is not None and not isinstance(label, str):
            raise SpecError(file, f"scenarios[{i}].name", f"must be a string, not {label!r}")
        exp = table.pop("expect", {})
        if not isinstance(exp, dict):
            raise SpecError(file, f"scenarios[{i}].expect", "must be a table of expectations", label)
        own = flatten(table)
        for k, v in own.items():
            _check_param(file, f"scenarios[{i}].{k}", k, v, st, faults, driver, label)
        exp = _expectations(file, f"scenarios[{i}].expect", exp, st)
        rows.append((own, tuple(own), exp, f"scenarios[{i}]", label))
    sample = dict(_table(file, data, "sample"))
    if sample:
        count, seed = sample.pop("count", None), sample.pop("seed", None)
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            raise SpecError(file, "sample.count", f"is required: how many scenarios to draw (>= 1), not {count!r}")
        if isinstance(seed, bool) or not isinstance(seed, int):
            raise SpecError(file, "sample.seed", f"is required: a whole number, so the same scenarios are drawn every run, not {seed!r}")
        dists = flatten(sample)
        for k, d in dists.items():
            _check_param(file, f"sample.{k}", k, d, st, faults, driver)
            _check_distribution(file, f"sample.{k}", d)
        rng = random.Random(seed)
        keys = tuple(dists)
        for _ in range(count):
            own = {k: _draw(rng, dists[k]) for k in keys}
            for k, v in own.items():
                _check_param(file, f"sample.{k}", k, v, st, faults, driver)
            rows.append((own, keys, {}, "sample", None))
    if not rows:
        rows.append(({}, (), {}, "base", None))
    scenarios, seen = [], {}
    for index, (own, keys, exp, origin, label) in enumerate(rows):
        params = {**base, **own}
        name = label or scenario_name(params, keys)
        if name in seen:
            name = f"{name} #{index}"
        seen[name] = index
        scenarios.append(Scenario(index, name, params, keys, exp, origin))
    return scenarios


def _check_distribution(file, key, d) -> None:
    if isinstance(d, dict):
        kinds = [k for k in ("uniform", "choice", "normal", "integers") if k in d]
        if len(kinds) != 1:
            raise SpecError(file, key, "a distribution is one of { uniform = [low, high] }, { choice = [...] }, "
                                       "{ normal = [mean, sd] }, { integers = [low, high] } (optional round = digits)")
        v = d[kinds[0]]
        if not isinstance(v, list) or not v or (kinds[0] != "choice" and (len(v) != 2 or not all(
                isinstance(x, (int, float)) and not isinstance(x, bool) for x in v))):
            raise SpecError(file, key, f"{kinds[0]} needs {'a list of values' if kinds[0] == 'choice' else '[a, b] (numbers)'}")
        if "round" in d and (isinstance(d["round"], bool) or not isinstance(d["round"], int)):
            raise SpecError(file, f"{key}.round", "must be a whole number of digits")
    elif isinstance(d, list):
        if not d:
            raise SpecError(file, key, "an empty list: nothing to choose from")
    # a plain value: the same in every drawn scenario


def _draw(rng: random.Random, d):
    if isinstance(d, list):
        return d[rng.randrange(len(d))]
    if not isinstance(d, dict):
        return d
    if "choice" in d:
        return d["choice"][rng.randrange(len(d["choice"]))]
    if "integers" in d:
        lo, hi = d["integers"]
        return rng.randint(int(lo), int(hi))
    if "uniform" in d:
        lo, hi = d["uniform"]
        v = lo + (hi - lo) * rng.random()
    else:
        mu, sd = d["normal"]
        v = rng.gauss(mu, sd)
    return round(v, d["round"]) if "round" in d else v
