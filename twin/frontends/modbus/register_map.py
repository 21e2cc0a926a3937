"""The Modbus register map: derived from a station's signal table, never written by hand.

`build_register_map(signals)` is a pure function of the signal table (`twin.core.signals.SignalSpec`,
in the station's declaration order). The frozen `RegisterMap` it returns is the one map type of the
project: it feeds the server, the json/csv/md exports (`twin map`) and the PLC client, which loads the
same type from a station (`RegisterMap.from_station`, no physics) or from `twin map --format json`
output (`RegisterMap.from_json`). A map that cannot be built or loaded raises `MapError` (a `TwinError`)
naming the signal, or the file and the entry's index.

Two layouts (`build_register_map(..., layout)`, `twin serve --layout`): SIGNALS, the default, below; and PLC_LAYOUT
for a Modbus master PLC (`_plc_layout`: per table the PLC's inputs alone in one block from 0, every output in one
block without a gap, no float32; `master_ranges` gives the master's ranges). Every entry names its `owner`
(`twin.core.signals.OWNERS`). The default layout (addresses are 0-based protocol addresses):

- Every table starts with a block of `RESERVED` (16) addresses that belongs to the twin itself (the
  `sim.*` registers and the `fault` bit). Station signals start at address 16 of each table, in the
  signal table's order, so adding a signal at the end of the station (or a new `sim.*` register in the
  reserved block) never moves another entry. Unused reserved addresses are gaps: reading them gives
  exception 02.
- coils (read/write bits): the digital inputs (`Active`, ...).
- discrete inputs (read-only bits): `fault`, `sim.lockstep`, `sim.late`, then the digital outputs
  (`doGripped`, per axis `.in_position` and `.moving`, per finger `.contact`).
- holding registers (read/write words): `sim.advance` at 0, then the analogue inputs.
- input registers (read-only words): `sim.step`, `sim.time_ms`, `sim.late_steps`, `sim.dt_us`,
  `sim.mode`, `sim.speed_pct`, `sim.map_crc` (10-11: the CRC-32 of the map itself, see `map_crc`, so a
  client can tell it holds the map the server serves), then the analogue outputs (actual positions,
  finger forces, robot axes) and `GrippedPart` (an index into the target group, 0 for none).

Values are scaled integers in the engineering units the PLC sees, `value = counts * scale`:

=========  ==========  ==================  ===============================================
SI unit    map unit    scale (per count)   e.g.
=========  ==========  ==================  ===============================================
m          mm          0.01                prismatic setpoints and positions (0.01 mm)
rad        deg         0.01                revolute setpoints and positions (0.01 degree)
N, N*m     N, N*m      0.01                finger forces
=========  ==========  ==================  ===============================================

The type is the smallest that holds the signal's range: uint16, int16, then uint32, int32 (a signal
without a range gets a 32-bit type); a float signal in another unit is a float32 of its SI value.
32-bit values take two registers, **big-endian, high word first** (and big-endian bytes in each word).
Enumerations are uint16 indices into their `choices` (0 = none). Outputs saturate at their declared range and their type's
limits (a finger a hair past its joint limit reads as the limit); inputs outside their range are
refused (exception 03), never clamped.
"""
from __future__ import annotations

import csv
import io
import json
import math
import struct
import zlib
from collections.abc import Callable, Iterable, Mapping
from dataclasses import asdict, dataclass, field, fields
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import Any

from twin.core.signal_table import (SIM_ADVANCE as ADVANCE, SIM_DT_US as DT_US, SIM_FAULT as FAULT,
                                    SIM_LATE as LATE, SIM_LATE_STEPS as LATE_STEPS, SIM_LOCKSTEP as LOCKSTEP,
                                    SIM_MAP_CRC as MAP_CRC, SIM_MODE as MODE, SIM_SIGNALS, SIM_SPEED_PCT as SPEED_PCT,
                                    SIM_STEP as STEP, SIM_TIME_MS as TIME_MS, WATCHDOG_MS, station_signals)
from twin.core.errors import TwinError
from twin.core.signals import BOOL, ENUM, FLOAT, INPUT, INT, OWNERS, PLC, SignalSpec, engineering_unit
from twin.core.station import load_station

from .protocol import ADDRESSES

COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER = "coil", "discrete_input", "holding_register", "input_register"
TABLES = (COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER)
BIT_TABLES = (COIL, DISCRETE_INPUT)
RESERVED = 16  # addresses 0..15 of every table belong to the twin (sim.* and fault)
MAP_UNIT_ID = 247  # the generated map's unit id while a device profile is served (twin.frontends.modbus.profile)
SIGNALS, PLC_LAYOUT = "signals", "plc"  # the two layouts (`twin serve --layout`); SIGNALS is the default
LAYOUTS = (SIGNALS, PLC_LAYOUT)
PLC_TYPES = ("uint16", "int16", "int32")  # the PLC layout's analogue types: an ST UINT, INT or DINT

