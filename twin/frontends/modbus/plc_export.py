"""What a Modbus-master PLC needs from a register map: its I/O declarations in Structured Text and its
slave-device configuration (`twin map STATION --format st | openplc`).

Both are derived from the map's PLC layout and `register_map.master_ranges` alone, so the addresses in the
declarations are those the master's ranges put them at. The convention is OpenPLC v3's (measured against a
real runtime, /work/shared/reference/measured-facts.md): for the first slave device, its discrete inputs
land at `%IX100.0` upward (eight to a byte), its coils at `%QX100.0`, its input registers and then its
holding registers read at `%IW100` upward, its holding registers written at `%QW100`, each range counted
from its own start. Registers are 16 bits there (no `%ID` from Modbus): a 32-bit value is two located words,
`NAME_HI` (high word first, as the map sends it) and `NAME_LO`.

The declarations are strict IEC 61131-3 2nd edition, as matiec compiles them: a CONFIGURATION whose
VAR_GLOBAL holds the located variables and whose VAR_GLOBAL CONSTANT the scales and the map's CRC (located
and ordinary variables never share a block), one RESOURCE with one cyclic TASK running the program named by
`program`. Names are the signals' with every character an identifier may not hold mapped to `_` (dots
included), never a reserved word or a standard function or block's name. Without `program`, a minimal
PROGRAM `main` comes along so the file compiles on its own; with it, the file goes after that program's
source (OpenPLC compiles one file: `cat gripper.st io.st > upload.st`).
"""
from __future__ import annotations

import re

from .register_map import (BIT_TABLES, COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER, MAP_CRC, Entry,
                           MapError, MasterRange, RegisterMap, master_ranges)

ST_TYPES = {"bool": "BOOL", "uint16": "UINT", "int16": "INT", "uint32": "UDINT", "int32": "DINT", "float32": "REAL"}
# Reserved in IEC 61131-3 (2nd and 3rd edition keywords, elementary and generic type names, standard functions and
# function blocks) or by matiec's library (RAMP, PID, ...): none may name a variable.
RESERVED = frozenset("""
ACTION END_ACTION ARRAY OF AT CASE ELSE END_CASE CONFIGURATION END_CONFIGURATION CONSTANT EN ENO EXIT FALSE F_EDGE
FOR TO BY DO END_FOR FUNCTION END_FUNCTION FUNCTION_BLOCK END_FUNCTION_BLOCK IF THEN ELSIF END_IF INITIAL_STEP
NOT OR XOR AND MOD PROGRAM WITH END_PROGRAM R_EDGE READ_ONLY READ_WRITE REPEAT UNTIL END_REPEAT RESOURCE ON
END_RESOURCE RETAIN NON_RETAIN RETURN STEP END_STEP STRUCT END_STRUCT TASK TRANSITION FROM END_TRANSITION TRUE
TYPE END_TYPE VAR END_VAR VAR_INPUT VAR_OUTPUT VAR_IN_OUT VAR_TEMP VAR_EXTERNAL VAR_ACCESS VAR_CONFIG VAR_GLOBAL
WHILE END_WHILE CONTINUE METHOD END_METHOD INTERFACE END_INTERFACE PROPERTY END_PROPERTY CLASS END_CLASS EXTENDS
IMPLEMENTS THIS SUPER ABSTRACT FINAL OVERRIDE PRIVATE PROTECTED PUBLIC INTERNAL NAMESPACE END_NAMESPACE USING
REF_TO REF REFERENCE POINTER JMP NULL
BOOL SINT INT DINT LINT USINT UINT UDINT ULINT REAL LREAL TIME DATE TIME_OF_DAY TOD DATE_AND_TIME DT STRING WSTRING
BYTE WORD DWORD LWORD LTIME LDATE LTOD LDT CHAR WCHAR ANY ANY_DERIVED ANY_ELEMENTARY ANY_MAGNITUDE ANY_NUM ANY_REAL
ANY_INT ANY_BIT ANY_STRING ANY_DATE
ABS SQRT LN LOG EXP SIN COS TAN ASIN ACOS ATAN EXPT ADD SUB MUL DIV MOVE SHL SHR ROL ROR SEL MAX MIN LIMIT MUX
GT GE EQ LE LT NE LEN LEFT RIGHT MID CONCAT INSERT DELETE REPLACE FIND TRUNC
TON TOF TP R_TRIG F_TRIG CTU CTD CTUD SR RS SEMA RTC RAMP PID HYSTERESIS INTEGRAL DERIVATIVE
""".split())
_BAD = re.compile(r"[^A-Za-z0-9]+")


