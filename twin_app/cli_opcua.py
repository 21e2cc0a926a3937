"""`twin serve STATION --opcua [PORT]`: the OPC UA options of `twin serve` (started by twin.frontends.opcua.serve).

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

from twin.frontends.opcua.security import POLICIES, Account, SecurityError
from twin.frontends.opcua.serve import DEFAULT_PORT
from twin_app.cli_args import tcp_port


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
