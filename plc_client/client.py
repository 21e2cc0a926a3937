"""A name-based Modbus/TCP client for a twin server: read and write signals in engineering units.

    from plc_client import TwinClient

    with TwinClient.connect("127.0.0.1", 5020, map="my_cell.json") as plc:   # or station="stations/my_cell"
        plc.write(axis1=320.0)                    # mm, as the map publishes prismatic axes
        plc.read("axis1.actual", "axis1.force", "doGripped")   # {'axis1.actual': 329.9, 'axis1.force': 3.1, 'doGripped': False}
        for t, values in plc.poll(["axis1.force"], interval=0.1, count=10): ...

The register map is the server's own type, `twin.frontends.modbus.register_map.RegisterMap` (also importable as
`plc_client.RegisterMap`), loaded from `twin map STATION --format json` output (`RegisterMap.from_json`)
or from a station (`RegisterMap.from_station`: the map the server builds, without physics), so both
sides agree. A batch read groups signals at contiguous addresses of one table into one request. Values
are checked against the map before anything is sent (`plc_client.checks`): an unknown name or an
out-of-range value (an entry without a range: its type's, whole numbers for integer types of scale 1,
finite float32) raises before the wire (see `plc_client.errors`). A write sends `sim.advance` last. On
connect, a map with `sim.map_crc` is checked against the server's CRC: a map of another station raises
`MapError` instead of reading wrong values.
"""
from __future__ import annotations

import functools
import math
from itertools import compress
from operator import itemgetter, ne
import socket
import ssl
import struct
import threading
import time
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from twin.frontends.modbus.pdu import IMAGE_IN, IMAGE_OUT, ImageLayout
from twin.frontends.modbus.protocol import (DEFAULT_PORT, MAX_READ_BITS, MAX_READ_REGISTERS, MAX_RW_WRITE, MAX_WRITE_BITS,
                                  MAX_WRITE_REGISTERS, TLS_PORT)
from twin.frontends.modbus.register_map import (ADVANCE, BIT_TABLES, COIL, DISCRETE_INPUT, DT_US, HOLDING_REGISTER,
                                      INPUT_REGISTER, LOCKSTEP, MAP_CRC, STEP, TABLES, WATCHDOG_MS, Entry, MapError,
                                      RegisterMap)

from .checks import check_names, check_value, lookup, range_text  # noqa: F401 (range_text: plc map's)
from .errors import ConnectionFailedError, ModbusExceptionError, PlcClientError
from .scan import LocalSignals

Signal = Entry  # one entry of the register map, as the server builds it (twin.frontends.modbus.register_map)


@dataclass(frozen=True)
class TlsFiles:
    """Modbus/TCP Security from the client's side: its certificate and key, and the CA the server's
    certificate must chain to (checked; its host name is not: pymodbus's TLS client does not pass one)."""

    cert: str | Path
    key: str | Path
    ca: str | Path

    def context(self) -> ssl.SSLContext:
        ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
        ctx.minimum_version = ssl.TLSVersion.TLSv1_2
        ctx.check_hostname = False  # the chain to the CA is still required (verify_mode stays CERT_REQUIRED)
        try:
            ctx.load_verify_locations(str(self.ca))
            ctx.load_cert_chain(str(self.cert), str(self.key))
        except (OSError, ssl.SSLError) as exc:
            raise PlcClientError(f"TLS: cannot use certificate {self.cert} / key {self.key} / CA {self.ca}: {exc}") from None
        return ctx


# -- encode / decode: the server's own (twin.frontends.modbus.register_map.Entry), in engineering units ---------------
def encode(s: Signal, value: Any) -> list:
    """Engineering value (checked) -> register words, or [bit] for the bit tables."""
    if s.choices and not isinstance(value, str):
        value = s.choices[int(value)]
    words = s.encode(value, engineering=True)
    return [bool(w) for w in words] if s.table in BIT_TABLES else words


def decode(s: Signal, words: list) -> Any:
    """Register words (or bits) -> engineering value (bool, number, or the enumeration's text)."""
    value = s.decode([int(w) for w in words])
    if isinstance(value, float) and s.type != "float32" and 0 < s.scale < 1:
        digits = round(-math.log10(s.scale))
        if math.isclose(s.scale, 10.0 ** -digits):
            value = round(value, digits)  # 32050 counts of 0.01 mm read 320.5, not 320.50000000000006
    elif isinstance(value, float) and s.scale == 1.0 and s.type != "float32":
        value = int(value)
    return value