def st_name(name: str) -> str:
    """A signal's name as an ST identifier: letters, digits and single underscores, not starting with a digit,
    never reserved (`axis1.actual` -> `axis1_actual`, `STEP` -> `STEP_sig`)."""
    ident = _BAD.sub("_", name).strip("_") or "signal"
    if ident[0].isdigit():
        ident = "s_" + ident
    if ident.upper() in RESERVED:
        ident += "_sig"
    return ident


class Located:
    """One located variable: a bit, a 16-bit register, or one word of a 32-bit value."""

    def __init__(self, name: str, address: str, st_type: str, entry: Entry, word: str = ""):
        self.name, self.address, self.st_type, self.entry, self.word = name, address, st_type, entry, word


def _area(r: MasterRange) -> str:
    return {"Discrete_Inputs": "IX", "Coils": "QX", "Input_Registers": "IW",
            "Holding_Registers_Read": "IW", "Holding_Registers": "QW"}[r.key]


def located_variables(rmap: RegisterMap) -> list[Located]:
    """Every entry a master PLC reads or writes, as located variables in OpenPLC's convention (module docstring),
    in the order of the master's ranges. MapError when the map is not the PLC layout."""
    ranges = master_ranges(rmap)
    out, used, next_word = [], {}, {"IX": 0, "QX": 0, "IW": 0, "QW": 0}

    def unique(ident: str, entry: Entry) -> str:
        key, n = ident.upper(), 2
        while key in used:
            ident, n = f"{st_name(entry.name)}_{n}", n + 1
            key = ident.upper()
        used[key] = entry.name
        return ident

    for r in ranges:
        area = _area(r)
        base = next_word[area]
        for e in sorted(r.entries, key=lambda e: e.address):
            n = base + e.address - r.start
            ident = st_name(e.name)
            if e.table in BIT_TABLES:
                out.append(Located(unique(ident, e), f"%{area}{100 + n // 8}.{n % 8}", "BOOL", e))
            elif e.count == 1:
                out.append(Located(unique(ident, e), f"%{area}{100 + n}", ST_TYPES[e.type], e))
            else:
                if e.type == "float32":
                    raise MapError(f"{e.name}: a float32 cannot be declared for a PLC (the PLC layout has none)")
                high = "INT" if e.type == "int32" else "UINT"
                out.append(Located(unique(ident + "_HI", e), f"%{area}{100 + n}", high, e, "HI"))
                out.append(Located(unique(ident + "_LO", e), f"%{area}{100 + n + 1}", "UINT", e, "LO"))
        next_word[area] = base + r.size
    return out


# What each ST type holds, for a located variable over a register (ST elementary integer and bit-string types).
ST_RANGES = {"SINT": (-128, 127), "USINT": (0, 255), "BYTE": (0, 255), "INT": (-32768, 32767), "UINT": (0, 65535),
             "WORD": (0, 65535)}
_WHERE = {"IX": "discrete inputs", "QX": "coils", "IW": "input registers (then holding registers read)",
          "QW": "holding registers written"}


def located_problem(rmap: RegisterMap, area: str, size: str, indexes: tuple[int, ...], st_type: str) -> str | None:
    """Why a located variable `%<area><size><indexes>` of type `st_type` does not fit what a Modbus master reads
    and writes on this map (the device ranges of `master_ranges`, OpenPLC's convention), naming the signal; None
    when it fits, and for memory (`%M`). The ST checker's hook to the map: `plc check` reports the message at the
    variable's position. A located variable outside the ranges, a bit at a word, a 32-bit location (a master has
    none), or a type that cannot hold the register's values (REAL on a 16-bit register; INT on a uint16 above
    32767 counts) is a problem."""
    area, size, st_type = area.upper(), (size or "X").upper(), st_type.upper()
    if area not in ("I", "Q"):
        return None
    at = f"%{area}{size}" + ".".join(str(i) for i in indexes)
    if size not in ("X", "W"):
        return (f"{at}: a Modbus master's slave device gives bits (%{area}X) and 16-bit registers (%{area}W) only; "
                f"a 32-bit value is two %{area}W words, NAME_HI and NAME_LO (`twin map --format st`)")
    variables = located_variables(rmap)
    found = next((v for v in variables if v.address == at), None)
    if found is None:
        same = [v.address for v in variables if v.address.startswith(f"%{area}{size}")]
        span = f"{same[0]} .. {same[-1]}" if same else "none"
        return (f"{at}: no signal there: the device's {_WHERE[area + size]} on this map are {span} "
                f"(`twin map --format st` declares every one)")
    e = found.entry
    what = f"{e.name} ({_where(e)} {e.address}{'' if e.count == 1 else f'-{e.end - 1}'}, {e.type})"
    if size == "X":
        return None if st_type == "BOOL" else f"{at} is {what}: a bit, declare it BOOL, not {st_type}"
    if st_type not in ST_RANGES:
        return (f"{at} is {what}: a 16-bit register cannot be a {st_type}"
                + ("; a 32-bit value is two words, NAME_HI and NAME_LO" if e.count == 2 else "")
                + f" (declare it {found.st_type})")
    lo, hi = _word_range(e, found.word)
    tlo, thi = ST_RANGES[st_type]
    if st_type != "WORD" and not (tlo <= lo and hi <= thi):
        which = {"HI": "its high word carries ", "LO": "its low word carries "}.get(found.word, "")
        return (f"{at} is {what}: {which}{lo} .. {hi}, a{'n' if st_type[0] in 'AEIOU' and st_type != 'UINT' else ''} "
                f"{st_type} holds {tlo} .. {thi} (declare it {found.st_type})")
    return None


