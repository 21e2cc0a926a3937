"""Robotiq's 2F-85 and 3-Finger Adaptive Gripper as a device of the twin: what their registers mean.

A real Robotiq gripper has its own controller: the robot (or PLC) writes 16 bytes of *robot output*
(action request, position / speed / force requests 0..255) and reads 16 bytes of *robot input* (gripper
status, object detection, fault, position request echo, position and current per axis). `RobotiqGripper`
is that controller for a twin: a `Device` (twin.core.twin.Device) stepped with the twin, so it is as
deterministic as the twin and knows no protocol. `twin.frontends.modbus.profile` puts its bytes on Modbus.

Sources (Robotiq instruction manuals, section 4 "Control": "Gripper register mapping", "Robot output
registers & functionalities", "Robot input registers & status"; 3-Finger Adaptive Robot Gripper manual
2008-2014 and 2008-2018 editions, 2F-85 & 2F-140 manual; and Robotiq's open ROS driver
`ros-industrial/robotiq`, `baseRobotiq3FGripper.py` and `Robotiq3FGripperStatusListener.py`, for the bit
packing and the fault texts). Bit layouts (byte 0 is the high byte of the first register):

robotiq-2f output: byte 0 ACTION REQUEST  rACT b0, rGTO b3, rATR b4, rARD b5; bytes 1-2 reserved;
                   byte 3 rPR position, 4 rSP speed, 5 rFR force; 6-15 reserved.
robotiq-2f input:  byte 0 GRIPPER STATUS  gACT b0, gGTO b3, gSTA b4-5, gOBJ b6-7; 1 reserved;
                   byte 2 FAULT gFLT (low nibble; kFLT high nibble, 0 here); 3 gPR echo; 4 gPO; 5 gCU.
robotiq-3f output: byte 0 ACTION REQUEST  rACT b0, rMOD b1-2, rGTO b3, rATR b4;
                   byte 1 GRIPPER OPTIONS rGLV b0, rAAC b1, rICF b2, rICS b3; 2 reserved;
                   bytes 3-5 rPRA rSPA rFRA (all fingers, or finger A with rICF), 6-8 finger B,
                   9-11 finger C (with rICF), 12-14 scissor (with rICS); 15 reserved.
robotiq-3f input:  byte 0 GRIPPER STATUS  gACT b0, gMOD b1-2, gGTO b3, gIMC b4-5, gSTA b6-7;
                   byte 1 OBJECT STATUS gDTA b0-1, gDTB b2-3, gDTC b4-5, gDTS b6-7; 2 gFLT;
                   3-5 gPRA gPOA gCUA, 6-8 finger B, 9-11 finger C, 12-14 scissor; 15 reserved.

Behaviour (the manuals' wording in quotes):
- rACT 0 -> 1 starts the activation: the axes open (position 0), gSTA (2F) / gIMC (3F) reads 1 "activation
  in progress" for `activation_time` of simulated time, then 3 "activation completed". rACT 0 resets: the
  axes hold where they are, every status reads 0 and the fault clears ("clear rACT to reset the gripper and
  clear fault status").
- rGTO 1 "go to requested position": each axis drives to its request with the requested speed and force
  (the station's `[profile]` maps 0..255 onto the input's range, velocity and effort limits); a change of a
  request while rGTO is 1 is taken at the next step. rGTO 0 stops the axes where they are.
- Object detection per axis (2F gOBJ, 3F gDTA/gDTB/gDTC/gDTS): 0 moving, 1 stopped by contact while
  opening, 2 stopped by contact while closing, 3 at the requested position; 0 while gGTO is 0. An axis
  that stands still short of its request for `STALL_TIME` has stopped on something (Robotiq detects
  objects the same way, from the motor, not from a contact sensor); "still" means it moved less than
  `STALL_SHARE` of what its requested speed covers in that time. The detection holds ("the axis will
  stop") until a new request, or until the axis moves on by twice that (the object was lost: moving
  again). When the twin publishes the finger's own `NAME.status` (same meaning, from its contacts), a
  contact stop there counts at once; the direction (opening or closing) is always the profile's own. 3F gSTA: 0 while any finger moves, 3 all at
  their request, 2 all stopped short, 1 some stopped short.
- 3F rMOD (basic, pinch, wide, scissor): a change while activated is a mode change, gIMC 2 for
  `mode_change_time`; gMOD echoes rMOD. In scissor mode rPRA drives the scissor axis and the fingers
  hold. With rICF each finger takes its own request, with rICS the scissor its own.
- Faults (gFLT): 0x05 "action delayed, activation (reactivation) must be completed prior to action",
  0x06 "action delayed, mode change must be completed prior to action", 0x07 "the activation bit must be
  set prior to action", 0x0B "automatic release in progress", 0x0F "automatic release completed, reset
  and activation is required".
- rATR 1 (automatic / emergency release): every axis opens slowly (2F with rARD 0: closes), status reads
  0 and gFLT 0x0B; once every axis stops, 0x0F until rACT is cleared and set again.
- Position echo gPR: the request as taken (3F: B, C and scissor echo 0 unless individually controlled,
  as in the manual's frames). Position gPO: the input's actual value on the 0..255 scale. Current gCU:
  the drive's force on a 0..255 scale (255 = the axis's `current_full`), not a motor current.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from twin.core.errors import SignalError

from .mapping import AxisMapping, Defaults, ProfileMapping, read_mapping

RESET, ACTIVATING, MODE_CHANGE, READY, RELEASING, RELEASED = "reset", "activating", "mode change", "ready", \
    "releasing", "released"
STALL_TIME = 0.06  # s an axis stands still short of its request before it counts as stopped by an object
STALL_SHARE = 0.25  # "stands still": it moved less than this share of what its speed covers in STALL_TIME ...
STALL_FLOOR = {"m": 0.00005, "rad": 0.0005}  # ... and at least this (servo jitter against a part)

NO_FAULT, ACTIVATION_PENDING, MODE_CHANGE_PENDING, NOT_ACTIVATED = 0x00, 0x05, 0x06, 0x07
RELEASE_IN_PROGRESS, RELEASE_COMPLETED = 0x0B, 0x0F
MODES = ("basic", "pinch", "wide", "scissor")

# Spec-sheet ranges used when the station gives none: speed and force at 0 as a fraction of 255.
# 2F-85: 20 to 150 mm/s, 20 to 235 N; 3-Finger: 22 to 110 mm/s, 15 to 60 N (manual, FORCE register).
DEFAULTS = {
    "robotiq-2f": Defaults(speed_ratio=20 / 150, force_ratio=20 / 235, activation_time=1.5, mode_change_time=0.0),
    "robotiq-3f": Defaults(speed_ratio=22 / 110, force_ratio=15 / 60, activation_time=1.5, mode_change_time=1.0),
}
AXES = {"robotiq-2f": (("jaw",), ()), "robotiq-3f": (("A", "B", "C"), ("scissor",))}


@dataclass
class AxisState:
    """What the gripper's controller knows about one axis."""

    mapping: AxisMapping | None  # None: the axis is not on the station (a 3F without a scissor)
    request: tuple[int, int, int] | None = None  # (position, speed, force) being driven to; None: holding
    closing: bool = True  # the direction of the last request
    stalled: int = 0  # steps standing still short of the request
    anchor: float | None = None  # where the axis was when it began to stand still
    still: float = 0.0  # how far it may move and still stand still (from its speed)
    status: int = 0  # 0 moving, 1 stopped opening, 2 stopped closing, 3 at request
    position: int = 0
    current: int = 0
    fingers: tuple[str, ...] = field(default_factory=tuple)  # fingers this axis carries (for force)


