"""`twin map --format st` and `--format openplc`: the PLC's declarations and its master's slave device, checked
against the register map and OpenPLC's located-variable convention (the first slave device's discrete inputs
at %IX100.0 upward, eight to a byte; coils at %QX100.0; input registers, then holding registers read, at
%IW100; holding registers written at %QW100; each counted from its range's start), and against the rules a
strict IEC 61131-3 2nd-edition compiler (matiec) enforces."""
from __future__ import annotations

import re
import subprocess
import sys

import pytest

from modbus_helpers import ROOT
from twin.frontends.modbus.plc_export import RESERVED, st_name
from twin.frontends.modbus.register_map import COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER, build_map

CELL = ROOT / "stations" / "ring_rig_plc"
IDENT = re.compile(r"^[A-Za-z](?:_?[A-Za-z0-9])*$")  # IEC 61131-3: no leading digit, no double or trailing _
DECL = re.compile(r"^\s*(\w+) AT %([IQ])([XW])(\d+)(?:\.(\d))? : (\w+);", re.M)


def twin_map(*args: str) -> str:
    return subprocess.run([sys.executable, "-m", "twin", "map", str(CELL), *args], cwd=ROOT, capture_output=True,
                          text=True, check=True).stdout


def ranges() -> dict[str, int]:
    text = twin_map("--format", "openplc")
    return {k: int(v) for k, v in re.findall(r'^device0\.(\w+) = "(\d+)"$', text, re.M)}


