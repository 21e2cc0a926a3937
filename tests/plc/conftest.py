"""Helpers for the PLC tests: the robot-less ring benches and the ring rig's grip sequence."""
from pathlib import Path

import pytest

from stations.ring_rig_plc import plc_logic as ring_rig
from plc_client.scan import ScanCycle, TwinIO
from tests.conftest import STATIONS  # noqa: F401  (re-exported for the tests here)
from twin.core import Twin

HERE = Path(__file__).resolve().parent
BENCH = HERE / "stations" / "ring_bench"  # fingers at 330 mm around the ring: outside grips
BENCH_INSIDE = HERE / "stations" / "ring_bench_inside"  # fingers at 150 mm in the bore: inside grips
RING_FORCES = ("L2.force", "L3.force", "L5.force")


def ring_sequence(**overrides):
    """The ring rig's grip sequence (mm, N): outside grips touch at 320 mm, inside grips at 200 mm."""
    return ring_rig.sequence(**overrides)


class Bench:
    """A ring bench with the grip sequence on a scan cycle; the test plays the robot."""

    def __init__(self, station, seq=None, remove_ring=False):
        self.twin = Twin.from_station(station)
        if remove_ring:
            self.twin.remove_object("ring")
        self.seq = seq or ring_sequence()
        self.io = TwinIO(self.twin, local=self.seq.handshake_signals())
        self.plc = ScanCycle(self.io, self.seq)

    def request(self, name, inside=False):
        """The robot's side of the handshake: set the mode, drop the other request, raise this one."""
        self.io.set("grip_inside", inside)
        other = "release_request" if name == "grip_request" else "grip_request"
        self.io.set(other, False)
        self.io.set(name, True)

    def wait(self, *phases, timeout=10.0):
        return self.plc.run_until(lambda image, state: state.phase in phases, timeout=timeout)

    def out(self, name):
        return self.io.local[name]


@pytest.fixture
def bench():
    b = Bench(BENCH)
    yield b
    b.twin.close()


@pytest.fixture
def bench_inside():
    b = Bench(BENCH_INSIDE)
    yield b
    b.twin.close()
