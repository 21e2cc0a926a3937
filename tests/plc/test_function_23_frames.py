"""The client frames a scan's function 23 itself (pymodbus's request objects cost more than the exchange): its
frames are checked here by pymodbus's own decoder, and the answers it takes are pymodbus's own encoding, on a
real loopback socket. An exception answer names the function; an answer of another transaction breaks the
connection (a stream that lost its framing cannot be trusted)."""
from __future__ import annotations

import socket
import struct
import threading

import pytest
from pymodbus.framer import FramerSocket
from pymodbus.pdu import DecodePDU, ExceptionResponse
from pymodbus.pdu.register_message import ReadHoldingRegistersResponse, ReadWriteMultipleRegistersResponse

from plc_client.client import TwinClient
from plc_client.errors import ConnectionFailedError, ModbusExceptionError
from twin.core.signals import BOOL, FLOAT, INPUT, OUTPUT, SignalSpec
from twin.frontends.modbus.pdu import IMAGE_IN, IMAGE_OUT
from twin.frontends.modbus.register_map import MAP_CRC, RegisterMap, build_register_map

SIGNALS = (SignalSpec("go", INPUT, BOOL), SignalSpec("target", INPUT, FLOAT, "m", 0.0, 0.1),
           SignalSpec("x", OUTPUT, FLOAT, "m", 0.0, 0.1))


class PymodbusPeer:
    """A loopback server that decodes each request with pymodbus and answers with `answer(request) -> PDU` (its
    `foreign` attribute, if any, added to the transaction id)."""

    def __init__(self, answer):
        self.answer, self.requests = answer, []
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        conn, _ = self.listener.accept()
        decode, encode = FramerSocket(DecodePDU(True)), FramerSocket(DecodePDU(False))
        data = b""
        with conn:
            while chunk := conn.recv(4096):
                data += chunk
                used, request = decode.handleFrame(data, 0, 0)
                if request is None:
                    continue
                data = data[used:]
                self.requests.append(request)
                response = self.answer(request)
                response.dev_id = request.dev_id
                response.transaction_id = request.transaction_id + getattr(response, "foreign", 0)
                conn.sendall(encode.buildFrame(response))


@pytest.fixture
def rmap():
    full = build_register_map(SIGNALS, "stand-in")
    return RegisterMap(tuple(e for e in full if e.name != MAP_CRC), "stand-in")  # nothing to check on connect


def test_the_scan_exchange_is_a_function_23_pymodbus_reads_and_its_answer_is_taken_as_pymodbus_wrote_it(rmap):
    def answer(request):
        if request.function_code == 3:
            return ReadHoldingRegistersResponse(registers=[0] * request.count)
        return ReadWriteMultipleRegistersResponse(registers=list(range(100, 100 + request.read_count)))

    peer = PymodbusPeer(answer)
    with TwinClient.connect("127.0.0.1", peer.port, map=rmap, heartbeat=None) as client:
        in_size = client.layout.in_size
        image = client.exchange({"target": 12.5}, client.read_window(), advance=3)
    rw = peer.requests[-1]
    assert rw.function_code == 23 and rw.dev_id == 1
    assert (rw.read_address, rw.read_count) == (IMAGE_IN, in_size)
    lay = client.layout
    first = min(lay.out_words(rmap["target"])[0], lay.out_words(rmap["sim.advance"])[0])
    assert rw.write_address == IMAGE_OUT + first
    words = dict(enumerate(rw.write_registers, start=first))
    assert words[lay.out_words(rmap["sim.advance"])[0]] == 3
    k, n = lay.out_words(rmap["target"])
    assert [words[k + i] for i in range(n)] == rmap["target"].encode(12.5, engineering=True)
    assert image.words == list(range(100, 100 + in_size))


def test_an_exception_answer_names_function_23_and_a_foreign_answer_breaks_the_connection(rmap):
    calls = []

    def answer(request):
        if request.function_code == 3:
            return ReadHoldingRegistersResponse(registers=[0] * request.count)
        calls.append(request)
        if len(calls) == 1:
            return ExceptionResponse(23, 3)
        response = ReadWriteMultipleRegistersResponse(registers=[0] * request.read_count)
        response.foreign = 1  # another transaction's answer
        return response

    peer = PymodbusPeer(answer)
    with TwinClient.connect("127.0.0.1", peer.port, map=rmap, heartbeat=None) as client:
        image = client.read_window()
        with pytest.raises(ModbusExceptionError) as refused:
            client.exchange({"target": 12.5}, image, advance=1)
        assert refused.value.code == 3 and refused.value.function == 0x17
        with pytest.raises(ConnectionFailedError, match="not this request's"):
            client.exchange({"target": 12.5}, image, advance=1)
        with pytest.raises(ConnectionFailedError):  # the connection is gone, not misread
            client.exchange({"target": 12.5}, image, advance=1)
