"""A Structured Text PLC's located variables and the twin's register map: the same device ranges a Modbus
master PLC is configured with (`twin.frontends.modbus.register_map.master_ranges`, OpenPLC's convention), so what the
ST PLC reads in the twin is what it reads on the real PLC.

- `located_problems(program, rmap)`: `plc check FILE.st... --station DIR` (or `--map FILE.json`, or `--port P`:
  the server's map): every located variable outside what the master moves, or of a type that cannot hold its
  register's values, is an error at its declaration naming the signal (`twin.frontends.modbus.plc_export.located_problem`).
- `LocatedBinding(rmap)`: the input image from signal values (engineering units, by entry name) word by word
  as the master hands them over, and signal values from the output image.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from twin.frontends.modbus.plc_export import located_problem, located_variables
from twin.frontends.modbus.register_map import PLC_LAYOUT, RegisterMap


def _located_symbols(program):
    """(symbol) of every located variable: the globals and the program instances' own."""
    for s in program.globals.values():
        if s.location is not None:
            yield s
    seen = set()
    for inst in program.instances:
        if id(inst.pou) in seen:
            continue
        seen.add(id(inst.pou))
        for s in inst.pou.symbols.values():
            if s.location is not None and not s.is_global:
                yield s


def located_problems(program, rmap: RegisterMap) -> list[str]:
    """`FILE:LINE:COL: error: MESSAGE` per located variable that does not fit the map's device ranges."""
    out = []
    for s in _located_symbols(program):
        area, size, indexes = s.location
        problem = located_problem(rmap, area, size, tuple(indexes), str(s.type.name))
        if problem is not None:
            out.append(f"{s.span}: error: {s.name}: {problem}")
    return out


def check_against_map(files: list[str], rmap: RegisterMap) -> int:
    """`plc check FILE.st... --station DIR`: the language's checks, then the located variables against the map.
    Exit 0, 65 (an error: one line each on stderr), 66 (a file that cannot be read)."""
    import sys

    from structured_text.errors import StError
    from structured_text.runtime import compile_files, read_source

    try:
        sources = {f: read_source(f) for f in files}
    except (OSError, UnicodeDecodeError) as exc:
        print(f"plc: error: cannot read {getattr(exc, 'filename', '') or ''}: {exc}", file=sys.stderr)
        return 66
    try:
        compiled = compile_files(files, sources)
    except StError as exc:
        print(exc.headline(), file=sys.stderr)
        return 65
    from twin.frontends.modbus.register_map import MapError

    try:
        problems = located_problems(compiled.program, rmap)
    except MapError as exc:
        where = f" ({rmap.source})" if rmap.source else ""
        print(f"plc: error: the register map{where} is not laid out for a Modbus master PLC: {exc}; take the PLC "
              "layout (`twin map STATION --layout plc --format json`, or a server run with --layout plc)", file=sys.stderr)
        return 2
    for line in problems:
        print(line, file=sys.stderr)
    return 65 if problems else 0


class LocatedBinding:
    """The located variables of a map's PLC layout, bound to its entries (OpenPLC's convention)."""

    def __init__(self, rmap: RegisterMap):
        if rmap.layout and rmap.layout != PLC_LAYOUT:
            from twin.frontends.modbus.register_map import MapError

            raise MapError("an ST PLC's located variables bind to the PLC layout (twin serve --layout plc)")
        self.map = rmap
        self.variables = located_variables(rmap)
        self.inputs = [v for v in self.variables if v.address.startswith("%I")]
        self.outputs = [v for v in self.variables if v.address.startswith("%Q")]
        self.output_entries = list(dict.fromkeys(v.entry for v in self.outputs))
        self.input_entries = list(dict.fromkeys(v.entry for v in self.inputs))
        # per entry, its words: (address, which word, a bit?), in the order of the entry's words
        self._words_in = {e.name: [(v.address, 1 if v.word == "LO" else 0, e.type == "bool")
                                   for v in self.inputs if v.entry is e] for e in self.input_entries}
        self._words_out = {e.name: [(v.address, 1 if v.word == "LO" else 0) for v in self.outputs if v.entry is e]
                           for e in self.output_entries}

    def input_image(self, values: Mapping[str, Any]) -> dict[str, int | bool]:
        """Address -> word (or bit) from signal values in engineering units, by entry name."""
        image = {}
        for e in self.input_entries:
            if e.name not in values:
                continue
            words = e.encode(values[e.name], engineering=True)
            for address, k, bit in self._words_in[e.name]:
                image[address] = bool(words[k]) if bit else int(words[k])
        return image

    def output_values(self, image: Mapping[str, int | bool]) -> dict[str, Any]:
        """Signal values in engineering units from the output image (address -> word or bit)."""
        words: dict[str, list] = {}
        for v in self.outputs:
            w = image.get(v.address, 0)
            slot = words.setdefault(v.entry.name, [0] * v.entry.count)
            slot[1 if v.word == "LO" else 0] = int(w)
        by_name = {e.name: e for e in self.output_entries}
        return {name: by_name[name].decode(w) for name, w in words.items()}


