"""A Modbus/TCP server that serves a register map. It knows nothing of physics.

The server answers from register images (`Images`) that its backend publishes after each completed
simulation step, and hands validated writes to the backend (`Backend.submit`), which applies them at
the start of the next step and shows them in the coil and holding-register images at once. So a read
of an output always sees one completed step, a read of an input what was last written, and a write
takes effect at the next step.

What is taken from pymodbus, and what is not
--------------------------------------------
Measured on pymodbus 3.16.1 (see /work/shared/reference/measured-facts.md), its server is wrong on the
wire: exception responses carry function code 0x80 instead of the request's code | 0x80, an oversized
read gets exception 01 instead of 03, only the first of several pipelined requests is answered, a half
frame has no timeout (the next request is glued onto it) and a wrong protocol id silences the
connection. Its PDU decoder (`pymodbus.pdu.DecodePDU`) swallows the reason a request is bad (a count
check raises and the decoder returns None), which is where the wrong codes come from. Its classic
datastore is deprecated for v4. So the transport (MBAP framing on asyncio), the PDU codec for function
codes 1, 2, 3, 4, 5, 6, 15, 16 and 23 (a few lines of `struct` each) and the checks are our own,
written from the Modbus Application Protocol specification v1.1b3 and the Messaging on TCP/IP
Implementation Guide v1.0b. pymodbus is used on the other side: the tests and the benchmark talk to
this server with pymodbus's own clients (`ModbusTcpClient`, `AsyncModbusTcpClient`), so its (correct)
client PDU encoder and decoder check our frames, and the benchmark's reference server is a bare
pymodbus `ModbusTcpServer` on `SimDevice` (the v4 datastore). Tested with pymodbus >= 3.16, < 4.

Wire behaviour
--------------
- MBAP header: 7 bytes; a protocol id other than 0, or a length field outside 2..265, cannot be
  resynchronised: that connection is closed (and logged) once the requests before it in the stream
  are answered; other connections are not affected. 265 is the unit id plus the longest PDU a
  supported request can describe (function 23 writing 127 registers, a byte count of 254), so a
  request that is merely over its function's quantity limit (e.g. function 16 with 124 registers,
  length 255) is framed and answered with exception 03 rather than dropped.
- Requests on one connection are handled one after another and answered in order, however many are
  pipelined before the first reply. A connection gets at most `requests_per_turn` requests answered
  per turn of the event loop; with more pipelined, it stops reading and goes on at the next turn, so
  one flooding client cannot starve the simulation runner or the other clients. A half frame that is
  not completed within `frame_timeout` seconds closes that connection (the next request is never
  glued onto it).
- Unit id: the server answers its `unit_id`, and 0 and 255 (which the TCP implementation guide uses for
  "this device"). Any other unit id gets exception 0B (gateway target device failed to respond).
- Exceptions: the response's function code is the request's with the high bit set. An unknown function
  gets 01; a quantity of 0 or above the limit (2000 bits, 125 registers to read; 1968 bits, 123
  registers to write; 125/121 for function 23), a byte count that does not match the quantity, or a PDU
  of the wrong length gets 03; an address range that leaves the map or touches a gap gets 02 (so does a
  write that covers only part of a 32-bit value); a value outside the signal's range gets 03 and
  changes nothing (a multi-register write is all or nothing); a write while the simulation is faulted
  gets 04.
- An accepted write shows at once when its coils or holding registers are read back (function 23
  writes, then reads); the twin applies it at the next step.
"""
from __future__ import annotations

import asyncio
import socket
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

from .log import log as _log
from .register_map import BIT_TABLES, COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER, TABLES, Entry, RegisterMap

ILLEGAL_FUNCTION, ILLEGAL_DATA_ADDRESS, ILLEGAL_DATA_VALUE, SERVER_DEVICE_FAILURE = 0x01, 0x02, 0x03, 0x04
GATEWAY_TARGET_FAILED = 0x0B

MAX_READ_BITS, MAX_READ_REGISTERS = 2000, 125
MAX_WRITE_BITS, MAX_WRITE_REGISTERS = 1968, 123
MAX_RW_READ, MAX_RW_WRITE = 125, 121
MAX_LENGTH = 1 + 10 + 2 * 127  # MBAP length: unit id + function 23 writing 127 registers (byte count 254)
REQUESTS_PER_TURN = 64  # pipelined requests answered per connection per event-loop turn

_HDR = struct.Struct(">HHHB")
_AQ = struct.Struct(">HH")


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


class _Table:
    """Address bookkeeping for one table: which addresses are mapped, where entries start."""

    def __init__(self, rmap: RegisterMap, table: str):
        self.size = rmap.size(table)
        valid, starts, ends = bytearray(self.size + 1), bytearray(self.size + 1), bytearray(self.size + 1)
        self.entry_at: dict[int, Entry] = {}
        for e in rmap.table(table):
            valid[e.address:e.end] = b"\x01" * e.count
            starts[e.address] = 1
            ends[e.end] = 1
            self.entry_at[e.address] = e
        self.valid, self.starts, self.ends = bytes(valid), bytes(starts), bytes(ends)

    def readable(self, address: int, count: int) -> bool:
        end = address + count
        return end <= self.size and self.valid.find(0, address, end) == -1

    def writable(self, address: int, count: int) -> bool:
        return self.readable(address, count) and self.starts[address] == 1 and self.ends[address + count] == 1


