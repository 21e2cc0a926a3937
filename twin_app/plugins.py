"""Station plug-ins: code that belongs to one station, named in its station file, loaded by name at run time.

The general packages (twin, twin_app, plc_client, rapid_like) know no station; a station brings its own demo
and PLC logic in its folder and names them in `station.toml`:

    [plugins]
    twin_demo = "my_cell_demo.py"                  # `twin demo STATION`: in process, through the simulation API
    plc_demo = "stations.my_cell.demo"             # `plc demo --station STATION`: the cell over the network
    plc_logic = "plc_logic.py:gripper_plc"         # `plc run --station STATION` without MODULE:NAME

A reference is `package.module`, `package.module:name`, `file.py` or `file.py:name` (a file beside the
station file). A demo is a module (or object) with `add_arguments(parser)` and `main(args) -> int` (the
command adds `station` to `args`); a PLC logic is what `plc run` takes. `shipped_station_with(KEY)` finds
the shipped station that offers a plug-in, so `plc demo` and `twin demo` run one without naming it.
"""
from __future__ import annotations

import importlib
import importlib.util
import sys
import tomllib
from pathlib import Path

from twin.core.errors import StationError, TwinError

SHIPPED_STATIONS = Path(__file__).resolve().parent.parent / "stations"  # the ready cells installed with the project


def shipped_plugin_tables() -> dict[Path, dict]:
    """Each shipped station folder -> its station file's `[plugins]` table, read once, without loading the
    station (a plain look into the TOML; a file that does not parse is left out: loading it says why)."""
    global _tables
    if _tables is None:
        _tables = {}
        for toml in sorted(SHIPPED_STATIONS.glob("*/station.toml")):
            try:
                plugins = tomllib.loads(toml.read_text(encoding="utf-8")).get("plugins", {})
            except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
                continue
            if isinstance(plugins, dict):
                _tables[toml.parent] = plugins
    return _tables


_tables: dict[Path, dict] | None = None



class LoadError(TwinError):
    """A reference that does not lead to an object: says which part failed."""


def load_object(ref: str, base: Path, *, module_alone: bool = False):
    """The object `ref` names: `module:name` (importable) or `file.py:name` (relative to `base`); with
    `module_alone`, `module` or `file.py` alone is the module itself."""
    module_ref, sep, attr = ref.rpartition(":")
    if not sep and module_alone:
        module_ref, attr = ref, ""
    if not module_ref or (not attr and not module_alone):
        raise LoadError(f"{ref!r} is not \"module:name\" or \"file.py:name\"")
    if module_ref.endswith(".py"):
        path = (Path(base) / module_ref).resolve()
        if not path.is_file():
            raise LoadError(f"{ref!r}: no file {path}")
        name = f"station_code_{path.stem}_{abs(hash(str(path)))}"
        module = sys.modules.get(name)
        if module is None:
            spec = importlib.util.spec_from_file_location(name, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            try:
                spec.loader.exec_module(module)
            except Exception as exc:
                del sys.modules[name]
                raise LoadError(f"{ref!r}: {path.name} fails to load: {type(exc).__name__}: {exc}") from None
    else:
        try:
            module = importlib.import_module(module_ref)
        except ImportError as exc:
            raise LoadError(f"{ref!r}: cannot import {module_ref!r}: {exc}") from None
    obj = module
    try:
        for part in attr.split(".") if attr else ():
            obj = getattr(obj, part)
    except AttributeError:
        raise LoadError(f"{ref!r}: {module_ref} has no {attr!r}") from None
    return obj


def station_plugin(station, key: str):
    """The plug-in `key` of a station (a Station, a folder or a station.toml), loaded; a StationError naming
    the station file and `plugins.KEY` when it has none or it cannot be loaded."""
    from twin.core.station import Station, load_station

    st = station if isinstance(station, Station) else load_station(station)
    ref = st.plugins.get(key)
    if ref is None:
        offered = [p.name for p in shipped_stations_with(key)]
        hint = f" (shipped stations with one: {', '.join(offered)})" if offered else ""
        raise StationError(str(st.file), "", f"station {st.name!r} has no {key.replace('_', ' ')}: its station file "
                           f"names none under [plugins] {key}{hint}")
    try:
        return load_object(ref, st.folder, module_alone=True)
    except LoadError as exc:
        raise StationError(str(st.file), f"plugins.{key}", str(exc)) from None


def shipped_stations_with(key: str) -> list[Path]:
    """The shipped station folders whose station file names a `key` plug-in (read without loading the
    station: a plain look into the TOML)."""
    return [folder for folder, plugins in shipped_plugin_tables().items() if key in plugins]


def shipped_station_with(key: str) -> Path:
    """The one shipped station offering a `key` plug-in: what `plc demo` / `twin demo` run when no station is
    named. A StationError when there is none, or several (then the station must be named)."""
    found = shipped_stations_with(key)
    if len(found) != 1:
        what = "none" if not found else ", ".join(p.name for p in found)
        raise StationError(str(SHIPPED_STATIONS), "", f"name a station: the shipped stations offering a "
                           f"{key.replace('_', ' ')} are {what}")
    return found[0]


def run_station_demo(key: str, argv: list[str], *, prog: str, parser_class=None, positional: bool) -> int:
    """Run a station's demo plug-in with its own options: `twin demo [STATION] ...` (positional) or
    `plc demo [--station DIR] ...`. Without a station, the shipped station that offers one."""
    import argparse

    parser_class = parser_class or argparse.ArgumentParser
    station = _named_station(argv, positional) or shipped_station_with(key)
    while True:
        demo = station_plugin(station, key)
        parser = parser_class(prog=prog)
        help_text = f"the station (a folder or station.toml; default {Path(station).name})"
        if positional:
            parser.add_argument("station", nargs="?", default=str(station), help=help_text)
        else:
            parser.add_argument("--station", metavar="DIR", default=str(station), help=help_text)
        demo.add_arguments(parser)
        args = parser.parse_args(argv)
        if Path(args.station) == Path(station):
            return demo.main(args)
        station = args.station  # named after the options: that station's demo, with its options


def _named_station(argv: list[str], positional: bool) -> str | None:
    if positional:
        return argv[0] if argv and not argv[0].startswith("-") else None
    for i, arg in enumerate(argv):
        if arg == "--station" and i + 1 < len(argv):
            return argv[i + 1]
        if arg.startswith("--station="):
            return arg.split("=", 1)[1]
    return None


def parse_command_line(parser, argv: list[str] | None):
    """`parser.parse_args(argv)`, except that a command that runs a station's demo (`takes_options`) keeps the
    options it does not know, for the demo's own parser (`args.demo_options`)."""
    args, extra = parser.parse_known_args(argv)
    if getattr(args, "takes_options", False):
        args.demo_options = extra
    elif extra:
        parser.error(f"unrecognized arguments: {' '.join(extra)}")
    return args
