"""One scenario, run in lockstep: the station with the scenario's parameters, its faults, its driver, and
what was measured. `run_scenario(campaign, index)` returns a dict of plain values that depends only on the
campaign file and the scenario (the same on every run, backend and machine): no wall time in it.

The cell is assembled by `twin_app.cell.Cell` (the twin, the station's RAPID controller and the comm-loss
watchdog as devices, as `twin serve` has them), in process and without front ends; the scenario adds its
fault injector, monitor and recorder to the cell's twin, and steps the cell (the PLC through `TwinIO(cell)`).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

from twin_app.plugins import load_object
from .spec import Campaign, Scenario
from twin.core.device import ObservingDevice
from twin.core.errors import TwinError
from twin.core.signals import ENGINEERING_UNITS

UNIT_TO_MAP = {si: factor for si, (_, factor) in ENGINEERING_UNITS.items()}  # SI -> the map's units (mm, deg)
# wall seconds of the last scenario run in this process: loading the station, running the driver (for the
# benchmark; never part of the results, which must not depend on the wall clock)
LAST_TIMING: dict[str, float] = {}


class ScenarioError(TwinError):
    """A scenario that cannot run as written (a parameter that does not fit the station, a bad logic)."""


# -- the station with the scenario's parameters ---------------------------------------------------------------
def build_station(station, params: dict):
    """A copy of `station` (a frozen `Station`) with the scenario's parameters applied."""
    from twin.core.station import JointOverride, Placement

    targets = []
    for body in station.targets:
        p = {k.split(".", 1)[1]: v for k, v in params.items() if k.startswith(body.name + ".")}
        if not p:
            targets.append(body)
            continue
        xyz = tuple(c + p.get(f"offset_{a}_mm", 0.0) / 1000.0 for c, a in zip(body.pose.xyz, "xyz"))
        rpy = tuple(c + p.get(f"{a}_deg", 0.0) for c, a in zip(body.pose.rpy_deg, ("roll", "pitch", "yaw")))
        changes: dict[str, Any] = {"pose": Placement(xyz, rpy)}
        for key, attr in (("outer_diameter_mm", "outer_diameter"), ("inner_diameter_mm", "inner_diameter"),
                          ("height_mm", "height"), ("radius_mm", "radius")):
            if key in p:
                changes[attr] = p[key] / 1000.0
        if any(f"size_{a}_mm" in p for a in "xyz"):
            changes["size"] = tuple(p.get(f"size_{a}_mm", s * 1000.0) / 1000.0 for a, s in zip("xyz", body.size))
        if "friction" in p:
            changes["friction"] = float(p["friction"])
        if "density" in p:
            changes["density"] = float(p["density"])
        body = dataclasses.replace(body, **changes)
        if body.shape == "ring" and not body.inner_diameter < body.outer_diameter:
            raise ScenarioError(f"{body.name}: inner diameter {body.inner_diameter * 1000:g} mm is not below the "
                                f"outer diameter {body.outer_diameter * 1000:g} mm")
        if "mass_kg" in p:
            if body.volume <= 0:
                raise ScenarioError(f"{body.name}.mass_kg: a {body.shape} has no volume to give a mass")
            body = dataclasses.replace(body, density=p["mass_kg"] / body.volume)
        targets.append(body)

    g = station.gripper
    from twin.core.station import gripper_mechanism

    inputs = {i.name: i for i in gripper_mechanism(station).inputs}
    joints = dict(g.joints)
    for name, inp in inputs.items():
        velocity = effort = None
        for scope in ("gripper", f"gripper.{name}"):
            if f"{scope}.effort" in params:
                effort = float(params[f"{scope}.effort"])
            for key, unit, factor in (("velocity_mm_s", "m", 1e-3), ("velocity_deg_s", "rad", math.pi / 180.0)):
                if f"{scope}.{key}" in params:
                    if inp.unit == unit:
                        velocity = float(params[f"{scope}.{key}"]) * factor
                    elif scope != "gripper":
                        raise ScenarioError(f"{scope}.{key}: {name} is a {'prismatic' if inp.unit == 'm' else 'revolute'} "
                                            f"axis: use {scope}.{'velocity_mm_s' if inp.unit == 'm' else 'velocity_deg_s'}")
        if velocity is not None or effort is not None:
            old = joints.get(name) or JointOverride()
            joints[name] = JointOverride(velocity if velocity is not None else old.velocity,
                                         effort if effort is not None else old.effort)
    gripper = dataclasses.replace(g, joints=joints, **({"friction": float(params["gripper.friction"])}
                                                        if "gripper.friction" in params else {}))
    changes = {"targets": tuple(targets), "gripper": gripper}
    if "sim.step" in params:
        changes["step"] = float(params["sim.step"])
    if "sim.substeps" in params:
        changes["substeps"] = int(params["sim.substeps"])
    return dataclasses.replace(station, **changes)


