"""The bridge between a twin and the register map: register images out, queued writes in.

`TwinBridge.step()` is what a runner (`twin.pacing`) calls once per simulation step: it applies the
writes queued since the last step (each request's writes together, in arrival order), steps the twin
once, and publishes new register images. The server only ever reads published images, so a read of an
output sees the state after the last completed step, and a write takes effect at the next step.

Inputs (coils, holding registers) are what the client wrote: an accepted write is copied into their
images at once (`_show_written`), so reading it back gives the written value before the step applies
it. A step's publish cannot undo that: the runner and the server share one event loop, so no write
arrives between a step taking the queue and its publish, and every write queued before the step has
been applied to the twin by then. `publish` still lays the writes still queued over what it reads
from the twin, so the rule does not depend on who calls it when.

The twin is anything with `signals`, `read(name)`, `write(name, value)`, `step()`, `step_count`,
`time` and `dt` (the `twin.core.Twin` contract). The bridge imports neither sockets nor clocks.
"""
from __future__ import annotations

import dataclasses
import struct
import traceback
from collections.abc import Callable, Sequence

from .log import log as _log
from .register_map import (ADVANCE, BIT_TABLES, COIL, DISCRETE_INPUT, DT_US, FAULT, HOLDING_REGISTER,
                           INPUT_REGISTER, LATE, LATE_STEPS, LOCKSTEP, MAP_CRC, MODE, SPEED_PCT, STEP, TIME_MS,
                           Entry, RegisterMap, map_crc)
from .pdu import ILLEGAL_DATA_VALUE, SERVER_DEVICE_FAILURE, Images


class TwinBridge:
    """Publishes a twin's signals as register images and queues writes for the next step."""

    def __init__(self, twin, rmap: RegisterMap, *, log: Callable[[str], None] = _log):
        self.twin, self.map, self.log = twin, rmap, log
        self.runner = None  # set by whoever paces the twin (twin.pacing): mode, speed, late_steps, remaining
        self.fault = False
        self._encoded: dict[int, tuple[object, list[int]]] = {}  # id(entry): the map outlives it
        self.extra_status: dict[str, object] = {}  # values of sim.* entries the server's owner knows (comm.watchdog_ms)
        self._queue: list[Sequence[tuple[Entry, object]]] = []
        self._sizes = {t: rmap.size(t) for t in (COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER)}
        self._entries = {t: rmap.table(t) for t in self._sizes}
        self._advance = rmap[ADVANCE] if ADVANCE in rmap else None
        self.live_addresses = frozenset({self._advance.address} if self._advance is not None else ())
        self.crc = map_crc(rmap)  # published in sim.map_crc: the client checks it holds this map
        self.images: Images = Images(b"", b"", b"", b"")
        self.publish()

    # -- the server's side ----------------------------------------------------------------------------
    def submit(self, changes: Sequence[tuple[Entry, object]]) -> int:
        if self.fault:
            return SERVER_DEVICE_FAILURE
        signals = []
        for entry, value in changes:
            if entry.name == ADVANCE:
                n = int(value)
                runner = self.runner
                if runner is None or runner.mode != "lockstep":
                    if n != 0:
                        return ILLEGAL_DATA_VALUE
                elif runner.remaining + n > 0xFFFF:
                    return ILLEGAL_DATA_VALUE
            elif entry.signal is not None:
                signals.append((entry, value))
        for entry, value in changes:  # checked: now act
            if entry.name == ADVANCE and int(value) and self.runner is not None and self.runner.mode == "lockstep":
                self.runner.request(int(value))
        if signals:
            self._queue.append(signals)
            self._show_written(signals)
        return 0

    def _show_written(self, changes: Sequence[tuple[Entry, object]]) -> None:
        """Copy accepted writes into the coil and holding-register images (as the next publish will show them)."""
        coils = holding = None
        for entry, value in changes:
            if entry.table == COIL:
                if coils is None:
                    coils = bytearray(self.images.coils)
                coils[entry.address] = 1 if value else 0
            elif entry.table == HOLDING_REGISTER:
                if holding is None:
                    holding = bytearray(self.images.holding)
                struct.pack_into(f">{entry.count}H", holding, 2 * entry.address, *entry.encode(value))
        changed = {}
        if coils is not None:
            changed["coils"] = bytes(coils)
        if holding is not None:
            changed["holding"] = bytes(holding)
        if changed:
            self.images = dataclasses.replace(self.images, **changed)

    def stepping(self) -> bool:
        runner = self.runner
        return runner is not None and runner.mode == "lockstep" and runner.remaining > 0

    def when_stepped(self, callback) -> None:
        if not self.stepping() or self.fault:
            callback()
        else:
            self.runner.when_done(callback)

    def live_holding(self, address: int) -> int | None:
        if self._advance is not None and address == self._advance.address:
            return 0 if self.runner is None else min(0xFFFF, self.runner.remaining)
        return None

    # -- the runner's side ----------------------------------------------------------------------------
    def step(self) -> bool:
        """Apply queued writes, run one step, publish. False (and the fault bit) if the twin failed."""
        if self.fault:
            return False
        queue, self._queue = self._queue, []
        try:
            for batch in queue:
                for entry, value in batch:
                    self.twin.write(entry.signal, value)
            self.twin.step()
        except Exception as exc:  # a physics or device error: keep serving the last state, flag it
            self.fault = True
            self.log(f"simulation fault at step {self.twin.step_count}: {type(exc).__name__}: {exc}\n"
                     + traceback.format_exc().rstrip())
            self.publish()
            return False
        self.publish()
        return True

    def _status(self) -> dict:
        twin, runner = self.twin, self.runner
        lockstep = runner is not None and runner.mode == "lockstep"
        return {
            FAULT: self.fault, LOCKSTEP: lockstep, LATE: bool(runner is not None and runner.last_late),
            STEP: twin.step_count, TIME_MS: round(twin.time * 1000), DT_US: round(twin.dt * 1e6),
            LATE_STEPS: 0 if runner is None else runner.late_steps, MODE: 0 if lockstep else 1,
            SPEED_PCT: 0 if runner is None or lockstep else round(runner.speed * 100), ADVANCE: 0,
            MAP_CRC: self.crc, **self.extra_status,
        }

    def publish(self) -> None:
        status = self._status()
        read = self.twin.read
        images = {}
        for table, entries in self._entries.items():
            size = self._sizes[table]
            if table in BIT_TABLES:
                img = bytearray(size)
                for e in entries:
                    v = read(e.signal) if e.signal is not None else status.get(e.name, 0)
                    img[e.address] = 1 if v else 0
                images[table] = bytes(img)
            else:
                words = [0] * size
                encoded = self._encoded  # entry -> (value, words): most values do not change from step to step
                for e in entries:
                    v = read(e.signal) if e.signal is not None else status.get(e.name, 0)
                    last = encoded.get(id(e))
                    if last is None or last[0] != v or type(last[0]) is not type(v):
                        last = encoded[id(e)] = (v, e.encode(v))
                    words[e.address:e.end] = last[1]
                images[table] = struct.pack(f">{size}H", *words)
        self.images = Images(images[COIL], images[DISCRETE_INPUT], images[HOLDING_REGISTER], images[INPUT_REGISTER])
        for batch in self._queue:  # written but not yet applied (empty after a step): still reads as written
            self._show_written(batch)
