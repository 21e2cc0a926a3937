"""The PLC layout of the register map, as a Modbus master PLC (OpenPLC's polling, measured in
/work/shared/reference/measured-facts.md) uses it: it writes its whole configured write ranges on every poll,
reads each table in its own request while the twin steps in between, and reads across everything it is
configured for. Real `twin serve --layout plc` subprocesses on loopback; the master's ranges are taken from
the generated slave-device configuration (`twin map --format openplc`), as a real master's would be."""
from __future__ import annotations

import re
import subprocess
import sys
import time

import pytest
from pymodbus.client import ModbusTcpClient

from modbus_helpers import ROOT, ServerProcess
from twin.core.signals import OWNERS, PLC
from twin.frontends.modbus.register_map import (COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER, TABLES, RegisterMap,
                                      build_map)

CELL = ROOT / "stations" / "ring_rig_plc"
RING_RIG = ROOT / "stations" / "ring_rig"


def twin(*args: str) -> str:
    return subprocess.run([sys.executable, "-m", "twin", *args], cwd=ROOT, capture_output=True, text=True,
                          check=True).stdout


def mbconfig(station) -> dict[str, int]:
    """The generated OpenPLC slave-device ranges: {'Coils_Start': 0, ...}."""
    return {k: int(v) for k, v in re.findall(r'^device0\.(\w+_(?:Start|Size)) = "(\d+)"$',
                                              twin("map", str(station), "--format", "openplc"), re.M)}


# -- the map, without a server ---------------------------------------------------------------------------
def test_what_the_plc_writes_is_one_block_per_table_from_0_holding_exactly_the_plcs_entries():
    rmap = build_map(CELL, "plc")
    cfg = mbconfig(CELL)
    for table, key in ((COIL, "Coils"), (HOLDING_REGISTER, "Holding_Registers")):
        start, size = cfg[f"{key}_Start"], cfg[f"{key}_Size"]
        inside = [e for e in rmap.table(table) if start <= e.address < start + size]
        assert sum(e.count for e in inside) == size  # no gap inside the block
        assert {e.name for e in inside} == {e.name for e in rmap.table(table) if e.owner == PLC}
    # the thesis cell's PLC: its answers to the robot, the gripper's enable and the fingers' setpoints; not the
    # operator's path signals, the program's start and stop, a part taken out of the cell, or the simulator's clock
    assert {e.name for e in rmap if e.owner == PLC} == {"Active", "diGripDone", "diGripOk", "diGripFault",
                                                         "L2", "L3", "L4", "L5"}
    for name, owner in (("ring.present", "simulator"), ("fullAutoRun", "operator"), ("rapid.start", "operator"),
                        ("sim.advance", "simulator"), ("doPrepare", "robot"), ("aoFingerReady", "robot"),
                        ("L2.force", "simulator")):
        assert rmap[name].owner == owner, name


def test_what_the_plc_reads_is_every_address_of_its_table_from_0_and_nothing_is_a_float():
    rmap = build_map(CELL, "plc")
    cfg = mbconfig(CELL)
    for table, key in ((DISCRETE_INPUT, "Discrete_Inputs"), (INPUT_REGISTER, "Input_Registers")):
        covered = sorted(a for e in rmap.table(table) for a in range(e.address, e.end))
        assert covered == list(range(rmap.size(table)))  # no gap anywhere
        assert (cfg[f"{key}_Start"], cfg[f"{key}_Size"]) == (0, rmap.size(table))
    assert rmap["sim.step"].table == INPUT_REGISTER and rmap["sim.step"].address == 0  # the step inside the block
    analogue = [e for e in rmap if e.type != "bool" and not e.name.startswith(("sim.", "comm."))]
    assert analogue and all(e.type in ("int16", "uint16", "int32") for e in analogue)  # ST INT, UINT, DINT
    # the robot's finger-ready position, a float32 on the signals layout, is counts of 0.01 mm: 123.45 mm = 12345
    assert build_map(CELL)["aoFingerReady"].type == "float32"
    assert rmap["aoFingerReady"].encode(123.45, engineering=True) == [0, 12345]
    # a 441 mm setpoint is 44100 counts: above an INT, so a UINT
    assert rmap["L2"].type == "uint16" and rmap["L2"].encode(441.0, engineering=True) == [44100]