# -- faults -------------------------------------------------------------------------------------------------
def fault_names(params: dict) -> list[str]:
    value = params.get("fault", "none")
    names = value if isinstance(value, list) else [value]
    return [n for n in names if n != "none"]


def build_faults(campaign: Campaign, params: dict, twin) -> tuple[list, dict]:
    """The scenario's plant faults (for `FaultInjector`) and its link faults (for `LinkFaults`)."""
    from twin.runtime import faults as F

    plant, link = [], {"lost": [], "latency": 0.0, "jitter": 0.0, "seed": 0}
    for name in fault_names(params):
        spec = campaign.faults[name]
        k = dict(spec.keys)
        for p, v in params.items():
            if p.startswith(f"faults.{name}."):
                k[p.rsplit(".", 1)[1]] = v
        at, duration = float(k.get("at", 0.0)), k.get("duration")
        duration = None if duration is None else float(duration)
        kind = spec.kind
        if kind == "part_missing":
            plant.append(F.PartMissing(at, duration, target=k["target"]))
        elif kind == "part_displaced":
            offset = tuple(v / 1000.0 for v in k.get("offset_mm", (0.0, 0.0, 0.0)))
            plant.append(F.PartDisplaced(at, None, target=k["target"], offset=offset, yaw_deg=float(k.get("yaw_deg", 0.0))))
        elif kind == "finger_jammed":
            position = None
            if "position_mm" in k:
                position = k["position_mm"] / 1000.0
            elif "position_deg" in k:
                position = math.radians(k["position_deg"])
            plant.append(F.FingerJammed(at, duration, input=k["input"], position=position))
        elif kind == "finger_force_lost":
            plant.append(F.DriveForceLost(at, duration, input=k["input"], effort=float(k.get("effort", 0.0))))
        elif kind in ("force_stuck", "force_offset", "reading_stuck", "reading_offset"):
            signal = k["signal"] if "signal" in k else f"{k['finger']}.force"
            factor = UNIT_TO_MAP.get(_unit(twin, signal, name), 1.0)
            if kind.endswith("stuck"):
                value = k.get("value")
                if value is not None and not isinstance(value, bool):
                    value = float(value) / factor
                plant.append(F.ReadingStuck(at, duration, signal=signal, value=value))
            else:
                plant.append(F.ReadingOffset(at, duration, signal=signal, offset=float(k["offset"]) / factor))
        elif kind == "robot_stopped":
            plant.append(F.RobotStopped(at, duration))
        elif kind == "link_lost":
            link["lost"].append((at, at + float(k["duration"])))
        elif kind == "link_latency":
            link["latency"] = float(k.get("latency", 0.0))
            link["jitter"] = float(k.get("jitter", 0.0))
            link["seed"] = int(k.get("seed", 0))
    return plant, link


def _unit(twin, signal: str, fault: str) -> str:
    from twin.core.errors import SignalError

    try:
        return twin.spec(signal).unit
    except SignalError as exc:
        raise ScenarioError(f"fault {fault!r}: {exc}") from None