@dataclass
class _Run:
    table: str
    start: int
    end: int  # exclusive
    signals: list[Signal] = field(default_factory=list)


def plan_reads(signals: Iterable[Signal], mapped: Mapping[str, set[int]] | None = None) -> list[_Run]:
    """Group signals into requests: contiguous addresses of one table, within the protocol's size limits.
    With `mapped` (the addresses the map covers, per table), a gap of mapped addresses is read through
    too, so axis1.actual and axis1.force with axis2.actual between them still take one request."""
    runs: list[_Run] = []
    for s in sorted(set(signals), key=lambda s: (TABLES.index(s.table), s.address)):
        limit = MAX_READ_BITS if s.table in BIT_TABLES else MAX_READ_REGISTERS
        last = runs[-1] if runs else None
        joins = last is not None and last.table == s.table and max(last.end, s.address + s.count) - last.start <= limit and (
            s.address <= last.end or (mapped is not None and all(a in mapped.get(s.table, ()) for a in range(last.end, s.address))))
        if joins:
            last.end = max(last.end, s.address + s.count)
            last.signals.append(s)
        else:
            runs.append(_Run(s.table, s.address, s.address + s.count, [s]))
    return runs


class WindowImage:
    """The server's input window as read in one request: every signal's value, and the output window's
    current words (coils and holding registers read back), to fill a write block."""

    def __init__(self, client: "TwinClient", words: list[int]):
        self.client, self.words = client, words
        self.layout = client.layout

    @staticmethod
    def slot(layout, s: Signal) -> tuple[int, int, int]:
        """(first word, words, bit) of a signal in the input window; bit -1 for a register value."""
        k, n = layout.in_words(s)
        return k, n, s.address % 16 if s.table in BIT_TABLES else -1

    def value(self, s: Signal) -> Any:
        k, n, bit = self.slot(self.layout, s)
        if bit >= 0:
            return decode(s, [(self.words[k] >> bit) & 1])
        return decode(s, self.words[k:k + n])

    def out_word(self, k: int) -> int:
        """The current value of word k of the output window."""
        lay = self.layout
        if k < lay.out_offset[HOLDING_REGISTER]:
            return (self.words[lay.in_offset[COIL] + k // 16] >> (k % 16)) & 1
        return self.words[lay.in_offset[HOLDING_REGISTER] + k - lay.out_offset[HOLDING_REGISTER]]

    def out_words(self, lo: int, hi: int) -> list[int]:
        """The current values of words lo..hi-1 of the output window (`out_word`'s, the holding registers in one slice)."""
        lay = self.layout
        first = lay.out_offset[HOLDING_REGISTER]  # the output window's first holding register
        words = [self.out_word(k) for k in range(lo, min(hi, first))]
        if hi > first:
            base = lay.in_offset[HOLDING_REGISTER] - first
            words += self.words[base + max(lo, first):base + hi]
        return words


_MBAP = struct.Struct(">HHHBB")  # transaction, protocol, length, unit, function
_FC23 = struct.Struct(">HHHBBHHHHB")  # MBAP, function 23, read address and count, write address and count, bytes


@functools.lru_cache(maxsize=None)
def _words(n: int) -> struct.Struct:
    return struct.Struct(f">{n}H")


_SERVED_MAPS: dict[int, RegisterMap] = {}  # CRC-32 -> a map fetched from a server


def fetch_map(host: str = "127.0.0.1", port: int = DEFAULT_PORT, unit_id: int = 1, *, timeout: float = 3.0,
              tls: TlsFiles | None = None) -> RegisterMap:
    """The register map a running server serves, read from the server itself (function 20, read file record:
    `twin.frontends.modbus.pdu.MapFile`): first its CRC-32 and length, then the JSON, unless a map of that CRC was
    fetched before (a server restarted with another map has another CRC, so it is fetched anew). A document
    whose JSON does not have the CRC it came with is a MapError."""
    import struct

    from pymodbus.client import ModbusTcpClient, ModbusTlsClient
    from pymodbus.exceptions import ModbusException
    from pymodbus.pdu.file_message import FileRecord

    from twin.frontends.modbus.pdu import MAP_FILE, RECORDS_PER_FILE

    if tls is not None:
        client = ModbusTlsClient(host, port=port, sslctx=tls.context(), timeout=timeout, retries=0)
    else:
        client = ModbusTcpClient(host, port=port, timeout=timeout, retries=0)
    try:
        if not client.connect():
            raise ConnectionFailedError(host, port, "connection refused or timed out")

        def records(first: int, count: int) -> bytes:
            file, record = MAP_FILE + first // RECORDS_PER_FILE, first % RECORDS_PER_FILE
            try:
                r = client.read_file_record([FileRecord(file_number=file, record_number=record, record_length=2 * count)],
                                            device_id=unit_id)
            except (ModbusException, OSError) as exc:
                raise ConnectionFailedError(host, port, str(exc).strip() or type(exc).__name__) from None
            if r.isError():
                code = getattr(r, "exception_code", 0)
                if code == 1:
                    raise MapError(f"the server at {host}:{port} does not serve its register map (function 20 answered "
                                   "exception 01: an older twin serve?); give --map FILE.json or --station DIR") from None
                raise ModbusExceptionError(code, 20, first, count, unit_id, ("the register map",))
            return bytes(r.records[0].record_data)

        crc, length = struct.unpack(">II", records(0, 4))
        if crc in _SERVED_MAPS:
            return _SERVED_MAPS[crc]
        total, data = (length + 1) // 2, bytearray()
        while len(data) < 2 * total:
            at = 4 + len(data) // 2
            n = min(MAX_READ_REGISTERS - 1, total - len(data) // 2, RECORDS_PER_FILE - at % RECORDS_PER_FILE)
            data += records(at, n)
    finally:
        client.close()
    where = f"the map served at {host}:{port}"
    try:
        rmap = RegisterMap.from_json(bytes(data[:length]).decode("utf-8"))
    except UnicodeDecodeError:
        raise MapError(f"{where}: not UTF-8 text") from None
    rmap = RegisterMap(rmap.entries, rmap.station, source=where, meta=rmap.meta)
    if rmap.crc != crc:
        raise MapError(f"{where}: its JSON has CRC {rmap.crc:#010x}, the server announced {crc:#010x}")
    _SERVED_MAPS[crc] = rmap
    return rmap


class TwinClient:
    """A connection to a twin server, signals by name (see the module's docstring)."""

    def __init__(self, register_map: RegisterMap, host: str = "127.0.0.1", port: int = DEFAULT_PORT, unit_id: int = 1,
                 timeout: float = 3.0, *, tls: TlsFiles | None = None, heartbeat: float | str | None = "auto"):
        self.map, self.host, self.port, self.unit_id, self.timeout = register_map, host, int(port), int(unit_id), timeout
        self.tls = tls
        self.heartbeat = heartbeat  # s between requests at least; "auto": a third of the server's watchdog time
        self._client = None
        self._lock = threading.RLock()  # the heartbeat thread and the caller share the connection
        self._last_request = 0.0
        self._beat: threading.Thread | None = None
        self._closing = threading.Event()
        self.requests = 0  # requests sent, for tests and diagnostics
        self.heartbeats = 0
        self._tid = 0  # the transaction id of the last function 23 framed here (`_read_write`)
        self._answer = bytearray(9 + 2 * MAX_READ_REGISTERS)
        self._out_places: dict[str, tuple[Signal, int, int]] = {}  # name -> (entry, first word, words) in the output window

    @classmethod
    def connect(cls, host: str = "127.0.0.1", port: int | None = None, unit_id: int = 1, *,
                map: str | Path | RegisterMap | None = None, station: str | Path | None = None, timeout: float = 3.0,
                tls: TlsFiles | None = None, heartbeat: float | str | None = "auto") -> "TwinClient":
        """Connect to the server at host:port with the map from a JSON file (`map`) or a `station`, else the map
        the server serves (`fetch_map`).
        `tls`: Modbus/TCP Security with these certificate files (port default 802, else 5020: `twin.frontends.modbus.protocol`).
        `heartbeat`: see `TwinClient` (a request at least that often, so the server's watchdog sees a quiet
        but healthy PLC)."""
        if port is None:
            port = TLS_PORT if tls is not None else DEFAULT_PORT
        if isinstance(map, RegisterMap):
            rmap = map
        elif map is not None:
            rmap = RegisterMap.from_json(map)
        elif station is not None:
            rmap = RegisterMap.from_station(station)
        else:
            rmap = fetch_map(host, port, unit_id, timeout=timeout, tls=tls)  # the server's own (function 20)
        client = cls(rmap, host, port, unit_id, timeout, tls=tls, heartbeat=heartbeat)
        client.open()
        return client

    def open(self) -> None:
        from pymodbus.client import ModbusTcpClient, ModbusTlsClient

        if self.tls is not None:
            self._client = ModbusTlsClient(self.host, port=self.port, sslctx=self.tls.context(), timeout=self.timeout,
                                           retries=0)
        else:
            self._client = ModbusTcpClient(self.host, port=self.port, timeout=self.timeout, retries=0)
        try:
            ok = self._client.connect()
        except Exception as exc:  # pymodbus wraps socket errors differently across versions
            raise ConnectionFailedError(self.host, self.port, str(exc)) from None
        if not ok:
            self._client = None
            raise ConnectionFailedError(self.host, self.port, "connection refused or timed out")
        sock = getattr(self._client, "socket", None)
        if sock is not None:  # a request is one small frame, sent at once (no Nagle wait for the last ACK)
            try:
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            except OSError:
                pass
        try:
            self._check_map()
        except BaseException:
            self.close()
            raise
        self._start_heartbeat()

    def _start_heartbeat(self) -> None:
        """A background request (a read of sim.step) whenever the connection has been quiet for the
        heartbeat interval. "auto": a third of the server's `comm.watchdog_ms` (none when it is 0)."""
        interval = self.heartbeat
        if interval == "auto":
            interval = None
            if WATCHDOG_MS in self.map:
                try:
                    ms = self.get(WATCHDOG_MS)
                except PlcClientError:
                    ms = 0
                interval = ms / 3000.0 if ms else None
        if not interval:
            return
        self.heartbeat_interval = float(interval)
        self._closing.clear()
        self._beat = threading.Thread(target=self._heartbeat, args=(self.heartbeat_interval,), daemon=True,
                                      name="plc-heartbeat")
        self._beat.start()

    def _heartbeat(self, interval: float) -> None:
        probe = self.map[STEP] if STEP in self.map else next(iter(self.map))
        while not self._closing.wait(max(0.001, self._last_request + interval - time.monotonic())):
            if time.monotonic() - self._last_request < interval:
                continue
            with self._lock:
                if self._client is None:
                    return
                try:
                    self.read_signals([probe])
                    self.heartbeats += 1
                except PlcClientError:
                    return  # the caller sees the broken connection at its next request

    def _check_map(self) -> None:
        """A map with `sim.map_crc`: the server must publish the same CRC, else it serves another map (a
        server of one station read with another station's map would give wrong values without a word)."""
        if MAP_CRC not in self.map:
            return  # a map from before sim.map_crc: nothing to compare
        ours = self.map.crc
        given = f" ({self.map.source})" if self.map.source else ""
        try:
            theirs = self.get(MAP_CRC)
        except ModbusExceptionError as exc:
            if exc.code != 2:
                raise
            raise MapError(f"the server at {self.host}:{self.port} serves another register map than the one "
                           f"given{given}: it has no {MAP_CRC} at input register {lookup(self.map, MAP_CRC).address} "
                           "(an older twin serve?); take the map from the server's station: --station DIR, "
                           "or `twin map STATION --format json`") from None
        if theirs != ours:
            raise MapError(f"the server at {self.host}:{self.port} serves another register map (another station?) "
                           f"than the one given{given}: its {MAP_CRC} is {theirs:#010x}, the given map's "
                           f"{ours:#010x}; take the map from the station the server runs: --station DIR, "
                           "or `twin map STATION --format json`")

    def close(self) -> None:
        self._closing.set()
        with self._lock:
            if self._client is not None:
                self._client.close()
                self._client = None

    def __enter__(self) -> "TwinClient":
        if self._client is None:
            self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- the wire -----------------------------------------------------------------------------------
    def _call(self, function: int, method: str, address: int, size: int, signals: Iterable[Signal], *args, **kw):
        if self._client is None:
            raise ConnectionFailedError(self.host, self.port, "not connected")
        from pymodbus.exceptions import ModbusException

        self.requests += 1
        try:
            with self._lock:
                self._last_request = time.monotonic()
                call = getattr(self._client, method)
                if method == "readwrite_registers":  # keyword arguments only
                    response = call(device_id=self.unit_id, **kw)
                else:
                    response = call(address, *args, device_id=self.unit_id, **kw)
        except ModbusException as exc:
            raise ConnectionFailedError(self.host, self.port, str(exc).strip() or type(exc).__name__) from None
        except OSError as exc:
            raise ConnectionFailedError(self.host, self.port, exc.strerror or str(exc)) from None
        if response.isError():
            code = getattr(response, "exception_code", 0)
            raise ModbusExceptionError(code, function, address, size, self.unit_id, (s.name for s in signals))
        return response

    def read_signals(self, signals: Iterable[Signal]) -> dict[str, Any]:
        values: dict[str, Any] = {}
        for run in plan_reads(signals, self.map.mapped):
            n = run.end - run.start
            fc, method = {COIL: (1, "read_coils"), DISCRETE_INPUT: (2, "read_discrete_inputs"),
                          HOLDING_REGISTER: (3, "read_holding_registers"), INPUT_REGISTER: (4, "read_input_registers")}[run.table]
            r = self._call(fc, method, run.start, n, run.signals, count=n)
            words = r.bits if run.table in BIT_TABLES else r.registers
            for s in run.signals:
                off = s.address - run.start
                values[s.name] = decode(s, list(words[off:off + s.count]))
        return values

    # -- the process-image windows (twin.frontends.modbus.pdu.ImageLayout): a scan in one or two requests ----------
    @property
    def layout(self):
        """Where each table sits in the server's process-image windows (computed from the map, as the server does)."""
        if getattr(self, "_layout", None) is None:
            self._layout = ImageLayout({t: self.map.size(t) for t in TABLES})
        return self._layout

    @property
    def windows_fit(self) -> bool:
        """The whole input window fits one read (125 registers) and the output window one function 23 write."""
        return self.layout.in_size <= MAX_READ_REGISTERS and 0 < self.layout.out_size <= MAX_RW_WRITE

    def read_window(self) -> "WindowImage":
        """The whole input window in one request (function 3)."""
        n = self.layout.in_size
        r = self._call(3, "read_holding_registers", IMAGE_IN, n, (), count=n)
        return WindowImage(self, list(r.registers))

    def exchange(self, values: Mapping[str, Any], image: "WindowImage", advance: int = 0, *,
                 checked: bool = False) -> "WindowImage":
        """Write `values` (names in engineering units, and `advance` steps of sim.advance) into the output
        window and read the whole input window back, in one function 23. In lockstep with `advance`, the
        server answers once the steps are done, so the image returned is the state after them. `image`
        (the last one read) gives the current values of the words between the ones written. `checked`: the
        values have passed `check_value` already (a scan's outputs, checked when the scan set them)."""
        words = self._out_words(values, image, advance, checked)
        if words is None:
            raise PlcClientError("the output window cannot be filled from the last image")
        start, block = words
        n = self.layout.in_size
        if self.tls is None:
            return WindowImage(self, self._read_write(IMAGE_IN, n, IMAGE_OUT + start, block, values))
        r = self._call(23, "readwrite_registers", IMAGE_OUT + start, n, check_names(self.map, values),
                       read_address=IMAGE_IN, read_count=n, write_address=IMAGE_OUT + start, values=block)
        return WindowImage(self, list(r.registers))

    def _read_write(self, read_address: int, read_count: int, write_address: int, words: list[int],
                    names: Iterable[str]) -> list[int]:
        """Function 23 (read/write multiple registers, spec 6.17) framed here, on pymodbus's own connection: a
        scan's one request, whose PDU objects and framer in pymodbus cost several times the exchange itself.
        The frame is the Messaging on TCP/IP guide's MBAP header and the PDU; the answer must be that
        transaction's function 23 (or its exception); anything else breaks the connection, as a stream
        that lost its framing cannot be trusted."""
        if self._client is None or getattr(self._client, "socket", None) is None:
            raise ConnectionFailedError(self.host, self.port, "not connected")
        n = len(words)
        self.requests += 1
        with self._lock:
            sock = self._client.socket
            self._last_request = time.monotonic()
            self._tid = tid = (self._tid + 1) & 0xFFFF
            frame = _FC23.pack(tid, 0, 11 + 2 * n, self.unit_id, 23, read_address, read_count, write_address, n,
                               2 * n) + _words(n).pack(*words)
            size = 9 + 2 * read_count  # the answer: MBAP, function, byte count, the registers
            buf = self._answer if len(self._answer) >= size else bytearray(size)
            self._answer = buf
            view, got, need = memoryview(buf), 0, 9
            try:
                if sock.gettimeout() != self.timeout:  # pymodbus leaves its socket non-blocking
                    sock.settimeout(self.timeout)
                sock.sendall(frame)
                while got < need:
                    k = sock.recv_into(view[got:size], size - got)
                    if k == 0:
                        raise OSError("the server closed the connection")
                    got += k
                    if got >= 7:
                        need = 6 + _MBAP.unpack_from(buf, 0)[2]
                        if need > size or need < 9:
                            break
            except OSError as exc:  # socket.timeout included
                self._drop()
                raise ConnectionFailedError(self.host, self.port, str(exc) or type(exc).__name__) from None
            t, pid, length, unit, fc = _MBAP.unpack_from(buf, 0)
            if t != tid or pid != 0 or unit != self.unit_id or need > size or need < 9:
                self._drop()
                raise ConnectionFailedError(self.host, self.port, "an answer that is not this request's "
                                            f"(transaction {t}, protocol {pid}, unit {unit}, length {length})")
            if fc == 23 | 0x80 and length == 3:
                raise ModbusExceptionError(buf[8], 23, write_address, n, self.unit_id, names)
            if fc != 23 or length != 3 + 2 * read_count or buf[8] != 2 * read_count:
                self._drop()
                raise ConnectionFailedError(self.host, self.port, f"a malformed answer to function 23 (function "
                                            f"{fc}, length {length})")
            return list(_words(read_count).unpack_from(buf, 9))

    def _drop(self) -> None:
        """The connection's framing is lost (a broken or foreign answer): close it; the next request fails."""
        if self._client is not None:
            self._client.close()
            self._client = None

    def write_window(self, values: Mapping[str, Any], image: "WindowImage") -> None:
        """Write `values` into the output window in one request (function 16)."""
        start, block = self._out_words(values, image, 0)
        self._call(16, "write_registers", IMAGE_OUT + start, len(block), check_names(self.map, values), block)

    def _out_words(self, values: Mapping[str, Any], image: "WindowImage", advance: int, checked: bool = False):
        """(first word, words) of the output window covering `values` (and sim.advance), the words between
        them filled with the values `image` holds (so they are written unchanged)."""
        lay = self.layout
        places = self._out_places
        mine: dict[int, int] = {}
        for name, value in values.items():
            place = places.get(name)
            if place is None:
                s = lookup(self.map, name)
                place = places[name] = (s, *lay.out_words(s))
            s, k, n = place
            ws = encode(s, value if checked else check_value(self.map, name, value))
            for i in range(n):
                mine[k + i] = int(ws[i])
        if advance:
            place = places.get(ADVANCE)
            if place is None:
                s = lookup(self.map, ADVANCE)
                place = places[ADVANCE] = (s, *lay.out_words(s))
            mine[place[1]] = int(advance)
        lo, hi = min(mine), max(mine)
        if hi - lo + 1 > MAX_RW_WRITE:
            return None
        block = image.out_words(lo, hi + 1)
        for k, w in mine.items():
            block[k - lo] = w
        return lo, block

    # -- by name ------------------------------------------------------------------------------------
    def read(self, *names: str) -> dict[str, Any]:
        """Values by name, in engineering units, in the order asked. Unknown names raise before any request.
        An enumeration (an entry with `choices`, e.g. `GrippedPart`) reads as its text ("ring", "" for
        none); on the wire it is the index into `choices` (`plc read` prints both: `1  (ring)`)."""
        if len(names) == 1 and not isinstance(names[0], str):
            names = tuple(names[0])
        signals = check_names(self.map, names)
        values = self.read_signals(signals)
        return {n: values[n] for n in names}

    def get(self, name: str) -> Any:
        return self.read(name)[name]

    def write(self, values: Mapping[str, Any] | None = None, /, **more: Any) -> None:
        """Write signals by name (`write(axis1=320.0)` or `write({"axis1.x": 1})`). Everything is checked first:
        one bad name or value and nothing is written. Contiguous registers go in one request. `sim.advance`
        goes last, in a request of its own, once every other write of the call has been answered: in
        lockstep, `write(axis1=320.0, **{"sim.advance": 10})` runs the 10 steps with axis1 already set."""
        items = dict(values or {}, **more)
        checked = [(lookup(self.map, n), check_value(self.map, n, v)) for n, v in items.items()]
        last = [(s, v) for s, v in checked if s.name == ADVANCE]
        checked = [(s, v) for s, v in checked if s.name != ADVANCE]
        by_table: dict[str, list[tuple[Signal, list]]] = {}
        for s, v in sorted(checked, key=lambda sv: (sv[0].table, sv[0].address)):
            by_table.setdefault(s.table, []).append((s, encode(s, v)))
        for table, entries in by_table.items():
            limit = MAX_WRITE_BITS if table == COIL else MAX_WRITE_REGISTERS
            run: list[tuple[Signal, list]] = []
            for s, words in entries:
                if run and (s.address != run[-1][0].address + run[-1][0].count or
                            s.address + s.count - run[0][0].address > limit):
                    self._write_run(table, run)
                    run = []
                run.append((s, words))
            if run:
                self._write_run(table, run)
        for s, v in last:
            self._write_run(s.table, [(s, encode(s, v))])

    def _write_run(self, table: str, run: list[tuple[Signal, list]]) -> None:
        start = run[0][0].address
        words = [w for _, ws in run for w in ws]
        if table == COIL:
            self._call(15, "write_coils", start, len(words), [s for s, _ in run], words)
        else:
            self._call(16, "write_registers", start, len(words), [s for s, _ in run], words)

    def poll(self, names: Iterable[str], interval: float = 0.1, count: int | None = None) -> Iterator[tuple[float, dict]]:
        """Read `names` every `interval` s (against the wall clock): yields (s since the first read, values).
        Endless unless `count` is given: stop by breaking out of the loop."""
        names = list(names)
        check_names(self.map, names)
        t0 = time.monotonic()
        n = 0
        while count is None or n < count:
            yield time.monotonic() - t0, self.read(*names)
            n += 1
            if count is not None and n >= count:
                break
            delay = t0 + n * interval - time.monotonic()
            if delay > 0:
                time.sleep(delay)

    # -- lockstep -----------------------------------------------------------------------------------
    @property
    def lockstep(self) -> bool:
        """The server steps only through `sim.advance` (it was started with --lockstep)."""
        return bool(self.get(LOCKSTEP)) if LOCKSTEP in self.map else False

    @property
    def dt(self) -> float:
        """The simulation step, s."""
        return self.get(DT_US) / 1e6

    def advance(self, steps: int, timeout: float = 30.0) -> None:
        """Lockstep: run `steps` simulation steps on the server and wait until they are done."""
        if steps <= 0:
            return
        self.write({ADVANCE: steps})
        end = time.monotonic() + timeout
        delay = 0.0001
        while self.get(ADVANCE) != 0:  # each read is a round trip: poll briskly, a step takes about a ms
            if time.monotonic() > end:
                raise PlcClientError(f"the server did not finish {steps} steps within {timeout:g} s "
                                     "(is it serving in lockstep mode?)")
            time.sleep(delay)
            delay = min(delay * 1.5, 0.001)


class _ReadPlan:
    """Where the names one scan reads sit in the input window, and their values as last read: a scan decodes only
    the values whose words changed (most do not from one scan to the next)."""

    def __init__(self, layout, signals: list[Signal]):
        self.slots = [(s.name, s, *WindowImage.slot(layout, s)) for s in signals]  # (name, entry, word, words, bit)
        at: dict[int, list[int]] = {}  # word of the window -> the slots that read it
        for i, (_, _, k, n, _) in enumerate(self.slots):
            for w in range(k, k + n):
                at.setdefault(w, []).append(i)
        self.indices = tuple(sorted(at))
        self.readers = tuple(tuple(at[w]) for w in self.indices)
        self.take = itemgetter(*self.indices) if len(self.indices) > 1 else (lambda ws, k=self.indices[0]: (ws[k],))
        self.words: tuple | None = None  # the words read last time, and the values they gave
        self.values: dict[str, Any] = {}

    def values_of(self, words: list[int], decoded: dict[str, tuple]) -> dict[str, Any]:
        """The values in `words` (the input window), decoding anew only those whose words changed since the last
        call; `decoded`: name -> (its words or bit as last decoded, their value), shared by the plans."""
        now = self.take(words)
        last = self.words
        if now == last:
            return self.values
        if last is None:
            todo = range(len(self.slots))
        else:
            todo = {i for readers in compress(self.readers, map(ne, now, last)) for i in readers}  # (any order:
            # `values` already holds every name)
        values = dict(self.values)
        slots = self.slots
        for i in todo:
            name, s, k, n, bit = slots[i]
            raw = (words[k] >> bit) & 1 if bit >= 0 else words[k] if n == 1 else tuple(words[k:k + n])
            seen = decoded.get(name)
            if seen is not None and seen[0] == raw:  # another bit of the word changed, or another plan decoded it
                values[name] = seen[1]
            else:
                values[name] = value = decode(s, [raw] if bit >= 0 else words[k:k + n])
                decoded[name] = (raw, value)
        self.words, self.values = now, values
        return values


class ClientIO(LocalSignals):
    """The network side of a scan cycle: `ScanCycle(ClientIO(client), logic)`.

    Lockstep (the server was started with `--lockstep`): each scan runs `cycle / dt` steps through
    `sim.advance` (carried over, so the average matches); otherwise the scan cycle paces itself against the
    wall clock and the server runs in real time. `local`: signals the PLC holds itself (see `LocalSignals`).

    The process image travels through the server's process-image windows (`twin.frontends.modbus.pdu.ImageLayout`)
    when they fit one request each, as a real PLC's I/O exchange does: in lockstep one function 23 per scan
    (the outputs and sim.advance written, the inputs read back once the steps are done), in real time one
    read of the input window and, when an output changed, one write of the output window. `requests` counts
    what went on the wire. `exchange=False` reads and writes signal by signal (several requests a scan).
    """

    def __init__(self, client: TwinClient, *, lockstep: bool | None = None, dt: float | None = None,
                 local: Mapping[str, Any] | None = None, exchange: bool = True):
        super().__init__(local)
        self.client = client
        self.lockstep = client.lockstep if lockstep is None else lockstep
        self.dt = dt or client.dt
        self._time, self._steps = 0.0, 0
        self.exchange = exchange and client.windows_fit
        self._image: WindowImage | None = None  # the input window as last read
        self._fresh = False  # it shows the process as it is now (lockstep: read after the last steps)
        self._pending: dict[str, Any] = {}  # lockstep: outputs to write with the next advance (checked)
        self._reads: dict[tuple, _ReadPlan] = {}  # the names a scan reads -> where each sits in the window
        self._decoded: dict[str, tuple] = {}  # name -> (its words or bit as last read, their value)

    def _read(self, names: list[str]) -> dict[str, Any]:
        if not names:
            return {}
        if not self.exchange:
            return self.client.read(*names)
        key = tuple(names)
        plan = self._reads.get(key)
        if plan is None:
            plan = self._reads[key] = _ReadPlan(self.client.layout, check_names(self.client.map, names))
        if not self._fresh or self._image is None:
            self._image = self.client.read_window()
        self._fresh = self.lockstep  # real time: the next scan reads anew; lockstep: until the next advance
        return plan.values_of(self._image.words, self._decoded)

    def _write(self, values: dict[str, Any]) -> None:
        if not self.exchange:
            self.client.write(values)
            return
        checked = {name: check_value(self.client.map, name, value)  # refused here, at the scan that set it
                   for name, value in values.items()}
        if ADVANCE in values or self._image is None:
            self.client.write(values)
            self._fresh = False
        elif self.lockstep:
            self._pending.update(checked)
        else:
            self.client.write_window(values, self._image)

    def advance(self, seconds: float) -> None:
        self._time += seconds
        target = math.floor(self._time / self.dt + 1e-9)
        steps = max(0, target - self._steps)
        if self.exchange and self._image is not None and (steps or self._pending):
            pending, self._pending = self._pending, {}
            self._image = self.client.exchange(pending, self._image, advance=steps, checked=True)
            self._fresh = True
            self._steps = target
            return
        if self._pending:
            pending, self._pending = self._pending, {}
            self.client.write(pending)
        if steps:
            self.client.advance(steps)
            self._steps = target
            self._fresh = False
