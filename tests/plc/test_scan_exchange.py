"""A PLC scan over Modbus exchanges its process image in at most two requests (one in lockstep: a
function 23 that writes the outputs and sim.advance and reads the inputs after the steps), and sees the
same values as signal-by-signal reads and the same process as the in-process run."""
from __future__ import annotations

import pytest

from plc_client import ClientIO, ScanCycle
from plc_client.scan import TwinIO
from plc_client.testing import twin_server
from tests.plc.conftest import BENCH
from twin.core import Twin

INPUTS = ("L2.actual", "L3.actual", "L4.actual", "doGripped", "GrippedPart", "L2.force", "L2.in_position",
          "Active", "ring.present", "L2")


def close_at(t):
    """Close the three fingers to 300 mm after 50 ms, open to 330 mm after 600 ms."""
    if t < 0.05:
        return {}
    v = 300.0 if t < 0.6 else 330.0
    return {"L2": v, "L3": v, "L4": v}


def logic(inputs, state):
    return close_at(inputs.time)


logic.inputs = INPUTS


@pytest.fixture(scope="module")
def server():
    with twin_server(BENCH, lockstep=True) as s:
        yield s


def test_a_lockstep_scan_takes_one_request_and_reads_what_signal_by_signal_reads_give(server):
    with server.client() as c:
        io = ClientIO(c)
        assert io.exchange
        plc = ScanCycle(io, logic, cycle=0.012)
        before = c.requests
        plc.run(scans=80)
        per_scan = (c.requests - before) / 80
        assert per_scan <= 1.05, per_scan  # one function 23 a scan (and one read before the first)
        image = dict(plc.image)
        plc.io.advance(0)  # nothing more: the process stands (lockstep)
        assert io._read(list(INPUTS)) == image  # the window as read after the last steps ...
        assert c.read(*INPUTS) == image | {"L2": plc.written["L2"]}  # ... is what the plain reads show


def test_the_same_logic_over_modbus_moves_the_process_as_in_process(server):
    with server.client() as c:
        c.write(L2=330.0, L3=330.0, L4=330.0)
        start = c.get("sim.step")
        plc = ScanCycle(ClientIO(c), logic, cycle=0.012)
        plc.run(scans=90)
        remote = c.read("L2.actual", "L3.actual", "L2.force", "doGripped")
        steps = c.get("sim.step") - start
    with Twin.from_station(BENCH) as twin:
        twin.write("L2", 0.33), twin.write("L3", 0.33), twin.write("L4", 0.33)
        twin.step(start)
        local = ScanCycle(TwinIO(twin), logic, cycle=0.012)
        local.run(scans=90)
        assert twin.step_count - start == steps
        assert remote["doGripped"] == twin.read("doGripped")
        assert remote["L2.actual"] == pytest.approx(twin.read("L2.actual") * 1000, abs=0.011)
        assert remote["L2.force"] == pytest.approx(twin.read("L2.force"), abs=0.011)


def test_a_real_time_scan_takes_at_most_two_requests():
    with twin_server(BENCH, lockstep=False) as srv, srv.client() as c:
        plc = ScanCycle(ClientIO(c), logic, cycle=0.02)
        before = c.requests
        plc.run(scans=40)
        assert (c.requests - before) / 40 <= 2.0
        assert c.read("L2")["L2"] == 300.0 or plc.time >= 0.6
