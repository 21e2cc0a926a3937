"""The Modbus PDU codec: one request PDU in, its response PDU out. No sockets, no clock.

Written from the Modbus Application Protocol specification v1.1b3: functions 1, 2, 3, 4, 5, 6, 15, 16,
20 (read file record, 6.14: the register map itself, see `MapFile`), 22 (mask write register, 6.16), 23
(read/write multiple registers, 6.17) and 43/14 (read device identification, 6.21). What each exception
means here is listed in `server.py`'s docstring.

A consistent input image (`PollHold`): a master that reads its inputs in several requests (OpenPLC: discrete
inputs, then input registers, then holding registers, the twin stepping in between) gets them all from the
step of its first read. Each connection keeps the outputs' images (discrete inputs, input registers) of its
first read; later reads on that connection are answered from them until one reads an address it already
read (the next poll), asks for steps or waits for them (writes or reads `sim.advance`), or reads nothing for
`POLL_HOLD` seconds (`twin serve --poll-hold`). Coils and holding registers are what was written, as always.
"""
from __future__ import annotations

import functools
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from .register_map import (ADVANCE, COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER, POLL_HOLD, TABLES, Entry,
                           RegisterMap)

from .protocol import (GATEWAY_TARGET_FAILED, ILLEGAL_DATA_ADDRESS, ILLEGAL_DATA_VALUE, ILLEGAL_FUNCTION,  # noqa: F401
                       MAX_PDU, MAX_READ_BITS, MAX_READ_REGISTERS, MAX_RW_READ, MAX_RW_WRITE, MAX_WRITE_BITS,
                       MAX_WRITE_REGISTERS, SERVER_DEVICE_FAILURE)

WRITE_FUNCTIONS = frozenset({5, 6, 15, 16, 22, 23})
MEI, MEI_DEVICE_ID = 0x2B, 0x0E

_AQ = struct.Struct(">HH")
_H = struct.Struct(">H")
_RW = struct.Struct(">HHHH")  # function 23: read address and count, write address and count


@dataclass(frozen=True)
class Images:
    """The four tables after one completed step: bits as bytes of 0/1, registers as big-endian bytes."""

    coils: bytes
    discrete_inputs: bytes
    holding: bytes
    input_registers: bytes


class Backend(Protocol):
    """What the server serves: published images, and a place to put validated writes."""

    images: Images

    def submit(self, changes: Sequence[tuple[Entry, object]]) -> int:
        """Queue writes (entry, value in SI units) for the next step, all or nothing, and show them in
        the coil / holding-register images at once. Returns 0, or a Modbus exception code (nothing queued)."""

    live_addresses: frozenset[int]  # holding registers whose value is live (read through live_holding)

    def live_holding(self, address: int) -> int | None:
        """A holding register whose value is live rather than from the last step (e.g. sim.advance)."""

    def stepping(self) -> bool:
        """Lockstep steps asked for are still to run (a function 23 that asked for them waits: `Deferred`)."""

    def when_stepped(self, callback) -> None:
        """Call `callback()` once the steps asked for are done (at once if none are left)."""

    # optional: `hold_steps()` as a turn of answering starts and `run_steps()` when it ends (steps asked for in
    # the turn run then, not a turn of the event loop later; `TwinBridge`'s)


# -- device identification (6.21) ---------------------------------------------------------------------
BASIC, REGULAR, EXTENDED, INDIVIDUAL = 1, 2, 3, 4
VENDOR_NAME, PRODUCT_CODE, REVISION, VENDOR_URL, PRODUCT_NAME, MODEL_NAME, USER_APPLICATION_NAME = range(7)
STATION_NAME_OBJECT = 0x80  # extended (private) objects: the station's name, the map's CRC-32
MAP_CRC_OBJECT = 0x81