# Conventional 1-based "Modicon" references, for the printed map.
REFERENCE_BASE = {COIL: 1, DISCRETE_INPUT: 10001, INPUT_REGISTER: 30001, HOLDING_REGISTER: 40001}

WIDTH = {"bool": 1, "uint16": 1, "int16": 1, "uint32": 2, "int32": 2, "float32": 2}
TYPE_LIMITS = {"uint16": (0, 0xFFFF), "int16": (-0x8000, 0x7FFF), "uint32": (0, 0xFFFFFFFF),
           "int32": (-0x80000000, 0x7FFFFFFF), "bool": (0, 1)}
_STRUCT = {"uint16": ">H", "int16": ">h", "uint32": ">I", "int32": ">i", "float32": ">f"}

# SI unit -> (map unit, factor from SI to the map unit, scale in map units per count): the engineering units
# of `twin.core.signals.ENGINEERING_UNITS` (mm, deg; forces as they are), in counts of 0.01
UNITS = {si: (*engineering_unit(si), 0.01) for si in ("m", "rad", "N", "N*m")}



class MapError(TwinError, ValueError):
    """A register map cannot be built or loaded: a signal table that does not fit (a duplicate name, a full
    table), a map file that cannot be read or is not `twin map --format json` output (the message names the
    file and the entry's index), a station whose map cannot be derived, or (raised by the PLC client) a
    server that serves another map than the one given. The one map error of the project: `plc_client`
    re-exports it."""


def map_crc(entries: Iterable) -> int:
    """The CRC-32 of a register map: what `sim.map_crc` publishes, and what a client computes from the map it
    was given to check that both are the same. Over every entry but `sim.map_crc` itself, in a canonical
    form: one line `name,table,address,count,type,scale` per entry (scale with 10 significant digits), in
    table order, then address order, joined by newlines, UTF-8. `entries`: objects with those attributes."""
    order = {t: i for i, t in enumerate(TABLES)}
    rows = sorted((e for e in entries if e.name != MAP_CRC), key=lambda e: (order.get(e.table, len(order)), e.address, e.name))
    text = "\n".join(f"{e.name},{e.table},{int(e.address)},{int(e.count)},{e.type},{float(e.scale):.10g}" for e in rows)
    return zlib.crc32(text.encode("utf-8")) & 0xFFFFFFFF


