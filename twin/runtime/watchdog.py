"""The comm-loss watchdog: when the cell's controllers fall silent, the cell goes to a safe state.

A cell-level piece, fed by any front end: the Modbus server calls `feed("modbus 10.0.0.5:50312")` for
every request it answers, the OPC UA server `feed("opcua 127.0.0.1:50312 user 'plc1'")` for
every request of a session. The watchdog keeps a
"last request seen" per source; the link counts as lost when **no source** has sent a request for
`timeout` seconds (it is armed by the first request: a cell nobody has talked to yet is not "lost").
Then, once:

- the signal `comm.lost` (an output of the cell: a Modbus discrete input, and a robot-controller DI when
  the station wires one to it with `source = "comm.lost"`) rises, and the event is logged;
- the gripper goes to the station's safe state (`[watchdog] safe_state`):
  - `hold` (default): an axis whose finger touches a part keeps its setpoint (the part stays squeezed and
    held); every other axis stops where it is (its setpoint becomes its actual position);
  - `stop`: every axis stops where it is (a squeezing grip relaxes to a touch);
  - `open`: every axis goes to its open setpoint (`[watchdog] open = { axis1 = 0.35 }`, else the station's
    `gripper.initial`, else it stops where it is).

In lockstep, requests that only write or read `sim.advance` (a script driving simulated time and
waiting for its steps) arm the watchdog but do not feed or clear it. The first other request afterwards
(from any source) clears `comm.lost` (its answer still shows the state of
the last completed step, so a client reading `comm.lost` sees the 1 once); the safe setpoints stay until a
client writes new ones.

Time: `clock` gives seconds. In real time the server passes the runner's wall clock; by default (and in
lockstep) it is the twin's simulated time, so a lockstep script sees the watchdog fire after exactly
`timeout` simulated seconds without a request, whatever the wall clock did. The check runs after every
simulation step. The module knows no sockets and no front end.
"""
from __future__ import annotations

import logging
import math
from collections.abc import Callable, Mapping

from twin.core.errors import SignalError, TwinError
from twin.core.signal_table import COMM_LOST, watchdog_signals
from twin.core.defaults import SAFE_STATES



class Watchdog:
    """A `twin.core` Device: adds `comm.lost` to the signal table and checks the silence after each step."""

    def __init__(self, timeout: float | None = None, safe_state: str = "hold",
                 open_setpoints: Mapping[str, float] | None = None,
                 log: Callable[[str], None] | None = None):
        if safe_state not in SAFE_STATES:
            raise TwinError(f"watchdog: safe state {safe_state!r}: one of {', '.join(SAFE_STATES)}")
        self.timeout = timeout if timeout and timeout > 0 else None
        self.safe_state = safe_state
        self.open_setpoints = dict(open_setpoints or {})
        self.log = log or (lambda text: logging.getLogger("twin.serve").warning(text))
        self.signals = watchdog_signals(safe_state)  # declared in the static signal table
        self.on_event: Callable[..., None] | None = None  # `twin.observe.events.Events.emit`: lost and restored
        self.clock: Callable[[], float] | None = None  # None: the twin's simulated time
        self.twin = None
        self.last_seen: dict[str, float] = {}  # source -> when its last request came
        self.last: float | None = None
        self.last_source = ""
        self.lost = False
        self.trips = 0

    @classmethod
    def for_station(cls, station, log=None) -> "Watchdog":
        spec = getattr(station, "watchdog", None)
        if spec is None:
            return cls(log=log)
        return cls(spec.timeout, spec.safe_state, spec.open, log=log)

    def attach(self, twin) -> "Watchdog":
        self.twin = twin
        twin.add_device(self)
        return self

    def now(self) -> float:
        if self.clock is not None:
            return self.clock()
        return self.twin.time if self.twin is not None else 0.0

    # -- the front ends' side -------------------------------------------------------------------------
    def feed(self, source: str, clock_only: bool = False) -> None:
        """A request came from `source` (e.g. "modbus 10.0.0.5:50312"): the link is alive.

        `clock_only`: in lockstep, a request that only drives or polls simulated time (`sim.advance`) is
        the test harness's clock, not the controller's traffic: it arms the watchdog but neither feeds nor
        clears it, so a script that advances and waits for the steps sees the watchdog fire."""
        t = self.now()
        if clock_only:
            if self.last is None:
                self.last, self.last_source = t, source
            return
        self.last_seen[source] = t
        if self.lost:
            self.lost = False
            self.log(f"comm restored: request from {source} after {t - self.last:.3f} s of silence; "
                     f"{COMM_LOST} cleared")
            if self.on_event is not None:
                self.on_event("comm_restored", source=source, silent_s=round(t - self.last, 6))
        self.last, self.last_source = t, source

    # -- the Device protocol --------------------------------------------------------------------------
    def read(self, name: str) -> bool:
        return self.lost

    def write(self, name: str, value) -> None:
        raise SignalError(name, "an output of the watchdog: it cannot be written")

    def before_step(self, twin) -> None:
        pass

    def after_step(self, twin) -> None:
        if self.timeout is None or self.last is None or self.lost:
            return
        silent = self.now() - self.last
        if silent >= self.timeout:
            self.lost = True
            self.trips += 1
            self.log(f"comm lost: no request for {silent:.3f} s (watchdog {self.timeout:g} s; last from "
                     f"{self.last_source}); {COMM_LOST} raised, gripper to its safe state '{self.safe_state}'")
            if self.on_event is not None:
                self.on_event("comm_lost", silent_s=round(silent, 6), timeout_s=self.timeout,
                              last_source=self.last_source, safe_state=self.safe_state)
            self._safe_state(twin)

    def _safe_state(self, twin) -> None:
        mech = twin.mechanism
        actual = twin.joint_positions()
        touching = set()
        if self.safe_state == "hold":
            axis_of_joint = {i.joint: i.name for i in mech.inputs}
            for m in mech.mimics:
                axis_of_joint.setdefault(m.joint, axis_of_joint.get(m.master))
            contacts = twin.finger_contacts()
            for f in mech.fingers:
                if contacts.get(f.name):
                    touching.add(axis_of_joint.get(f.joint))
        initial = getattr(twin.station.gripper, "initial", {}) or {}
        for inp in mech.inputs:
            if self.safe_state == "hold" and inp.name in touching:
                continue
            target = actual.get(inp.name)
            if self.safe_state == "open":
                target = self.open_setpoints.get(inp.name, initial.get(inp.name, target))
            if target is None or not math.isfinite(target):
                continue
            twin.write(inp.name, min(max(target, inp.min), inp.max))
