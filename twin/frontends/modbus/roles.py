"""Modbus/TCP Security roles: what a client certificate's role lets its holder do.

The Modbus/TCP Security specification carries a client's role in its X.509v3 certificate, in the extension
with OID 1.3.6.1.4.1.50316.802.1 (the Modbus Organization's arc), whose value is an ASN.1 UTF8String; the
server maps the role to the rights it grants (role-based client authorization). This server knows:

    role (any case)                              access
    Operator, Engineer, Administrator            read and write (every function code it serves)
    ReadOnly, Viewer, Observer                   read only: every write function gets exception 01
    any other role                               read only (and the log says the role is unknown)
    no role extension                            as the server is: read and write unless --read-only

`--read-only` makes every client read-only whatever its role. Reading the extension needs `cryptography`.
"""
from __future__ import annotations

from dataclasses import dataclass

ROLE_OID = "1.3.6.1.4.1.50316.802.1"
FULL_ROLES = ("operator", "engineer", "administrator")
READ_ONLY_ROLES = ("readonly", "viewer", "observer")


@dataclass(frozen=True)
class Access:
    """What a connection may do, and why (for the log and the events)."""

    role: str | None  # the certificate's role, None without the extension
    read_only: bool
    why: str


def role_of(der: bytes | None) -> str | None:
    """The role a client certificate (DER) carries, None when it has no role extension.

    A role extension whose value is not a UTF8String is a role nobody knows (``"?"``): read-only."""
    if not der:
        return None
    from cryptography import x509
    from cryptography.x509.oid import ObjectIdentifier

    cert = x509.load_der_x509_certificate(der)
    try:
        ext = cert.extensions.get_extension_for_oid(ObjectIdentifier(ROLE_OID))
    except x509.ExtensionNotFound:
        return None
    value = ext.value.value  # UnrecognizedExtension: the DER of the extension's value
    if len(value) >= 2 and value[0] == 0x0C:  # UTF8String, short or long form length
        length, start = value[1], 2
        if length & 0x80:
            n = length & 0x7F
            length, start = int.from_bytes(value[2:2 + n], "big"), 2 + n
        try:
            return value[start:start + length].decode("utf-8")
        except UnicodeDecodeError:
            return "?"
    return "?"


def access_for(role: str | None, server_read_only: bool = False) -> Access:
    """The access a role is granted (see the module docstring)."""
    if server_read_only:
        return Access(role, True, "--read-only")
    if role is None:
        return Access(None, False, "no role in the certificate: read and write")
    key = role.strip().lower()
    if key in FULL_ROLES:
        return Access(role, False, f"role {role!r}: read and write")
    if key in READ_ONLY_ROLES:
        return Access(role, True, f"role {role!r}: read only")
    return Access(role, True, f"role {role!r} is none this server knows: read only "
                              f"(roles: {', '.join(r.title() for r in FULL_ROLES)}; ReadOnly, Viewer, Observer)")
