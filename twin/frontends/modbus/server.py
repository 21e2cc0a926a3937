"""A Modbus/TCP server that serves a register map. It knows nothing of physics.

The server answers from register images (`Images`) that its backend publishes after each completed
simulation step, and hands validated writes to the backend (`Backend.submit`), which applies them at
the start of the next step and shows them in the coil and holding-register images at once. So a read
of an output always sees one completed step, a read of an input what was last written, and a write
takes effect at the next step. This module is the transport (MBAP framing on asyncio, plain TCP and
Modbus/TCP Security over TLS), the fair share of the event loop, and who may connect; the PDUs are
`pdu.py`'s.

What is taken from pymodbus, and what is not
--------------------------------------------
Measured on pymodbus 3.16.1 (see /work/shared/reference/measured-facts.md), its server is wrong on the
wire: exception responses carry function code 0x80 instead of the request's code | 0x80, an oversized
read gets exception 01 instead of 03, only the first of several pipelined requests is answered, a half
frame has no timeout (the next request is glued onto it) and a wrong protocol id silences the
connection. Its PDU decoder (`pymodbus.pdu.DecodePDU`) swallows the reason a request is bad (a count
check raises and the decoder returns None), which is where the wrong codes come from. Its classic
datastore is deprecated for v4. So the transport, the PDU codec and the checks are our own, written from
the Modbus Application Protocol specification v1.1b3, the Messaging on TCP/IP Implementation Guide
v1.0b and the Modbus/TCP Security protocol specification. pymodbus is used on the other side: the tests
and the benchmark talk to this server with pymodbus's own clients, so its (correct) client PDU encoder
and decoder check our frames. Tested with pymodbus >= 3.16, < 4.

Wire behaviour
--------------
- MBAP header: 7 bytes; a protocol id other than 0, or a length field outside 2..265, cannot be
  resynchronised: that connection is closed (and logged) once the requests before it in the stream
  are answered; other connections are not affected. 265 is the unit id plus the longest PDU a
  supported request can describe (function 23 writing 127 registers, a byte count of 254), so a
  request that is merely over its function's quantity limit (e.g. function 16 with 124 registers,
  length 255) is framed and answered with exception 03 rather than dropped.
- Requests on one connection are handled one after another and answered in order, however many are
  pipelined before the first reply. A half frame that is not completed within `frame_timeout` seconds
  closes that connection (the next request is never glued onto it).
- Fairness: all connections share one budget per step period (`requests_per_step` requests, and at
  most `serve_share` of the period's wall time spent answering). Connections with complete requests
  wait in a round-robin queue; each turn of the event loop answers a few requests of each in turn. A
  connection that was idle goes before the ones with a backlog, and a tenth of the budget is kept for
  such connections, so a client polling one request at a time is answered at once however many others
  flood the server; the
  simulation runner gets the loop between turns. A connection with a backlog is not read further
  (TCP pushes back on its sender) until its backlog is answered. The simulation comes first: while it
  runs late (`behind()`: on a loaded machine the process may not get the CPU it needs), the budget is
  halved each period (down to 1/16), and it grows back by a quarter per period once steps are on time.
- Unit id: the server answers its `unit_id`, and 0 and 255 (which the TCP implementation guide uses for
  "this device"). Any other unit id gets exception 0B (gateway target device failed to respond).
- Exceptions: the response's function code is the request's with the high bit set. An unknown function
  gets 01 (so does every write function with `read_only`); a quantity of 0 or above the limit (2000
  bits, 125 registers to read; 1968 bits, 123 registers to write; 125/121 for function 23), a byte
  count that does not match the quantity, or a PDU of the wrong length gets 03; an address range that
  leaves the map or touches a gap gets 02 (reads across gaps read 0 with `gaps_zero`; so does a write
  that covers only part of a 32-bit value); a value outside the signal's range gets 03 and changes
  nothing (a multi-register write is all or nothing); a write while the simulation is faulted gets 04.
- An accepted write shows at once when its coils or holding registers are read back (function 23
  writes, then reads); the twin applies it at the next step.

Who may connect
---------------
`allow` (networks): a connection from any other address is closed at once and logged. `max_connections`:
one more is refused (closed at once, logged); the ones already connected keep being served.
`idle_timeout`: a connection with no complete request for that long is closed (logged). TLS
(`start(..., ssl=context)`, built by `tls_context`): TLS 1.2 or later, client certificates required
and checked against the CA; a client without one, or speaking plain Modbus/TCP, fails the handshake
and is dropped.
"""
from __future__ import annotations