def test_an_axis_the_robot_drives_is_the_robots_not_the_plcs():
    rmap = build_map(RING_RIG, "plc")  # the ring rig without a PLC: aoAxis1..3 drive L2..L4
    assert {rmap[n].owner for n in ("L2", "L3", "L4")} == {"robot"}
    assert rmap["Active"].owner == PLC and rmap["L5"].owner == PLC
    assert mbconfig(RING_RIG)["Holding_Registers_Size"] == sum(e.count for e in rmap.table(HOLDING_REGISTER)
                                                               if e.owner == PLC)


def test_every_entry_names_its_owner_in_json_csv_and_markdown():
    rmap = build_map(CELL, "plc")
    assert all(e.owner in OWNERS for e in rmap)
    back = RegisterMap.from_json(twin("map", str(CELL), "--layout", "plc", "--format", "json"))
    assert [(e.name, e.owner) for e in back] == [(e.name, e.owner) for e in rmap]
    csv = twin("map", str(CELL), "--layout", "plc", "--format", "csv").splitlines()
    assert csv[0].split(",")[-1] == "owner" and any(line.startswith("diGripDone,") and line.endswith(",plc") for line in csv)
    md = twin("map", str(CELL), "--layout", "plc")
    assert re.search(r"\| `diGripOk` \| bool \|.*\| rw \| plc \|", md)
    assert re.search(r"\| input \(read-only\) \| 0x8000 \| \d+ \| (\d+) \|", md)


# -- a master on a running server ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def cell_server():
    with ServerProcess(CELL, "--lockstep", "--layout", "plc", "--poll-hold", "5") as s:  # a loaded machine: slow steps
        yield s


def _client(port: int) -> ModbusTcpClient:
    c = ModbusTcpClient("127.0.0.1", port=port, timeout=5, retries=0)
    assert c.connect()
    return c


def _advance(c: ModbusTcpClient, rmap: RegisterMap, steps: int) -> None:
    adv = rmap["sim.advance"].address
    assert not c.write_register(adv, steps).isError()
    while c.read_holding_registers(adv, count=1).registers[0]:
        time.sleep(0.002)


def test_a_master_writing_its_whole_write_ranges_every_10_ms_changes_nothing_it_does_not_own(cell_server):
    rmap = build_map(CELL, "plc")
    cfg = mbconfig(CELL)
    operator, master, clock = (_client(cell_server.port) for _ in range(3))
    try:
        # the operator takes the ring out of the cell and sets the robot's full-auto switch
        assert not operator.write_coil(rmap["ring.present"].address, False).isError()
        assert not operator.write_coil(rmap["fullAutoRun"].address, True).isError()
        _advance(clock, rmap, 2)
        others = [e for e in rmap.table(COIL) + rmap.table(HOLDING_REGISTER) if e.owner != PLC and e.name != "sim.advance"]
        before = {e.name: _read(operator, e) for e in others}
        coils = [True] * cfg["Coils_Size"]
        words = [30000] * cfg["Holding_Registers_Size"]  # 300 mm, and L5 (0 .. 10 mm) gets its own below
        words[rmap["L5"].address - cfg["Holding_Registers_Start"]] = 500
        for _ in range(20):  # a poll every 10 ms: read, write every configured coil and register, the twin steps
            assert not master.read_discrete_inputs(0, count=cfg["Discrete_Inputs_Size"]).isError()
            assert not master.write_coils(cfg["Coils_Start"], coils).isError()
            assert not master.read_input_registers(0, count=cfg["Input_Registers_Size"]).isError()
            assert not master.write_registers(cfg["Holding_Registers_Start"], words).isError()
            _advance(clock, rmap, 1)
            time.sleep(0.010)
        assert {e.name: _read(operator, e) for e in others} == before
        assert before["ring.present"] is False and before["fullAutoRun"] is True
        ring_z = operator.read_input_registers(rmap["ring.z"].address, count=2).registers
        assert rmap["ring.z"].decode(ring_z) == pytest.approx(-100000.0)  # still out of the cell: parked far below
        assert _read(operator, rmap["diGripOk"]) is True and _read(operator, rmap["L2"]) == pytest.approx(300.0)
    finally:
        for c in (operator, master, clock):
            c.close()


