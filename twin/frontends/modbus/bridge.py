"""The Modbus front end of a cell: register images from the cell's snapshots, writes into its exchange.

`TwinBridge(exchange, rmap)` follows the front-end contract of `twin.runtime.exchange`: it subscribes to the
exchange and turns each published snapshot into four register images (coils, discrete inputs, holding
registers, input registers), which the server (`twin.frontends.modbus.server`) answers reads from. A write request
becomes one batch of (signal, SI value) for `exchange.submit`: it is validated there like any front end's
write (an error answers exception 03, a faulted simulation 04) and takes effect at the next step.

Inputs (coils, holding registers) are what a client wrote: an accepted write (from this or any other
front end) is copied into their images at once (`_show_written`), so reading it back gives the written
value before the step applies it. A publish lays the writes still queued over the snapshot, so no step
can undo that.
"""
from __future__ import annotations

import struct
from collections.abc import Sequence

from twin.core.errors import SignalError, TwinError
from twin.runtime.exchange import Exchange, SimulationFault, Snapshot

from .register_map import (ADVANCE, BIT_TABLES, COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER, MAP_CRC,
                           Entry, RegisterMap)
from .pdu import ILLEGAL_DATA_VALUE, SERVER_DEVICE_FAILURE, Images


class TwinBridge:
    """Publishes an exchange's snapshots as register images and submits writes to it."""

    def __init__(self, exchange: Exchange, rmap: RegisterMap):
        self.exchange, self.map = exchange, rmap
        self._sizes = {t: rmap.size(t) for t in (COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER)}
        self._keyed = {t: [(e, e.signal or e.name) for e in rmap.table(t)] for t in self._sizes}  # entry, value key
        self._by_signal = {e.signal or e.name: e for e in rmap}
        self._advance = rmap[ADVANCE] if ADVANCE in rmap else None
        self.live_addresses = frozenset({self._advance.address} if self._advance is not None else ())
        self.crc = rmap.crc  # sim.map_crc: the CRC of the map this front end serves
        # the images as of the last snapshot, kept between publishes: a publish re-encodes only the values that
        # changed (most do not from one step to the next) into them
        self._buffers = {t: bytearray(size if t in BIT_TABLES else 2 * size) for t, size in self._sizes.items()}
        self._last = {t: [_UNSET] * len(entries) for t, entries in self._keyed.items()}
        self._bytes = {t: bytes(b) for t, b in self._buffers.items()}  # each image as last built from its buffer
        self._bits = {t: [(e.address, key) for e, key in self._keyed[t]] for t in BIT_TABLES}
        self.images: Images = Images(b"", b"", b"", b"")
        self.publish(exchange.snapshot)
        self._unsubscribe = exchange.subscribe(on_snapshot=self.publish, on_writes=self._show_written)

    def close(self) -> None:
        self._unsubscribe()

    @property
    def fault(self) -> bool:
        """The simulation stopped on an error (writes get exception 04)."""
        return self.exchange.fault

    # -- the server's side ----------------------------------------------------------------------------
    def submit(self, changes: Sequence[tuple[Entry, object]]) -> int:
        """One request's writes: 0 when queued, else the Modbus exception code (nothing queued)."""
        try:
            self.exchange.submit([(entry.signal or entry.name, value) for entry, value in changes])
        except SimulationFault:
            return SERVER_DEVICE_FAILURE
        except SignalError:
            return ILLEGAL_DATA_VALUE
        except TwinError:
            return SERVER_DEVICE_FAILURE
        return 0

    def stepping(self) -> bool:
        """Lockstep steps asked for are still to run."""
        runner = self.exchange.runner
        return runner is not None and runner.mode == "lockstep" and runner.remaining > 0

    def when_stepped(self, callback) -> None:
        """Call `callback()` once the lockstep steps asked for are done (at once when none are left)."""
        if not self.stepping() or self.fault:
            callback()
        else:
            self.exchange.runner.when_done(callback)

    def live_holding(self, address: int) -> int | None:
        if self._advance is not None and address == self._advance.address:
            runner = self.exchange.runner
            return 0 if runner is None else min(0xFFFF, runner.remaining)
        return None

    # -- the exchange's side --------------------------------------------------------------------------
    def _show_written(self, batch: Sequence[tuple[str, object]]) -> None:
        """Copy accepted writes into the coil and holding-register images (as the next publish will show them)."""
        coils = holding = None
        for name, value in batch:
            entry = self._by_signal.get(name)
            if entry is None:
                continue
            if entry.table == COIL:
                if coils is None:
                    coils = bytearray(self.images.coils)
                coils[entry.address] = 1 if value else 0
            elif entry.table == HOLDING_REGISTER:
                if holding is None:
                    holding = bytearray(self.images.holding)
                entry.pack_into(holding, 2 * entry.address, value)
        if coils is not None or holding is not None:
            old = self.images
            self.images = Images(old.coils if coils is None else bytes(coils), old.discrete_inputs,
                                 old.holding if holding is None else bytes(holding), old.input_registers)

    def publish(self, snapshot: Snapshot | None = None) -> None:
        """New images from a snapshot (default: the exchange's latest), with the writes still queued on top."""
        values = (snapshot or self.exchange.snapshot).values
        get, crc = values.get, self.crc
        images = {}
        for table, entries in self._keyed.items():
            buf, last = self._buffers[table], self._last[table]
            if table in BIT_TABLES:
                bits = [1 if get(key, 0) else 0 for _, key in self._bits[table]]
                if bits != last:  # unchanged bits (most steps): the image as it was
                    last[:] = bits
                    for (address, _), bit in zip(self._bits[table], bits):
                        buf[address] = bit
                    self._bytes[table] = bytes(buf)
                images[table] = self._bytes[table]
                continue
            new = [crc if key == MAP_CRC else get(key, 0) for _, key in entries]
            if new != last:  # equal lists: the same values, the image as it was (a changed type packs the same words)
                for i, v in enumerate(new):
                    old = last[i]
                    if old is v or (old == v and type(old) is type(v)):
                        continue
                    last[i] = v
                    e = entries[i][0]
                    e.pack_into(buf, 2 * e.address, v)
                self._bytes[table] = bytes(buf)
            images[table] = self._bytes[table]
        self.images = Images(images[COIL], images[DISCRETE_INPUT], images[HOLDING_REGISTER], images[INPUT_REGISTER])
        for batch in self.exchange.pending:  # written but not yet applied (empty after a step): still reads as written
            self._show_written(batch)


_UNSET = object()  # no value encoded yet