@dataclass(frozen=True)
class DeviceIdentity:
    """What function 43/14 tells: the basic objects (vendor, product code, revision), the regular ones
    and extended (private) objects 0x80.. (the station name, the register map's CRC)."""

    vendor: str = "gripper-twin"
    product_code: str = "GT-TWIN-SERVE"
    revision: str = "0.1"
    vendor_url: str = ""
    product_name: str = "gripper-twin twin serve"
    model_name: str = ""
    user_application_name: str = ""
    extended: Mapping[int, str] = field(default_factory=dict)

    def objects(self) -> dict[int, bytes]:
        objs = {VENDOR_NAME: self.vendor, PRODUCT_CODE: self.product_code, REVISION: self.revision,
                VENDOR_URL: self.vendor_url, PRODUCT_NAME: self.product_name, MODEL_NAME: self.model_name,
                USER_APPLICATION_NAME: self.user_application_name}
        out = {k: v.encode("utf-8")[:MAX_PDU - 10] for k, v in objs.items() if k <= REVISION or v}
        for k, v in sorted(self.extended.items()):
            if 0x80 <= k <= 0xFF:
                out[k] = v.encode("utf-8")[:MAX_PDU - 10]
        return out


def _category(object_id: int) -> int:
    return BASIC if object_id <= 2 else REGULAR if object_id <= 0x7F else EXTENDED


# -- the process-image window (one read, one write or one function 23 per PLC scan) --------------------
IMAGE_IN, IMAGE_OUT = 0x8000, 0xC000  # holding-register addresses of the two windows


class ImageLayout:
    """Where each table sits in the process-image windows, derived from the map's table sizes alone (so
    the client computes the same layout from the same map).

    - The input window (read-only, from holding register 0x8000): the discrete inputs packed 16 to a word
      (discrete input 16*k + i is bit i of word k), the input registers one to one, the coils packed like
      the discrete inputs, then the holding registers one to one. Unmapped addresses read 0.
    - The output window (from 0xC000): one word per coil (0 or 1), then the holding registers one to one.
      A write here is a write of the entries it covers whose words differ from what they read, all or
      nothing, checked as any write; an entry written with the words it reads is left as it is (a PLC
      writes its whole output image every scan), words over unmapped addresses are ignored, a read-only
      entry may only be written with the value it has."""

    def __init__(self, sizes: dict[str, int]):
        self.sizes = dict(sizes)
        di_words, coil_words = (sizes[DISCRETE_INPUT] + 15) // 16, (sizes[COIL] + 15) // 16
        self.in_offset = {DISCRETE_INPUT: 0, INPUT_REGISTER: di_words,
                          COIL: di_words + sizes[INPUT_REGISTER],
                          HOLDING_REGISTER: di_words + sizes[INPUT_REGISTER] + coil_words}
        self.in_size = self.in_offset[HOLDING_REGISTER] + sizes[HOLDING_REGISTER]
        self.out_offset = {COIL: 0, HOLDING_REGISTER: sizes[COIL]}
        self.out_size = sizes[COIL] + sizes[HOLDING_REGISTER]

    def in_words(self, entry) -> tuple[int, int]:
        """(first word, words) of an entry in the input window (relative to IMAGE_IN)."""
        base = self.in_offset[entry.table]
        if entry.table in (COIL, DISCRETE_INPUT):
            return base + entry.address // 16, 1
        return base + entry.address, entry.count

    def out_words(self, entry) -> tuple[int, int]:
        return self.out_offset[entry.table] + entry.address, entry.count


class PollHold:
    """One connection's input image for its current poll (see the module docstring)."""

    def __init__(self, clock, hold: float = POLL_HOLD):
        self.clock, self.hold = clock, hold
        self.images: Images | None = None
        self.since = 0.0
        self.read: list[tuple[str, int, int]] = []  # (table, start, end) read from `images`

    def outputs(self, table: str, address: int, count: int, latest: Images) -> Images:
        """The images to answer this read of an output table from (and note the read)."""
        now, end = self.clock(), address + count
        if (self.images is None or now - self.since > self.hold
                or any(t == table and a < end and address < b for t, a, b in self.read)):
            self.images, self.read = latest, []
        self.since = now
        self.read.append((table, address, end))
        return self.images

    def release(self) -> None:
        self.images = None