class RobotiqGripper:
    """The controller of a Robotiq 2F-85 (`kind` "robotiq-2f") or 3-Finger gripper ("robotiq-3f") on a twin."""

    signals = ()  # it adds no signals to the twin's table: it is reached through its registers

    def __init__(self, twin, kind: str, mapping: ProfileMapping):
        if kind not in AXES:
            raise ValueError(f"unknown Robotiq profile {kind!r} (known: {', '.join(AXES)})")
        self.kind, self.mapping = kind, mapping
        self.dt = twin.dt
        self.output = bytearray(16)  # robot output: what the PLC wrote
        self.input = bytearray(16)  # robot input: the status, as of the last completed step
        self.version = 0  # bumped whenever output or input change (a front end's cache key)
        self.state = RESET
        self.state_steps = 0  # steps spent in the current state
        self.fault = NO_FAULT
        self.mode = 0
        self._gto = False
        self._names = {s.name for s in twin.signals}
        self._enabled: bool | None = None  # what was last written to the twin's `Active`
        servos = getattr(getattr(twin, "gripper", None), "finger_servos", {}) or {}
        required, optional = AXES[kind]
        self.axes: dict[str, AxisState] = {}
        for name in required + optional:
            m = mapping.axes.get(name)
            fingers = ()
            if m is not None:
                fingers = tuple(f for f, inputs in servos.items() if m.input in inputs)
                if m.finger is not None and m.finger not in fingers:
                    fingers = (m.finger,) + fingers
            self.axes[name] = AxisState(m, fingers=fingers)
        self._stall_steps = max(1, math.ceil(STALL_TIME / self.dt - 1e-9))
        self._publish(twin)

    # -- the front end's side ---------------------------------------------------------------------
    def write_output(self, index: int, value: int) -> None:
        """Store byte `index` (0..15) of the robot output; the gripper acts on it at the next step."""
        if self.output[index] != value:
            self.output[index] = value
            self.version += 1

    def write_output_word(self, register: int, word: int) -> None:
        """Register `register` (0..7) of the robot output: its high byte is byte 2r, its low byte 2r+1."""
        self.write_output(2 * register, (word >> 8) & 0xFF)
        self.write_output(2 * register + 1, word & 0xFF)

    # -- Device protocol ----------------------------------------------------------------------------
    def read(self, name: str):
        raise SignalError(name, "is not a signal of the Robotiq profile (it has only registers)")

    def write(self, name: str, value) -> None:
        raise SignalError(name, "is not a signal of the Robotiq profile (it has only registers)")

    def before_step(self, twin) -> None:
        """Act on the robot output as it stands: the state machine, then the axes' commands."""
        self._step(twin)
        enabled = self.state != RESET  # a reset gripper's drives are off: the twin's `Active` follows
        if enabled != self._enabled and "Active" in self._names:
            twin.write("Active", enabled)
            self._enabled = enabled

    def _step(self, twin) -> None:
        out = self.output
        act, gto, atr = out[0] & 1, (out[0] >> 3) & 1, (out[0] >> 4) & 1
        mode = (out[0] >> 1) & 3 if self.kind == "robotiq-3f" else 0
        state = self.state
        if not act:
            if state != RESET:
                self._hold_all(twin)
                self._enter(RESET)
            self.fault = NOT_ACTIVATED if (gto or atr) else NO_FAULT
            self._gto = False
            return
        if atr and state not in (RELEASING, RELEASED, RESET):
            self._enter(RELEASING)
            self._release(twin)
        elif state == RESET:
            self._enter(ACTIVATING)
            self.mode = mode
            for ax in self.axes.values():
                self._drive(twin, ax, (0, 255, 0))
        elif state == ACTIVATING and self.state_steps >= self._steps(self.mapping.activation_time):
            self._enter(READY)
            self.mode = mode
            self._hold_all(twin)
        elif state == READY and mode != self.mode:
            self._enter(MODE_CHANGE)
            self._hold_all(twin)
        elif state == MODE_CHANGE and self.state_steps >= self._steps(self.mapping.mode_change_time):
            self.mode = mode
            self._enter(READY)
        state = self.state
        if state == RELEASING and self.state_steps > self._stall_steps and all(
                ax.mapping is None or ax.stalled >= self._stall_steps or ax.status == 3 for ax in self.axes.values()):
            self._enter(RELEASED)
            state = RELEASED
        self.fault = {ACTIVATING: ACTIVATION_PENDING if gto else NO_FAULT,
                      MODE_CHANGE: MODE_CHANGE_PENDING if gto else NO_FAULT,
                      RELEASING: RELEASE_IN_PROGRESS, RELEASED: RELEASE_COMPLETED}.get(state, NO_FAULT)
        if state != READY:
            self._gto = False
            return
        if not gto:
            if self._gto:
                self._hold_all(twin)
            self._gto = False
            return
        rising = not self._gto
        self._gto = True
        for name, request in self._requests().items():
            ax = self.axes[name]
            if request is None:
                if ax.request is not None:
                    self._hold(twin, ax)
            elif rising or request != ax.request:
                self._drive(twin, ax, request)

    def after_step(self, twin) -> None:
        for ax in self.axes.values():
            self._sense(twin, ax)
        self.state_steps += 1
        self._publish(twin)

    # -- requests and commands ----------------------------------------------------------------------
    def _requests(self) -> dict[str, tuple[int, int, int] | None]:
        """Each axis's (position, speed, force) request from the robot output, or None (hold)."""
        out = self.output
        common = (out[3], out[4], out[5])
        if self.kind == "robotiq-2f":
            return {"jaw": common}
        icf, ics = (out[1] >> 2) & 1, (out[1] >> 3) & 1
        scissor_mode = self.mode == 3
        req: dict[str, tuple[int, int, int] | None] = {}
        for i, name in enumerate(("A", "B", "C")):
            if scissor_mode and not icf:
                req[name] = None
            else:
                req[name] = tuple(out[3 + 3 * i:6 + 3 * i]) if icf else common
        req["scissor"] = tuple(out[12:15]) if ics else (common if scissor_mode else None)
        return req

    def _drive(self, twin, ax: AxisState, request: tuple[int, int, int]) -> None:
        m = ax.mapping
        ax.request = request
        ax.stalled = 0
        if m is None:
            return
        position, speed, force = request
        target = m.value_of(position)
        twin.set_drive_limits(m.input, velocity=m.velocity_of(speed), effort=m.effort_of(force))
        twin.write(m.input, _clamp_to(twin, m.input, target))
        actual = twin.read(f"{m.input}.actual")
        ax.closing = (target - actual) * (m.closed - m.open) > 0
        ax.anchor, ax.status = actual, 0
        ax.still = max(STALL_FLOOR.get(twin.spec(m.input).unit, STALL_FLOOR["m"]),
                       STALL_SHARE * m.velocity_of(speed) * self._stall_steps * self.dt)

    def _hold(self, twin, ax: AxisState) -> None:
        ax.request = None
        ax.stalled, ax.anchor = 0, None
        if ax.mapping is not None:
            inp = ax.mapping.input
            twin.write(inp, _clamp_to(twin, inp, twin.read(f"{inp}.actual")))

    def _hold_all(self, twin) -> None:
        for ax in self.axes.values():
            self._hold(twin, ax)

    def _release(self, twin) -> None:
        """Automatic release: open slowly (the 2F with rARD 0 closes), at the lowest speed and force."""
        position = 255 if self.kind == "robotiq-2f" and not (self.output[0] >> 5) & 1 else 0
        for ax in self.axes.values():
            self._drive(twin, ax, (position, 0, 0))

    def _enter(self, state: str) -> None:
        self.state, self.state_steps = state, 0

    def _steps(self, seconds: float) -> int:
        return max(0, round(seconds / self.dt))

    # -- status -------------------------------------------------------------------------------------
    def _sense(self, twin, ax: AxisState) -> None:
        m = ax.mapping
        if m is None:  # not on the station: reads as standing at its request
            ax.position = ax.request[0] if ax.request else 0
            ax.status, ax.current = 3, 0
            return
        inp = m.input
        actual = twin.read(f"{inp}.actual")
        ax.position = m.position_of(actual)
        ax.current = m.current_of(self._drive_force(twin, ax))
        finger_status = f"{m.finger}.status" if m.finger else None
        if twin.read(f"{inp}.in_position") and not twin.read(f"{inp}.moving"):  # arrived, not passing by
            ax.status, ax.stalled, ax.anchor = 3, 0, actual
            return
        if ax.anchor is None:
            ax.anchor = actual
        moved = abs(actual - ax.anchor)
        if ax.status in (1, 2) and ax.request is not None:  # detected: held until it moves on (object lost)
            if moved > 2 * ax.still:
                ax.status, ax.stalled, ax.anchor = 0, 0, actual
            return
        if moved <= ax.still:
            ax.stalled += 1
        else:
            ax.stalled, ax.anchor = 0, actual
        # the core's own per-finger status (contact-aware) detects a stop at once; the direction is the profile's
        touched = (ax.request is not None and finger_status in self._names
                   and int(twin.read(finger_status)) in (1, 2))
        if touched:
            ax.stalled, ax.anchor = max(ax.stalled, self._stall_steps), actual
        ax.status = (2 if ax.closing else 1) if ax.stalled >= self._stall_steps else 0

    def _drive_force(self, twin, ax: AxisState) -> float:
        effort = f"{ax.mapping.input}.effort"
        if effort in self._names:
            return float(twin.read(effort))
        forces = [float(twin.read(f"{f}.force")) for f in ax.fingers if f"{f}.force" in self._names]
        return max(forces, default=0.0)

    def _publish(self, twin) -> None:
        out, b = self.output, bytearray(16)
        act = out[0] & 1
        gto = 1 if (self.state == READY and self._gto) else 0
        if self.kind == "robotiq-2f":
            sta = {ACTIVATING: 1, READY: 3}.get(self.state, 0)
            jaw = self.axes["jaw"]
            obj = jaw.status if gto else 0
            b[0] = act | gto << 3 | sta << 4 | obj << 6
            b[2] = self.fault
            b[3] = out[3] if act else 0
            b[4], b[5] = jaw.position, jaw.current
        else:
            imc = {ACTIVATING: 1, MODE_CHANGE: 2, READY: 3}.get(self.state, 0)
            mod = (out[0] >> 1) & 3 if act else 0
            fingers = [self.axes[n].status for n in ("A", "B", "C")]
            if not gto or 0 in fingers:
                sta = 0
            elif all(s == 3 for s in fingers):
                sta = 3
            elif all(s in (1, 2) for s in fingers):
                sta = 2
            else:
                sta = 1
            b[0] = act | mod << 1 | gto << 3 | imc << 4 | sta << 6
            if gto:
                b[1] = sum(self.axes[n].status << (2 * i) for i, n in enumerate(("A", "B", "C", "scissor")))
            b[2] = self.fault
            icf, ics = (out[1] >> 2) & 1, (out[1] >> 3) & 1
            echoes = (out[3], out[6] if icf else 0, out[9] if icf else 0, out[12] if ics else 0)
            for i, n in enumerate(("A", "B", "C", "scissor")):
                ax = self.axes[n]
                b[3 + 3 * i] = echoes[i] if act else 0
                b[4 + 3 * i], b[5 + 3 * i] = ax.position, ax.current
        if b != self.input:
            self.input = b
            self.version += 1


def _clamp_to(twin, name: str, value: float) -> float:
    spec = twin.spec(name)
    lo = -math.inf if spec.min is None else spec.min
    hi = math.inf if spec.max is None else spec.max
    return min(max(value, lo), hi)


PROFILES = tuple(AXES)


def open_profile(twin, kind: str) -> RobotiqGripper:
    """The Robotiq controller for `twin`'s station (its `[profile]` table), stepped with the twin."""
    if kind not in AXES:
        raise ValueError(f"unknown device profile {kind!r} (known: {', '.join(AXES)})")
    required, optional = AXES[kind]
    gripper = RobotiqGripper(twin, kind, read_mapping(twin, required, DEFAULTS[kind], optional))
    twin.add_device(gripper)
    return gripper