@dataclass(frozen=True)
class Entry:
    """One named value at an address of one table."""

    name: str
    table: str  # coil, discrete_input, holding_register, input_register
    address: int  # 0-based protocol address
    count: int  # registers (or bits) it takes
    type: str  # bool, uint16, int16, uint32, int32, float32
    scale: float  # engineering units per count
    unit: str  # the engineering unit the PLC sees (mm, deg, N, ...)
    min: float | None  # in engineering units
    max: float | None
    access: str  # "r" or "rw"
    description: str
    choices: tuple[str, ...] = ()  # enumerations: the value is an index into these ("" = none)
    signal: str | None = None  # the twin signal it carries (None: the twin's own sim.* entries)
    factor: float = 1.0  # SI value * factor = engineering value
    owner: str = ""  # plc, robot, operator, simulator (`twin.core.signals.OWNERS`): who writes an input, makes an output

    @property
    def writable(self) -> bool:
        return self.access == "rw"

    def __getstate__(self) -> dict:
        """Its fields only: the encoders cached on it (`counter`, `_packer`) are formed again where it is used."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @property
    def end(self) -> int:
        return self.address + self.count

    @property
    def reference(self) -> int:
        """The conventional 1-based reference (00001, 10001, 30001, 40001 + address)."""
        return REFERENCE_BASE[self.table] + self.address

    # -- counts ---------------------------------------------------------------------------------------
    @cached_property
    def count_range(self) -> tuple[float, float]:
        """The counts a write may carry (inclusive); floats for float32."""
        if self.type == "bool":
            return 0, 1
        if self.type == "float32":
            lo = -math.inf if self.min is None else self.min
            hi = math.inf if self.max is None else self.max
            return lo, hi
        # the range's ends round inwards, but the count nearest an exact end (what a client writing the end
        # itself sends, e.g. 0.9 rad = 51.566 deg as 5157 counts) is accepted too: it means the end
        tlo, thi = TYPE_LIMITS[self.type]
        lo = tlo if self.min is None else max(tlo, min(math.ceil(self.min / self.scale - 1e-6), round(self.min / self.scale)))
        hi = thi if self.max is None else min(thi, max(math.floor(self.max / self.scale + 1e-6), round(self.max / self.scale)))
        return lo, hi

    # -- engineering value <-> words ------------------------------------------------------------------
    def counts_of(self, value, *, engineering: bool = False) -> int | float:
        """SI value (as the twin reads it) -> counts (an output saturated at its declared range, anything at its
        type's limits). `engineering`: the value is in the entry's `unit` already (mm, deg: as a PLC holds it)."""
        return (self.engineering_counter if engineering else self.counter)(value)

    @cached_property
    def counter(self) -> Callable[[Any], int | float]:
        """`counts_of` for an SI value, as one function of the value (the server encodes every changed output at
        every step)."""
        return self._counter(self.factor)

    @cached_property
    def engineering_counter(self) -> Callable[[Any], int | float]:
        return self._counter(1.0)

    def _counter(self, factor: float) -> Callable[[Any], int | float]:
        """The rule of `counts_of` for values `factor` times the SI value: bits 0/1, an enumeration's index
        (its text, or the index itself), a float32's value, else the value in counts, rounded and saturated
        (`_saturation`; NaN is 0). A bool is the number 0 or 1."""
        if self.type == "bool":
            return lambda value: 1 if value else 0
        if self.choices:
            choices = self.choices

            def index(value):
                if isinstance(value, int) and not isinstance(value, bool):
                    return value
                return choices.index(value) if value in choices else 0
            return index
        if self.type == "float32":
            return lambda value: float(value) * factor  # float(True) is float(1)
        scale = self.scale
        lo, hi = self._saturation

        def scaled(value):
            v = float(value) * factor / scale
            if v != v:  # NaN
                return 0
            return lo if v <= lo else hi if v >= hi else int(round(v))
        return scaled

    @cached_property
    def _saturation(self) -> tuple[int, int]:
        """The counts a value saturates at: its type's limits; an output a hair past its declared range (a finger
        pressed past its limit) reads as the range's end."""
        lo, hi = TYPE_LIMITS[self.type]
        if self.access == "r":
            if self.min is not None:
                lo = max(lo, math.ceil(self.min / self.scale - 1e-9))
            if self.max is not None:
                hi = min(hi, math.floor(self.max / self.scale + 1e-9))
        return lo, hi

    @cached_property
    def _packer(self) -> struct.Struct:
        return struct.Struct(">H" if self.type in ("bool", "uint16") else _STRUCT[self.type])

    def pack_into(self, buffer, offset: int, value, *, engineering: bool = False) -> None:
        """`encode`'s words written big-endian into `buffer` at byte `offset` (a register image)."""
        self._packer.pack_into(buffer, offset, (self.engineering_counter if engineering else self.counter)(value))

    def encode(self, value, *, engineering: bool = False) -> list[int]:
        """SI value -> register words (big-endian, high word first), or [0/1] for a bit. `engineering`: the
        value is in the entry's `unit` (what `decode` gives back), as a client or a PLC holds it."""
        c = self.counts_of(value, engineering=engineering)
        if self.type in ("bool", "uint16"):
            return [c]
        if self.type == "int16":
            return [c & 0xFFFF]
        raw = struct.pack(_STRUCT[self.type], c)
        return [int.from_bytes(raw[:2], "big"), int.from_bytes(raw[2:], "big")]

    def decode_counts(self, words: list[int]) -> int | float:
        """Register words (or [bit]) -> counts (or the float32 value)."""
        if self.type in ("bool", "uint16"):
            return words[0]
        if self.type == "int16":
            return words[0] - 0x10000 if words[0] & 0x8000 else words[0]
        raw = struct.pack(">HH", words[0], words[1])
        return struct.unpack(_STRUCT[self.type], raw)[0]

    def decode(self, words: list[int]):
        """Register words -> engineering value (bool, the enumeration's text, or counts * scale)."""
        c = self.decode_counts(words)
        if self.type == "bool":
            return bool(c)
        if self.choices:
            return self.choices[c] if 0 <= c < len(self.choices) else c
        return c * self.scale

    def si_of_words(self, words: list[int]):
        """Register words written by a client -> the SI value for the twin, or None when out of range.

        A value on the range's edge (in counts) maps inside the SI range even after rounding."""
        c = self.decode_counts(words)
        if isinstance(c, float) and math.isnan(c):
            return None
        lo, hi = self.count_range
        if not lo <= c <= hi:
            return None
        if self.type == "bool":
            return bool(c)
        if self.choices:
            return self.choices[c]
        if self.type == "float32":
            return c / self.factor
        si = c * self.scale / self.factor
        if self.signal is not None and self.min is not None:
            si = max(si, self.min / self.factor)
        if self.signal is not None and self.max is not None:
            si = min(si, self.max / self.factor)
        return si

    def as_dict(self) -> dict:
        d = {k: v for k, v in asdict(self).items() if k not in ("signal", "factor")}
        d["choices"] = list(self.choices)
        return d