def _where(e: Entry) -> str:
    return {COIL: "coil", DISCRETE_INPUT: "discrete input", INPUT_REGISTER: "input register",
            HOLDING_REGISTER: "holding register"}[e.table]


def _word_range(e: Entry, word: str) -> tuple[int, int]:
    """The values a register (or one word of a 32-bit value) carries, as a 16-bit integer."""
    if word == "LO":
        return 0, 0xFFFF
    lo, hi = e.count_range
    if word == "HI":
        lo, hi = int(lo) >> 16, int(hi) >> 16  # the high word of a 32-bit value, sign included
        return lo, hi
    return int(lo), int(hi)


def _comment(text: str) -> str:
    return "(* " + text.replace("(*", "( *").replace("*)", "* )") + " *)"


def _describe(v: Located) -> str:
    e = v.entry
    where = {COIL: "coil", DISCRETE_INPUT: "discrete input", INPUT_REGISTER: "input register",
             HOLDING_REGISTER: "holding register"}[e.table]
    words = f"{e.address}" if e.count == 1 else f"{e.address}-{e.end - 1}"
    parts = [f"{e.name}: {where} {words}", ST_TYPES[e.type] if e.type != "bool" else "BOOL"]
    if v.word:
        parts.append(f"{'high' if v.word == 'HI' else 'low'} word of a {e.type}")
    if e.type != "bool":
        parts.append(f"value = counts x {e.scale:g}{' ' + e.unit if e.unit else ''}" if e.scale != 1 or e.unit
                     else "counts")
        if e.min is not None or e.max is not None:
            lo = "" if e.min is None else f"{e.min:.10g}"
            hi = "" if e.max is None else f" {e.max:.10g}"
            parts.append(f"range {lo} ..{hi}{' ' + e.unit if e.unit else ''}".replace("  ", " "))
    if e.choices:
        parts.append(", ".join(f"{i} = {c or 'none'}" for i, c in enumerate(e.choices)))
    parts.append(f"owner {e.owner}" if e.owner else "")
    return "; ".join(p for p in parts if p)


def scale_constants(rmap: RegisterMap, variables: list[Located]) -> list[tuple[str, str, str, str]]:
    """(name, type, value, comment) per unit and scale the declared registers use: UNIT_PER_COUNT (REAL) and
    COUNTS_PER_UNIT (DINT, when the scale is a whole fraction)."""
    seen, out = set(), []
    for v in variables:
        e = v.entry
        if e.type == "bool" or e.scale == 1 or (e.unit, e.scale) in seen:
            continue
        seen.add((e.unit, e.scale))
        unit = st_name(e.unit.replace("*", "_").replace("%", "pct")) if e.unit else "UNIT"
        out.append((f"{unit}_PER_COUNT", "REAL", f"{e.scale:.10g}" if "." in f"{e.scale:.10g}" or "e" in f"{e.scale:.10g}"
                    else f"{e.scale:.10g}.0", f"{e.unit or 'units'} per count"))
        per = 1 / e.scale
        if abs(per - round(per)) < 1e-9 and round(per) > 1:
            out.append((f"COUNTS_PER_{unit}", "DINT", str(round(per)), f"counts per {e.unit or 'unit'}"))
    return out