import asyncio
import ipaddress
import socket
import ssl
import struct
import time
from collections import deque
from collections.abc import Callable, Iterable

from twin.core.defaults import DEFAULT_STEP

from .log import log as _log
from .pdu import (GATEWAY_TARGET_FAILED, ILLEGAL_DATA_ADDRESS, ILLEGAL_DATA_VALUE, ILLEGAL_FUNCTION,  # noqa: F401
                  SERVER_DEVICE_FAILURE, WRITE_FUNCTIONS, Backend, Deferred, DeviceIdentity, Images, PduHandler,
                  PollHold)
from .protocol import DEFAULT_PORT, MAX_CONNECTIONS, REQUESTS_PER_STEP, TLS_PORT  # noqa: F401
from .register_map import POLL_HOLD, RegisterMap

MAX_LENGTH = 1 + 10 + 2 * 127  # MBAP length: unit id + function 23 writing 127 registers (byte count 254)
SERVE_SHARE = 0.5  # at most this share of a step period's wall time goes to answering requests
MIN_SCALE = 1 / 16  # however late the simulation, a period still answers this share of the budget
TURN_SECONDS = 0.002  # one turn of answering gives the loop back after this long
QUANTUM = 32  # requests of one connection answered in a row before the next connection's turn
READ_BACKLOG = 16384  # bytes buffered per connection before it is no longer read

_HDR = struct.Struct(">HHHB")


def tls_context(cert: str, key: str, ca: str) -> ssl.SSLContext:
    """A server context per the Modbus/TCP Security specification: TLS 1.2 or later, mutual
    authentication (the client's certificate is required and must chain to `ca`)."""
    ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
    ctx.minimum_version = ssl.TLSVersion.TLSv1_2
    ctx.load_cert_chain(cert, key)
    ctx.load_verify_locations(ca)
    ctx.verify_mode = ssl.CERT_REQUIRED
    return ctx


def parse_networks(text: str | Iterable[str]) -> tuple[ipaddress.IPv4Network | ipaddress.IPv6Network, ...]:
    """`127.0.0.1,10.0.0.0/8` -> networks (a bare address is a /32 or /128). ValueError names the bad one."""
    items = text.split(",") if isinstance(text, str) else list(text)
    out = []
    for item in items:
        item = item.strip()
        if not item:
            continue
        try:
            out.append(ipaddress.ip_network(item, strict=False))
        except ValueError:
            raise ValueError(f"{item!r} is not an address or a network (CIDR, e.g. 192.168.0.0/24)") from None
    if not out:
        raise ValueError("no address or network given")
    return tuple(out)


