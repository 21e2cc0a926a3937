"""Modbus/TCP Security: TLS on its own port, client certificates required (a real `twin serve`, real TLS)."""
from __future__ import annotations

import socket
import ssl
import struct
import subprocess
import sys

import pytest

from modbus_helpers import RING_BENCH, ROOT, Raw, ServerProcess, pdu
from tls_certs import make_pki


@pytest.fixture(scope="module")
def pki(tmp_path_factory):
    return make_pki(tmp_path_factory.mktemp("pki"))


@pytest.fixture(scope="module")
def tls_server(pki):
    with ServerProcess(RING_BENCH, "--lockstep", "--tls-cert", str(pki["server"]), "--tls-key", str(pki["server_key"]),
                       "--tls-ca", str(pki["ca"]), "--tls-port", "0") as s:
        yield s


def client_context(pki, who: str | None = "client") -> ssl.SSLContext:
    ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
    ctx.load_verify_locations(str(pki["ca"]))
    if who is not None:
        ctx.load_cert_chain(str(pki[who]), str(pki[f"{who}_key"]))
    return ctx


def tls_request(pki, port: int, who: str | None, frame_pdu: bytes) -> bytes:
    raw_sock = socket.create_connection(("127.0.0.1", port), timeout=5)
    with client_context(pki, who).wrap_socket(raw_sock, server_hostname="localhost") as s:
        s.sendall(struct.pack(">HHHB", 7, 0, len(frame_pdu) + 1, 1) + frame_pdu)
        head = b""
        while len(head) < 7:
            chunk = s.recv(7 - len(head))
            if not chunk:
                raise ConnectionError("closed")
            head += chunk
        tid, _, length, _ = struct.unpack(">HHHB", head)
        body = b""
        while len(body) < length - 1:
            body += s.recv(length - 1 - len(body))
        assert tid == 7
        return body


def test_a_client_with_a_certificate_from_the_ca_is_served_over_tls(pki, tls_server):
    assert tls_server.tls_port and tls_server.tls_port != tls_server.port
    assert tls_request(pki, tls_server.tls_port, "client", pdu(3, 16, 1))[:2] == b"\x03\x02"
    tls_server.wait_for(r"connected over TLS as 'plc-1'")


def test_a_client_without_a_certificate_or_with_a_strangers_is_refused(pki, tls_server):
    for who in (None, "stranger"):
        with pytest.raises((ssl.SSLError, ConnectionError, OSError)):
            tls_request(pki, tls_server.tls_port, who, pdu(3, 16, 1))


def test_plain_modbus_on_the_tls_port_is_dropped_and_the_plain_port_still_serves(pki, tls_server):
    with Raw(tls_server.tls_port) as raw:
        raw.send(raw.frame(pdu(3, 16, 1)))
        assert raw.closed_by_peer(10.0)
    with Raw(tls_server.port) as raw:
        assert raw.request(pdu(3, 16, 1))[:2] == b"\x03\x02"


def test_the_plc_client_and_cli_connect_over_tls_when_given_certificates(pki, tls_server):
    from plc_client import TwinClient
    from plc_client.client import TlsFiles

    files = TlsFiles(pki["client"], pki["client_key"], pki["ca"])
    with TwinClient.connect("127.0.0.1", tls_server.tls_port, station=RING_BENCH, tls=files) as plc:
        plc.write(L2=250.0)
        assert plc.read("L2") == {"L2": 250.0}
    r = subprocess.run([sys.executable, "-m", "plc_client", "--station", str(RING_BENCH), "--port", str(tls_server.tls_port),
                        "--tls-cert", str(pki["client"]), "--tls-key", str(pki["client_key"]), "--tls-ca", str(pki["ca"]),
                        "read", "L2"], capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split()[:2] == ["L2", "250"]


def test_tls_only_does_not_listen_on_plain_tcp_and_missing_files_are_errors(pki, tmp_path):
    with ServerProcess(RING_BENCH, "--tls-cert", str(pki["server"]), "--tls-key", str(pki["server_key"]),
                       "--tls-ca", str(pki["ca"]), "--tls-port", "0", "--tls-only") as s:
        assert not any(line.rstrip().endswith(tuple("0123456789")) and "listening on" in line for line in s.lines)
        assert tls_request(pki, s.tls_port, "client", pdu(4, 0, 2))[:2] == b"\x04\x04"
    r = subprocess.run([sys.executable, "-m", "twin", "serve", str(RING_BENCH), "--tls-cert", str(pki["server"]),
                        "--tls-key", str(pki["server_key"])], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "missing --tls-ca" in r.stderr


def test_the_certificate_role_grants_read_and_write_or_read_only(pki, tls_server):
    """The Modbus/TCP Security role extension: an Operator writes, a Viewer only reads (exception 01 for a
    write, as the specification's role-based authorization and --read-only refuse), an unknown role only reads."""
    write = pdu(6, 16, 33000)  # L2 = 330 mm (holding register 16, 0.01 mm per count)
    assert tls_request(pki, tls_server.tls_port, "operator", write) == write  # echoed: accepted
    assert tls_request(pki, tls_server.tls_port, "viewer", write) == b"\x86\x01"  # ILLEGAL FUNCTION
    assert tls_request(pki, tls_server.tls_port, "viewer", pdu(3, 16, 1)) == b"\x03\x02" + struct.pack(">H", 33000)
    assert tls_request(pki, tls_server.tls_port, "janitor", write) == b"\x86\x01"
    assert tls_request(pki, tls_server.tls_port, "client", write) == write  # no role: as the server is (read and write)
    seen = {e["tls_subject"]: (e["role"], e["access"]) for e in tls_server.events.seen + tls_server.events.new()
            if e["event"] == "client_connected" and "tls_subject" in e}
    assert seen["operator-1"] == ("Operator", "read/write") and seen["viewer-1"] == ("Viewer", "read")
    assert seen["janitor-1"] == ("Janitor", "read") and seen["plc-1"] == (None, "read/write")


def test_read_only_overrides_every_role(pki):
    with ServerProcess(RING_BENCH, "--lockstep", "--read-only", "--tls-cert", str(pki["server"]), "--tls-key",
                       str(pki["server_key"]), "--tls-ca", str(pki["ca"]), "--tls-port", "0", "--tls-only") as s:
        assert tls_request(pki, s.tls_port, "operator", pdu(6, 16, 33000)) == b"\x86\x01"
        assert tls_request(pki, s.tls_port, "operator", pdu(3, 16, 1))[:2] == b"\x03\x02"