# -- the register map as a file (function 20, read file record) -----------------------------------------
MAP_FILE, RECORDS_PER_FILE = 1, 10000  # the spec's record numbers are 0..9999 (0x270F) per file


class MapFile:
    """The map the server serves, as `twin map --format json` prints it, readable with function 20: a document
    of 16-bit records over files 1, 2, ... (10000 records each; record r of file f is record 10000 (f - 1) + r
    of the document): records 0-1 the map's CRC-32 (`sim.map_crc`), 2-3 the JSON's length in bytes, then the
    UTF-8 JSON two bytes a record, the last one padded with a space. A client learns the map from the server."""

    def __init__(self, rmap: RegisterMap):
        text = rmap.to_json().encode("utf-8")
        body = text + (b" " if len(text) % 2 else b"")
        self.document = struct.pack(">II", rmap.crc, len(text)) + body
        self.records = len(self.document) // 2

    def read(self, file: int, record: int, length: int) -> bytes | None:
        start = (file - MAP_FILE) * RECORDS_PER_FILE + record
        if file < MAP_FILE or record + length > RECORDS_PER_FILE or start + length > self.records:
            return None
        return self.document[2 * start:2 * (start + length)]


class Deferred:
    """A response that waits: function 23 that set sim.advance answers once the steps are done."""

    def __init__(self, finish):
        self.finish = finish  # () -> the response PDU


class _Table:
    """Address bookkeeping for one table: which addresses are mapped, where entries start."""

    def __init__(self, rmap: RegisterMap, table: str, gaps_zero: bool):
        self.size = rmap.size(table)
        valid, starts, ends = bytearray(self.size + 1), bytearray(self.size + 1), bytearray(self.size + 1)
        self.entry_at: dict[int, Entry] = {}
        for e in rmap.table(table):
            valid[e.address:e.end] = b"\x01" * e.count
            starts[e.address] = 1
            ends[e.end] = 1
            self.entry_at[e.address] = e
        self.valid, self.starts, self.ends = bytes(valid), bytes(starts), bytes(ends)
        self.gaps_zero = gaps_zero

    def readable(self, address: int, count: int) -> bool:
        end = address + count
        return end <= self.size and (self.gaps_zero or self.valid.find(0, address, end) == -1)

    def writable(self, address: int, count: int) -> bool:
        end = address + count
        return (end <= self.size and self.valid.find(0, address, end) == -1 and self.starts[address] == 1
                and self.ends[end] == 1)


_ASCII_BITS = bytes.maketrans(b"\x00\x01", b"01")
# what a write of an entry in the output window is (`PduHandler._window_plan`)
_COIL, _COMMAND, _VALUE = "coil", "command", "value"


@functools.lru_cache(maxsize=None)
def _words(n: int) -> struct.Struct:
    """n big-endian 16-bit words."""
    return struct.Struct(f">{n}H")


def _patched(holding: bytes, live: Sequence[tuple[int, int | None]]) -> bytes:
    """The holding-register image with its live registers (sim.advance) filled in (`live`: `PduHandler._live_values`)."""
    if all(v is None or 2 * a + 2 > len(holding) or holding[2 * a:2 * a + 2] == _H.pack(v) for a, v in live):
        return holding  # they read as the image has them (sim.advance 0 once the steps are done)
    out = bytearray(holding)
    for a, v in live:
        if v is not None and 2 * a + 2 <= len(out):
            _H.pack_into(out, 2 * a, v)
    return bytes(out)


def pack_words(bits: bytes, words: int) -> bytes:
    """Bytes of 0/1 -> `words` big-endian words, bit i of word k being bit 16k + i (the input window's packing)."""
    data = pack_bits(bits).ljust(2 * words, b"\x00")[:2 * words]
    swapped = bytearray(data)
    swapped[0::2], swapped[1::2] = data[1::2], data[0::2]
    return bytes(swapped)