class ModbusServer:
    """Serve `rmap` from `backend` over Modbus/TCP (see the module docstring)."""

    def __init__(self, rmap: RegisterMap, backend: Backend, *, unit_id: int = 1, frame_timeout: float = 1.0,
                 requests_per_step: int = REQUESTS_PER_STEP, step_period: float = DEFAULT_STEP,
                 serve_share: float = SERVE_SHARE, max_connections: int = MAX_CONNECTIONS,
                 idle_timeout: float | None = None, allow: Iterable | None = None, read_only: bool = False,
                 gaps_zero: bool = False, identity: DeviceIdentity | None = None,
                 on_request: Callable[[str, bool], None] | None = None, behind: Callable[[], bool] | None = None,
                 log: Callable[[str], None] = _log, clock: Callable[[], float] = time.perf_counter,
                 poll_hold: float = POLL_HOLD):
        self.map, self.backend, self.unit_id = rmap, backend, unit_id
        self._hold_steps = getattr(backend, "hold_steps", None)  # optional (`Backend`)
        self._run_steps = getattr(backend, "run_steps", None)
        self.units = {unit_id, 0, 255}
        self.pdus = PduHandler(rmap, backend, read_only=read_only, gaps_zero=gaps_zero, identity=identity)
        self.route: Callable[[int], PduHandler | None] | None = None  # other unit ids: another device (a profile)
        self.frame_timeout = frame_timeout
        self.requests_per_step, self.step_period, self.serve_share = requests_per_step, step_period, serve_share
        self.max_connections, self.idle_timeout = max_connections, idle_timeout
        self.allow = tuple(allow) if allow is not None else None
        self.on_request = on_request
        self.behind = behind  # the simulation is late: answer less until it has caught up
        self.scale = 1.0  # the share of the budget in force (halved per late period, regrown when on time)
        self.log, self.clock, self.poll_hold = log, clock, poll_hold
        self.on_event: Callable[..., None] | None = None  # `twin.observe.events.Events.emit`: clients come and go
        self.connections: set[_Connection] = set()
        self._servers: list[asyncio.base_events.Server] = []
        self.refused = 0  # connections refused (allow list, limit)
        # the fair share: connections with complete requests, and this step period's budget
        self._fresh: deque[_Connection] = deque()  # were idle: answered first
        self._backlog: deque[_Connection] = deque()
        self._scheduled: asyncio.Handle | None = None
        self._window, self._used, self._busy = 0.0, 0, 0.0
        self._sweeper: asyncio.TimerHandle | None = None

    @property
    def requests(self) -> int:
        return self.pdus.requests

    async def start(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT, *, ssl: ssl.SSLContext | None = None) -> tuple[str, int]:
        """Listen on host:port (plain Modbus/TCP, or Modbus/TCP Security with `ssl`); may be called for both."""
        loop = asyncio.get_running_loop()
        kw = {"ssl": ssl, "ssl_handshake_timeout": max(1.0, 5 * self.frame_timeout)} if ssl is not None else {}
        server = await loop.create_server(lambda: _Connection(self, tls=ssl is not None), host, port,
                                          reuse_address=True, **kw)
        self._servers.append(server)
        if self.idle_timeout and self._sweeper is None:
            self._sweep()
        return server.sockets[0].getsockname()[:2]

    async def close(self) -> None:
        if self._sweeper is not None:
            self._sweeper.cancel()
            self._sweeper = None
        for server in self._servers:
            server.close()
        for conn in list(self.connections):
            conn.close("server stopping")
        for server in self._servers:
            await server.wait_closed()
        self._servers = []

    # -- who may connect -----------------------------------------------------------------------------
    def admit(self, conn: "_Connection") -> str:
        """'' to accept the connection, or why it is refused."""
        if self.allow is not None:
            try:
                addr = ipaddress.ip_address(conn.address)
            except ValueError:
                return f"address {conn.address!r} not understood"
            if addr.version == 6 and addr.ipv4_mapped is not None:
                addr = addr.ipv4_mapped
            if not any(addr in net for net in self.allow):
                return "not in the allowed networks (--allow)"
        if len(self.connections) >= self.max_connections:
            self._reap_closed()
        if len(self.connections) >= self.max_connections:
            return f"{len(self.connections)} connections already, the limit (--max-connections)"
        return ""

    def _reap_closed(self) -> None:
        """At the limit: forget connections whose client has already closed (its end of file waits unread
        behind the accept; a harness that connects and closes in a tight loop must not hit the limit)."""
        for conn in list(self.connections):
            sock = conn.transport.get_extra_info("socket") if conn.transport is not None else None
            if sock is None:
                continue
            try:
                with socket.fromfd(sock.fileno(), sock.family, sock.type) as peek:  # a dup: asyncio's has no recv
                    gone = peek.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
            except (BlockingIOError, InterruptedError):
                gone = False
            except OSError:
                gone = True
            if gone:
                self.connections.discard(conn)
                conn.close("closed by the client")

    def _sweep(self) -> None:
        """Close connections idle longer than `idle_timeout`; runs every quarter of it (at most 1 s)."""
        loop = asyncio.get_running_loop()
        now = loop.time()
        for conn in list(self.connections):
            if now - conn.last_request >= self.idle_timeout and not conn.closed:
                conn.close(f"idle for {self.idle_timeout:g} s (--idle-timeout)")
        self._sweeper = loop.call_later(min(1.0, self.idle_timeout / 4), self._sweep)

    # -- requests -----------------------------------------------------------------------------------
    def handle(self, unit: int, pdu: bytes, hold: PollHold | None = None, read_only: bool = False) -> bytes:
        """One request PDU -> its response PDU (`hold`: the connection's poll, see `pdu.PollHold`; `read_only`:
        the connection may only read, its certificate's role says so: a write function gets exception 01)."""
        if read_only and pdu[:1] and pdu[0] in WRITE_FUNCTIONS:
            self.pdus.requests += 1
            self.pdus.refused_writes += 1
            return bytes((pdu[0] | 0x80, ILLEGAL_FUNCTION))
        if unit not in self.units:
            other = self.route(unit) if self.route is not None else None
            if other is not None:
                return other.handle(pdu)
            self.pdus.requests += 1
            return bytes((pdu[0] | 0x80, GATEWAY_TARGET_FAILED))
        return self.pdus.handle(pdu, hold)

    # -- the fair share ------------------------------------------------------------------------------
    def want_turn(self, conn: "_Connection", fresh: bool) -> None:
        idle = self._scheduled is None and not self._fresh and not self._backlog
        (self._fresh if fresh else self._backlog).append(conn)
        conn.queued = True
        if fresh and idle and conn.one_request():  # a client asking one thing at a time (a PLC's scan), and
            self._serve()  # nobody else waiting: answered now, not a turn of the loop later
            return
        loop = asyncio.get_running_loop()
        if self._scheduled is None:
            self._scheduled = loop.call_soon(self._serve)
        elif fresh and isinstance(self._scheduled, asyncio.TimerHandle):  # waiting for the next period:
            self._scheduled.cancel()  # an idle client's request may use the reserve now
            self._scheduled = loop.call_soon(self._serve)

    def _serve(self) -> None:
        """One turn: answer connections round-robin, within this step period's budget. Connections with a
        backlog use the budget less a reserve (a tenth) kept for connections that were idle, so a client
        asking one request at a time is answered at once however busy the others keep the server. Lockstep
        steps asked for in the turn run at its end, once the requests are answered and counted (the watchdog
        fed), without a turn of the loop in between (`Backend.hold_steps`, `run_steps`)."""
        self._scheduled = None
        hold = self._hold_steps
        if hold is None:
            self._turn()
            return
        hold()
        try:
            self._turn()
        finally:
            self._run_steps()

    def _limit(self, now: float) -> int:
        """This step period's budget of requests (a new period starts the count again, scaled to how late the
        simulation runs)."""
        if now >= self._window + self.step_period:
            self._window, self._used, self._busy = now, 0, 0.0
            if self.behind is not None:
                self.scale = max(MIN_SCALE, self.scale * 0.5) if self.behind() else min(1.0, self.scale * 1.25)
        return max(2, int(self.requests_per_step * self.scale))

    def answer_lone(self, conn: "_Connection", data: bytes) -> bool:
        """The common case, answered at once: `data` is one whole request from an idle connection while nobody
        else waits and the budget has room (a PLC's scan). What a turn would do for it, without the turn's
        round-robin; False (nothing done) for anything else, which takes the general path."""
        if self._scheduled is not None or self._fresh or self._backlog or len(data) < 7:
            return False
        tid, pid, length, unit = _HDR.unpack_from(data, 0)
        if pid != 0 or not 2 <= length <= MAX_LENGTH or len(data) != 6 + length:
            return False
        clock = self.clock
        t0 = clock()
        if self._used >= self._limit(t0):
            return False
        hold = self._hold_steps
        if hold is not None:
            hold()
        try:
            conn.answer_one(tid, unit, data[7:])
            self._used += 1
            if self.on_request is not None:
                self.on_request(conn.peer, conn.clock_only)
            self._busy += clock() - t0
        finally:
            if hold is not None:
                self._run_steps()
        return True

    def _turn(self) -> None:
        clock = self.clock
        now = clock()
        limit = self._limit(now)
        backlog_limit = limit - max(1, limit // 10)
        share = self.serve_share * self.scale * self.step_period
        t0 = now
        fresh, backlog = self._fresh, self._backlog
        pass_left = quantum = 0
        while (fresh or backlog) and clock() - t0 < TURN_SECONDS:
            if fresh:
                room = limit - self._used
            else:
                room = min(backlog_limit - self._used, 1 << 30 if self._busy + clock() - t0 < share else 0)
            if room <= 0:
                break
            if pass_left == 0:  # a pass over the waiting connections: the budget left, split evenly
                pass_left = len(fresh) + len(backlog)
                quantum = max(1, min(QUANTUM, room // pass_left))
            pass_left -= 1
            conn = fresh.popleft() if fresh else backlog.popleft()
            conn.queued = False
            if conn.closed or conn.writing_paused:
                continue
            n = conn.answer(min(quantum, room))
            self._used += n
            if n and self.on_request is not None:
                self.on_request(conn.peer, conn.clock_only)
            if conn.has_request() and not conn.closed and not conn.writing_paused:
                backlog.append(conn)
                conn.queued = True
        self._busy += clock() - t0
        if fresh or backlog:
            loop = asyncio.get_running_loop()
            more_fresh = fresh and self._used < limit
            more_backlog = backlog and self._used < backlog_limit and self._busy < share
            if more_fresh or more_backlog:
                self._scheduled = loop.call_soon(self._serve)
            else:
                delay = max(0.0, self._window + self.step_period - clock())
                self._scheduled = loop.call_later(delay, self._serve)


class _Connection(asyncio.Protocol):
    """One client: MBAP framing, requests answered in order when the scheduler gives it a turn, a
    timeout on half frames. Reading stops (so TCP pushes back on the client) while the client does not
    read its answers (`pause_writing`) and while its backlog is large."""

    def __init__(self, server: ModbusServer, tls: bool = False):
        self.server, self.tls = server, tls
        self.read_only = False  # Modbus/TCP Security: the client certificate's role grants reads only (twin.frontends.modbus.roles)
        self.buf = bytearray()
        self.transport: asyncio.Transport | None = None
        self.loop: asyncio.AbstractEventLoop | None = None  # the server's (asking asyncio for it costs a system call)
        self.timer: asyncio.TimerHandle | None = None
        self.writing_paused = False
        self.reading_paused = False
        self.queued = False
        self.clock_only = False
        self.waiting = False  # a deferred answer (function 23 with sim.advance in lockstep) is pending
        self.closed = False
        self.admitted = False
        self.peer = "?"
        self.address = ""
        self.reason = ""
        self.last_request = 0.0
        self.hold = PollHold(server.clock, server.poll_hold)  # this client's poll: one step's outputs

    def connection_made(self, transport) -> None:
        self.transport = transport
        self.loop = loop = asyncio.get_running_loop()
        self.last_request = loop.time()
        sock = transport.get_extra_info("socket")
        if sock is not None:
            for level, opt, value in ((socket.IPPROTO_TCP, socket.TCP_NODELAY, 1),
                                      (socket.SOL_SOCKET, socket.SO_KEEPALIVE, 1),
                                      (socket.IPPROTO_TCP, getattr(socket, "TCP_KEEPIDLE", None), 10),
                                      (socket.IPPROTO_TCP, getattr(socket, "TCP_KEEPINTVL", None), 5),
                                      (socket.IPPROTO_TCP, getattr(socket, "TCP_KEEPCNT", None), 3)):
                if opt is not None:
                    try:
                        sock.setsockopt(level, opt, value)
                    except OSError:
                        pass
        peer = transport.get_extra_info("peername")
        self.address = str(peer[0]) if peer else ""
        self.peer = (f"[{peer[0]}]:{peer[1]}" if ":" in str(peer[0]) else f"{peer[0]}:{peer[1]}") if peer else "?"
        server = self.server
        why = server.admit(self)
        if why:
            server.refused += 1
            self.closed = True
            server.log(f"client {self.peer} refused: {why}")
            if server.on_event is not None:
                server.on_event("client_refused", front_end="modbus", peer=self.peer, reason=why)
            transport.abort()
            return
        self.admitted = True
        server.connections.add(self)
        extra, tls = "", {}
        if self.tls:
            cert = transport.get_extra_info("peercert") or {}
            subject = dict(x[0] for x in cert.get("subject", ()) if x)
            access = self._access(transport)
            self.read_only = access.read_only
            extra = f" over TLS as {subject.get('commonName', '?')!r} ({access.why})"
            tls = {"tls_subject": subject.get("commonName", ""), "role": access.role,
                   "access": "read" if access.read_only else "read/write"}
        server.log(f"client {self.peer} connected{extra} ({len(server.connections)} connected)")
        if server.on_event is not None:
            server.on_event("client_connected", front_end="modbus", peer=self.peer, connected=len(server.connections), **tls)

    def _access(self, transport):
        """What the client certificate's role grants (`twin.frontends.modbus.roles`); a certificate whose role cannot be
        read is granted reads only."""
        from .roles import Access, access_for, role_of

        ssl_object = transport.get_extra_info("ssl_object")
        try:
            role = role_of(ssl_object.getpeercert(binary_form=True) if ssl_object is not None else None)
        except Exception as exc:  # noqa: BLE001 - a certificate the TLS layer took but we cannot read: least rights
            return Access("?", True, f"its role cannot be read ({type(exc).__name__}): read only")
        return access_for(role, self.server.pdus.read_only)

    def connection_lost(self, exc) -> None:
        self.closed = True
        self._stop_timer()
        if not self.admitted:
            return
        self.server.connections.discard(self)
        reason = self.reason or (f"error: {exc}" if exc else "closed by the client")
        self.server.log(f"client {self.peer} disconnected ({reason}; {len(self.server.connections)} connected)")
        if self.server.on_event is not None:
            self.server.on_event("client_gone", front_end="modbus", peer=self.peer, reason=reason,
                                 connected=len(self.server.connections))

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
        self.loop.call_later(self.server.frame_timeout, self.transport.abort)

    def pause_writing(self) -> None:  # the client does not read its answers: stop reading its requests
        self.writing_paused = True
        self._stop_timer()  # it cannot complete a half frame while we do not read
        self._pause_reading()

    def resume_writing(self) -> None:
        self.writing_paused = False
        if self.closed:
            return
        if self.has_request():
            if not self.queued:
                self.server.want_turn(self, fresh=False)
        else:
            self._resume_reading()

    def _pause_reading(self) -> None:
        if not self.reading_paused and not self.closed:
            self.reading_paused = True
            self.transport.pause_reading()

    def _resume_reading(self) -> None:
        if self.reading_paused and not self.closed:
            self.reading_paused = False
            self.transport.resume_reading()

    def data_received(self, data: bytes) -> None:
        if self.closed:
            return
        fresh = not self.buf
        if fresh and not self.waiting and not self.queued and not self.writing_paused and self.server.answer_lone(self, data):
            return
        self.buf += data
        if self.waiting:  # a deferred answer first: keep what comes, answer it afterwards
            if len(self.buf) >= READ_BACKLOG:
                self._pause_reading()
            return
        if self.has_request():
            self._stop_timer()
            if not self.queued and not self.writing_paused:
                self.server.want_turn(self, fresh=fresh)
            if len(self.buf) >= READ_BACKLOG:
                self._pause_reading()
        elif self.timer is None:
            self.timer = self.loop.call_later(self.server.frame_timeout, self._stalled)

    def has_request(self) -> bool:
        """A complete frame (or a header that cannot be framed, to be refused) waits at the front."""
        buf = self.buf
        if len(buf) < 7 or self.waiting:
            return False
        _, pid, length, _ = _HDR.unpack_from(buf, 0)
        return pid != 0 or not 2 <= length <= MAX_LENGTH or len(buf) >= 6 + length

    def one_request(self) -> bool:
        """The buffer holds exactly one complete request."""
        buf = self.buf
        return len(buf) >= 7 and len(buf) == 6 + _HDR.unpack_from(buf, 0)[2]

    def _respond(self, tid: int, unit: int, request: bytes) -> bytes | None:
        """The answer's frame to one request, or None when it waits for lockstep steps (`_finish` sends it)."""
        response = self.server.handle(unit, request, self.hold, self.read_only)
        if isinstance(response, Deferred):
            self.waiting = True
            self.server.backend.when_stepped(lambda: self._finish(tid, unit, response))
            return None
        return _HDR.pack(tid, 0, len(response) + 1, unit) + response

    def answer_one(self, tid: int, unit: int, request: bytes) -> None:
        """A lone request (`ModbusServer.answer_lone`), the buffer empty: answered, or waiting for its steps."""
        self.clock_only = self.server.pdus.clock_only(request)
        frame = self._respond(tid, unit, request)
        self.last_request = self.loop.time()
        if frame is not None:
            self.transport.write(frame)  # may call pause_writing

    def answer(self, limit: int) -> int:
        """Answer up to `limit` complete requests at the front of the buffer; returns how many."""
        buf = self.buf
        out = []
        pos, n = 0, len(buf)
        count = 0
        bad = ""
        clock = self.server.pdus.clock_only
        self.clock_only = True  # every request answered this turn only touched sim.advance (lockstep time)
        while count < limit and n - pos >= 7:
            tid, pid, length, unit = _HDR.unpack_from(buf, pos)
            if pid != 0:
                bad = f"protocol id {pid}, not 0 (Modbus)"
                break
            if not 2 <= length <= MAX_LENGTH:
                bad = f"frame length field {length} outside 2..{MAX_LENGTH}"
                break
            if n - pos < 6 + length:
                break
            request = bytes(memoryview(buf)[pos + 7:pos + 6 + length])
            if self.clock_only and not clock(request):
                self.clock_only = False
            frame = self._respond(tid, unit, request)
            pos += 6 + length
            count += 1
            if frame is None:  # answered once the lockstep steps are done; later ones wait
                break
            out.append(frame)
        if pos:
            del buf[:pos]
            self.last_request = self.loop.time()
        if out:
            self.transport.write(b"".join(out))  # may call pause_writing
        if bad:
            self._close_after_answers(bad)
            return count
        if len(buf) < READ_BACKLOG and not self.writing_paused:
            self._resume_reading()
        if buf and not self.has_request() and self.timer is None and not self.writing_paused:
            self.timer = self.loop.call_later(self.server.frame_timeout, self._stalled)
        return count

    def _finish(self, tid: int, unit: int, deferred: Deferred) -> None:
        """The steps a function 23 asked for are done: its answer (the read after them), then go on."""
        self.waiting = False
        if self.closed:
            return
        response = deferred.finish()
        self.transport.write(_HDR.pack(tid, 0, len(response) + 1, unit) + response)
        if self.has_request():
            if not self.queued and not self.writing_paused:
                self.server.want_turn(self, fresh=False)
        elif self.buf and self.timer is None:
            self.timer = self.loop.call_later(self.server.frame_timeout, self._stalled)
        if not self.writing_paused and len(self.buf) < READ_BACKLOG:
            self._resume_reading()

    def _stop_timer(self) -> None:
        if self.timer is not None:
            self.timer.cancel()
            self.timer = None

    def _stalled(self) -> None:
        self.timer = None
        if self.has_request() or self.closed or self.waiting:
            return
        self.close(f"half a frame ({len(self.buf)} bytes) not completed within {self.server.frame_timeout:g} s")
