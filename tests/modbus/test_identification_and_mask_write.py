"""Function 43/14 (read device identification, spec v1.1b3 6.21) and 22 (mask write register, 6.16),
checked byte by byte against the specification's layouts, on a real `twin serve` (the `raw` fixture: the
ring bench in lockstep) and on the codec."""
from __future__ import annotations

import struct

from modbus_helpers import pdu

L2 = 16  # holding register of the ring bench's L2 setpoint (0.01 mm counts)


def parse_43(resp: bytes) -> dict:
    """The 6.21 response: MEI type, read device id code, conformity level, more follows, next object id,
    number of objects, then (id, length, value) per object."""
    assert resp[0] == 0x2B and resp[1] == 0x0E, resp.hex()
    code, conformity, more, next_id, n = resp[2:7]
    objects, pos = {}, 7
    for _ in range(n):
        oid, length = resp[pos], resp[pos + 1]
        objects[oid] = resp[pos + 2:pos + 2 + length].decode()
        pos += 2 + length
    assert pos == len(resp), "trailing bytes after the objects"
    return {"code": code, "conformity": conformity, "more": more, "next": next_id, "objects": objects}


def test_basic_regular_and_extended_streams_carry_their_categories(raw):
    basic = parse_43(raw.request(bytes([0x2B, 0x0E, 0x01, 0x00])))
    assert basic["code"] == 1 and basic["more"] == 0x00 and basic["next"] == 0x00
    assert sorted(basic["objects"]) == [0, 1, 2]  # VendorName, ProductCode, MajorMinorRevision: mandatory
    assert basic["objects"][0] == "gripper-twin" and basic["objects"][1] and basic["objects"][2][0].isdigit()
    assert basic["conformity"] in (0x83, 0x03)  # extended objects served (0x80: individual access too)
    regular = parse_43(raw.request(bytes([0x2B, 0x0E, 0x02, 0x00])))
    assert set(regular["objects"]) >= {0, 1, 2} and all(k <= 0x7F for k in regular["objects"])
    assert regular["objects"].get(6) == "ring_bench"  # UserApplicationName: the station
    extended = parse_43(raw.request(bytes([0x2B, 0x0E, 0x03, 0x00])))
    assert extended["objects"][0x80] == "ring_bench"
    assert set(extended["objects"]) >= set(regular["objects"])


def test_individual_access_gives_one_object_and_an_unknown_one_exception_02(raw):
    one = parse_43(raw.request(bytes([0x2B, 0x0E, 0x04, 0x01])))
    assert one["code"] == 4 and one["more"] == 0 and list(one["objects"]) == [1]
    assert parse_43(raw.request(bytes([0x2B, 0x0E, 0x04, 0x80])))["objects"] == {0x80: "ring_bench"}
    assert raw.request(bytes([0x2B, 0x0E, 0x04, 0x50])) == b"\xAB\x02"


def test_a_stream_from_an_unknown_object_restarts_at_object_0_and_bad_requests_get_their_exceptions(raw):
    restarted = parse_43(raw.request(bytes([0x2B, 0x0E, 0x01, 0x50])))
    assert sorted(restarted["objects"]) == [0, 1, 2]
    from_1 = parse_43(raw.request(bytes([0x2B, 0x0E, 0x01, 0x01])))
    assert sorted(from_1["objects"]) == [1, 2]
    assert raw.request(bytes([0x2B, 0x0E, 0x05, 0x00])) == b"\xAB\x03"  # read device id code 5: illegal value
    assert raw.request(bytes([0x2B, 0x0E, 0x01])) == b"\xAB\x03"  # too short
    assert raw.request(bytes([0x2B, 0x0D, 0x00, 0x00])) == b"\xAB\x01"  # CANopen general reference: not here


def test_a_response_too_long_for_one_pdu_says_more_follows_and_where_to_go_on():
    from twin.frontends.modbus.pdu import DeviceIdentity, Images, PduHandler
    from twin.frontends.modbus.register_map import build_register_map

    ident = DeviceIdentity(extended={0x80 + i: chr(65 + i) * 100 for i in range(5)})
    handler = PduHandler(build_register_map([]), type("B", (), {"images": Images(b"", b"", b"", b"")})(), identity=ident)
    seen, next_id, rounds = {}, 0, 0
    while True:
        resp = handler.handle(bytes([0x2B, 0x0E, 0x03, next_id]))
        assert len(resp) <= 253
        r = parse_43(resp)
        seen.update(r["objects"])
        rounds += 1
        if r["more"] == 0x00:
            assert r["next"] == 0
            break
        assert r["more"] == 0xFF and r["next"] not in r["objects"] and r["next"] > max(r["objects"])
        next_id = r["next"]
    assert rounds >= 2 and [seen[0x80 + i] for i in range(5)] == [chr(65 + i) * 100 for i in range(5)]


def test_mask_write_follows_the_specifications_example(raw):
    """6.16's example: current 0x12, AND mask 0xF2, OR mask 0x25 -> 0x17; the response echoes the request."""
    assert raw.request(pdu(6, L2, 0x12)) == pdu(6, L2, 0x12)
    assert raw.request(pdu(22, L2, 0xF2, 0x25)) == pdu(22, L2, 0xF2, 0x25)
    assert raw.request(pdu(3, L2, 1)) == b"\x03\x02" + struct.pack(">H", 0x17)
    # AND all ones, OR 0: unchanged; AND 0: the OR mask is the new value
    assert raw.request(pdu(22, L2, 0xFFFF, 0x0000))[0] == 22
    assert raw.request(pdu(3, L2, 1))[2:] == struct.pack(">H", 0x17)
    assert raw.request(pdu(22, L2, 0x0000, 0x1234))[0] == 22
    assert raw.request(pdu(3, L2, 1))[2:] == struct.pack(">H", 0x1234)


def test_mask_write_is_checked_like_any_write(raw):
    assert raw.request(pdu(22, 9, 0, 1)) == b"\x96\x02"  # a gap
    assert raw.request(pdu(22, L2, 0x0000, 0xFFFF)) == b"\x96\x03"  # 655.35 mm: beyond L2's range
    assert raw.request(pdu(22, L2, 0, 1, fmt="HHH", tail=b"\x00")) == b"\x96\x03"  # wrong length
    assert raw.request(pdu(3, L2, 1))[2:] != b"\xff\xff"
