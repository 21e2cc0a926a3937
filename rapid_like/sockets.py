"""RAPID socket messaging over real TCP: SocketCreate, SocketConnect, SocketBind, SocketListen,
SocketAccept, SocketSend, SocketReceive, SocketClose and SocketGetStatus, as a mixin of the evaluator.

Sockets are the operating system's, non-blocking. An instruction that has to wait for the peer
(connect, accept, receive) checks its socket, and when nothing is there yet waits up to
`io_wall_wait` seconds of wall time for the peer (10 ms offline; a station sets 0 so the simulation
never stalls), then lets 10 ms of simulated time pass (`IO_POLL`). So offline, simulated time keeps
pace with the wall clock while a program waits on a socket (`--max-time 20` gives a client about 20
s), and a peer on the same machine (a test client on loopback, a vision system's simulator) is
served promptly. \\Time (60 s by default, WAIT_MAX for
ever) is counted in simulated time; when it runs out the error is ERR_SOCK_TIMEOUT. A peer that
closes the connection, or one that refuses it, is ERR_SOCK_CLOSED.

SocketReceive \\Str takes what has arrived, at most 80 characters; \\RawData at most 1024 bytes and
\\Data at most the array's size; \\ReadNoOfBytes waits for exactly that many bytes.
"""
from __future__ import annotations

import errno
import select
import socket

from . import builtins as B
from .runtime import Wait, to_ns
from .strings import RAWBYTES_MAX
from .values import STRING_MAX, Opaque, fmt_num

IO_POLL = 0.01  # simulated seconds between two looks at a waiting socket
DEFAULT_SOCKET_TIME = 60.0


class SocketState:
    __slots__ = ("sock", "status", "address")

    def __init__(self) -> None:
        self.sock: socket.socket | None = None
        self.status = "SOCKET_CLOSED"
        self.address = ""


def _status_value(name: str) -> float:
    return float(B.predefined_data()[name.lower()][1])  # type: ignore[arg-type]


