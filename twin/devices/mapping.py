"""The `[profile]` table of a station: how a device profile's axes map onto the station's inputs.

A device profile (a real gripper's register layout, `twin.devices.robotiq`) speaks in the device's own
terms: a position request 0..255 (0 open, 255 closed), a speed and a force 0..255, per axis (the 2F's
jaw, the 3F's fingers A, B, C and its scissor). The station says what those mean for its gripper:

    [profile]
    activation_time = 1.5         # s the activation sequence takes (gSTA/gIMC 1 -> 3)
    mode_change_time = 1.0        # s a 3F grasping-mode change takes (gIMC 2 -> 3)

    [profile.jaw]                 # robotiq-2f: the one axis; robotiq-3f: [profile.A], .B, .C, .scissor
    input = "jaw"                 # the station input (joint setpoint) the axis drives
    open = 0.025                  # the input's value at position 0 (SI: m or rad)
    closed = 0.0                  # ... at position 255
    speed = [0.0067, 0.05]        # m/s (rad/s) at speed 0 and 255 (default: the profile's ratio, the joint's limit)
    force = [0.43, 5.0]           # N (N*m) at force 0 and 255 (default: the profile's ratio, the joint's effort)
    current_full = 5.0            # the drive force that reads as current 255 (default: force's upper end)
    finger = "jaw"                # the finger whose `NAME.status` (if the twin has it) gives object detection

This module reads and checks the table; every mistake is a StationError naming the file and the key
(`stations/x/station.toml: profile.A.input: ...`). It knows no protocol and no registers.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from twin.core.errors import StationError

AXIS_KEYS = ("input", "open", "closed", "speed", "force", "current_full", "finger")


@dataclass(frozen=True)
class AxisMapping:
    """One device axis on one station input. Positions in the input's SI unit, speed per second, force in N (N*m)."""

    name: str  # the device's name for the axis: jaw, A, B, C, scissor
    input: str
    open: float  # input value at position 0
    closed: float  # input value at position 255
    speed: tuple[float, float]  # velocity limit at speed 0 and 255
    force: tuple[float, float]  # effort limit at force 0 and 255
    current_full: float  # drive force read as current 255
    finger: str | None  # finger whose NAME.status / NAME.force the axis reads (None: none named, derived)

    def value_of(self, position: int) -> float:
        """Position request 0..255 -> input value (linear between open and closed)."""
        return self.open + (self.closed - self.open) * position / 255.0

    def position_of(self, value: float) -> int:
        """Input value -> position 0..255 (rounded, saturated)."""
        span = self.closed - self.open
        c = round((value - self.open) / span * 255.0) if span else 0
        return 0 if c < 0 else 255 if c > 255 else int(c)

    def velocity_of(self, speed: int) -> float:
        lo, hi = self.speed
        return lo + (hi - lo) * speed / 255.0

    def effort_of(self, force: int) -> float:
        lo, hi = self.force
        return lo + (hi - lo) * force / 255.0

    def current_of(self, drive_force: float) -> int:
        c = round(abs(drive_force) / self.current_full * 255.0) if self.current_full > 0 else 0
        return 0 if c < 0 else 255 if c > 255 else int(c)


@dataclass(frozen=True)
class ProfileMapping:
    axes: dict[str, AxisMapping]
    activation_time: float
    mode_change_time: float


@dataclass(frozen=True)
class Defaults:
    """What a profile assumes where the station is silent: speed and force ranges as ratios of the joint's limits."""

    speed_ratio: float  # speed 0 as a fraction of speed 255
    force_ratio: float  # force 0 as a fraction of force 255
    activation_time: float
    mode_change_time: float


