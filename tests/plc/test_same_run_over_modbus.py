"""The gripper PLC of the ring rig in process and over Modbus/TCP (`twin serve --lockstep` on loopback, one
function 23 a scan): reading and writing the cell through the register map's resolution in process
(`TwinIO(..., wire=map)`), the PLC sees and does exactly what it sees and does over the wire, so the two are
the same run, bit for bit: every signal and every body's pose at every step, both recorded (`--record`)."""
from __future__ import annotations

import numpy as np
import pytest

from plc_client.client import ClientIO
from plc_client.scan import Combined, ScanCycle, TwinIO
from plc_client.testing import twin_server
from stations.ring_rig_plc.demo import DEFAULT_STATION as STATION, ST_FILES, operator
from twin.observe.recording import Recording, record
from twin_app.cell import Cell


def gripper_plc(kind: str, rmap):
    if kind == "python":
        from stations.ring_rig_plc.plc_logic import cell_sequence

        return cell_sequence()
    from plc_client.st_io import StLogic

    return StLogic([STATION / f for f in ST_FILES], rmap)


def scan(io, kind: str, rmap, scans: int) -> list:
    """`scans` scans of the gripper PLC and the operator; the grip sequence's phases as they came."""
    logic = Combined(gripper_plc(kind, rmap), operator(1))
    plc = ScanCycle(io, logic, cycle=0.010)
    phases = []
    for _ in range(scans):
        plc.scan()
        state = plc.state[0]
        phase = int(state.phase) if kind == "python" else int(state.get(f"{logic.logics[0].instance}.phase"))
        if not phases or phases[-1] != phase:
            phases.append(phase)
    return phases


# 520 scans: the Python PLC prepares the fingers, grips the ring, holds it while the robot carries it and
# lets it go (scan 467); the ST PLC's 300 scans reach its grip
@pytest.mark.parametrize("kind, scans", [("python", 520), ("st", 300)])
def test_the_plc_over_modbus_runs_the_same_cell_as_in_process_bit_for_bit(tmp_path, kind, scans):
    layout = "plc" if kind == "st" else ""
    remote_file, local_file = tmp_path / "over_modbus.parquet", tmp_path / "in_process.parquet"
    with twin_server(STATION, lockstep=True, layout=layout, extra_args=["--record", str(remote_file)]) as server:
        with server.client() as client:
            remote_phases = scan(ClientIO(client, lockstep=True), kind, server.map, scans)
            remote_steps = client.get("sim.step")
    with Cell(STATION, layout=layout) as cell, record(cell.twin, local_file):
        local_phases = scan(TwinIO(cell, wire=cell.register_map), kind, cell.register_map, scans)
        assert cell.step_count == remote_steps
    assert len(local_phases) >= 3 and local_phases == remote_phases  # the grip went through its phases alike
    remote, local = Recording.open(remote_file), Recording.open(local_file)
    assert len(remote) == len(local) == remote_steps + 1
    names = set(local.names)
    assert {"ring.x", "L2.actual", "L2.force"} <= names and any(n.startswith("pose:") for n in names)
    assert names <= set(remote.names)
    for name in sorted(names):
        a, b = local.column(name), remote.column(name)
        assert np.array_equal(a, b), f"{name}: first differs at step {int(np.argmax(a != b))}"