@dataclass(frozen=True)
class RegisterMap:
    """All entries, by name. Built by `build_register_map` (grouped by table in address order), or loaded:
    `from_station` (the map `twin serve` serves, without physics) and `from_json` (`twin map --format json`
    output, in its order).

    `source` says where the map came from, for messages (a file, or "station 'NAME'"); `meta` holds what a
    json map carries beside its entries. Neither takes part in comparing maps."""

    entries: tuple[Entry, ...]
    station: str = ""
    source: str = field(default="", compare=False)
    meta: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    layout: str = field(default="", compare=False)  # SIGNALS or PLC when built here; "" when loaded
    by_name: Mapping[str, Entry] = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "entries", tuple(self.entries))
        object.__setattr__(self, "by_name", {e.name: e for e in self.entries})
        object.__setattr__(self, "meta", MappingProxyType(dict(self.meta)))

    # -- loading --------------------------------------------------------------------------------------
    @classmethod
    def from_station(cls, station, layout: str = "") -> "RegisterMap":
        """The map `twin serve` serves for a station (a folder or a station.toml), from its static signal
        table: no physics, no RAPID. A station that cannot be read is a MapError too (naming its file and
        key, chained to the core's StationError), so a client has one error for "no map"."""
        try:
            built = build_map(station, layout)
        except MapError:
            raise
        except TwinError as exc:
            raise MapError(str(exc)) from exc
        return cls(built.entries, built.station, source=f"station {built.station!r}", layout=built.layout)

    @classmethod
    def from_json(cls, source: str | Path | Mapping | list) -> "RegisterMap":
        """From `twin map --format json` output: a file path, its text, or the parsed data (a list of
        entries, or an object with them under "signals", "entries" or "registers"; its other keys become
        `meta`, its "station" the map's station). Values are in the entries' engineering units (a json map
        has no SI factor). Anything that is not such a map is a MapError naming the file and the entry."""
        where = ""
        if isinstance(source, Path) or (isinstance(source, str) and not source.lstrip().startswith(("{", "["))):
            where = str(source)
            try:
                source = Path(source).read_text(encoding="utf-8")
            except (OSError, UnicodeDecodeError) as exc:
                raise MapError(f"{where}: cannot read the register map: {getattr(exc, 'strerror', None) or exc}") from None
        label = where or "register map"
        if isinstance(source, (bytes, bytearray)):
            source = source.decode("utf-8", errors="replace")
        if isinstance(source, str):
            try:
                source = json.loads(source)
            except json.JSONDecodeError as exc:
                raise MapError(f"{label}: not JSON (line {exc.lineno}: {exc.msg}); "
                               f"make one with `twin map STATION --format json`") from None
        data, meta = source, {}
        if isinstance(data, Mapping):
            meta = {k: v for k, v in data.items() if k not in ("signals", "entries", "registers")}
            data = data.get("signals", data.get("entries", data.get("registers")))
        if not isinstance(data, list):
            raise MapError(f"{label}: expected a list of entries (the output of `twin map STATION --format json`)")
        entries, seen = [], {}
        for i, item in enumerate(data):
            e = _entry_from_dict(item, label, i)
            if e.name in seen:
                raise MapError(f"{label}: entry {i} ({e.name!r}): the name appears twice (entry {seen[e.name]} too)")
            seen[e.name] = i
            entries.append(e)
        _check_no_overlap(entries, label)
        station = meta.get("station")
        return cls(tuple(entries), station if isinstance(station, str) else "", source=where, meta=meta)

    @cached_property
    def mapped(self) -> Mapping[str, frozenset[int]]:
        """Per table, every address some entry covers (a read across these answers; others get exception 02)."""
        return MappingProxyType({t: frozenset(a for e in self.entries if e.table == t for a in range(e.address, e.end))
                                 for t in TABLES})

    @property
    def crc(self) -> int:
        """The CRC-32 of the map (`map_crc`), as `sim.map_crc` publishes it."""
        return map_crc(self.entries)

    def __iter__(self):
        return iter(self.entries)

    def __len__(self) -> int:
        return len(self.entries)

    def __getitem__(self, name: str) -> Entry:
        return self.by_name[name]

    def __contains__(self, name: object) -> bool:
        return name in self.by_name

    def table(self, table: str) -> tuple[Entry, ...]:
        return tuple(e for e in self.entries if e.table == table)

    def size(self, table: str) -> int:
        """One past the highest address used in `table`."""
        return max((e.end for e in self.entries if e.table == table), default=0)

    # -- exports --------------------------------------------------------------------------------------
    def as_list(self) -> list[dict]:
        return [e.as_dict() for e in self.entries]

    def to_json(self) -> str:
        return json.dumps(self.as_list(), indent=2) + "\n"

    def to_csv(self) -> str:
        out = io.StringIO()
        cols = ["name", "table", "address", "count", "type", "scale", "unit", "min", "max", "access",
                "description", "choices", "owner"]
        w = csv.writer(out, lineterminator="\n")
        w.writerow(cols)
        for d in self.as_list():
            d["choices"] = "|".join(d["choices"])
            w.writerow(["" if d[c] is None else _num(d[c]) for c in cols])
        return out.getvalue()

    def to_markdown(self) -> str:
        title = f"# Modbus register map: station `{self.station}`" if self.station else "# Modbus register map"
        lines = [title, "",
                 "Modbus/TCP, one unit. Addresses are 0-based protocol addresses; `Ref` is the conventional",
                 "1-based reference (coil 00001, discrete input 10001, input register 30001, holding register 40001).",
                 "32-bit values take two registers, big-endian, **high word first**. Value = counts x scale,",
                 "in the unit shown (lengths in mm, angles in degrees, forces in N). Bits: 1 = true.",
                 f"Addresses 0 to {RESERVED - 1} of each table belong to the simulator; station signals start at {RESERVED}.",
                 "Writes take effect at the next simulation step; coils and holding registers read back what was",
                 "written at once, discrete inputs and input registers show the state after the last completed step.",
                 "Out of range: exception 03, nothing changes. Address not in the map: exception 02.", ""]
        names = {COIL: "Coils (read/write bits, FC 1, 5, 15)",
                 DISCRETE_INPUT: "Discrete inputs (read-only bits, FC 2)",
                 HOLDING_REGISTER: "Holding registers (read/write, FC 3, 6, 16, 23)",
                 INPUT_REGISTER: "Input registers (read-only, FC 4)"}
        for table in TABLES:
            rows = self.table(table)
            lines += [f"## {names[table]}", ""]
            if not rows:
                lines += ["(none)", ""]
                continue
            lines.append("| Addr | Ref | Name | Type | Unit | Scale | Range | Access | Owner | Description |")
            lines.append("|---:|---:|---|---|---|---:|---|---|---|---|")
            for e in rows:
                addr = f"{e.address}" if e.count == 1 else f"{e.address}-{e.end - 1}"
                ref = f"{e.reference:05d}"
                desc = e.description
                if e.choices:
                    desc += " (" + ", ".join(f"{i} = {c or 'none'}" for i, c in enumerate(e.choices)) + ")"
                lines.append(f"| {addr} | {ref} | `{e.name}` | {e.type} | {e.unit} | "
                             f"{'' if e.type == 'bool' else _num(e.scale)} | {_range(e)} | {e.access} | {e.owner} | "
                             f"{desc.replace('|', '/')} |")
            lines.append("")
        lines += self._markdown_windows() + self._markdown_master()
        return "\n".join(lines)

    def _markdown_windows(self) -> list[str]:
        from .pdu import IMAGE_IN, IMAGE_OUT, ImageLayout

        lay = ImageLayout({t: self.size(t) for t in TABLES})
        step = self.by_name.get(STEP)
        where = (f"; `{STEP}` is words {lay.in_words(step)[0]}-{sum(lay.in_words(step)) - 1} of it"
                 if step is not None and step.table == INPUT_REGISTER else "")
        return ["## Process-image windows (holding registers; one request per PLC scan)", "",
                "| Window | Addr | Ref | Words | Holds |", "|---|---:|---:|---:|---|",
                f"| input (read-only) | {IMAGE_IN:#06x} | {REFERENCE_BASE[HOLDING_REGISTER] + IMAGE_IN} | {lay.in_size} | "
                f"discrete inputs packed 16 a word ({lay.in_offset[INPUT_REGISTER]} words), input registers "
                f"({self.size(INPUT_REGISTER)}), coils packed ({lay.in_offset[HOLDING_REGISTER] - lay.in_offset[COIL]}), "
                f"holding registers ({self.size(HOLDING_REGISTER)}): everything of one step{where} |",
                f"| output | {IMAGE_OUT:#06x} | {REFERENCE_BASE[HOLDING_REGISTER] + IMAGE_OUT} | {lay.out_size} | "
                f"one word per coil ({self.size(COIL)}), then the holding registers ({self.size(HOLDING_REGISTER)}) |", ""]

    def _markdown_master(self) -> list[str]:
        try:
            ranges = master_ranges(self)
        except MapError as exc:
            return ["## A Modbus master PLC", "", f"Not on this layout ({exc}): serve `--layout plc` and take "
                    "`twin map STATION --layout plc` (`--format openplc` writes its slave-device configuration).", ""]
        lines = ["## A Modbus master PLC (its device ranges)", "",
                 "What the PLC writes on every poll is its own and nothing else; what it reads has no gap. "
                 "Reads of one poll (one connection, up to "
                 f"{POLL_HOLD * 1000:g} ms) come from one step: see the Modbus README, \"A consistent input image\".", "",
                 "| Range | Function | Start | Size | Located at (first slave device) |", "|---|---|---:|---:|---|"]
        for r in ranges:
            lines.append(f"| {r.title} | {r.function} | {r.start} | {r.size} | {r.located or '-'} |")
        return lines + [""]