class StLogic:
    """A Structured Text PLC as a scan-cycle logic (`plc_client.scan`): each scan writes its input image from
    the signals (through `LocatedBinding`), runs the PLC's tasks at the scan's time (`inputs.time`: the cell's
    time in lockstep, so runs repeat bit for bit), and returns its located outputs as signals. So it runs
    wherever a Python logic does: `plc run FILE.st --port P` over Modbus, in process on a cell. Its state is
    the PLC itself (`structured_text.runtime.Plc`, compiled once); a runtime error stops it (`PlcFault`)."""

    def __init__(self, files: list, rmap: RegisterMap, settings: Mapping[str, Any] | None = None):
        """`settings`: values for the program's variables before the first scan (a campaign's `plc.NAME`:
        its VAR CONSTANT parameters or VAR_INPUTs, by name, case-insensitive)."""
        from structured_text.runtime import Plc, compile_files

        self.files = [str(f) for f in files]
        self.compiled = compile_files(self.files)
        self.binding = LocatedBinding(rmap)
        self.inputs = tuple(e.name for e in self.binding.input_entries)
        self.outputs = tuple(e.name for e in self.binding.output_entries)
        from weakref import WeakKeyDictionary

        from structured_text.runtime import address_key, parse_address

        self._keys = {v.address: address_key(*parse_address(v.address))  # the runtime's image keys
                      for v in self.binding.variables}
        self._last: WeakKeyDictionary = WeakKeyDictionary()  # per PLC: the input values last written
        self.settings = dict(settings or {})
        self.instance = self.compiled.program.instances[0].name if self.compiled.program.instances else ""
        probe = Plc(self.compiled)
        for name, value in self.settings.items():  # a wrong name or value is an error now, not at the first scan
            probe.set(f"{self.instance}.{name}", value)
        self._watched = all(self._has(probe, n) for n in ("phase", "fault_code"))

    def _has(self, plc, name: str) -> bool:
        try:
            plc.get(f"{self.instance}.{name}")
        except Exception:  # noqa: BLE001 - the runtime names what it cannot resolve
            return False
        return True

    def initial_state(self):
        from structured_text.runtime import Plc

        plc = Plc(self.compiled)
        for name, value in self.settings.items():
            plc.set(f"{self.instance}.{name}", value)
        return plc

    def sequence_state(self, plc):
        """The grip sequence's phase and fault, when the program keeps them as `phase` and `fault_code` in the
        codes of `plc_client.grip_sequence` (Phase, Fault), as the shipped gripper PLC in ST does: a campaign
        counts grips and names the PLC's faults from them as from a Python GripSequence. Else None."""
        if not self._watched:
            return None
        from types import SimpleNamespace

        from .grip_sequence import Fault, Phase

        return SimpleNamespace(phase=Phase(int(plc.get(f"{self.instance}.phase"))),
                               fault=Fault(int(plc.get(f"{self.instance}.fault_code"))))

    def __call__(self, inputs: Mapping, plc) -> dict:
        """One scan. The input image is written straight into the runtime's (`Plc.inputs`, keyed as its
        `address_key` keys an address), only for the values that changed since the last scan."""
        last = self._last.get(plc)
        if last is None or not plc.inputs:  # a new PLC, or one restarted cold (its input image cleared)
            last = self._last[plc] = {}
        keys = self._keys
        image, words_in = plc.inputs, self.binding._words_in
        for e in self.binding.input_entries:
            name = e.name
            if name not in inputs:
                continue
            value = inputs[name]
            if name in last and last[name] == value and type(last[name]) is type(value):
                continue
            last[name] = value
            words = e.encode(value, engineering=True)
            for address, k, bit in words_in[name]:
                image[keys[address]] = bool(words[k]) if bit else int(words[k]) & 0xFFFF
        plc.scan(float(getattr(inputs, "time", 0.0)))
        out = plc.outputs
        return self.binding.output_values({v.address: out.get(keys[v.address], 0) for v in self.binding.outputs})