# -- what is watched while it runs ---------------------------------------------------------------------------
class Monitor(ObservingDevice):
    """A device stepped with the twin: the true finger forces (not the readings), grips, slip."""

    signals: tuple = ()

    def __init__(self, twin):
        self.max_force = 0.0
        self.gripped_edges = 0
        self.slip = False if "slip" in {s.name for s in twin.signals} else None
        self._was_gripped = bool(twin.read("doGripped"))

    def after_step(self, twin) -> None:
        forces = twin.finger_forces()
        if forces:
            self.max_force = max(self.max_force, max(forces.values()))
        gripped = bool(twin.read("doGripped"))
        if gripped and not self._was_gripped:
            self.gripped_edges += 1
        self._was_gripped = gripped
        if self.slip is not None and twin.read("slip"):
            self.slip = True


class Signals:
    """Signal values by name in the map's units (mm, deg, N), for conditions; plus `time` (s)."""

    def __init__(self, twin, local: dict | None = None):
        self.twin = twin
        self.local = local if local is not None else {}  # signals the PLC holds itself (a bench's handshake)
        self._factor = {s.name: UNIT_TO_MAP.get(s.unit, 1.0) for s in twin.signals}

    def values(self, names) -> dict:
        out = {}
        for n in names:
            if n == "time":
                out[n] = self.twin.time
            elif n in self.local:
                out[n] = self.local[n]
            elif n in self._factor:
                v = self.twin.read(n)
                out[n] = v * self._factor[n] if isinstance(v, float) else v
        return out

    def write(self, name: str, value) -> None:
        if name in self.local:
            self.local[name] = value
            return
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        factor = self._factor[name]
        self.twin.write(name, value / factor if number and factor != 1.0 else value)

    def check(self, names, where: str) -> None:
        missing = [n for n in names if n != "time" and n not in self._factor and n not in self.local]
        if missing:
            known = "" if not self.local else f" nor held by the PLC ({', '.join(self.local)})"
            raise ScenarioError(f"{where}: no signal {missing[0]!r} in the station{known}")


# -- grips as the PLC saw them ------------------------------------------------------------------------------
class GripWatch:
    """Counts confirmed grips and detected misses: from a GripSequence's phases when the logic has one,
    else from rising edges of the `measure.grip` / `measure.miss` signals."""

    def __init__(self, logic, state, grip_signal: str | None, miss_signal: str | None):
        from plc_client.grip_sequence import GripSequence
        from plc_client.scan import Combined

        self.sequences = []
        if isinstance(logic, GripSequence):
            self.sequences.append((logic, lambda: state))
        elif getattr(logic, "sequence_state", None) is not None and logic.sequence_state(state) is not None:
            self.sequences.append((logic, lambda: logic.sequence_state(state)))  # an ST PLC with phase, fault_code
        elif isinstance(logic, Combined):
            for i, part in enumerate(logic.logics):
                if isinstance(part, GripSequence):
                    self.sequences.append((part, lambda i=i: state[i]))
        self.grip_signal, self.miss_signal = grip_signal, miss_signal
        self.grips = self.misses = 0
        self.plc_faults: list[str] = []
        self._phase = {}
        self._fault = {}
        self._edges = {}

    def observe(self, values: dict) -> None:
        from plc_client.grip_sequence import Fault, Phase

        if self.sequences and not (self.grip_signal or self.miss_signal):
            for i, (_, get) in enumerate(self.sequences):
                st = get()
                if st.phase != self._phase.get(i):
                    if st.phase is Phase.HELD:
                        self.grips += 1
                    elif st.phase is Phase.FAULT_MISSED:
                        self.misses += 1
                    self._phase[i] = st.phase
                if st.fault != self._fault.get(i, Fault.NONE) and st.fault is not Fault.NONE:
                    name = st.fault.name.lower()
                    if name not in self.plc_faults:
                        self.plc_faults.append(name)
                self._fault[i] = st.fault
            return
        for attr, signal in (("grips", self.grip_signal), ("misses", self.miss_signal)):
            if signal and signal in values:
                v = bool(values[signal])
                if v and not self._edges.get(signal, False):
                    setattr(self, attr, getattr(self, attr) + 1)
                self._edges[signal] = v


