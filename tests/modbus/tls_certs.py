"""Certificates for Modbus/TCP Security tests, made with `cryptography`: a CA, a server certificate for
localhost / 127.0.0.1, a client certificate from the same CA and one from a stranger's CA."""
from __future__ import annotations

import datetime
import ipaddress
from pathlib import Path

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID


def _name(cn: str) -> x509.Name:
    return x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, cn)])


def _write(folder: Path, stem: str, cert: x509.Certificate, key) -> tuple[Path, Path]:
    c, k = folder / f"{stem}.pem", folder / f"{stem}.key"
    c.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
    k.write_bytes(key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                                    serialization.NoEncryption()))
    return c, k


ROLE_OID = x509.ObjectIdentifier("1.3.6.1.4.1.50316.802.1")  # Modbus/TCP Security: the role extension


def _utf8string(text: str) -> bytes:
    """ASN.1 DER of a UTF8String (tag 12), written out here from X.690, not by the code under test."""
    data = text.encode("utf-8")
    assert len(data) < 128  # the short form of the length
    return bytes((0x0C, len(data))) + data


def _cert(subject: str, key, issuer_name: x509.Name, issuer_key, *, ca: bool = False, server: bool = False,
          role: str | None = None):
    now = datetime.datetime.now(datetime.timezone.utc)
    b = (x509.CertificateBuilder().subject_name(_name(subject)).issuer_name(issuer_name)
         .public_key(key.public_key()).serial_number(x509.random_serial_number())
         .not_valid_before(now - datetime.timedelta(minutes=5)).not_valid_after(now + datetime.timedelta(days=2))
         .add_extension(x509.BasicConstraints(ca=ca, path_length=None), critical=True))
    if server:
        b = b.add_extension(x509.SubjectAlternativeName([x509.DNSName("localhost"),
                                                         x509.IPAddress(ipaddress.ip_address("127.0.0.1"))]), critical=False)
        b = b.add_extension(x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH]), critical=False)
    elif not ca:
        b = b.add_extension(x509.ExtendedKeyUsage([ExtendedKeyUsageOID.CLIENT_AUTH]), critical=False)
    if role is not None:
        b = b.add_extension(x509.UnrecognizedExtension(ROLE_OID, _utf8string(role)), critical=False)
    return b.sign(issuer_key, hashes.SHA256())


def make_pki(folder: Path) -> dict[str, Path]:
    keys = {n: ec.generate_private_key(ec.SECP256R1()) for n in ("ca", "server", "client", "stranger_ca", "stranger",
                                                                    "operator", "viewer", "janitor")}
    ca = _cert("twin test CA", keys["ca"], _name("twin test CA"), keys["ca"], ca=True)
    sca = _cert("stranger CA", keys["stranger_ca"], _name("stranger CA"), keys["stranger_ca"], ca=True)
    out = {"ca": _write(folder, "ca", ca, keys["ca"])[0]}
    out["server"], out["server_key"] = _write(folder, "server", _cert("twin serve", keys["server"], ca.subject, keys["ca"],
                                                                      server=True), keys["server"])
    out["client"], out["client_key"] = _write(folder, "client", _cert("plc-1", keys["client"], ca.subject, keys["ca"]),
                                              keys["client"])
    out["stranger"], out["stranger_key"] = _write(folder, "stranger", _cert("mallory", keys["stranger"], sca.subject,
                                                                            keys["stranger_ca"]), keys["stranger"])
    for who, role in (("operator", "Operator"), ("viewer", "Viewer"), ("janitor", "Janitor")):  # role certificates
        out[who], out[f"{who}_key"] = _write(folder, who, _cert(f"{who}-1", keys[who], ca.subject, keys["ca"], role=role),
                                             keys[who])
    return out