_ASCII_BITS = bytes.maketrans(b"\x00\x01", b"01")


def _pack_bits(bits: bytes) -> bytes:
    """Bytes of 0/1 -> Modbus bit packing (first bit in the low bit of the first byte)."""
    if not bits:
        return b""
    return int(bits.translate(_ASCII_BITS)[::-1], 2).to_bytes((len(bits) + 7) // 8, "little")


class ModbusServer:
    """Serve `rmap` from `backend` over Modbus/TCP (see the module docstring)."""

    def __init__(self, rmap: RegisterMap, backend: Backend, *, unit_id: int = 1, frame_timeout: float = 1.0,
                 requests_per_turn: int = REQUESTS_PER_TURN, log: Callable[[str], None] = _log):
        self.map, self.backend, self.unit_id = rmap, backend, unit_id
        self.units = {unit_id, 0, 255}
        self.frame_timeout = frame_timeout
        self.requests_per_turn = requests_per_turn
        self.log = log
        self.tables = {t: _Table(rmap, t) for t in TABLES}
        self.connections: set[_Connection] = set()
        self._server: asyncio.base_events.Server | None = None
        self.requests = 0

    async def start(self, host: str = "127.0.0.1", port: int = 5020) -> tuple[str, int]:
        loop = asyncio.get_running_loop()
        self._server = await loop.create_server(lambda: _Connection(self), host, port, reuse_address=True)
        return self._server.sockets[0].getsockname()[:2]

    async def close(self) -> None:
        if self._server is not None:
            self._server.close()
            for conn in list(self.connections):
                conn.close("server stopping")
            await self._server.wait_closed()
            self._server = None

    # -- requests -----------------------------------------------------------------------------------
    def handle(self, unit: int, pdu: bytes) -> bytes:
        """One request PDU -> its response PDU."""
        self.requests += 1
        fc = pdu[0]
        if unit not in self.units:
            return bytes((fc | 0x80, GATEWAY_TARGET_FAILED))
        try:
            handler = self._HANDLERS[fc]
        except KeyError:
            return bytes((fc | 0x80, ILLEGAL_FUNCTION))
        result = handler(self, pdu)
        if isinstance(result, int):
            return bytes((fc | 0x80, result))
        return result

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
        image = images.coils if table == COIL else images.discrete_inputs
        data = _pack_bits(image[address:address + count])
        return bytes((pdu[0], len(data))) + data

    def _read_registers(self, pdu: bytes):
        if len(pdu) != 5:
            return ILLEGAL_DATA_VALUE
        address, count = _AQ.unpack_from(pdu, 1)
        if not 1 <= count <= MAX_READ_REGISTERS:
            return ILLEGAL_DATA_VALUE
        data = self._registers(HOLDING_REGISTER if pdu[0] == 3 else INPUT_REGISTER, address, count)
        if isinstance(data, int):
            return data
        return bytes((pdu[0], len(data))) + data

    def _registers(self, table: str, address: int, count: int):
        if not self.tables[table].readable(address, count):
            return ILLEGAL_DATA_ADDRESS
        images = self.backend.images
        if table == INPUT_REGISTER:
            return images.input_registers[2 * address:2 * (address + count)]
        data = images.holding[2 * address:2 * (address + count)]
        patched = None
        for a in self.backend.live_addresses:
            if address <= a < address + count:
                v = self.backend.live_holding(a)
                if v is not None:
                    if patched is None:
                        patched = bytearray(data)
                    struct.pack_into(">H", patched, 2 * (a - address), v)
        return data if patched is None else bytes(patched)

    def _write(self, table: str, address: int, words: Sequence[int]) -> int:
        """Validate and queue a write of `words` (or bits) at `address`. 0 or an exception code."""
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
        words = struct.unpack_from(f">{count}H", pdu, 6)
        return self._write(HOLDING_REGISTER, address, words) or pdu[:5]

    def _read_write_registers(self, pdu: bytes):
        if len(pdu) < 10:
            return ILLEGAL_DATA_VALUE
        raddr, rcount, waddr, wcount = struct.unpack_from(">HHHH", pdu, 1)
        nbytes = pdu[9]
        if (not 1 <= rcount <= MAX_RW_READ or not 1 <= wcount <= MAX_RW_WRITE or nbytes != 2 * wcount
                or len(pdu) != 10 + nbytes):
            return ILLEGAL_DATA_VALUE
        if not self.tables[HOLDING_REGISTER].readable(raddr, rcount):
            return ILLEGAL_DATA_ADDRESS
        # The spec's order: the write first, then the read (which sees the write).
        code = self._write(HOLDING_REGISTER, waddr, struct.unpack_from(f">{wcount}H", pdu, 10))
        if code:
            return code
        data = self._registers(HOLDING_REGISTER, raddr, rcount)
        return bytes((23, len(data))) + data

    _HANDLERS = {1: _read_bits, 2: _read_bits, 3: _read_registers, 4: _read_registers, 5: _write_coil,
                 6: _write_register, 15: _write_coils, 16: _write_registers, 23: _read_write_registers}


class _Connection(asyncio.Protocol):
    """One client: MBAP framing, requests answered in order, a fair share of the loop, a timeout on half frames.

    Reading stops (so TCP pushes back on the client) while the client does not read its answers
    (`pause_writing`) and while complete requests wait for the next turn of the loop (`_later`)."""

    def __init__(self, server: ModbusServer):
        self.server = server
        self.buf = bytearray()
        self.transport: asyncio.Transport | None = None
        self.timer: asyncio.TimerHandle | None = None
        self._later: asyncio.Handle | None = None  # the next turn's share of pipelined requests
        self.writing_paused = False
        self.closed = False
        self.peer = "?"
        self.reason = ""

    def connection_made(self, transport) -> None:
        self.transport = transport
        sock = transport.get_extra_info("socket")
        if sock is not None:
            try:
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            except OSError:
                pass
        peer = transport.get_extra_info("peername")
        self.peer = f"{peer[0]}:{peer[1]}" if peer else "?"
        self.server.connections.add(self)
        self.server.log(f"client {self.peer} connected ({len(self.server.connections)} connected)")

    def connection_lost(self, exc) -> None:
        self.closed = True
        self._stop_timer()
        if self._later is not None:
            self._later.cancel()
            self._later = None
        self.server.connections.discard(self)
        reason = self.reason or (f"error: {exc}" if exc else "closed by the client")
        self.server.log(f"client {self.peer} disconnected ({reason}; {len(self.server.connections)} connected)")

    def close(self, reason: str) -> None:
        """Drop the connection now (anything not yet sent is lost)."""
        if not self.reason:
            self.reason = reason
        self.closed = True
        if self.transport is not None:
            self.transport.abort()

    def _close_after_answers(self, reason: str) -> None:
        """Close once the answers already written are sent; abort if the client will not take them."""
        self.reason = self.reason or reason
        self.closed = True
        self.transport.close()
        asyncio.get_running_loop().call_later(self.server.frame_timeout, self.transport.abort)

    def pause_writing(self) -> None:  # the client does not read its answers: stop reading its requests
        self.writing_paused = True
        self._stop_timer()  # it cannot complete a half frame while we do not read
        self.transport.pause_reading()

    def resume_writing(self) -> None:
        self.writing_paused = False
        if self._later is None and not self.closed:
            self._later = asyncio.get_running_loop().call_soon(self._next_turn)

    def data_received(self, data: bytes) -> None:
        self.buf += data
        if self._later is None and not self.writing_paused:
            self._answer()

    def _next_turn(self) -> None:
        self._later = None
        if not self.closed and not self.writing_paused:
            self._answer()

    def _answer(self) -> None:
        """Answer the complete requests at the front of the buffer, at most `requests_per_turn` of them."""
        buf = self.buf
        out = []
        pos, n = 0, len(buf)
        handle = self.server.handle
        budget = self.server.requests_per_turn
        bad = ""
        while budget and n - pos >= 7:
            tid, pid, length, unit = _HDR.unpack_from(buf, pos)
            if pid != 0:
                bad = f"protocol id {pid}, not 0 (Modbus)"
                break
            if not 2 <= length <= MAX_LENGTH:
                bad = f"frame length field {length} outside 2..{MAX_LENGTH}"
                break
            if n - pos < 6 + length:
                break
            response = handle(unit, bytes(buf[pos + 7:pos + 6 + length]))
            out.append(_HDR.pack(tid, 0, len(response) + 1, unit) + response)
            pos += 6 + length
            budget -= 1
        if pos:
            del buf[:pos]
            self._stop_timer()
        if out:
            self.transport.write(b"".join(out))  # may call pause_writing
        if bad:
            self._close_after_answers(bad)
            return
        if not budget and len(buf) >= 7:  # more may be waiting: the loop's other work first
            self.transport.pause_reading()
            if not self.writing_paused:
                self._later = asyncio.get_running_loop().call_soon(self._next_turn)
            return
        if not self.writing_paused:
            self.transport.resume_reading()
            if buf and self.timer is None:
                self.timer = asyncio.get_running_loop().call_later(self.server.frame_timeout, self._stalled)

    def _stop_timer(self) -> None:
        if self.timer is not None:
            self.timer.cancel()
            self.timer = None

    def _stalled(self) -> None:
        self.timer = None
        self.close(f"half a frame ({len(self.buf)} bytes) not completed within {self.server.frame_timeout:g} s")
