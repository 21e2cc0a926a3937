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

from collections.abc import Sequence
from operator import itemgetter

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
        self._last = {t: (_UNSET,) * len(entries) for t, entries in self._keyed.items()}
        self._bytes = {t: bytes(b) for t, b in self._buffers.items()}  # each image as last built from its buffer
        # per table: its values taken from a snapshot in one call, and how each is written into the image
        values = exchange.snapshot.values
        self._tables = []
        for t, entries in self._keyed.items():
            keys = tuple(key for _, key in entries)
            take = (_taker(keys) if all(k in values for k in keys)
                    else (lambda v, keys=keys: tuple(v.get(k, 0) for k in keys)))
            crc_at = keys.index(MAP_CRC) if MAP_CRC in keys and t not in BIT_TABLES else None
            if t in BIT_TABLES:
                writers = tuple(e.address for e, _ in entries)
            else:
                writers = tuple((e._packer.pack_into, 2 * e.address, e.counter) for e, _ in entries)
            self._tables.append((t, take, crc_at, t in BIT_TABLES, writers))
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

    def hold_steps(self) -> None:
        """A turn of answering starts: lockstep steps asked for in it wait for `run_steps` (`LockstepRunner.hold`)."""
        runner = self.exchange.runner
        if runner is not None and runner.mode == "lockstep":
            runner.hold()

    def run_steps(self) -> None:
        """The turn is over: the lockstep steps asked for in it run now."""
        runner = self.exchange.runner
        if runner is not None and runner.mode == "lockstep":
            runner.release()

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
        """New images from a snapshot (default: the exchange's latest), with the writes still queued on top.
        Only the values that changed since the last snapshot are encoded (most do not from one step to the next)."""
        values = (snapshot or self.exchange.snapshot).values
        buffers, lasts, images = self._buffers, self._last, self._bytes
        for table, take, crc_at, bits, writers in self._tables:
            new = take(values)
            if crc_at is not None:
                new = (*new[:crc_at], self.crc, *new[crc_at + 1:])
            last = lasts[table]
            if new == last:  # the same values: the image as it was
                continue
            buf = buffers[table]
            if bits:
                for address, v in zip(writers, new):
                    buf[address] = 1 if v else 0
            else:
                for old, v, (pack_into, offset, counter) in zip(last, new, writers):
                    # equal values of the same type pack the same words (a changed type, e.g. 1 for 1.0, is packed)
                    if old is v or (old == v and type(old) is type(v)):
                        continue
                    pack_into(buf, offset, counter(v))
            lasts[table] = new
            images[table] = bytes(buf)
        self.images = Images(images[COIL], images[DISCRETE_INPUT], images[HOLDING_REGISTER], images[INPUT_REGISTER])
        for batch in self.exchange.pending:  # written but not yet applied (empty after a step): still reads as written
            self._show_written(batch)


def _taker(keys: tuple[str, ...]):
    """mapping -> the values of `keys` as a tuple, in one call."""
    if len(keys) == 1:
        key = keys[0]
        return lambda values: (values[key],)
    if not keys:
        return lambda values: ()
    return itemgetter(*keys)


_UNSET = object()  # no value encoded yet