# -- running ------------------------------------------------------------------------------------------------
def make_logic(campaign: Campaign, params: dict, station=None):
    kwargs = {k.split(".", 1)[1]: v for k, v in params.items() if k.startswith("plc.")}
    from .spec import st_files

    if st_files(campaign.driver.ref):  # a Structured Text PLC on the station's PLC layout; plc.NAME sets its NAME
        from plc_client.st_io import StLogic
        from twin.frontends.modbus.register_map import build_register_map
        from twin.core.signal_table import station_signals
        from structured_text.errors import StError

        try:
            return StLogic([campaign.driver.base / f for f in st_files(campaign.driver.ref)],
                           build_register_map(station_signals(station), station.name, "plc"), settings=kwargs)
        except (StError, TwinError) as exc:
            raise ScenarioError(f"driver.plc {campaign.driver.ref!r}: {exc}") from None
    obj = load_object(campaign.driver.ref, campaign.driver.base)
    if getattr(obj, "inputs", None) is not None and not isinstance(obj, type):
        if kwargs:
            raise ScenarioError(f"driver.plc {campaign.driver.ref!r} is a logic, not a factory: it takes no "
                                f"parameters ({', '.join('plc.' + k for k in kwargs)})")
        return obj
    try:
        logic = obj(**kwargs)
    except TypeError as exc:
        raise ScenarioError(f"driver.plc {campaign.driver.ref!r} does not take {', '.join('plc.' + k for k in kwargs)}: {exc}") from None
    except ValueError as exc:
        raise ScenarioError(f"driver.plc {campaign.driver.ref!r}: {exc}") from None
    if getattr(logic, "inputs", None) is None:
        raise ScenarioError(f"driver.plc {campaign.driver.ref!r} gives {logic!r}, which is no PLC logic (no .inputs)")
    return logic


class Context:
    """What a check function gets: the running twin and the scenario, and helpers that keep it in lockstep.

    cell        the running cell (twin_app.cell.Cell: read, write, step, time; in process, no front ends)
    twin        the cell's twin (with its RAPID controller, if the station has one) and the faults
    params      the scenario's parameters (dict)
    scenario    the Scenario (name, index)
    io()        a lockstep PLC I/O to the twin (mm, N), through the scenario's link faults
    scan(logic, cycle=None)   a ScanCycle of `logic` on io()
    measure(name, value)      add a value to the results table (and to expectations' `values`)
    """

    def __init__(self, campaign: Campaign, scenario: Scenario, cell, link: dict):
        self.campaign, self.scenario, self.cell, self._link = campaign, scenario, cell, link
        self.twin = cell.twin
        self.watchdog = cell.watchdog  # the cell's comm-loss watchdog
        self.params = dict(scenario.params)
        self.measured: dict = {}
        self.grip_watch: GripWatch | None = None

    def io(self, local=None):
        from plc_client.link import LinkFaults
        from plc_client.scan import TwinIO

        io = TwinIO(self.cell, local=local)
        watchdog = self.watchdog
        feed = (lambda: watchdog.feed("plc")) if watchdog is not None and watchdog.timeout else None
        if self._link["lost"] or self._link["latency"] or self._link["jitter"] or feed:
            io = LinkFaults(io, **self._link, on_exchange=feed)
        return io

    def scan(self, logic, cycle: float | None = None, local=None):
        from plc_client.scan import ScanCycle

        return ScanCycle(self.io(local), logic, cycle=cycle or self.campaign.driver.scan)

    def measure(self, name: str, value) -> None:
        self.measured[name] = value


