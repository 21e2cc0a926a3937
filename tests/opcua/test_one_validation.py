"""One write validation: the same bad writes are refused for the same reason on Modbus, OPC UA, the page and
the PLC client, because each asks `SignalSpec.check` and maps its error by type to its protocol.

The reference is the station's own signal table (`SignalSpec.check`, no server involved); then a real
`twin serve --lockstep --opcua 0` answers the Modbus frames and the OPC UA writes, the page's check runs on
the scene's signals as the page process has them, and the client checks against the register map."""
from __future__ import annotations

import asyncio
import math
import struct

import pytest
from asyncua import Client, ua

from opcua_helpers import NAMESPACE, OpcUaServerProcess, node, write_status  # (puts modbus_helpers on the path)
from modbus_helpers import Raw, pdu  # noqa: I001
from plc_client.checks import check_value
from plc_client.client import RegisterMap
from tests.conftest import ROOT
from twin.core.errors import SignalError, SignalRangeError, SignalTypeError, TwinError
from twin.core.signal_table import station_signals
from twin.core.station import load_station
from twin.frontends.view.live import check_write

BENCH = ROOT / "tests" / "plc" / "stations" / "ring_bench"
# Modbus/TCP: a value refused by the validation is exception 03 (ILLEGAL DATA VALUE; an output is in a read-only
# table, so no write names it); OPC UA: see twin.frontends.opcua.errors.status_of and docs/opcua.md
MODBUS = {SignalRangeError: 0x03, SignalTypeError: 0x03}
# (signal, value in SI, the OPC UA Variant type the client sends, what the page and the client are given)
BAD = [("L2", 0.5, ua.VariantType.Double), ("L2", -0.001, ua.VariantType.Double),
       ("L2", math.nan, ua.VariantType.Double), ("L2.actual", 0.1, ua.VariantType.Double),
       ("Active", 2, ua.VariantType.Int64)]
OPCUA = {("L2", 0.5): "BadOutOfRange", ("L2", -0.001): "BadOutOfRange", ("L2", "nan"): "BadOutOfRange",
         ("L2.actual", 0.1): "BadNotWritable", ("Active", 2): "BadTypeMismatch"}  # the Variant's type: an Int64


def reference(specs, name, value) -> TwinError:
    with pytest.raises(TwinError) as caught:
        specs[name].check(value)
    return caught.value


def modbus_frame(entry, value_si: float) -> bytes:
    """The write a PLC would send for `value_si` to `entry` (FC 5 for a coil, FC 16 for registers)."""
    if entry.type == "bool":
        return pdu(5, entry.address, 0xFF00 if value_si == 1 else value_si)
    eng = value_si * 1000.0 if entry.unit == "mm" else value_si
    if entry.type == "float32":
        words = struct.unpack(">HH", struct.pack(">f", eng))
    else:
        counts = round(eng / entry.scale) & 0xFFFFFFFF
        words = struct.unpack(">HH", struct.pack(">I", counts)) if entry.count == 2 else (counts & 0xFFFF,)
    return pdu(16, entry.address, len(words), 2 * len(words), *words, fmt="HHB" + "H" * len(words))


def test_the_same_bad_writes_are_refused_for_the_same_reason_everywhere(tmp_path):
    specs = {s.name: s for s in station_signals(load_station(BENCH))}
    rmap = RegisterMap.from_station(BENCH)
    expected = {(n, v if v == v else "nan"): reference(specs, n, v) for n, v, _ in BAD}
    assert {type(e) for e in expected.values()} == {SignalRangeError, SignalTypeError, SignalError}

    # the page: the scene's signals as the page process gets them, its message the validation's own
    from twin.observe.scene import _signal_dict

    for (name, value), err in expected.items():
        value = math.nan if value == "nan" else value
        assert check_write(_signal_dict(specs[name]), value) == str(err)

    # the PLC client: refused before the wire, with the twin's own error classes
    for (name, value), err in expected.items():
        value = math.nan if value == "nan" else value
        eng = value * 1000.0 if rmap[name].unit == "mm" else value
        with pytest.raises(TwinError) as caught:
            check_value(rmap, name, eng)
        assert isinstance(caught.value, type(err)), (name, value, caught.value)

    with OpcUaServerProcess(BENCH, "--lockstep") as server:
        # Modbus/TCP: the exception code the error's type maps to; nothing changes
        answers = {}
        with Raw(server.port) as raw:
            for (name, value), err in expected.items():
                value = math.nan if value == "nan" else value
                entry = rmap[name]
                if entry.type != "float32" and isinstance(value, float) and not math.isfinite(value):
                    continue  # a scaled integer register cannot carry a NaN
                if not entry.writable:
                    continue  # an output has no address a Modbus write can name (its table is read-only)
                answer = raw.request(modbus_frame(entry, value))
                answers[(name, value)] = answer[1] if answer[0] & 0x80 else None
        assert len(answers) == 3  # two out of range, one bool written as 2
        for (name, value), code in answers.items():
            key = (name, "nan" if value != value else value)
            assert code == MODBUS[type(expected[key])], (name, value, code)

        # OPC UA: the status code the error's type maps to
        async def opcua():
            async with Client(server.url, timeout=60) as c:
                ns = await c.get_namespace_index(NAMESPACE + "ring_bench")
                return {(n, v if v == v else "nan"): await write_status(node(c, ns, n), v, t) for n, v, t in BAD}

        assert asyncio.run(asyncio.wait_for(opcua(), 120)) == OPCUA