def _read(c: ModbusTcpClient, e):
    if e.table == COIL:
        return c.read_coils(e.address, count=1).bits[0]
    return e.decode(c.read_holding_registers(e.address, count=e.count).registers)


def test_a_master_reading_in_three_requests_sees_one_step_while_the_twin_steps_between_them(cell_server):
    """OpenPLC reads discrete inputs, input registers and holding registers in separate requests; here the
    twin steps between each of them. Its pieces must all be of the step of its first read."""
    rmap = build_map(CELL, "plc")
    n_di, n_ir = rmap.size(DISCRETE_INPUT), rmap.size(INPUT_REGISTER)
    step_of = lambda regs: rmap["sim.step"].decode(regs[0:2])  # noqa: E731
    master, stepper, witness = (_client(cell_server.port) for _ in range(3))
    try:
        _advance(stepper, rmap, 5)
        for setpoint in (200.0, 300.0, 250.0):
            # a step's whole image, read by a witness while nothing steps: the reference
            ref_di = witness.read_discrete_inputs(0, count=n_di).bits
            ref_ir = witness.read_input_registers(0, count=n_ir).registers
            di = master.read_discrete_inputs(0, count=n_di).bits  # request 1
            # the twin steps: an axis starts moving, its position and in-position bit change
            assert not stepper.write_register(rmap["L2"].address, rmap["L2"].encode(setpoint, engineering=True)[0]).isError()
            _advance(stepper, rmap, 3)
            ir = master.read_input_registers(0, count=n_ir).registers  # request 2
            _advance(stepper, rmap, 1)
            hr = master.read_holding_registers(0, count=rmap.size(HOLDING_REGISTER)).registers  # request 3
            later = witness.read_input_registers(0, count=n_ir).registers  # what an unheld read gives now
            assert step_of(later) == step_of(ref_ir) + 4  # the twin did step between the master's requests
            assert di[:n_di] == ref_di[:n_di] and ir == ref_ir  # yet every piece is of the first read's step
            a = rmap["L2.actual"]
            assert a.decode(later[a.address:a.end]) != a.decode(ir[a.address:a.end])  # and that step differs
            assert rmap["L2"].decode(hr[rmap["L2"].address:rmap["L2"].end]) == pytest.approx(setpoint)  # written
            # the next poll starts with a read it already made (its discrete inputs): the step as it is now
            assert master.read_discrete_inputs(0, count=n_di).bits[:n_di] == witness.read_discrete_inputs(0, count=n_di).bits[:n_di]
            assert master.read_input_registers(0, count=n_ir).registers == later
    finally:
        for c in (master, stepper, witness):
            c.close()


def test_a_client_that_waits_for_steps_reads_the_new_step(cell_server):
    """A lockstep script polls sim.advance until its steps are done: its next reads are of the step they led to,
    even if it (or its heartbeat) read something of an earlier step just before."""
    rmap = build_map(CELL, "plc")
    script, stepper = _client(cell_server.port), _client(cell_server.port)
    try:
        before = rmap["sim.step"].decode(script.read_input_registers(0, count=2).registers)  # holds this step
        _advance(stepper, rmap, 3)  # someone else steps
        script.read_holding_registers(rmap["sim.advance"].address, count=1)  # the script sees the steps done
        ir = script.read_input_registers(2, count=2).registers  # sim.time_ms: not read before, of the new step
        assert rmap["sim.time_ms"].decode(ir) == round((before + 3) * 12)  # 12 ms steps
    finally:
        script.close()
        stepper.close()