def run_scenario(campaign: Campaign, index: int, record_to: str | None = None) -> dict:
    """Run scenario `index` of `campaign`; the measured values (see docs/campaigns.md, "The results").
    `record_to`: also record the run (every signal and body pose at every step) into this file."""
    scenario = campaign.scenarios[index]
    try:
        return _run(campaign, scenario, record_to)
    except ScenarioError as exc:
        return {"outcome": "error", "fault": "scenario_error", "message": str(exc)}
    except Exception as exc:  # noqa: BLE001 - one scenario's failure is its result, named
        from twin.core.errors import TwinError

        kind = "station_error" if isinstance(exc, TwinError) else "exception"
        return {"outcome": "error", "fault": kind, "message": f"{type(exc).__name__}: {exc}"}


def _run(campaign: Campaign, scenario: Scenario, record_to: str | None = None) -> dict:
    import contextlib
    import time

    from twin.core.station import load_station
    from twin.runtime.faults import FaultInjector, FaultError
    from twin.core.native_output import quiet_native_output
    from twin_app.cell import Cell

    params = scenario.params
    LAST_TIMING.clear()
    t0 = time.perf_counter()
    station = build_station(load_station(campaign.station), params)
    driver = campaign.driver
    if driver.kind == "rapid" and station.controller is None and not driver.ref:
        raise ScenarioError("driver.rapid: the station has no [controller] program to run")
    if driver.kind == "rapid" and driver.ref:
        if station.controller is None:
            raise ScenarioError("driver.rapid: a program needs a station with a [controller] (its I/O)")
        program = (driver.base / driver.ref).resolve()
        station = dataclasses.replace(station, controller=dataclasses.replace(station.controller, program=program))
    with quiet_native_output():
        # the cell as `twin serve` assembles it (watchdog, then the RAPID controller), headless and in process
        cell = Cell(station, entry=driver.entry, publish=False)
    twin = cell.twin
    stack = contextlib.ExitStack()
    try:
        watchdog = cell.watchdog
        if campaign.watchdog is not None:
            cell.set_watchdog_timeout(campaign.watchdog)
        watchdog.log = lambda text: None
        plant, link = build_faults(campaign, params, cell)
        if (link["lost"] or link["latency"] or link["jitter"]) and driver.kind == "rapid":
            raise ScenarioError("link faults act on a PLC's link: this campaign's driver is the RAPID program alone")
        try:
            injector = FaultInjector.attach(twin, plant)
        except FaultError as exc:
            raise ScenarioError(str(exc)) from None
        monitor = Monitor(twin)
        twin.add_device(monitor)
        if record_to is not None:  # a recording of every signal and pose at every step (twin.observe.recording)
            from twin.observe.recording import record

            stack.enter_context(record(twin, record_to))
        part = campaign.measure.get("part") or (station.targets[0].name if station.targets else None)
        part_start = twin.object_pose(part)[0] if part else None
        logic, local = None, {}
        if driver.kind == "plc":
            logic = make_logic(campaign, params, station)
            have = {s.name for s in cell.signals}
            held = getattr(logic, "handshake_signals", None)
            local = {k: v for k, v in (held() if held else {}).items() if k not in have}
            missing = [n for n in (*logic.inputs, *getattr(logic, "outputs", ())) if n not in have and n not in local]
            if missing:
                raise ScenarioError(f"driver.plc {driver.ref!r} uses {', '.join(missing)}, which station "
                                    f"{station.name!r} does not have")
        signals = Signals(cell, local)
        for key, value in {**campaign.start, **{k[6:]: v for k, v in params.items() if k.startswith("start.")}}.items():
            signals.check([key], f"start.{key}")
            signals.write(key, value)
        for t in station.targets:
            if params.get(f"{t.name}.present") is False:
                cell.write(f"{t.name}.present", False)
        conditions = [(name, expr) for name, expr in campaign.stop_when.items()]
        cond_names = set().union(*(e.names for _, e in conditions), campaign.done_when.names if campaign.done_when else set())
        signals.check(cond_names, "run.stop_when / run.done_when")
        watch_signals = [s for s in (campaign.measure.get("grip"), campaign.measure.get("miss")) if s]
        signals.check(watch_signals, "measure")
        names = sorted(cond_names | set(watch_signals))
        ctx = Context(campaign, scenario, cell, link)
        outcome = {"outcome": "", "fault": "none", "message": ""}
        t1 = time.perf_counter()
        LAST_TIMING["load"] = t1 - t0

        def verdict() -> bool:
            values = signals.values(names)
            if ctx.grip_watch is not None:
                ctx.grip_watch.observe(values)
            for name, expr in conditions:
                if expr.evaluate(values):
                    outcome.update(outcome="stopped", fault=name)
                    return True
            if campaign.done_when is not None and campaign.done_when.evaluate(values):
                outcome["outcome"] = "completed"
                return True
            if cell.time >= campaign.max_time - 1e-9:
                if campaign.done_when is None:
                    outcome["outcome"] = "completed"
                else:
                    outcome.update(outcome="timeout", fault="max_time",
                                   message=f"neither done nor stopped after {campaign.max_time:g} s simulated")
                return True
            return False

        if driver.kind == "plc":
            from plc_client.errors import OutputRefusedError

            plc = ctx.scan(logic, local=local)
            signals.local = plc.io.io.local if hasattr(plc.io, "io") else plc.io.local
            ctx.grip_watch = GripWatch(logic, plc.state, campaign.measure.get("grip"), campaign.measure.get("miss"))
            try:
                while True:
                    plc.scan()
                    if verdict():
                        break
            except OutputRefusedError as exc:
                outcome.update(outcome="error", fault="output_refused", message=str(exc))
        elif driver.kind == "rapid":
            ctx.grip_watch = GripWatch(None, None, campaign.measure.get("grip") or "doGripped", campaign.measure.get("miss"))
            while True:
                cell.step()
                if verdict():
                    break
        else:
            check = load_object(driver.ref, driver.base)
            ctx.grip_watch = GripWatch(None, None, campaign.measure.get("grip") or "doGripped", campaign.measure.get("miss"))
            try:
                returned = check(ctx)
            except AssertionError as exc:
                outcome.update(outcome="error", fault="check_failed", message=f"{exc}" or "assertion failed")
                returned = None
            if isinstance(returned, dict):
                for k in ("outcome", "fault", "message"):
                    if k in returned:
                        outcome[k] = returned.pop(k)
                ctx.measured.update(returned)
            if not outcome["outcome"]:
                outcome["outcome"] = "completed"
            if ctx.grip_watch.grips == 0 and ctx.grip_watch.misses == 0:
                ctx.grip_watch.grips = monitor.gripped_edges
        LAST_TIMING["sim"] = time.perf_counter() - t1
        gw = ctx.grip_watch
        result = {**outcome, "time": round(twin.time, 9), "steps": twin.step_count,
                  "grips": gw.grips, "misses": gw.misses, "grip": _grip(gw.grips, gw.misses),
                  "plc_faults": "+".join(gw.plc_faults) or "none", "max_finger_force": monitor.max_force,
                  "slip": monitor.slip}
        if part:
            present = bool(twin.read(f"{part}.present"))
            end = twin.object_pose(part)[0]
            result.update({"part": part, "part_present": present,
                           "part_start_mm": [v * 1000.0 for v in part_start],
                           "part_end_mm": [v * 1000.0 for v in end] if present else None,
                           "part_moved_mm": math.dist(end, part_start) * 1000.0 if present else None})
        result["faults_log"] = [f"{t:.3f} s {text}" for t, text in injector.log]
        if watchdog.timeout:
            result["comm_lost_trips"] = watchdog.trips
        for k, v in ctx.measured.items():
            result[f"m.{k}" if k in result else k] = v
        return result
    finally:
        stack.close()
        cell.close()


def _grip(grips: int, misses: int) -> str:
    if grips and not misses:
        return "confirmed"
    if misses and not grips:
        return "missed"
    if grips and misses:
        return "retried"
    return "none"
