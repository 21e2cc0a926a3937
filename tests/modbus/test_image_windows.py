"""The process-image windows: the whole input image in one read, the outputs in one write, a lockstep
scan in one function 23 that answers after its steps (a real `twin serve`, raw frames)."""
from __future__ import annotations

import struct

from modbus_helpers import pdu

IMAGE_IN, IMAGE_OUT = 0x8000, 0xC000
# the ring bench's table sizes (from `twin map`): coils 18, discrete inputs 29, holding 20, input registers 44
DI_WORDS, IR, COIL_WORDS, HR, COILS = 2, 44, 2, 20, 18
L2 = 16


def words(resp: bytes) -> list[int]:
    return list(struct.unpack(f">{resp[1] // 2}H", resp[2:]))


def test_the_input_window_holds_every_table_as_the_plain_reads_show_it(raw):
    window = words(raw.request(pdu(3, IMAGE_IN, DI_WORDS + IR + COIL_WORDS + HR)))
    low, high = raw.request(pdu(2, 0, 3))[2], raw.request(pdu(2, 16, 13))[2:]
    bits = {a: (low >> a) & 1 for a in range(3)} | {16 + i: (high[i // 8] >> (i % 8)) & 1 for i in range(13)}
    for a, bit in bits.items():  # packed 16 to a word: discrete input a is bit a % 16 of word a // 16
        assert (window[a // 16] >> (a % 16)) & 1 == bit, a
    assert window[0] & 0xFFF8 == 0  # the gap 3..15 reads 0
    assert window[DI_WORDS:DI_WORDS + 9] == words(raw.request(pdu(4, 0, 9)))  # sim.step .. sim.speed_pct
    assert window[DI_WORDS + 10:DI_WORDS + 14] == words(raw.request(pdu(4, 10, 4)))  # map CRC, watchdog
    assert window[DI_WORDS + 9] == window[DI_WORDS + 14] == 0  # gaps
    assert window[DI_WORDS + 16:DI_WORDS + IR] == words(raw.request(pdu(4, 16, IR - 16)))
    coils = raw.request(pdu(1, 16, 2))[2]
    assert (window[DI_WORDS + IR + 1] >> 0) & 1 == coils & 1  # coil 16 (Active)
    assert window[DI_WORDS + IR + COIL_WORDS + 16:] == words(raw.request(pdu(3, 16, 4)))
    assert raw.request(pdu(3, IMAGE_IN, DI_WORDS + IR + COIL_WORDS + HR + 1)) == b"\x83\x02"  # past its end


def test_a_write_into_the_output_window_writes_the_entries_it_covers(raw):
    out_l2 = IMAGE_OUT + COILS + L2
    assert raw.request(pdu(16, out_l2, 2, fmt="HH", tail=struct.pack(">BHH", 4, 31000, 31500)))[0] == 16
    assert words(raw.request(pdu(3, L2, 2))) == [31000, 31500]
    assert words(raw.request(pdu(3, out_l2, 2))) == [31000, 31500]  # reads back too
    assert raw.request(pdu(6, out_l2, 60000)) == b"\x86\x03"  # out of L2's range: refused as any write
    assert raw.request(pdu(6, IMAGE_IN, 1)) == b"\x86\x02"  # the input window is read-only
    # coils one word each: Active (coil 16) low, then back
    assert raw.request(pdu(6, IMAGE_OUT + 16, 0))[0] == 6
    assert raw.request(pdu(1, 16, 1))[2] & 1 == 0
    assert raw.request(pdu(6, IMAGE_OUT + 16, 2)) == b"\x86\x03"
    assert raw.request(pdu(6, IMAGE_OUT + 16, 1))[0] == 6


def test_a_lockstep_scan_in_one_function_23_answers_with_the_state_after_its_steps(raw):
    def step() -> int:
        hi, lo = words(raw.request(pdu(4, 0, 2)))
        return hi << 16 | lo

    s0 = step()
    block = [0] * (L2 + 1)  # sim.advance .. L2 in the output window: advance 7, L2 = 300 mm
    block[0], block[L2] = 7, 30000
    n = DI_WORDS + IR + COIL_WORDS + HR
    resp = raw.request(pdu(23, IMAGE_IN, n, IMAGE_OUT + COILS, len(block), fmt="HHHH",
                           tail=struct.pack(f">B{len(block)}H", 2 * len(block), *block)))
    assert resp[0] == 23 and resp[1] == 2 * n
    w = words(resp)
    assert (w[DI_WORDS] << 16 | w[DI_WORDS + 1]) == s0 + 7  # sim.step in the read part: after the 7 steps
    assert w[DI_WORDS + IR + COIL_WORDS + L2] == 30000 and w[DI_WORDS + IR + COIL_WORDS] == 0  # sim.advance done
    assert step() == s0 + 7