def test_every_signal_a_master_moves_is_declared_where_its_range_puts_it():
    rmap, cfg = build_map(CELL, "plc"), ranges()
    decls = {name: (io, size, int(byte), None if bit == "" else int(bit), t)
             for name, io, size, byte, bit, t in DECL.findall(twin_map("--format", "st"))}
    seen = set()
    for e in rmap:
        if e.table == DISCRETE_INPUT:
            n = e.address - cfg["Discrete_Inputs_Start"]
            want = [("I", "X", 100 + n // 8, n % 8, "BOOL")]
        elif e.table == COIL:
            n = e.address - cfg["Coils_Start"]
            if not 0 <= n < cfg["Coils_Size"]:
                continue  # not the PLC's: never written by it
            want = [("Q", "X", 100 + n // 8, n % 8, "BOOL")]
        elif e.table == INPUT_REGISTER:
            n = e.address - cfg["Input_Registers_Start"]
            want = [("I", "W", 100 + n + k, None, None) for k in range(e.count)]
        else:
            n = e.address - cfg["Holding_Registers_Start"]
            if not 0 <= n < cfg["Holding_Registers_Size"]:
                continue
            want = [("Q", "W", 100 + n + k, None, None) for k in range(e.count)]
        names = [st_name(e.name)] if e.count == 1 else [st_name(e.name) + "_HI", st_name(e.name) + "_LO"]
        for name, (io, size, byte, bit, t) in zip(names, want):
            got = decls[name]
            assert got[:4] == (io, size, byte, bit), (e.name, got)
            if t is None:  # a word: UINT or INT as the value's range needs, the low word of a 32-bit always UINT
                t = {"uint16": "UINT", "int16": "INT", "uint32": "UINT", "int32": "INT"}[e.type]
                t = "UINT" if name.endswith("_LO") else t
            assert got[4] == t, (e.name, got)
            seen.add(name)
    assert seen == set(decls)  # nothing else is located
    # a uint16 setpoint up to 44100 counts is a UINT (an INT would overflow above 327.67 mm)
    assert decls["L2"] == ("Q", "W", 100 + rmap["L2"].address, None, "UINT")


def test_the_declarations_obey_a_strict_compiler():
    text = twin_map("--format", "st")
    names = [m[0] for m in DECL.findall(text)]
    assert names and all(IDENT.match(n) and n.upper() not in RESERVED for n in names)
    assert len({n.upper() for n in names}) == len(names)  # identifiers are case-insensitive
    code = re.sub(r"\(\*.*?\*\)", "", text, flags=re.S)
    assert not re.search(r";\s*;", code) and not re.search(r"^\s*;", code, re.M)  # no empty statement
    blocks = re.findall(r"(VAR\w*(?: CONSTANT)?)\s(.*?)END_VAR", code, re.S)
    for kind, body in blocks:  # located and ordinary variables never share a block
        decls = [line for line in body.splitlines() if ":" in line]
        located = [d for d in decls if " AT %" in d]
        assert not located or len(located) == len(decls), kind
    crc = build_map(CELL, "plc").crc
    assert f"MAP_CRC : UDINT := 16#{crc:08X};" in code
    assert f"MAP_CRC_HI : UINT := 16#{crc >> 16:04X};" in code and f"MAP_CRC_LO : UINT := 16#{crc & 0xFFFF:04X};" in code
    assert "mm_PER_COUNT : REAL := 0.01;" in code and "COUNTS_PER_mm : DINT := 100;" in code
    assert re.search(r"PROGRAM plc WITH cycle : main;", code) and "PROGRAM main" in code
    named = twin_map("--format", "st", "--program", "gripper")
    assert "PROGRAM plc WITH cycle : gripper;" in named and "PROGRAM main" not in named


def test_a_signals_name_becomes_a_legal_identifier():
    for name, ident in (("L2.actual", "L2_actual"), ("sim.map_crc", "sim_map_crc"), ("STEP", "STEP_sig"),
                        ("limit", "limit_sig"), ("Ramp", "Ramp_sig"), ("a..b", "a_b"), ("3rd.finger", "s_3rd_finger"),
                        ("left", "left_sig"), ("x-y z", "x_y_z")):
        assert st_name(name) == ident
        assert IDENT.match(ident) and ident.upper() not in RESERVED


def test_the_slave_device_has_the_maps_ranges_and_the_options_given():
    rmap = build_map(CELL, "plc")
    text = twin_map("--format", "openplc", "--address", "10.0.0.7", "--port", "502", "--unit-id", "3",
                    "--polling-ms", "20")
    for line in ('Num_Devices = "1"', 'Polling_Period = "20"', 'device0.protocol = "TCP"',
                 'device0.address = "10.0.0.7"', 'device0.IP_Port = "502"', 'device0.slave_id = "3"'):
        assert line in text.splitlines()
    cfg = {k: int(v) for k, v in re.findall(r'^device0\.(\w+) = "(\d+)"$', text, re.M)}
    plc_coils = [e for e in rmap.table(COIL) if e.owner == "plc"]
    plc_regs = [e for e in rmap.table(HOLDING_REGISTER) if e.owner == "plc"]
    assert (cfg["Coils_Start"], cfg["Coils_Size"]) == (0, len(plc_coils))
    assert (cfg["Holding_Registers_Start"], cfg["Holding_Registers_Size"]) == (0, sum(e.count for e in plc_regs))
    assert (cfg["Discrete_Inputs_Start"], cfg["Discrete_Inputs_Size"]) == (0, rmap.size(DISCRETE_INPUT))
    assert (cfg["Input_Registers_Start"], cfg["Input_Registers_Size"]) == (0, rmap.size(INPUT_REGISTER))
    assert cfg["Holding_Registers_Read_Size"] == 0


def test_the_st_formats_refuse_the_signals_layout():
    out = subprocess.run([sys.executable, "-m", "twin", "map", str(CELL), "--format", "st", "--layout", "signals"],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 2 and "--layout plc" in out.stderr


def test_a_located_variable_the_master_does_not_serve_or_whose_type_cannot_hold_its_register_is_named():
    from twin.frontends.modbus.plc_export import located_problem

    rmap, cfg = build_map(CELL, "plc"), ranges()
    last_di = cfg["Discrete_Inputs_Size"] - 1
    ok = [("I", "X", (100 + last_di // 8, last_di % 8), "BOOL"), ("Q", "W", (100 + rmap["L2"].address,), "UINT"),
          ("Q", "W", (100 + rmap["L5"].address,), "INT"),  # 0 .. 10 mm is 0 .. 1000 counts: an INT holds it
          ("M", "W", (7,), "REAL")]  # memory is not the master's business
    for loc in ok:
        assert located_problem(rmap, *loc) is None, loc
    past = cfg["Discrete_Inputs_Size"]
    bad = {("I", "X", (100 + past // 8, past % 8), "BOOL"): "no signal there",  # one past the last discrete input
           ("Q", "X", (100, cfg["Coils_Size"]), "BOOL"): "no signal there",  # the operator's coils are not the PLC's
           ("Q", "W", (100 + rmap["L2"].address,), "INT"): "L2",  # 44100 counts above an INT
           ("I", "W", (100 + rmap["L2.actual"].address,), "REAL"): "L2.actual",  # a float on a 16-bit register
           ("I", "D", (100,), "DINT"): "two %IW words",  # a master has no 32-bit locations
           ("I", "X", (100, 0), "INT"): "fault"}
    for loc, named in bad.items():
        problem = located_problem(rmap, *loc)
        assert problem is not None and named in problem, (loc, problem)
    assert "44100" in located_problem(rmap, "Q", "W", (100 + rmap["L2"].address,), "INT")


def _plc(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "plc_client", *args], cwd=ROOT, capture_output=True, text=True)


def test_the_declarations_pass_plc_check_alone_and_with_a_program_that_uses_them(tmp_path):
    alone = tmp_path / "io.st"
    alone.write_text(twin_map("--format", "st"))
    out = _plc("check", str(alone))
    assert out.returncode == 0, out.stderr
    (tmp_path / "io.st").write_text(twin_map("--format", "st", "--program", "gripper"))
    (tmp_path / "gripper.st").write_text(GRIPPER)
    out = _plc("check", str(tmp_path / "gripper.st"), str(tmp_path / "io.st"))
    assert out.returncode == 0, out.stderr


GRIPPER = """PROGRAM gripper
  VAR_EXTERNAL
    doPrepare : BOOL;
    diGripDone : BOOL;
    L2 : UINT;
    L2_actual : UINT;
    L2_force_HI : INT;
    L2_force_LO : UINT;
  END_VAR
  VAR_EXTERNAL CONSTANT
    COUNTS_PER_N : DINT;
  END_VAR
  VAR
    force : DINT;
  END_VAR
  force := INT_TO_DINT(L2_force_HI) * 65536 + UINT_TO_DINT(L2_force_LO);
  IF doPrepare THEN
    L2 := L2_actual;
  END_IF;
  diGripDone := force > 100 * COUNTS_PER_N;
END_PROGRAM
"""


def test_the_ring_rigs_shipped_declarations_and_slave_device_are_what_twin_map_generates():
    """stations/ring_rig_plc/io.st and mbconfig.cfg go with gripper.st to a real PLC: they must be current."""
    assert (CELL / "io.st").read_text() == twin_map("--format", "st", "--program", "gripper").replace(
        str(CELL), "stations/ring_rig_plc")
    assert (CELL / "mbconfig.cfg").read_text() == twin_map("--format", "openplc")