POLL_HOLD = 0.1  # s: reads of one connection within this long of its first come from one step (twin.frontends.modbus.pdu)


@dataclass(frozen=True)
class MasterRange:
    """One of a Modbus master's device ranges (OpenPLC's slave-device form), on the PLC layout."""

    key: str  # OpenPLC's mbconfig.cfg key: Discrete_Inputs, Coils, Input_Registers, Holding_Registers_Read, Holding_Registers
    title: str
    function: str
    table: str
    start: int
    size: int
    located: str  # where the first slave device's range lands in the PLC (OpenPLC's convention)
    entries: tuple[Entry, ...]


def master_ranges(rmap: "RegisterMap") -> tuple[MasterRange, ...]:
    """The ranges a Modbus master PLC is configured with, in its order (discrete inputs, coils, input registers,
    holding registers read, holding registers written): all it reads (whole tables, no gap), exactly what the
    PLC owns to write. MapError when the map is not laid out for it (the default layout mixes owners)."""
    def block(table: str, entries) -> tuple[int, int]:
        entries = sorted(entries, key=lambda e: e.address)
        if not entries:
            return 0, 0
        start, end = entries[0].address, entries[-1].end
        covered = sum(e.count for e in entries)
        if covered != end - start:
            raise MapError(f"the {table}s a PLC {'writes' if table in (COIL, HOLDING_REGISTER) else 'reads'} are not one "
                           f"block ({start}..{end - 1} has gaps or others' entries)")
        return start, end - start

    ranges, counted = [], {"IX": 0, "IW": 0}
    specs = (("Discrete_Inputs", "Discrete inputs (read)", "FC 2", DISCRETE_INPUT, "IX"),
             ("Coils", "Coils (written)", "FC 15", COIL, "QX"),
             ("Input_Registers", "Input registers (read)", "FC 4", INPUT_REGISTER, "IW"),
             ("Holding_Registers_Read", "Holding registers (read)", "FC 3", HOLDING_REGISTER, "IW"),
             ("Holding_Registers", "Holding registers (written)", "FC 16", HOLDING_REGISTER, "QW"))
    for key, title, fc, table, area in specs:
        if key == "Holding_Registers_Read":
            chosen = ()  # the PLC reads back nothing it wrote: its own setpoints are in its own memory
        elif table in (COIL, HOLDING_REGISTER):
            chosen = tuple(e for e in rmap.table(table) if e.writable and e.owner == PLC)
        else:
            chosen = rmap.table(table)
        start, size = block(table, chosen)
        if table in (DISCRETE_INPUT, INPUT_REGISTER) and size and (start != 0 or size != rmap.size(table)):
            raise MapError(f"the {table}s do not start at 0 without a gap")
        if table in (COIL, HOLDING_REGISTER) and chosen and start != 0:
            raise MapError(f"the PLC's {table}s do not start at 0")
        if table == DISCRETE_INPUT and any(a not in rmap.mapped[table] for a in range(start, start + size)):
            raise MapError(f"the {table}s have gaps")
        first = counted.get(area, 0)
        located = ""
        if size:
            located = f"%{area}{100 + first // 8}.{first % 8}" if area.endswith("X") else f"%{area}{100 + first}"
        if area in counted:
            counted[area] = first + size
        ranges.append(MasterRange(key, title, fc, table, start, size, located, chosen))
    return tuple(ranges)


