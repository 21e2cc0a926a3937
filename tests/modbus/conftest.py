"""Fixtures: a real `twin serve` subprocess (lockstep, ring bench) and a raw socket to it."""
from __future__ import annotations

import pytest

from modbus_helpers import RING_BENCH, Raw, ServerProcess


@pytest.fixture(scope="module")
def lockstep_server():
    with ServerProcess(RING_BENCH, "--lockstep", "--frame-timeout", "0.3") as s:
        yield s


@pytest.fixture
def raw(lockstep_server):
    with Raw(lockstep_server.port) as r:
        yield r
