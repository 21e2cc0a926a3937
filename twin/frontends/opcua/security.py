"""Who may connect to the OPC UA server, and how: security policies, the server certificate, user accounts.

- Policies: `none` (no signing, no encryption), `sign` and `encrypt` (Basic256Sha256, Sign and
  SignAndEncrypt). By default all three are offered when the server listens on a loopback address, and only
  the two secure ones otherwise (a plain endpoint on a network needs `--opcua-security none,...`).
- Certificate: the one given (`--opcua-cert` DER/PEM and `--opcua-key` PEM), or one generated on first start
  (RSA 2048, self-signed, a year, for the application URI `urn:gripper-twin:server` and this host) and kept in
  the certificate folder (`--opcua-cert-dir`, default `$XDG_DATA_HOME/gripper-twin/opcua`), so a client that
  trusted it once keeps trusting it. Client certificates are not checked against a trust list (a test bench).
- Users: none configured means anonymous sessions. With accounts (`--opcua-user NAME:PASSWORD` may write and
  call `Sim.Advance`, `--opcua-reader NAME:PASSWORD` may browse, read and subscribe only), only those accounts
  may open a session. A read-only user's write is refused with BadUserAccessDenied, its method calls too.
"""
from __future__ import annotations

import ipaddress
import os
import socket
from dataclasses import dataclass, field
from pathlib import Path

from twin.core.errors import TwinError

APPLICATION_URI = "urn:gripper-twin:server"
NONE, SIGN, ENCRYPT = "none", "sign", "encrypt"
# policy name -> asyncua's SecurityPolicyType member (asyncua is imported only when a server starts)
POLICIES = {NONE: "NoSecurity", SIGN: "Basic256Sha256_Sign", ENCRYPT: "Basic256Sha256_SignAndEncrypt"}


class SecurityError(TwinError):
    """A security option that cannot work (a missing certificate file, a malformed account)."""


@dataclass(frozen=True)
class Account:
    name: str
    password: str
    read_only: bool = False

    @classmethod
    def parse(cls, text: str, *, read_only: bool = False) -> "Account":
        name, sep, password = text.partition(":")
        if not sep or not name:
            raise SecurityError(f"an account is NAME:PASSWORD, not {text!r}")
        return cls(name, password, read_only)


def default_cert_dir() -> Path:
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")
    return Path(base) / "gripper-twin" / "opcua"


def is_loopback(host: str) -> bool:
    if host in ("localhost",):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


@dataclass(frozen=True)
class Security:
    policies: tuple[str, ...] | None = None  # None: the defaults for the host (see the module docstring)
    cert: Path | None = None
    key: Path | None = None
    cert_dir: Path | None = None
    accounts: tuple[Account, ...] = field(default=())
    application_uri: str = APPLICATION_URI

    def policies_for(self, host: str) -> tuple[str, ...]:
        if self.policies is not None:
            return self.policies
        return (NONE, SIGN, ENCRYPT) if is_loopback(host) else (SIGN, ENCRYPT)

    @staticmethod
    def read_only(user) -> bool:
        return is_reader(user)

    def user_manager(self):
        from ._asyncua_roles import Accounts

        return Accounts(self.accounts)

    async def certificate_files(self) -> tuple[Path, Path]:
        """The certificate (DER) and private key (PEM) to serve with: given, kept, or generated now."""
        if self.cert is not None or self.key is not None:
            if self.cert is None or self.key is None:
                raise SecurityError("--opcua-cert and --opcua-key go together")
            for p in (self.cert, self.key):
                if not Path(p).is_file():
                    raise SecurityError(f"{p}: no such file")
            return Path(self.cert), Path(self.key)
        folder = Path(self.cert_dir) if self.cert_dir is not None else default_cert_dir()
        folder.mkdir(parents=True, exist_ok=True)
        cert, key = folder / "server-cert.der", folder / "server-key.pem"
        from asyncua.crypto.cert_gen import setup_self_signed_certificate
        from cryptography.x509.oid import ExtendedKeyUsageOID

        # makes the key and certificate when missing (or no longer valid), keeps them otherwise
        await setup_self_signed_certificate(key, cert, self.application_uri, socket.gethostname(),
                                            [ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH],
                                            {"commonName": "gripper-twin OPC UA server", "organizationName": "gripper-twin"})
        try:
            os.chmod(key, 0o600)
        except OSError:
            pass
        return cert, key

    async def apply(self, server, host: str, on_request=None) -> None:
        """Endpoints, certificate and identity tokens of an asyncua `Server` (before `start`); `on_request(user,
        type_id, body)` before every request of a session (`_asyncua_roles.Roles`)."""
        policies = self.policies_for(host)
        unknown = [p for p in policies if p not in POLICIES]
        if unknown or not policies:
            raise SecurityError(f"security policies are {', '.join(POLICIES)}, not {', '.join(unknown) or 'none at all'}")
        if any(p != NONE for p in policies):
            cert, key = await self.certificate_files()
            await server.load_certificate(str(cert))
            await server.load_private_key(str(key))
        from asyncua import ua

        from ._asyncua_roles import Roles

        server.set_security_policy([getattr(ua.SecurityPolicyType, POLICIES[p]) for p in policies],
                                   permission_ruleset=Roles(on_request))
        if self.accounts:
            server.set_identity_tokens([ua.UserNameIdentityToken])
        else:
            server.set_identity_tokens([ua.AnonymousIdentityToken])


def is_reader(user) -> bool:
    """A session of a read-only account (`_asyncua_roles.SessionUser.read_only`; asyncua is not imported here)."""
    return bool(getattr(user, "read_only", False))