def _entry_from_dict(e: Any, where: str, i: int) -> Entry:
    """One entry of a json map (as `Entry.as_dict` writes it; type, count, access have defaults by table)."""
    if not isinstance(e, Mapping) or not all(k in e for k in ("name", "table", "address")):
        raise MapError(f"{where}: entry {i} needs at least name, table and address")
    name, table = e["name"], e["table"]

    def bad(message: str) -> MapError:
        return MapError(f"{where}: entry {i} ({name!r}): {message}")

    if table not in TABLES:
        raise bad(f"unknown table {table!r} (one of {', '.join(TABLES)})")
    bit = table in BIT_TABLES
    try:
        type_ = str(e.get("type") or ("bool" if bit else "uint16"))
        if type_ not in WIDTH:
            raise bad(f"unknown type {type_!r} (one of {', '.join(WIDTH)})")
        if bit != (type_ == "bool"):
            raise bad(f"a {table} holds {'bools' if bit else 'words'}, not {type_}")
        entry = Entry(name=str(name), table=table, address=int(e["address"]), count=int(e.get("count") or WIDTH[type_]),
                      type=type_, scale=float(e.get("scale") or 1.0), unit=str(e.get("unit") or ""),
                      min=None if e.get("min") is None else float(e["min"]),
                      max=None if e.get("max") is None else float(e["max"]),
                      access=str(e.get("access") or ("rw" if table in (COIL, HOLDING_REGISTER) else "r")),
                      description=str(e.get("description") or ""), choices=tuple(str(c) for c in e.get("choices") or ()),
                      owner=str(e.get("owner") or ""))
    except (TypeError, ValueError) as exc:
        if isinstance(exc, MapError):
            raise
        raise bad(str(exc)) from None
    if entry.count != WIDTH[type_]:
        raise bad(f"a {type_} takes {WIDTH[type_]} {'bit' if bit else 'register'}{'s' if WIDTH[type_] > 1 else ''}, "
                  f"not count {entry.count}")
    if not (0 <= entry.address and entry.end <= ADDRESSES):
        raise bad(f"address {entry.address} is outside 0..{ADDRESSES - 1}")
    if entry.access not in ("r", "rw") or (entry.access == "rw" and table not in (COIL, HOLDING_REGISTER)):
        raise bad(f"access {entry.access!r}: 'r', or 'rw' in the coils and holding registers")
    if not entry.scale > 0:
        raise bad(f"scale {entry.scale:g} must be greater than 0")
    if entry.owner and entry.owner not in OWNERS:
        raise bad(f"owner {entry.owner!r}: one of {', '.join(OWNERS)}")
    if entry.min is not None and entry.max is not None and entry.min > entry.max:
        raise bad(f"min {entry.min:g} is above max {entry.max:g}")
    return entry


