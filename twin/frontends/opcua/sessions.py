"""OPC UA clients as they come and go: `client_connected` and `client_gone` (the events of `twin serve --events`).

A client is an activated session. asyncua's public API says who a session's user is (`UserManager.get_user`,
a new `SessionUser` per activation) but not from where it came nor when it ends; asyncua says both in its
log, through the standard `logging` module, with the session's peer address as an argument of the record.
`SessionWatcher` is a logging handler on those loggers that reads the records' arguments (never their text),
matching the few messages below by their format string:

- connected: the session was activated (its peer, its user: account name and whether it may write);
- gone: the session was closed (`closed by the client`: CloseSession), its connection was lost first
  (`connection lost`), or it timed out (`timed out`), whichever comes first; a session that asyncua keeps
  for its subscriptions after the connection is lost and that a client activates again is connected again.

If a later asyncua words these messages differently, no client event comes (tests/opcua/test_opcua_events.py
says so); nothing else depends on them.
"""
from __future__ import annotations

import logging
from collections.abc import Callable

ACTIVATED = "Activated internal session %s for user %s"  # asyncua.server.internal_session, INFO: (peer, user)
CLOSED = "close session %s"  # asyncua.server.internal_session, INFO: (peer,)
IDLE = "Session %s idle past %ss; closing"  # asyncua.server.internal_session, INFO: (peer, s)
LOST = "Lost connection from %s, %s"  # asyncua.server.binary_server_asyncio, INFO: (peer, error)
TIMED_OUT = "Session timed out after %ss of inactivity"  # asyncua.server.uaprocessor, WARNING: the close follows
LOGGERS = {"asyncua.server.internal_session": logging.INFO, "asyncua.server.binary_server_asyncio": logging.INFO,
           "asyncua.server.uaprocessor": logging.WARNING}

OnClient = Callable[..., None]  # on_client(kind, **fields): an event of `twin.observe.events`


def peer_text(peer) -> str:
    """HOST:PORT ([HOST]:PORT for IPv6), as the Modbus front end names its clients."""
    if isinstance(peer, (tuple, list)) and len(peer) >= 2:
        host = str(peer[0])
        return f"[{host}]:{peer[1]}" if ":" in host else f"{host}:{peer[1]}"
    return str(peer)


class SessionWatcher(logging.Handler):
    """Turns asyncua's session records into `on_client("client_connected" | "client_gone", ...)` calls."""

    def __init__(self, on_client: OnClient | None = None):
        """Without `on_client`, it still names each session's requests (`SessionUser.source`)."""
        super().__init__(logging.INFO)
        self.on_client = on_client or (lambda kind, **fields: None)
        self.active: dict[str, object] = {}  # peer -> the session's user (`_asyncua_roles.SessionUser`)
        self._why: dict[str, str] = {}  # peer -> why its session is about to close (a lost connection, a timeout)
        self._timing_out = False
        self.stopping = False  # the server stops: whatever ends now ends for that reason

    def install(self) -> None:
        for name, level in LOGGERS.items():
            lg = logging.getLogger(name)
            if self not in lg.handlers:
                lg.addHandler(self)
            if lg.getEffectiveLevel() > level:
                lg.setLevel(level)

    def uninstall(self) -> None:
        for name in LOGGERS:
            logging.getLogger(name).removeHandler(self)

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self._seen(record.msg, record.args if isinstance(record.args, tuple) else ())
        except Exception:  # noqa: BLE001 - a watcher's trouble must not reach asyncua (nor print a traceback)
            pass

    def _seen(self, msg, args: tuple) -> None:
        timing_out, self._timing_out = self._timing_out, False  # said just before the close it explains
        if msg == ACTIVATED and len(args) == 2:
            self._activated(peer_text(args[0]), args[1])
        elif msg == CLOSED and args:
            peer = peer_text(args[0])
            self._gone(peer, self._why.pop(peer, "timed out" if timing_out else "closed by the client"))
        elif msg == LOST and args:
            peer = peer_text(args[0])
            if peer in self.active:
                self._gone(peer, "connection lost")
        elif msg == IDLE and args:
            self._why[peer_text(args[0])] = "timed out"
        elif msg == TIMED_OUT:
            self._timing_out = True

    def _activated(self, peer: str, user) -> None:
        name = getattr(user, "name", None)
        read_only = bool(getattr(user, "read_only", False))
        try:
            user.peer = peer
            user.source = f"opcua {peer}" + (f" user {name!r}" if name else "")
        except AttributeError:  # not one of ours (asyncua's own internal session)
            return
        if peer in self.active:  # activated again (a new identity on the same session)
            self.active[peer] = user
            return
        self.active[peer] = user
        self.on_client("client_connected", front_end="opcua", peer=peer, connected=len(self.active), user=name,
                       access="read" if read_only else "read/write")

    def _gone(self, peer: str, reason: str) -> None:
        if self.active.pop(peer, None) is None:
            return
        self._why.pop(peer, None)
        if self.stopping:
            reason = "server stopped"
        self.on_client("client_gone", front_end="opcua", peer=peer, reason=reason, connected=len(self.active))