def read_mapping(twin, axes: tuple[str, ...], defaults: Defaults, optional: tuple[str, ...] = ()) -> ProfileMapping:
    """Read the station's `[profile]` table for a profile with these axes (required) and `optional` ones."""
    st = twin.station
    file = str(st.file)
    table = st.profile
    if table is None:
        raise StationError(file, "profile", "the station has no [profile] table: it must say which input each axis "
                                            f"({', '.join(axes)}) drives (see docs/station-format.md, [profile])")
    known = set(axes) | set(optional) | {"activation_time", "mode_change_time"}
    allowed_axes = {"jaw", "A", "B", "C", "scissor"}
    for key in table:
        if key not in known and key not in allowed_axes:
            raise StationError(file, f"profile.{key}", "is not a known key here (keys: activation_time, "
                                                       "mode_change_time, and the axes jaw, A, B, C, scissor)")
    result = {}
    for name in axes + optional:
        if name not in table:
            if name in optional:
                continue
            raise StationError(file, f"profile.{name}", f"is required for this profile (axes: {', '.join(axes)})")
        result[name] = _axis(twin, file, name, table[name], defaults)
    used: dict[str, str] = {}
    for a in result.values():
        if a.input in used:
            raise StationError(file, f"profile.{a.name}.input", f"{a.input!r} is already driven by axis {used[a.input]}")
        used[a.input] = a.name
    return ProfileMapping(result, _time(file, table, "activation_time", defaults.activation_time),
                          _time(file, table, "mode_change_time", defaults.mode_change_time))


def _time(file: str, table: dict, key: str, default: float) -> float:
    v = table.get(key, default)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
        raise StationError(file, f"profile.{key}", f"must be a number of seconds, 0 or more, not {v!r}")
    return float(v)


def _axis(twin, file: str, name: str, raw, defaults: Defaults) -> AxisMapping:
    key = f"profile.{name}"
    if not isinstance(raw, dict):
        raise StationError(file, key, "must be a table (input, open, closed, ...)")
    for k in raw:
        if k not in AXIS_KEYS:
            raise StationError(file, f"{key}.{k}", f"is not a known key here (keys: {', '.join(AXIS_KEYS)})")
    inp = raw.get("input")
    inputs = {s.name: s for s in twin.signals if s.group == "gripper" and s.writable and s.type == "float"}
    if not isinstance(inp, str):
        raise StationError(file, f"{key}.input", f"is required: the name of a gripper input ({', '.join(inputs)})")
    if inp not in inputs:
        raise StationError(file, f"{key}.input", f"{inp!r} is not a joint input of the gripper ({', '.join(inputs)})")
    spec = inputs[inp]

    def number(k, default=None):
        v = raw.get(k, default)
        if v is None:
            raise StationError(file, f"{key}.{k}", "is required (a number)")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise StationError(file, f"{key}.{k}", f"must be a finite number, not {v!r}")
        return float(v)

    open_, closed = number("open"), number("closed")
    for k, v in (("open", open_), ("closed", closed)):
        if not spec.min <= v <= spec.max:
            raise StationError(file, f"{key}.{k}", f"{v:g} {spec.unit} is outside {inp}'s range {spec.min:g} to "
                                                   f"{spec.max:g} {spec.unit}")
    if open_ == closed:
        raise StationError(file, f"{key}.closed", "must differ from open (positions 0 and 255 would be the same)")
    velocity, effort = twin.drive_limits(inp)

    def pair(k, top, ratio):
        v = raw.get(k)
        if v is None:
            return (top * ratio, top)
        if (not isinstance(v, list) or len(v) != 2
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)
                or not 0 < v[0] <= v[1]):
            raise StationError(file, f"{key}.{k}", f"must be [at 0, at 255], two positive numbers, the first not "
                                                   f"above the second, not {v!r}")
        return (float(v[0]), float(v[1]))

    speed = pair("speed", velocity, defaults.speed_ratio)
    force = pair("force", effort, defaults.force_ratio)
    current_full = number("current_full", force[1])
    if current_full <= 0:
        raise StationError(file, f"{key}.current_full", "must be greater than 0")
    finger = raw.get("finger")
    fingers = {s.name[:-len(".contact")] for s in twin.signals if s.name.endswith(".contact")}
    if finger is not None and (not isinstance(finger, str) or finger not in fingers):
        raise StationError(file, f"{key}.finger", f"{finger!r} is not a finger of the gripper ({', '.join(sorted(fingers))})")
    if finger is None and inp in fingers:
        finger = inp
    return AxisMapping(name, inp, open_, closed, speed, force, current_full, finger)