def _check_no_overlap(entries: list[Entry], label: str) -> None:
    """Two entries of one table may not share an address: a client would decode one from the other's words."""
    index = {id(e): i for i, e in enumerate(entries)}
    for table in TABLES:
        held = sorted((e for e in entries if e.table == table), key=lambda e: e.address)
        for a, b in zip(held, held[1:]):
            if b.address < a.address + a.count:
                raise MapError(f"{label}: entry {index[id(b)]} ({b.name!r}) at {table} {b.address} overlaps entry "
                               f"{index[id(a)]} ({a.name!r}, addresses {a.address}..{a.address + a.count - 1})")


def _num(v):
    if isinstance(v, float):
        return f"{v:.10g}"
    return v


def _range(e: Entry) -> str:
    if e.type == "bool":
        return "0/1"
    lo = "" if e.min is None else f"{e.min:.10g}"
    hi = "" if e.max is None else f"{e.max:.10g}"
    return f"{lo} .. {hi}".strip() if (lo or hi) else ""


# -- building ------------------------------------------------------------------------------------------
# Where the simulator's own signals (`twin.core.signal_table.SIM_SIGNALS`) sit in the reserved block.
SIM_PLACES = {
    ADVANCE: (HOLDING_REGISTER, 0, "uint16"),
    FAULT: (DISCRETE_INPUT, 0, "bool"), LOCKSTEP: (DISCRETE_INPUT, 1, "bool"), LATE: (DISCRETE_INPUT, 2, "bool"),
    STEP: (INPUT_REGISTER, 0, "uint32"), TIME_MS: (INPUT_REGISTER, 2, "uint32"), LATE_STEPS: (INPUT_REGISTER, 4, "uint32"),
    DT_US: (INPUT_REGISTER, 6, "uint16"), MODE: (INPUT_REGISTER, 7, "uint16"), SPEED_PCT: (INPUT_REGISTER, 8, "uint16"),
    MAP_CRC: (INPUT_REGISTER, 10, "uint32"), WATCHDOG_MS: (INPUT_REGISTER, 12, "uint32"),
}
# The PLC layout: the simulator's outputs lead what a PLC reads, in this order (sim.step at input registers 0-1).
PLC_SIM_FIRST = tuple(s.name for s in SIM_SIGNALS if s.direction != INPUT)
# What the protocol adds to a sim signal's description (the Modbus answer to a refused write).
SIM_NOTES = {ADVANCE: " (else exception 03)", FAULT: ", writes get exception 04"}


def _sim_entries() -> list[Entry]:
    entries = []
    for s in SIM_SIGNALS:
        table, address, type_ = SIM_PLACES[s.name]
        entries.append(_sim_entry(s, table, address, type_))
    return entries


def _sim_entry(s: SignalSpec, table: str, address: int, type_: str) -> Entry:
    return Entry(s.name, table, address, WIDTH[type_], type_, 1.0, s.unit, s.min, s.max,
                 "rw" if s.direction == INPUT else "r", s.description + SIM_NOTES.get(s.name, ""), owner=s.owned_by)


def _fit_type(lo_e: float | None, hi_e: float | None, scale: float, signed_default: bool,
              types: tuple[str, ...] = ("uint16", "int16", "uint32", "int32")) -> str:
    if lo_e is None or hi_e is None:
        if "uint32" not in types:
            return "int32"
        return "int32" if (lo_e is None or lo_e < 0 or signed_default) else "uint32"
    lo, hi = math.ceil(lo_e / scale - 1e-6), math.floor(hi_e / scale + 1e-6)
    for t in types:
        tlo, thi = TYPE_LIMITS[t]
        if tlo <= lo and hi <= thi:
            return t
    return "float32"


def _eng(v: float | None, factor: float) -> float | None:
    return None if v is None else round(v * factor, 9)


