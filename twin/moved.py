"""Old import paths of station code that moved out of the general packages keep working, with a warning.

Station code lives beside its station; when some moved there from a general package, the station keeps
its old module names in its own file, so that `plc run OLD.MODULE:NAME` and campaign files naming the
old path still run, and the general packages stay free of station names:

    [plugins]
    moved = { "plc_client.old_name" = "stations.my_cell.plc_logic" }

`install()` (done when `twin` or `plc_client` is imported) appends a finder to `sys.meta_path`: it is asked
only after the normal import has failed, reads the shipped station files once, and imports the new module
under the old name with a DeprecationWarning. Only names under the general packages are looked up.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import tomllib
import warnings
from pathlib import Path

GENERAL_PACKAGES = ("twin", "twin_app", "plc_client", "rapid_like")
SHIPPED_STATIONS = Path(__file__).resolve().parent.parent / "stations"


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


def moved_modules() -> dict[str, str]:
    """old module name -> new one, from every shipped station file's `[plugins] moved`."""
    table: dict[str, str] = {}
    for plugins in shipped_plugin_tables().values():
        moved = plugins.get("moved", {})
        if isinstance(moved, dict):
            table.update({str(k): str(v) for k, v in moved.items()})
    return table


class _Alias(importlib.abc.Loader):
    def __init__(self, old: str, new: str):
        self.old, self.new = old, new

    def create_module(self, spec):
        warnings.warn(f"{self.old} has moved to {self.new}: import it from there (the old name will be removed)",
                      DeprecationWarning, stacklevel=2)
        return importlib.import_module(self.new)  # the same module object under both names

    def exec_module(self, module) -> None:
        pass


class MovedModuleFinder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        if fullname.split(".")[0] not in GENERAL_PACKAGES or "." not in fullname:
            return None
        new = moved_modules().get(fullname)
        return None if new is None else importlib.util.spec_from_loader(fullname, _Alias(fullname, new))


def install() -> None:
    if not any(isinstance(f, MovedModuleFinder) for f in sys.meta_path):
        sys.meta_path.append(MovedModuleFinder())
