"""OPC UA security: the endpoints offered, a Basic256Sha256 session on a certificate generated at first start
(and kept), user accounts with a read-only role."""
from __future__ import annotations

import asyncio

import pytest
from asyncua import Client, ua
from asyncua.crypto.cert_gen import setup_self_signed_certificate
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from cryptography import x509
from cryptography.x509.oid import ExtendedKeyUsageOID

from opcua_helpers import RING_RIG, OpcUaServerProcess, advance, namespace, node, write_status

BASIC256SHA256 = "http://opcfoundation.org/UA/SecurityPolicy#Basic256Sha256"
NONE_URI = "http://opcfoundation.org/UA/SecurityPolicy#None"


def run(coro):
    return asyncio.run(asyncio.wait_for(coro, 600))


async def client_certificate(folder):
    key, cert = folder / "client-key.pem", folder / "client-cert.der"
    await setup_self_signed_certificate(key, cert, "urn:gripper-twin:test-client", "localhost",
                                        [ExtendedKeyUsageOID.CLIENT_AUTH], {"commonName": "test client"})
    return cert, key


def test_loopback_offers_none_and_basic256sha256_sign_and_encrypt_by_default(tmp_path):
    with OpcUaServerProcess(RING_RIG, "--lockstep", "--no-modbus", cert_dir=tmp_path) as server:
        async def main():
            c = Client(server.url, timeout=30)
            return await c.connect_and_get_server_endpoints()

        endpoints = run(main())
    offered = {(e.SecurityPolicyUri, e.SecurityMode) for e in endpoints}
    assert offered == {(NONE_URI, ua.MessageSecurityMode.None_),
                       (BASIC256SHA256, ua.MessageSecurityMode.Sign),
                       (BASIC256SHA256, ua.MessageSecurityMode.SignAndEncrypt)}
    der = (tmp_path / "server-cert.der").read_bytes()  # generated at first start
    assert all(e.ServerCertificate == der for e in endpoints)
    cert = x509.load_der_x509_certificate(der)
    uris = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value.get_values_for_type(
        x509.UniformResourceIdentifier)
    assert endpoints[0].Server.ApplicationUri in uris  # the certificate is the server application's


@pytest.mark.parametrize("mode", [ua.MessageSecurityMode.SignAndEncrypt, ua.MessageSecurityMode.Sign])
def test_a_secure_session_on_the_generated_certificate_reads_and_writes(tmp_path, mode):
    args = ("--lockstep", "--no-modbus", "--opcua-security", "sign,encrypt")
    with OpcUaServerProcess(RING_RIG, *args, cert_dir=tmp_path / "server") as server:
        first = (tmp_path / "server" / "server-cert.der").read_bytes()

        async def main():
            cert, key = await client_certificate(tmp_path)
            if mode == ua.MessageSecurityMode.Sign:
                endpoints = await Client(server.url, timeout=30).connect_and_get_server_endpoints()
                assert {e.SecurityPolicyUri for e in endpoints} == {BASIC256SHA256}  # no endpoint without security
            c = Client(server.url, timeout=30)
            await c.set_security(SecurityPolicyBasic256Sha256, str(cert), str(key),
                                 server_certificate=str(tmp_path / "server" / "server-cert.der"), mode=mode)
            async with c:
                ns = await namespace(c)
                assert await write_status(node(c, ns, "L2"), 0.34, ua.VariantType.Double) == "Good"
                assert await write_status(node(c, ns, "L2"), 0.9, ua.VariantType.Double) == "BadOutOfRange"
                await advance(c, ns, 50)
                return await node(c, ns, "L2.actual").read_value()

        assert run(main()) < 0.35  # the finger moved towards 340 mm
    if mode == ua.MessageSecurityMode.SignAndEncrypt:
        with OpcUaServerProcess(RING_RIG, *args, cert_dir=tmp_path / "server"):
            assert (tmp_path / "server" / "server-cert.der").read_bytes() == first  # kept, not made anew


def test_a_read_only_user_reads_but_its_writes_and_calls_are_refused(tmp_path):
    args = ("--lockstep", "--no-modbus", "--opcua-user", "operator:s3cret", "--opcua-reader", "viewer:look")
    with OpcUaServerProcess(RING_RIG, *args, cert_dir=tmp_path) as server:
        async def session(user=None, password=None):
            c = Client(server.url, timeout=30)
            if user is not None:
                c.set_user(user)
                c.set_password(password)
            return c

        async def main():
            out = {}
            async with await session("viewer", "look") as c:
                ns = await namespace(c)
                out["reader reads"] = await node(c, ns, "L2").read_value()
                try:
                    out["reader writes"] = await write_status(node(c, ns, "L2"), 0.3, ua.VariantType.Double)
                except ua.UaStatusCodeError as exc:
                    out["reader writes"] = type(exc).__name__
                try:
                    await advance(c, ns, 1)
                    out["reader advances"] = "Good"
                except ua.UaStatusCodeError as exc:
                    out["reader advances"] = type(exc).__name__
                out["still"] = await node(c, ns, "L2").read_value()
            async with await session("operator", "s3cret") as c:
                ns = await namespace(c)
                out["operator writes"] = await write_status(node(c, ns, "L2"), 0.3, ua.VariantType.Double)
                out["operator advances"] = await advance(c, ns, 1)
            for who, (user, password) in {"anonymous": (None, None), "wrong password": ("operator", "guess")}.items():
                try:
                    async with await session(user, password):
                        out[who] = "connected"
                except Exception as exc:
                    out[who] = "refused"
            return out

        out = run(main())
    assert out == {"reader reads": 0.35, "reader writes": "BadUserAccessDenied",
                   "reader advances": "BadUserAccessDenied", "still": 0.35, "operator writes": "Good",
                   "operator advances": 1, "anonymous": "refused", "wrong password": "refused"}
