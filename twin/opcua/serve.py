"""`twin serve STATION --opcua [PORT]`: the OPC UA options of `twin serve`, and starting the server on a cell.

    twin serve STATION --opcua [PORT]        OPC UA beside Modbus (PORT default 4840; 0 = any free port)
    twin serve STATION --opcua --no-modbus   OPC UA alone
    --opcua-host HOST                        address to bind (default: --host, i.e. loopback)
    --opcua-security none,sign,encrypt       endpoints offered (default: all three on loopback, else sign,encrypt)
    --opcua-cert FILE --opcua-key FILE       the server certificate (DER or PEM) and its private key (PEM)
    --opcua-cert-dir DIR                     where a generated certificate is kept (default
                                             $XDG_DATA_HOME/gripper-twin/opcua)
    --opcua-user NAME:PASSWORD               an account that may write and call Sim.Advance (repeatable)
    --opcua-reader NAME:PASSWORD             a read-only account (repeatable); with accounts, no anonymous sessions
"""
from __future__ import annotations

import argparse
import logging
from pathlib import Path

from twin.cli_args import tcp_port

from .security import POLICIES, Account, Security, SecurityError

DEFAULT_PORT = 4840


def _policies(text: str) -> tuple[str, ...]:
    names = tuple(p.strip().lower() for p in text.split(",") if p.strip())
    bad = [p for p in names if p not in POLICIES]
    if bad or not names:
        raise argparse.ArgumentTypeError(f"security policies are {', '.join(POLICIES)} (comma-separated), not {text!r}")
    return names


def _account(text: str) -> str:
    try:
        Account.parse(text)
    except SecurityError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    g = parser.add_argument_group("OPC UA", "serve the same cell on OPC UA (asyncua; see docs/opcua.md)")
    g.add_argument("--opcua", nargs="?", type=tcp_port, const=DEFAULT_PORT, default=None, metavar="PORT",
                   help=f"serve OPC UA too, on PORT (default {DEFAULT_PORT}; 0 = any free port, printed)")
    g.add_argument("--no-modbus", action="store_true", help="serve OPC UA only (needs --opcua)")
    g.add_argument("--opcua-host", default=None, help="address OPC UA binds (default: that of --host)")
    g.add_argument("--opcua-security", type=_policies, default=None, metavar="LIST",
                   help="endpoints: none, sign, encrypt (Basic256Sha256), comma-separated "
                        "(default: all three on loopback, sign,encrypt elsewhere)")
    g.add_argument("--opcua-cert", type=Path, default=None, metavar="FILE", help="server certificate (DER or PEM)")
    g.add_argument("--opcua-key", type=Path, default=None, metavar="FILE", help="its private key (PEM)")
    g.add_argument("--opcua-cert-dir", type=Path, default=None, metavar="DIR",
                   help="where the certificate generated on first start is kept")
    g.add_argument("--opcua-user", action="append", type=_account, default=[], metavar="NAME:PASSWORD",
                   help="an account that may read and write (repeatable)")
    g.add_argument("--opcua-reader", action="append", type=_account, default=[], metavar="NAME:PASSWORD",
                   help="a read-only account (repeatable)")


def security_from(args) -> Security:
    accounts = tuple(Account.parse(a) for a in args.opcua_user) + tuple(
        Account.parse(a, read_only=True) for a in args.opcua_reader)
    return Security(policies=args.opcua_security, cert=args.opcua_cert, key=args.opcua_key,
                    cert_dir=args.opcua_cert_dir, accounts=accounts)


def check_arguments(args) -> str | None:
    """What is wrong with the OPC UA options of `twin serve` (one line), or None. Checked before loading."""
    if getattr(args, "no_modbus", False) and getattr(args, "opcua", None) is None:
        return "--no-modbus leaves nothing to serve: add --opcua [PORT]"
    if getattr(args, "opcua", None) is None:
        return None
    if (args.opcua_cert is None) != (args.opcua_key is None):
        return "--opcua-cert and --opcua-key go together"
    try:
        import asyncua  # noqa: F401
    except ImportError:
        return "--opcua needs asyncua: pip install 'gripper-twin[opcua]'"
    return None