def to_structured_text(rmap: RegisterMap, *, program: str | None = None, task_ms: int = 10,
                       serve: str = "twin serve STATION --layout plc") -> str:
    """The declarations file (see the module docstring)."""
    variables = located_variables(rmap)
    ranges = master_ranges(rmap)
    crc = rmap.crc
    lines = [_comment(f"I/O of station '{rmap.station}' for a Modbus master PLC: generated by `twin map --format st` "
                      "from the register map's PLC layout; do not edit."),
             _comment(f"The twin: `{serve}`; the master's slave device: `twin map STATION --format openplc` "
                      "(OpenPLC v3 mbconfig.cfg)."),
             _comment(f"Register map CRC-32 {crc:08X} (sim.map_crc): compare sim_map_crc_HI/_LO with MAP_CRC_HI/_LO "
                      "to know the twin serves this map."),
             _comment("32-bit values are two words, high word first: v := INT_TO_DINT(x_HI) * 65536 + "
                      "UINT_TO_DINT(x_LO) (UINT_TO_UDINT for an unsigned x_HI)."),
             _comment("Device ranges: " + "; ".join(f"{r.key} start {r.start} size {r.size}" for r in ranges)), ""]
    prog = program or "main"
    if program is None:
        lines += [_comment("A minimal program, so this file compiles alone; give `--program NAME` to run yours."),
                  "PROGRAM main",
                  "  VAR_EXTERNAL",
                  f"    {_fault_name(variables)} : BOOL;",
                  "  END_VAR",
                  "  VAR",
                  "    running : BOOL;",
                  "  END_VAR",
                  f"  running := NOT {_fault_name(variables)};",
                  "END_PROGRAM", ""]
    cfg = st_name(f"twin_{rmap.station}" if rmap.station else "twin_cell")
    lines += [f"CONFIGURATION {cfg}", "  VAR_GLOBAL"]
    current = None
    for v in variables:
        key = v.entry.table if v.entry.table != HOLDING_REGISTER else (v.address[1:3])
        if key != current:
            current = key
            lines.append(f"    {_comment(_section(v))}")
        lines.append(f"    {v.name} AT {v.address} : {v.st_type}; {_comment(_describe(v))}")
    lines += ["  END_VAR", "  VAR_GLOBAL CONSTANT"]
    lines.append(f"    MAP_CRC : UDINT := 16#{crc:08X}; {_comment('CRC-32 of the register map (sim.map_crc)')}")
    lines.append(f"    MAP_CRC_HI : UINT := 16#{crc >> 16:04X};")
    lines.append(f"    MAP_CRC_LO : UINT := 16#{crc & 0xFFFF:04X};")
    for name, type_, value, note in scale_constants(rmap, variables):
        lines.append(f"    {name} : {type_} := {value}; {_comment(note)}")
    lines += ["  END_VAR",
              "  RESOURCE res ON PLC",
              f"    TASK cycle(INTERVAL := T#{task_ms}ms, PRIORITY := 0);",
              f"    PROGRAM plc WITH cycle : {prog};",
              "  END_RESOURCE",
              "END_CONFIGURATION", ""]
    return "\n".join(lines)


def _fault_name(variables: list[Located]) -> str:
    for v in variables:
        if v.entry.name == "fault":
            return v.name
    raise MapError("the map has no 'fault' discrete input")


def _section(v: Located) -> str:
    return {"IX": "discrete inputs (read)", "QX": "coils (written by the PLC)", "IW": "input registers (read)",
            "QW": "holding registers (written by the PLC)"}[v.address[1:3]]


def to_openplc(rmap: RegisterMap, *, host: str = "127.0.0.1", port: int = 5020, unit_id: int = 1,
               polling_ms: int = 10, timeout_ms: int = 1000, name: str = "") -> str:
    """OpenPLC v3's slave-device configuration (mbconfig.cfg) with one TCP device: the map's master ranges."""
    ranges = master_ranges(rmap)
    name = name or (rmap.station or "twin")
    lines = [f'Num_Devices = "1"', f'Polling_Period = "{polling_ms}"', f'Timeout = "{timeout_ms}"',
             "# ------------", "#   DEVICE 0", "# ------------",
             f'device0.name = "{name}"', f'device0.slave_id = "{unit_id}"', 'device0.protocol = "TCP"',
             f'device0.address = "{host}"', f'device0.IP_Port = "{port}"',
             'device0.RTU_Baud_Rate = "115200"', 'device0.RTU_Parity = "None"', 'device0.RTU_Data_Bits = "8"',
             'device0.RTU_Stop_Bits = "1"', 'device0.RTU_TX_Pause = "0"', ""]
    for r in ranges:
        lines += [f'device0.{r.key}_Start = "{r.start}"', f'device0.{r.key}_Size = "{r.size}"']
    lines.append(f"# register map CRC-32 {rmap.crc:08X} (sim.map_crc); serve the twin with --layout plc")
    return "\n".join(lines) + "\n"


__all__ = ["st_name", "located_variables", "located_problem", "to_structured_text", "to_openplc", "RESERVED",
           "MAP_CRC"]
