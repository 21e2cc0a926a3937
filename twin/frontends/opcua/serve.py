"""`twin serve STATION --opcua [PORT]`: starting the OPC UA server on a cell, from the options
`twin_app.cli_opcua` adds to `twin serve` (listed there).
"""
from __future__ import annotations

import logging

from .security import Account, Security

DEFAULT_PORT = 4840


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
        """`sink(text, level)`: where the lines go (default the `twin.serve` logger of this process). Warnings and
        errors only (`sessions` asks asyncua for some of its INFO records, which are not for the log)."""
        super().__init__(logging.WARNING)
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
    for name in ("asyncua.server", "asyncua.common", "asyncua.crypto", "twin.frontends.opcua"):  # not a client's (asyncua.client)
        lg = logging.getLogger(name)
        if not any(isinstance(h, OneLineLog) for h in lg.handlers):
            lg.addHandler(OneLineLog(sink))
        lg.propagate = False
        if lg.level == logging.NOTSET:
            lg.setLevel(logging.WARNING)


class OpcUaFrontEnd:
    """OPC UA as a front end of a cell (the contract: `twin_app.cell`): `OpcUaFrontEnd.from_args(args)`. The server
    runs in a process of its own behind the front-end adapter (`twin.frontends.process`; its side:
    `twin.frontends.opcua.cell_link`)."""

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
        from twin.frontends.process import FrontEndProcess

        watchdog = getattr(cell, "watchdog", None)
        if watchdog is not None:
            if self.watchdog is not None:
                cell.set_watchdog_timeout(self.watchdog)
            if hasattr(cell, "log"):
                watchdog.log = lambda text: cell.log(text, logging.WARNING)
        timeout = (watchdog.timeout or 0) if watchdog is not None else 0
        self.process = FrontEndProcess(self.name, "twin.frontends.opcua.cell_link:process", {
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
        """Where it listens, for the `ready` event (`twin.observe.events`)."""
        return [] if self.process is None else self.process.endpoints()

    async def close(self) -> None:
        if self.process is not None:
            await self.process.close()