def options_from(args) -> dict | None:
    """`serve`'s keyword `opcua` from the parsed command line (None without --opcua)."""
    if getattr(args, "opcua", None) is None:
        return None
    return {"host": args.opcua_host or args.host, "port": args.opcua, "security": security_from(args),
            "watchdog": getattr(args, "watchdog", None)}


class OneLineLog(logging.Handler):
    """asyncua's log (and the OPC UA front end's) in the server's log, one line per record, no traceback:
    a client that sends what is not OPC UA costs one line naming what asyncua could not read, not a stack."""

    # said again, with the error, by the record that follows
    NOISE = ("Received an error message type", "Unsupported message type")
    SAID = {"Exception raised while processing message from client": "a client's message could not be processed "
                                                                      "(its connection is closed)"}

    def __init__(self, sink=None):
        """`sink(text, level)`: where the lines go (default the `twin.serve` logger of this process)."""
        super().__init__()
        self.sink = sink

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = record.getMessage()
        except Exception:  # noqa: BLE001 - a bad format argument must not reach asyncua
            text = str(record.msg)
        if text.startswith(self.NOISE):
            return
        text = self.SAID.get(text, text)
        exc = record.exc_info[1] if record.exc_info else None
        if exc is not None:
            why = str(exc).splitlines()[0] if str(exc) else ""
            text = f"{text}: {type(exc).__name__}" + (f": {why}" if why else "")
        level = min(record.levelno, logging.WARNING)
        if self.sink is not None:
            self.sink(f"OPC UA: {text}", level)
        else:
            logging.getLogger("twin.serve").log(level, f"OPC UA: {text}")


def route_opcua_log(sink=None) -> None:
    """Send the loggers of asyncua and of this front end through `OneLineLog` (once; `sink`: see there)."""
    for name in ("asyncua.server", "asyncua.common", "asyncua.crypto", "twin.opcua"):  # not a client's (asyncua.client)
        lg = logging.getLogger(name)
        if not any(isinstance(h, OneLineLog) for h in lg.handlers):
            lg.addHandler(OneLineLog(sink))
        lg.propagate = False
        if lg.level == logging.NOTSET:
            lg.setLevel(logging.WARNING)


class OpcUaFrontEnd:
    """OPC UA as a front end of a cell (the contract: `twin_app.cell`): `OpcUaFrontEnd.from_args(args)`. The server
    runs in a process of its own behind the front-end adapter (`twin.frontend_process`; its side:
    `twin.opcua.cell_link`)."""

    name = "opcua"

    def __init__(self, *, host: str = "127.0.0.1", port: int = DEFAULT_PORT, security: Security | None = None,
                 watchdog: float | None = None):
        """`watchdog`: the comm-loss watchdog's seconds (`twin serve --watchdog S`; 0: off; None: the
        station's), which every request of an OPC UA session feeds."""
        self.host, self.port, self.security, self.watchdog = host, port, security or Security(), watchdog
        self.process = None

    @classmethod
    def from_args(cls, args) -> "OpcUaFrontEnd | None":
        """The front end `twin serve --opcua ...` asks for, or None without --opcua."""
        options = options_from(args)
        return None if options is None else cls(**options)

    @property
    def requests(self) -> int:
        return 0 if self.process is None else self.process.requests

    async def start(self, cell) -> list[str]:
        """Raises OSError when the port cannot be bound, TwinError for bad security options."""
        from twin.frontend_process import FrontEndProcess

        watchdog = getattr(cell, "watchdog", None)
        if watchdog is not None:
            if self.watchdog is not None:
                cell.set_watchdog_timeout(self.watchdog)
            if hasattr(cell, "log"):
                watchdog.log = lambda text: cell.log(text, logging.WARNING)
        timeout = (watchdog.timeout or 0) if watchdog is not None else 0
        self.process = FrontEndProcess(self.name, "twin.opcua.cell_link:process", {
            "host": self.host, "port": self.port, "security": self.security, "watchdog": timeout})
        try:
            return await self.process.start(cell)
        except OSError as exc:
            self.process = None
            raise OSError(f"OPC UA cannot listen on {self.host}:{self.port}: {exc}") from None
        except TwinError:
            self.process = None
            raise

    def endpoints(self) -> list[dict]:
        """Where it listens, for the `ready` event (`twin.events`)."""
        return [] if self.process is None else self.process.endpoints()

    async def close(self) -> None:
        if self.process is not None:
            await self.process.close()