def _signal_entry(s: SignalSpec, table: str, address: int, layout: str = SIGNALS) -> Entry:
    access = "rw" if s.direction == INPUT else "r"
    common = dict(name=s.name, table=table, address=address, access=access, description=s.description, signal=s.name,
                  owner=s.owned_by)
    if table in BIT_TABLES:
        return Entry(count=1, type="bool", scale=1.0, unit="", min=None, max=None, **common)
    if s.type == ENUM:
        return Entry(count=1, type="uint16", scale=1.0, unit="", min=0, max=max(0, len(s.choices) - 1),
                     choices=tuple(s.choices), **common)
    types = PLC_TYPES if layout == PLC_LAYOUT else ("uint16", "int16", "uint32", "int32")
    if s.type == INT:
        t = _fit_type(s.min, s.max, 1.0, False, types)
        if t == "float32":
            raise MapError(f"signal {s.name!r}: its range {s.min:g} .. {s.max:g} does not fit a 32-bit integer")
        return Entry(count=WIDTH[t], type=t, scale=1.0, unit=s.unit, min=s.min, max=s.max, **common)
    if s.unit in UNITS or layout == PLC_LAYOUT:  # the PLC layout has no float32: every float in counts of 0.01
        unit, factor, scale = UNITS.get(s.unit) or (*engineering_unit(s.unit), 0.01)
        lo, hi = _eng(s.min, factor), _eng(s.max, factor)
        t = _fit_type(lo, hi, scale, False, types)
        if t != "float32":
            return Entry(count=WIDTH[t], type=t, scale=scale, unit=unit, min=lo, max=hi, factor=factor, **common)
        if layout == PLC_LAYOUT:
            raise MapError(f"signal {s.name!r}: its range {lo:g} .. {hi:g} {unit} in counts of {scale:g} does not fit "
                           "a DINT (the PLC layout has no float32)")
    return Entry(count=2, type="float32", scale=1.0, unit=s.unit, min=s.min, max=s.max, **common)


def _table_of(s: SignalSpec) -> str | None:
    """Where a signal goes: bools in the bit tables, numbers in the registers; inputs writable, outputs not."""
    if s.type == BOOL:
        return COIL if s.direction == INPUT else DISCRETE_INPUT
    if s.type in (FLOAT, INT, ENUM):
        return HOLDING_REGISTER if s.direction == INPUT else INPUT_REGISTER
    return None  # text and other types are not served (none exist yet)


def build_register_map(signals: Iterable[SignalSpec], station: str = "", layout: str = "") -> RegisterMap:
    """The register map of a signal table (see the module docstring for the two layouts; default SIGNALS)."""
    layout = layout or SIGNALS
    if layout not in LAYOUTS:
        raise MapError(f"unknown register map layout {layout!r} (one of {', '.join(LAYOUTS)})")
    if layout == PLC_LAYOUT:
        return _plc_layout(signals, station)
    entries = _sim_entries()
    seen = {e.name for e in entries}
    nxt = {t: RESERVED for t in TABLES}
    for s in signals:
        if s in SIM_SIGNALS:  # the simulator's own: placed above, at their fixed addresses
            continue
        if s.name in seen:
            raise MapError(f"signal {s.name!r} appears twice (or clashes with the simulator's own entry)")
        seen.add(s.name)
        table = _table_of(s)
        if table is None:
            continue
        e = _signal_entry(s, table, nxt[table])
        nxt[table] = e.end
        if e.end > ADDRESSES:
            raise MapError(f"signal {s.name!r}: the {table} table is full ({ADDRESSES} addresses)")
        entries.append(e)
    order = {t: i for i, t in enumerate(TABLES)}
    entries.sort(key=lambda e: (order[e.table], e.address))
    return RegisterMap(tuple(entries), station, layout=SIGNALS)


def _plc_layout(signals: Iterable[SignalSpec], station: str) -> RegisterMap:
    """The PLC layout: per table, the PLC's inputs first and alone in one block from address 0 (what a Modbus
    master writes on every poll), the others' inputs after it; every output in one block from 0 without a
    gap (what it reads), the simulator's first (`sim.step` at input registers 0-1); no float32."""
    sims = {s.name: s for s in SIM_SIGNALS}
    station_specs, seen = [], set(sims)
    for s in signals:
        if s.name in sims:
            continue
        if s.name in seen:
            raise MapError(f"signal {s.name!r} appears twice (or clashes with the simulator's own entry)")
        seen.add(s.name)
        if _table_of(s) is not None:
            station_specs.append(s)
    first = [sims[n] for n in PLC_SIM_FIRST]  # the simulator's outputs, at the start of what a PLC reads
    ordered = ([s for s in station_specs if s.direction == INPUT and s.owned_by == PLC]
               + first + [s for s in station_specs if not (s.direction == INPUT and s.owned_by == PLC)]
               + [sims[n] for n in sims if n not in PLC_SIM_FIRST])
    entries, nxt = [], {t: 0 for t in TABLES}
    for s in ordered:
        table = _table_of(s)
        if s.name in sims:
            e = _sim_entry(s, table, nxt[table], SIM_PLACES[s.name][2])
        else:
            e = _signal_entry(s, table, nxt[table], PLC_LAYOUT)
        if e.end > ADDRESSES:
            raise MapError(f"signal {s.name!r}: the {table} table is full ({ADDRESSES} addresses)")
        nxt[table] = e.end
        entries.append(e)
    order = {t: i for i, t in enumerate(TABLES)}
    entries.sort(key=lambda e: (order[e.table], e.address))
    return RegisterMap(tuple(entries), station, layout=PLC_LAYOUT)


def build_map(station, layout: str = "") -> RegisterMap:
    """The map `twin serve` serves for a station (a folder or a station.toml), from its static signal table:
    no physics, no RAPID (a wrong station raises the core's StationError)."""
    st = load_station(station)
    return build_register_map(station_signals(st), st.name, layout)
