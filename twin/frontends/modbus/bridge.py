"""The Modbus front end of a cell: register images from the cell's snapshots, writes into its exchange.

`TwinBridge(exchange, rmap)` follows the front-end contract of `twin.runtime.exchange`: it subscribes to the
exchange and turns each published snapshot into four register images (coils, discrete inputs, holding
registers, input registers), which the server (`twin.frontends.modbus.server`) answers reads from. A write request
becomes one batch of (signal, SI value) for `exchange.submit`: it is validated there like any front end's
write (an error answers exception 03, a faulted simulation 04) and takes effect at the next step.

Inputs (coils, holding registers) are what a client wrote: an accepted write (from this or any other
front end) shows in their images at once, so reading it back gives the written value before the step
applies it; the images are always the last snapshot with the writes still queued laid over it, so no
step can undo that.

The images are formed when a request reads them, not at every step: a publish only notes the snapshot,
an accepted write only that the images must be formed anew. So a lockstep client that asks for several
steps pays for one encoding, and a write followed by its step (a PLC's scan) for none of its own. Only the
values that changed since the last encoding are encoded (most do not from one step to the next).
"""
from __future__ import annotations

from collections.abc import Sequence
from itertools import compress
from operator import is_not, itemgetter

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
        # the images as of the last snapshot encoded, kept between encodings: only the values that changed are
        # encoded into them
        self._buffers = {t: bytearray(size if t in BIT_TABLES else 2 * size) for t, size in self._sizes.items()}
        values = exchange.snapshot.values
        self._tables = []  # per table: its values taken from a snapshot in one call, and how each is encoded
        for t, entries in self._keyed.items():
            if t not in BIT_TABLES:  # sim.map_crc is this map's CRC whatever the snapshot says: encoded once
                for e, key in entries:
                    if key == MAP_CRC:
                        e.pack_into(self._buffers[t], 2 * e.address, self.crc)
                entries = [(e, key) for e, key in entries if key != MAP_CRC]
            keys = tuple(key for _, key in entries)
            take = (_taker(keys) if all(k in values for k in keys)
                    else (lambda v, keys=keys: tuple(v.get(k, 0) for k in keys)))
            if t in BIT_TABLES:
                writers = tuple(e.address for e, _ in entries)
            else:
                writers = tuple((e._packer.pack_into, 2 * e.address, e.counter) for e, _ in entries)
            self._tables.append((t, take, t in BIT_TABLES, writers, range(len(keys))))
        self._last = {t: (_UNSET,) * len(writers) for t, _, _, writers, _ in self._tables}
        self._encoded: Images = Images(*(bytes(self._buffers[t]) for t in (COIL, DISCRETE_INPUT, HOLDING_REGISTER,
                                                                          INPUT_REGISTER)))
        self._snapshot: Snapshot | None = None  # published, not yet encoded
        self._images: Images | None = None  # None: formed anew at the next read
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
    @property
    def images(self) -> Images:
        """The four tables: the last snapshot, with the writes still queued laid over it (formed at the first read
        after a step or a write, see the module docstring)."""
        images = self._images
        if images is None:
            if self._snapshot is not None:
                self._encode(self._snapshot.values)
                self._snapshot = None
            images = self._encoded
            for batch in self.exchange.pending:  # written but not yet applied (none after a step): read as written
                images = self._written_over(images, batch)
            self._images = images
        return images

    def publish(self, snapshot: Snapshot | None = None) -> None:
        """A new snapshot (default: the exchange's latest): the images are formed from it when next read."""
        self._snapshot = snapshot or self.exchange.snapshot
        self._images = None

    def _show_written(self, batch: Sequence[tuple[str, object]]) -> None:
        """An accepted write (of any front end), queued: the coil and holding-register images show it. Laid over
        images already formed (the batches queued before it are in them), else formed with it at the next read."""
        if self._images is not None:
            self._images = self._written_over(self._images, batch)

    def _written_over(self, images: Images, batch: Sequence[tuple[str, object]]) -> Images:
        """`images` with a batch of writes in the coil and holding-register images."""
        coils = holding = None
        for name, value in batch:
            entry = self._by_signal.get(name)
            if entry is None:
                continue
            if entry.table == COIL:
                if coils is None:
                    coils = bytearray(images.coils)
                coils[entry.address] = 1 if value else 0
            elif entry.table == HOLDING_REGISTER:
                if holding is None:
                    holding = bytearray(images.holding)
                entry.pack_into(holding, 2 * entry.address, value)
        if coils is None and holding is None:
            return images
        return Images(images.coils if coils is None else bytes(coils), images.discrete_inputs,
                      images.holding if holding is None else bytes(holding), images.input_registers)

    def _encode(self, values) -> None:
        """The snapshot's values into `_encoded`: only the tables, and in them only the values, that changed."""
        buffers, lasts = self._buffers, self._last
        changed = {}
        for table, take, bits, writers, indices in self._tables:
            new = take(values)
            last = lasts[table]
            if new == last:  # the same values: the image as it was
                continue
            buf = buffers[table]
            if bits:
                for address, v in zip(writers, new):
                    buf[address] = 1 if v else 0
            else:
                # the values that are not the very same objects (most of the rest are new floats)
                for i in compress(indices, map(is_not, last, new)):
                    old, v = last[i], new[i]
                    # equal values of the same type pack the same words (a changed type, e.g. 1 for 1.0, is packed)
                    if old == v and type(old) is type(v):
                        continue
                    pack_into, offset, counter = writers[i]
                    pack_into(buf, offset, counter(v))
            lasts[table] = new
            changed[table] = bytes(buf)
        if changed:
            old = self._encoded
            self._encoded = Images(changed.get(COIL, old.coils), changed.get(DISCRETE_INPUT, old.discrete_inputs),
                                   changed.get(HOLDING_REGISTER, old.holding),
                                   changed.get(INPUT_REGISTER, old.input_registers))


def _taker(keys: tuple[str, ...]):
    """mapping -> the values of `keys` as a tuple, in one call."""
    if len(keys) == 1:
        key = keys[0]
        return lambda values: (values[key],)
    if not keys:
        return lambda values: ()
    return itemgetter(*keys)


_UNSET = object()  # no value encoded yet