def test_reads_of_every_configured_range_never_get_an_exception(cell_server):
    cfg = mbconfig(CELL)
    c = _client(cell_server.port)
    try:
        for _ in range(3):
            assert not c.read_discrete_inputs(cfg["Discrete_Inputs_Start"], count=cfg["Discrete_Inputs_Size"]).isError()
            assert not c.read_input_registers(cfg["Input_Registers_Start"], count=cfg["Input_Registers_Size"]).isError()
            assert not c.read_holding_registers(0, count=build_map(CELL, "plc").size(HOLDING_REGISTER)).isError()
    finally:
        c.close()


def test_the_served_map_is_the_json_map_twin_map_prints(cell_server):
    """Function 20 (read file record): the CRC, the length, then `twin map --layout plc --format json`, over
    files 1, 2, ... of 10000 records (the spec's record numbers end at 9999)."""
    import struct

    from pymodbus.pdu.file_message import FileRecord

    def read(k: int, n: int):  # record k of the document
        return c.read_file_record([FileRecord(file_number=1 + k // 10000, record_number=k % 10000, record_length=2 * n)])

    c = _client(cell_server.port)
    try:
        crc, length = struct.unpack(">II", read(0, 4).records[0].record_data)
        assert length > 20000  # this map takes more than file 1
        data = b""
        while len(data) < length:
            k = 4 + len(data) // 2
            data += read(k, min(124, (length - len(data) + 1) // 2, 10000 - k % 10000)).records[0].record_data
        assert data[:length].decode() == twin("map", str(CELL), "--layout", "plc", "--format", "json")
        crc_words = c.read_input_registers(build_map(CELL, "plc")["sim.map_crc"].address, count=2).registers
        assert crc == build_map(CELL, "plc").crc == crc_words[0] << 16 | crc_words[1]
        past = read(4 + (length + 1) // 2, 1)
        assert past.isError() and past.exception_code == 2
        across = c.read_file_record([FileRecord(file_number=1, record_number=9999, record_length=4)])  # into file 2
        assert across.isError() and across.exception_code == 2
    finally:
        c.close()


def test_plc_reads_a_signal_by_name_with_no_station_files_and_notices_a_changed_map():
    from plc_client.client import fetch_map

    bench = ROOT / "tests" / "plc" / "stations" / "ring_bench"
    with ServerProcess(bench, "--lockstep") as first:
        port = first.port
        out = subprocess.run([sys.executable, "-m", "plc_client", "--port", str(port), "read", "L2.actual", "GrippedPart"],
                             cwd=ROOT, capture_output=True, text=True)
        one = fetch_map(port=port)
    assert out.returncode == 0, out.stderr
    assert re.search(r"^L2\.actual\s+330\s+mm$", out.stdout, re.M)  # the bench's initial 0.33 m
    assert re.search(r"^GrippedPart\s+0\s+\(none\)$", out.stdout, re.M)
    with ServerProcess(bench, "--lockstep", "--layout", "plc", port=str(port)) as second:
        two = fetch_map(port=second.port)
        out = subprocess.run([sys.executable, "-m", "plc_client", "--port", str(port), "read", "L2.actual"],
                             cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert re.search(r"^L2\.actual\s+330\s+mm$", out.stdout, re.M)
    assert one.crc != two.crc and one["L2.actual"].address != two["L2.actual"].address
    assert two.as_list() == build_map(bench, "plc").as_list() and one.as_list() == build_map(bench).as_list()
