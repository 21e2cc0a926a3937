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
from pathlib import Path

from .security import POLICIES, Account, Security, SecurityError

DEFAULT_PORT = 4840


def _port(text: str) -> int:
    v = int(text)
    if not 0 <= v <= 0xFFFF:
        raise argparse.ArgumentTypeError(f"a TCP port is 0..65535, not {text}")
    return v


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
    g.add_argument("--opcua", nargs="?", type=_port, const=DEFAULT_PORT, default=None, metavar="PORT",
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


async def start_opcua(link, *, host: str, port: int, security: Security):
    """Build the station's address space and serve it on the cell behind `link` (a `CellLink` the runner steps).

    Returns the started `OpcUaServer`; OSError when the port cannot be bound, SecurityError for bad options."""
    from .address_space import build_address_space
    from .server import OpcUaServer

    twin = link.twin
    space = build_address_space(link.signals(), twin.station.name)
    server = OpcUaServer(space, step_s=twin.dt, submit=link.submit, advance=link.advance, security=security)
    try:
        await server.start(host, port)
    except BaseException:
        await server.close()
        raise
    link.attach(server)
    return server


def options_from(args) -> dict | None:
    """`serve`'s keyword `opcua` from the parsed command line (None without --opcua)."""
    if getattr(args, "opcua", None) is None:
        return None
    return {"host": args.opcua_host or args.host, "port": args.opcua, "security": security_from(args)}


async def start_opcua_logged(link, *, host: str, port: int, security: Security):
    """`start_opcua`, with the server's log lines; None (and an error line) when it cannot start."""
    from twin.modbus.log import log

    try:
        server = await start_opcua(link, host=host, port=port, security=security)
    except OSError as exc:
        log(f"error: OPC UA cannot listen on {host}:{port}: {exc.strerror or exc}")
        return None
    except SecurityError as exc:
        log(f"error: OPC UA security: {exc}")
        return None
    policies = ", ".join(security.policies_for(host))
    users = f", {len(security.accounts)} account(s), no anonymous" if security.accounts else ", anonymous"
    log(f"OPC UA: namespace {server.space.namespace_uri} (ns={server.ns}), {len(server.space)} variables, "
        f"security {policies}{users}")
    log(f"OPC UA listening on {server.endpoint}")
    return server
