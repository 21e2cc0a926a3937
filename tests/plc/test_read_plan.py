"""A lockstep PLC client decodes only the values whose window words changed since its last scan
(`plc_client.client._ReadPlan`): whatever changes between two reads (one bit of a word of packed bits, a
whole register, one word of a 32-bit value, nothing), it must read what decoding the whole window anew reads."""
from __future__ import annotations

import random
from types import SimpleNamespace

from plc_client.client import WindowImage, _ReadPlan
from tests.plc.conftest import BENCH
from twin.frontends.modbus.pdu import ImageLayout
from twin.frontends.modbus.register_map import TABLES, RegisterMap


def test_a_scan_reads_what_decoding_the_whole_window_anew_reads():
    rmap = RegisterMap.from_station(BENCH)
    layout = ImageLayout({t: rmap.size(t) for t in TABLES})
    entries = list(rmap)
    plan, decoded = _ReadPlan(layout, entries), {}
    rng = random.Random(7)
    words = [0] * layout.in_size
    for _ in range(300):
        for _ in range(rng.choice((0, 1, 1, 2, 5))):
            k = rng.randrange(layout.in_size)
            if rng.random() < 0.5:
                words[k] ^= 1 << rng.randrange(16)
            else:  # any register, but no float32 NaN or infinity (their exponent all ones)
                words[k] = rng.randrange(0x7F80) | (0x8000 if rng.random() < 0.5 else 0)
        whole = WindowImage(SimpleNamespace(layout=layout), list(words))
        assert plan.values_of(list(words), decoded) == {e.name: whole.value(e) for e in entries}