class SocketsMixin:
    io_wall_wait = 0.01

    def _socket(self, ref, s, create: bool = False) -> SocketState:
        dev: Opaque = ref.get() if hasattr(ref, "get") else ref
        if not isinstance(dev.state, SocketState):
            dev.state = SocketState()
        return dev.state

    def _open(self, st: SocketState, s, what: str) -> socket.socket:
        if st.sock is None or st.status == "SOCKET_CLOSED":
            raise self.fail(f"{what}: the socket is closed (SocketCreate it first)", s.span, "ERR_SOCK_CLOSED")
        return st.sock

    def _io_wait(self, st_sock: socket.socket, s, what: str, deadline: int | None, write: bool = False):
        """Wait (a generator) until the socket is readable (writable), or raise ERR_SOCK_TIMEOUT. Each
        look waits up to `io_wall_wait` s of wall time for the peer, then lets 10 ms of simulated time
        pass: offline, simulated time keeps pace with the wall clock while a program waits on a socket."""
        while True:
            r, w, _ = select.select([] if write else [st_sock], [st_sock] if write else [], [], 0)
            if r or w:
                return
            if deadline is not None and self.now >= deadline:
                raise self.fail(f"{what}: no answer within \\Time", s.span, "ERR_SOCK_TIMEOUT")
            if self.io_wall_wait:  # the peer has wall time: simulated time keeps pace with it while waiting
                r, w, _ = select.select([] if write else [st_sock], [st_sock] if write else [], [], self.io_wall_wait)
                if r or w:
                    return
            at = self.now + to_ns(IO_POLL)
            if deadline is not None:
                at = min(at, deadline)
            yield from self.pause(Wait("io", at, what, s.span))

    def _deadline(self, arg) -> int | None:
        t = arg("time", DEFAULT_SOCKET_TIME)
        return None if t >= B.WAIT_MAX else self.now + to_ns(t)

    def i_socketcreate(self, s, arg, text, bound):
        st = self._socket(arg("socket"), s)
        if st.sock is not None and st.status != "SOCKET_CLOSED":
            st.sock.close()
        kind = socket.SOCK_DGRAM if arg("udp") else socket.SOCK_STREAM
        st.sock = socket.socket(socket.AF_INET, kind)
        st.sock.setblocking(False)
        st.status = "SOCKET_CREATED"
        self.sockets.append(st)
        yield from ()

    def i_socketconnect(self, s, arg, text, bound):
        st = self._socket(arg("socket"), s)
        sock = self._open(st, s, "SocketConnect")
        address, port = arg("address"), int(arg("port"))
        what = f"SocketConnect {address}:{port}"
        err = sock.connect_ex((address, port))
        if err not in (0, 115, 36, 10035, 11):  # EINPROGRESS / EWOULDBLOCK variants
            raise self.fail(f"{what}: {errno.errorcode.get(err, err)}", s.span, "ERR_SOCK_CLOSED")
        yield from self._io_wait(sock, s, what, self._deadline(arg), write=True)
        err = sock.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR)
        if err:
            raise self.fail(f"{what}: the connection was refused", s.span, "ERR_SOCK_CLOSED")
        st.status, st.address = "SOCKET_CONNECTED", address
        self.emit({"type": "socket", "event": "connected", "address": address, "port": port})

    def i_socketbind(self, s, arg, text, bound):
        st = self._socket(arg("socket"), s)
        sock = self._open(st, s, "SocketBind")
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((arg("localaddress"), int(arg("localport"))))
        except OSError as exc:
            raise self.fail(f"SocketBind {arg('localaddress')}:{fmt_num(arg('localport'))}: {exc.strerror}", s.span,
                            "ERR_SOCK_ADDR_INUSE") from None
        st.status = "SOCKET_BOUND"
        yield from ()

    def i_socketlisten(self, s, arg, text, bound):
        st = self._socket(arg("socket"), s)
        self._open(st, s, "SocketListen").listen(4)
        st.status = "SOCKET_LISTENING"
        yield from ()

    def i_socketaccept(self, s, arg, text, bound):
        st = self._socket(arg("socket"), s)
        sock = self._open(st, s, "SocketAccept")
        yield from self._io_wait(sock, s, "SocketAccept", self._deadline(arg))
        conn, (host, port) = sock.accept()
        conn.setblocking(False)
        client = self._socket(arg("clientsocket"), s)
        if client.sock is not None and client.status != "SOCKET_CLOSED":
            client.sock.close()
        client.sock, client.status, client.address = conn, "SOCKET_CONNECTED", host
        self.sockets.append(client)
        address = arg("clientaddress")
        if address is not None:
            address.set(host)
        self.emit({"type": "socket", "event": "accepted", "address": host})

    def i_socketsend(self, s, arg, text, bound):
        st = self._socket(arg("socket"), s)
        sock = self._open(st, s, "SocketSend")
        if arg("str") is not None:
            data = arg("str").encode("latin-1")
        elif arg("rawdata") is not None:
            data = bytes(arg("rawdata").state.data)
        elif arg("data") is not None:
            data = bytes(int(b) & 0xFF for b in arg("data"))
        else:
            raise self.fail("SocketSend needs \\Str, \\RawData or \\Data", s.span, "ERR_ARGVALERR")
        count = arg("noofbytes")
        if count is not None:
            data = data[:int(count)]
        sock.setblocking(True)
        try:
            sock.settimeout(DEFAULT_SOCKET_TIME)
            sock.sendall(data)
        except OSError as exc:
            st.status = "SOCKET_CLOSED"
            raise self.fail(f"SocketSend: {exc.strerror or exc}", s.span, "ERR_SOCK_CLOSED") from None
        finally:
            sock.setblocking(False)
        yield from ()

    def i_socketreceive(self, s, arg, text, bound):
        st = self._socket(arg("socket"), s)
        sock = self._open(st, s, "SocketReceive")
        target_str, target_raw, target_data = arg("str"), arg("rawdata"), arg("data")
        limit = STRING_MAX if target_str is not None else RAWBYTES_MAX
        if target_data is not None:
            limit = len(target_data.get())
        want = arg("readnoofbytes")
        if want is not None and not 1 <= want <= limit:
            raise self.fail(f"SocketReceive \\ReadNoOfBytes must be 1 to {limit}, not {fmt_num(want)}", s.span,
                            "ERR_OUTOFBND")
        deadline = self._deadline(arg)
        data = b""
        while True:
            yield from self._io_wait(sock, s, "SocketReceive", deadline)
            try:
                chunk = sock.recv((int(want) - len(data)) if want is not None else limit)
            except BlockingIOError:
                continue
            except OSError as exc:
                st.status = "SOCKET_CLOSED"
                raise self.fail(f"SocketReceive: {exc.strerror or exc}", s.span, "ERR_SOCK_CLOSED") from None
            if not chunk:
                st.status = "SOCKET_CLOSED"
                raise self.fail("SocketReceive: the peer closed the connection", s.span, "ERR_SOCK_CLOSED")
            data += chunk
            if want is None or len(data) >= want:
                break
        if target_str is not None:
            target_str.set(data.decode("latin-1"))
        elif target_raw is not None:
            target_raw.get().state.data = bytearray(data)
        elif target_data is not None:
            arr = target_data.get()
            for i, b in enumerate(data):
                arr[i] = float(b)
        count = arg("norecbytes")
        if count is not None:
            count.set(float(len(data)))
        self.changes += 1

    def i_socketclose(self, s, arg, text, bound):
        st = self._socket(arg("socket"), s)
        if st.sock is not None:
            st.sock.close()
        st.sock, st.status = None, "SOCKET_CLOSED"
        yield from ()

    def f_socketpeek(self, e, arg, bound):
        """SocketPeek: how many bytes wait to be received on the socket (0 when none, or closed)."""
        dev = arg("socket")
        st = dev.state if isinstance(dev.state, SocketState) else None
        self.changes += 1  # depends on the peer
        if st is None or st.sock is None or st.status == "SOCKET_CLOSED":
            raise self.fail("SocketPeek: the socket is closed (SocketCreate it first)", e.span, "ERR_SOCK_CLOSED")
        try:
            return float(len(st.sock.recv(RAWBYTES_MAX, socket.MSG_PEEK)))
        except BlockingIOError:
            return 0.0
        except OSError:
            return 0.0

    def f_socketgetstatus(self, e, arg, bound):
        dev = arg("socket")
        st = dev.state if isinstance(dev.state, SocketState) else None
        return _status_value(st.status if st else "SOCKET_CLOSED")

    def close_sockets(self) -> None:
        for st in self.sockets:
            if st.sock is not None:
                st.sock.close()
            st.sock, st.status = None, "SOCKET_CLOSED"
        self.sockets.clear()