def pack_bits(bits: bytes) -> bytes:
    """Bytes of 0/1 -> Modbus bit packing (first bit in the low bit of the first byte)."""
    if not bits:
        return b""
    return int(bits.translate(_ASCII_BITS)[::-1], 2).to_bytes((len(bits) + 7) // 8, "little")


class PduHandler:
    """Answers request PDUs for one register map from one backend.

    `read_only`: every write function (5, 6, 15, 16, 22, 23) gets exception 01 and changes nothing.
    `gaps_zero`: reads across unmapped addresses inside a table read 0 (writes there still get 02)."""

    def __init__(self, rmap: RegisterMap, backend: Backend, *, read_only: bool = False, gaps_zero: bool = False,
                 identity: DeviceIdentity | None = None):
        self.map, self.backend = rmap, backend
        self.read_only, self.gaps_zero = read_only, gaps_zero
        self.tables = {t: _Table(rmap, t, gaps_zero) for t in TABLES}
        self.layout = ImageLayout({t: self.tables[t].size for t in TABLES})
        self._plans: dict[tuple[int, int], list] = {}  # (window start, words) -> the entries a write covers
        self._in_cache: tuple | None = None  # (images, live registers, the input window as they make it)
        self._holding_cache: tuple | None = None  # (holding image, live words, the words as they read)
        self._in_parts: dict[str, tuple[bytes, bytes]] = {}  # table -> (its image, packed into the input window)
        self.identity = identity or DeviceIdentity()
        self.id_objects = self.identity.objects()
        self.requests = 0
        self.refused_writes = 0
        self.held_reads = 0  # reads answered from a poll's first step while a later one was published
        self.hold: PollHold | None = None  # the connection being answered (set by `handle`)
        adv = rmap.by_name.get(ADVANCE)
        self._advance = adv if adv is not None and adv.table == HOLDING_REGISTER else None
        self._map_file: MapFile | None = None
        # holding registers read live (sim.advance); a backend that serves no window may have none
        self._live_addresses = tuple(sorted(getattr(backend, "live_addresses", ())))
        # sim.advance's address in the output window
        self._advance_out = (None if self._advance is None
                             else IMAGE_OUT + self.layout.out_offset[HOLDING_REGISTER] + self._advance.address)

    def handle(self, pdu: bytes, hold: PollHold | None = None) -> bytes:
        """One request PDU -> its response PDU (an exception: the function code | 0x80 and the code).
        `hold`: the connection's poll (a consistent input image over several reads); None answers from the
        latest step."""
        self.requests += 1
        self.hold = hold
        fc = pdu[0]
        try:
            handler = self._HANDLERS[fc]
        except KeyError:
            return bytes((fc | 0x80, ILLEGAL_FUNCTION))
        if self.read_only and fc in WRITE_FUNCTIONS:
            self.refused_writes += 1
            return bytes((fc | 0x80, ILLEGAL_FUNCTION))
        result = handler(self, pdu)
        if isinstance(result, int):
            return bytes((fc | 0x80, result))
        return result

    def clock_only(self, pdu: bytes) -> bool:
        """The request only reads or writes sim.advance (holding register 0): a lockstep harness driving
        and waiting for simulated time, not a controller's traffic (see twin.runtime.watchdog)."""
        adv = self._advance
        if adv is None or len(pdu) < 5 or pdu[0] not in (3, 6, 16):
            return False
        address, second = _AQ.unpack_from(pdu, 1)
        return address == adv.address and (pdu[0] == 6 or second == 1)

    # -- reads ----------------------------------------------------------------------------------------
    def _read_bits(self, pdu: bytes):
        if len(pdu) != 5:
            return ILLEGAL_DATA_VALUE
        address, count = _AQ.unpack_from(pdu, 1)
        if not 1 <= count <= MAX_READ_BITS:
            return ILLEGAL_DATA_VALUE
        table = COIL if pdu[0] == 1 else DISCRETE_INPUT
        if not self.tables[table].readable(address, count):
            return ILLEGAL_DATA_ADDRESS
        images = self.backend.images
        image = images.coils if table == COIL else self._outputs(table, address, count).discrete_inputs
        data = pack_bits(image[address:address + count])  # gaps are 0 in the image
        return bytes((pdu[0], len(data))) + data

    def _read_registers(self, pdu: bytes):
        if len(pdu) != 5:
            return ILLEGAL_DATA_VALUE
        address, count = _AQ.unpack_from(pdu, 1)
        if not 1 <= count <= MAX_READ_REGISTERS:
            return ILLEGAL_DATA_VALUE
        data = self.registers(HOLDING_REGISTER if pdu[0] == 3 else INPUT_REGISTER, address, count)
        if isinstance(data, int):
            return data
        adv = self.map.by_name.get(ADVANCE)
        if self.hold is not None and pdu[0] == 3 and adv is not None and address <= adv.address < address + count:
            self.hold.release()  # a client reading sim.advance waits for steps: its next reads are of the new step
        return bytes((pdu[0], len(data))) + data

    def registers(self, table: str, address: int, count: int):
        """The words at address..address+count as bytes, or exception 02."""
        if table == HOLDING_REGISTER and address >= IMAGE_IN:
            return self._window(address, count)
        if not self.tables[table].readable(address, count):
            return ILLEGAL_DATA_ADDRESS
        images = self.backend.images
        if table == INPUT_REGISTER:
            return self._outputs(table, address, count).input_registers[2 * address:2 * (address + count)]
        return _patched(images.holding, self._live_values())[2 * address:2 * (address + count)]

    def _live_values(self) -> tuple[tuple[int, int | None], ...]:
        """The live holding registers as they read now: (address, value, None where the image's word stands)."""
        live_holding = self.backend.live_holding
        return tuple([(a, live_holding(a)) for a in self._live_addresses])

    def _outputs(self, table: str, address: int, count: int) -> Images:
        """The images an output read is answered from: the connection's poll's, else the latest."""
        latest = self.backend.images
        if self.hold is None:
            return latest
        images = self.hold.outputs(table, address, count, latest)
        if images is not latest:
            self.held_reads += 1
        return images

    def _window_fits(self, address: int, count: int) -> bool:
        lay = self.layout
        if address >= IMAGE_OUT:
            return address - IMAGE_OUT + count <= lay.out_size
        return address - IMAGE_IN + count <= lay.in_size

    def _window(self, address: int, count: int):
        if not self._window_fits(address, count):
            return ILLEGAL_DATA_ADDRESS
        start = address - (IMAGE_OUT if address >= IMAGE_OUT else IMAGE_IN)
        if address >= IMAGE_OUT:
            images = self.backend.images
            window = (b"".join(b"\x00" + bytes((b,)) for b in images.coils)
                      + _patched(images.holding, self._live_values()))
        else:
            window = self._input_window()
        return window[2 * start:2 * (start + count)]

    def _input_window(self) -> bytes:
        images = self.backend.images
        live = self._live_values()
        cached = self._in_cache
        if cached is not None and cached[0] is images and cached[1] == live:
            return cached[2]
        lay = self.layout
        parts = self._in_parts  # each table's part as last packed, kept while its image stays the same object
        di = parts.get(DISCRETE_INPUT)
        if di is None or di[0] is not images.discrete_inputs:
            di = parts[DISCRETE_INPUT] = (images.discrete_inputs,
                                          pack_words(images.discrete_inputs, lay.in_offset[INPUT_REGISTER]))
        coils = parts.get(COIL)
        if coils is None or coils[0] is not images.coils:
            coils = parts[COIL] = (images.coils,
                                   pack_words(images.coils, lay.in_offset[HOLDING_REGISTER] - lay.in_offset[COIL]))
        window = b"".join((di[1], images.input_registers, coils[1], _patched(images.holding, live)))
        self._in_cache = (images, live, window)
        return window

    def _window_plan(self, start: int, end: int) -> list:
        """The output window's words start..end as (offset, table, address, entry, kind, writable), in address
        order, with (offset, None, code, None, None, False) where a write of them must stop with exception `code`
        (part of an entry). `kind`: `_COIL`, `_COMMAND` (a writable entry of the simulator's own, sim.advance) or
        `_VALUE` (a holding register's value)."""
        lay = self.layout
        plan = []
        k = start
        while k < end:
            if k < lay.out_offset[HOLDING_REGISTER]:
                table, a = COIL, k
            else:
                table, a = HOLDING_REGISTER, k - lay.out_offset[HOLDING_REGISTER]
            t = self.tables[table]
            e = t.entry_at.get(a)
            if e is None:
                if t.valid[a]:  # inside an entry that starts before the write: only part of it
                    plan.append((k - start, None, ILLEGAL_DATA_ADDRESS, None, None, False))
                    break
                k += 1  # an unmapped address: ignored
                continue
            if k + e.count > end:
                plan.append((k - start, None, ILLEGAL_DATA_ADDRESS, None, None, False))
                break
            kind = _COIL if table == COIL else _COMMAND if e.signal is None and e.writable else _VALUE
            plan.append((k - start, table, a, e, kind, e.writable))
            k += e.count
        return plan

    def _holding_words(self, holding: bytes) -> tuple[int, ...]:
        """The holding registers' words as they read now (the live ones filled in), kept while they stay so."""
        live = self._live_values()
        cached = self._holding_cache
        if cached is not None and cached[0] is holding and cached[1] == live:
            return cached[2]
        h = _patched(holding, live)
        words = _words(len(h) // 2).unpack(h)
        self._holding_cache = (holding, live, words)
        return words

    def _write_window(self, address: int, words: Sequence[int], raw: bytes | None = None) -> int:
        """A write into the output window: the entries it covers, all or nothing (see ImageLayout). `raw`: the
        words as the request carried them (big-endian bytes), to compare with the image as it reads."""
        start = address - IMAGE_OUT
        if address < IMAGE_OUT or start + len(words) > self.layout.out_size:
            return ILLEGAL_DATA_ADDRESS
        key = (start, len(words))
        plan = self._plans.get(key)
        if plan is None:
            plan = self._plans[key] = self._window_plan(start, start + len(words))
        changes = []
        images = self.backend.images
        live = self._live_addresses
        current_h = None
        for off, table, a, e, kind, writable in plan:
            if table is None:
                return a
            end = off + e.count
            if kind is _COIL:
                w = words[off]
                if w != 0 and w != 1:
                    return ILLEGAL_DATA_VALUE
                same = images.coils[a] == w
            elif kind is _COMMAND:  # the simulator's own entries are commands (sim.advance: N more steps), taken
                same = False        # whatever they read now
            elif raw is not None and a not in live:
                same = raw[2 * off:2 * end] == images.holding[2 * a:2 * (a + end - off)]
            else:
                if current_h is None:
                    current_h = self._holding_words(images.holding)
                same = current_h[a:a + end - off] == tuple(words[off:end])
            if same:  # words written back as they read are no change (a PLC writes its whole image every scan)
                continue
            if not writable:
                return ILLEGAL_DATA_ADDRESS
            value = e.si_of_words(words[off:end])
            if value is None:
                return ILLEGAL_DATA_VALUE
            changes.append((e, value))
        return self.backend.submit(changes) if changes else 0

    # -- writes ---------------------------------------------------------------------------------------
    def _write(self, table: str, address: int, words: Sequence[int], advances: bool | None = None,
               raw: bytes | None = None) -> int:
        """Validate and queue a write of `words` (or bits) at `address`. 0 or an exception code. `advances`:
        whether it sets sim.advance, when known (`_advances`); `raw`: the registers' bytes as the request carried them."""
        if (self.hold is not None and table == HOLDING_REGISTER
                and (self._advances(address, words) if advances is None else advances)):
            self.hold.release()  # the client asked for steps: its next read is of them
        if table == HOLDING_REGISTER and address >= IMAGE_OUT:
            return self._write_window(address, words, raw)
        t = self.tables[table]
        if not t.writable(address, len(words)):
            return ILLEGAL_DATA_ADDRESS
        changes = []
        a, end = address, address + len(words)
        while a < end:
            e = t.entry_at[a]
            if not e.writable:
                return ILLEGAL_DATA_ADDRESS
            value = e.si_of_words(list(words[a - address:a - address + e.count]))
            if value is None:
                return ILLEGAL_DATA_VALUE
            changes.append((e, value))
            a += e.count
        return self.backend.submit(changes)

    def _write_coil(self, pdu: bytes):
        if len(pdu) != 5:
            return ILLEGAL_DATA_VALUE
        address, value = _AQ.unpack_from(pdu, 1)
        if value not in (0x0000, 0xFF00):
            return ILLEGAL_DATA_VALUE
        return self._write(COIL, address, [1 if value else 0]) or pdu

    def _write_register(self, pdu: bytes):
        if len(pdu) != 5:
            return ILLEGAL_DATA_VALUE
        address, value = _AQ.unpack_from(pdu, 1)
        return self._write(HOLDING_REGISTER, address, [value]) or pdu

    def _write_coils(self, pdu: bytes):
        if len(pdu) < 6:
            return ILLEGAL_DATA_VALUE
        address, count = _AQ.unpack_from(pdu, 1)
        nbytes = pdu[5]
        if not 1 <= count <= MAX_WRITE_BITS or nbytes != (count + 7) // 8 or len(pdu) != 6 + nbytes:
            return ILLEGAL_DATA_VALUE
        bits = [(pdu[6 + (i >> 3)] >> (i & 7)) & 1 for i in range(count)]
        return self._write(COIL, address, bits) or pdu[:5]

    def _write_registers(self, pdu: bytes):
        if len(pdu) < 6:
            return ILLEGAL_DATA_VALUE
        address, count = _AQ.unpack_from(pdu, 1)
        nbytes = pdu[5]
        if not 1 <= count <= MAX_WRITE_REGISTERS or nbytes != 2 * count or len(pdu) != 6 + nbytes:
            return ILLEGAL_DATA_VALUE
        words = _words(count).unpack_from(pdu, 6)
        return self._write(HOLDING_REGISTER, address, words, raw=pdu[6:]) or pdu[:5]

    def _mask_write_register(self, pdu: bytes):
        """6.16: result = (current AND and_mask) OR (or_mask AND NOT and_mask); the response echoes the request."""
        if len(pdu) != 7:
            return ILLEGAL_DATA_VALUE
        address, and_mask, or_mask = struct.unpack_from(">HHH", pdu, 1)
        current = self.registers(HOLDING_REGISTER, address, 1)
        if isinstance(current, int) or not self.tables[HOLDING_REGISTER].writable(address, 1):
            return ILLEGAL_DATA_ADDRESS
        (value,) = struct.unpack(">H", current)
        result = (value & and_mask) | (or_mask & ~and_mask & 0xFFFF)
        return self._write(HOLDING_REGISTER, address, [result]) or pdu

    def _read_write_registers(self, pdu: bytes):
        if len(pdu) < 10:
            return ILLEGAL_DATA_VALUE
        raddr, rcount, waddr, wcount = _RW.unpack_from(pdu, 1)
        nbytes = pdu[9]
        if (not 1 <= rcount <= MAX_RW_READ or not 1 <= wcount <= MAX_RW_WRITE or nbytes != 2 * wcount
                or len(pdu) != 10 + nbytes):
            return ILLEGAL_DATA_VALUE
        if raddr < IMAGE_IN and not self.tables[HOLDING_REGISTER].readable(raddr, rcount):
            return ILLEGAL_DATA_ADDRESS
        if raddr >= IMAGE_IN and not self._window_fits(raddr, rcount):
            return ILLEGAL_DATA_ADDRESS
        # The spec's order: the write first, then the read (which sees the write).
        words = _words(wcount).unpack_from(pdu, 10)
        advances = self._advances(waddr, words)
        code = self._write(HOLDING_REGISTER, waddr, words, advances, pdu[10:])
        if code:
            return code

        def read():
            data = self.registers(HOLDING_REGISTER, raddr, rcount)
            return b"".join((bytes((23, len(data))), data))

        if advances and self.backend.stepping():
            return Deferred(read)  # lockstep: the read sees the state after the steps asked for
        return read()

    def _advances(self, address: int, words: Sequence[int]) -> bool:
        """The write sets sim.advance to a number of steps (directly, or through the output window)."""
        adv = self._advance
        if adv is None:
            return False
        at = adv.address if address < IMAGE_OUT else self._advance_out
        return address <= at < address + len(words) and words[at - address] != 0

    # -- 20: read file record (6.14): the register map ---------------------------------------------------
    def _read_file_record(self, pdu: bytes):
        if len(pdu) < 2:
            return ILLEGAL_DATA_VALUE
        nbytes = pdu[1]
        if not 0x07 <= nbytes <= 0xF5 or nbytes % 7 or len(pdu) != 2 + nbytes:
            return ILLEGAL_DATA_VALUE
        if self._map_file is None:
            self._map_file = MapFile(self.map)
        out = bytearray()
        for k in range(2, 2 + nbytes, 7):
            ref, file, record, length = struct.unpack_from(">BHHH", pdu, k)
            if ref != 6 or length == 0:
                return ILLEGAL_DATA_VALUE if length == 0 else ILLEGAL_DATA_ADDRESS
            data = self._map_file.read(file, record, length)
            if data is None:
                return ILLEGAL_DATA_ADDRESS
            out += bytes((1 + len(data), 6)) + data
        if len(out) > MAX_PDU - 2:
            return ILLEGAL_DATA_VALUE  # the answer would not fit one PDU
        return bytes((20, len(out))) + bytes(out)

    # -- 43/14: read device identification (6.21) -----------------------------------------------------
    def _encapsulated(self, pdu: bytes):
        if len(pdu) < 2 or pdu[1] != MEI_DEVICE_ID:
            return ILLEGAL_FUNCTION  # 43/13 (CANopen) and other MEI types are not supported
        if len(pdu) != 4:
            return ILLEGAL_DATA_VALUE
        code, object_id = pdu[2], pdu[3]
        if code not in (BASIC, REGULAR, EXTENDED, INDIVIDUAL):
            return ILLEGAL_DATA_VALUE
        objects = self.id_objects
        levels = {_category(k) for k in objects}
        conformity = 0x80 | max(levels)  # stream and individual access
        if code == INDIVIDUAL:
            if object_id not in objects:
                return ILLEGAL_DATA_ADDRESS
            value = objects[object_id]
            return bytes((MEI, MEI_DEVICE_ID, code, conformity, 0x00, 0x00, 1, object_id, len(value))) + value
        ids = [k for k in sorted(objects) if _category(k) <= code]
        if object_id not in ids:  # "as if object 0 were pointed out": restart at the beginning
            object_id = 0
        ids = [k for k in ids if k >= object_id]
        body, count, more, next_id = bytearray(), 0, 0x00, 0x00
        room = MAX_PDU - 7
        for k in ids:
            item = bytes((k, len(objects[k]))) + objects[k]
            if len(item) > room - len(body):
                more, next_id = 0xFF, k
                break
            body += item
            count += 1
        return bytes((MEI, MEI_DEVICE_ID, code, conformity, more, next_id, count)) + bytes(body)

    _HANDLERS = {1: _read_bits, 2: _read_bits, 3: _read_registers, 4: _read_registers, 5: _write_coil,
                 6: _write_register, 15: _write_coils, 16: _write_registers, 20: _read_file_record, 22: _mask_write_register,
                 23: _read_write_registers, 43: _encapsulated}
