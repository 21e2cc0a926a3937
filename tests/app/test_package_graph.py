"""The package graph runs one way, by concept: `twin.core` (the stepped simulation) at the bottom; `twin.runtime`
(running a cell in time), `twin.devices` (vendors' devices over the twin) and `twin.observe` (seeing it) on
the core; `twin.frontends` (Modbus, OPC UA, the page, the front-end process) on those; the controller
(`rapid_like`) and the Structured Text runtime (`structured_text`) on the core alone; the PLC client above
the front ends; the application (`twin_app`, and every command's launcher) on top. Built from the source (ast,
imports inside functions too); every edge between two units must be written down in ALLOWED."""
from __future__ import annotations

import ast
import tomllib
from pathlib import Path

from tests.conftest import ROOT

PACKAGES = ("twin", "twin_app", "rapid_like", "structured_text", "plc_client", "stations", "bench")
TWIN_UNITS = ("core", "runtime", "devices", "frontends", "observe")  # twin's packages, each a unit of the graph
# A command's launcher (a package's `__main__.py`, a console script's module) belongs to the application layer.
LAUNCHER_LAYER = "twin_app"
LAUNCHERS = {ref.split(":")[0] for ref in
             tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["scripts"].values()}
BELOW_THE_APP = {"twin.core", "twin.runtime", "twin.devices", "twin.observe", "twin.frontends", "rapid_like",
                 "structured_text", "plc_client"}
# unit -> the units it may import (each one written down: a new edge is a decision, not an accident)
ALLOWED = {
    "twin": set(),  # twin/__init__.py: a docstring
    "twin.core": set(),
    "twin.runtime": {"twin.core"},
    "twin.devices": {"twin.core"},
    "twin.observe": {"twin.core"},
    "twin.frontends": {"twin.core", "twin.runtime", "twin.devices", "twin.observe"},
    "rapid_like": {"twin.core"},
    "structured_text": {"twin.core"},
    # one register map on both sides of the wire (twin.frontends.modbus.register_map); the demo's report (observe)
    "plc_client": {"twin.core", "twin.frontends", "twin.observe", "structured_text"},
    "twin_app": BELOW_THE_APP,
    "stations": BELOW_THE_APP | {"twin_app"},  # station code, loaded by name at run time (twin_app.plugins)
    "bench": BELOW_THE_APP | {"twin_app", "stations"},
}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imports_of(path: Path) -> set[str]:
    """Every project module `path` imports, wherever the import statement is (functions included)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    me = module_name(path)
    package = me if path.name == "__init__.py" else me.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            found.add(target)
            found.update(f"{target}.{alias.name}" for alias in node.names)  # `from pkg import module`
    return {m for m in found if m.split(".")[0] in PACKAGES}


def project_files():
    for pkg in PACKAGES:
        yield from sorted((ROOT / pkg).rglob("*.py"))


def layer(module: str, path: Path | None = None) -> str:
    """The unit of the graph a module belongs to: one of twin's packages, or a top-level package."""
    if path is not None and (path.name == "__main__.py" or module in LAUNCHERS):
        return LAUNCHER_LAYER
    parts = module.split(".")
    if parts[0] == "twin" and len(parts) > 1 and parts[1] in TWIN_UNITS:
        return f"twin.{parts[1]}"
    return parts[0]


def package_edges() -> dict[str, dict[str, list[str]]]:
    """layer -> imported layer -> the modules that do it (for messages)."""
    edges: dict[str, dict[str, list[str]]] = {}
    for path in project_files():
        src = layer(module_name(path), path)
        for target in imports_of(path):
            dst = layer(target)
            if dst != src:
                edges.setdefault(src, {}).setdefault(dst, []).append(f"{path.relative_to(ROOT)} -> {target}")
    return edges


def find_cycle(edges: dict[str, dict[str, list[str]]]) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in edges.get(node, {}):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if state.get(nxt) is None and (cycle := visit(nxt)):
                return cycle
        stack.pop()
        state[node] = 2
        return None

    for node in list(edges):
        if state.get(node) is None and (cycle := visit(node)):
            return cycle
    return None


def test_the_import_scanner_sees_local_and_relative_imports():
    edges = package_edges()
    assert "twin.core" in edges["rapid_like"]  # rapid_like/station_host.py binds to twin.core
    assert "rapid_like" in edges["twin_app"]  # the cell assembly attaches the controller (an import in a module)
    assert any("station_host" in e for e in edges["twin_app"]["rapid_like"])
    assert "twin.core" in edges["twin.observe"]  # relative imports inside twin's packages count too
    assert layer("plc_client.cli", ROOT / "plc_client" / "cli.py") == LAUNCHER_LAYER  # the `plc` command
    assert find_cycle({"a": {"b": []}, "b": {"c": []}, "c": {"a": []}}) == ["a", "b", "c", "a"]


def wrong_edges(edges: dict[str, dict[str, list[str]]]) -> list[str]:
    return [f"{src} -> {dst} ({'; '.join(why[:2])})" for src, targets in sorted(edges.items())
            for dst, why in sorted(targets.items()) if dst not in ALLOWED.get(src, set())]


def test_every_edge_between_units_is_an_allowed_one():
    bad = wrong_edges(package_edges())
    assert not bad, "imports against the layout (tests/app/test_package_graph.py ALLOWED):\n" + "\n".join(bad)


def test_a_wrong_edge_is_caught():
    assert wrong_edges({"twin.observe": {"twin.frontends": ["twin/observe/x.py -> twin.frontends.view"]}})
    assert wrong_edges({"twin.core": {"twin.runtime": ["twin/core/x.py -> twin.runtime.exchange"]}})
    assert not wrong_edges({"twin.frontends": {"twin.runtime": ["twin/frontends/x.py -> twin.runtime.exchange"]}})


def test_no_cycle_between_packages():
    edges = package_edges()
    cycle = find_cycle(edges)
    if cycle:
        why = [f"{a} -> {b}: " + "; ".join(edges[a][b][:3]) for a, b in zip(cycle, cycle[1:])]
        raise AssertionError("package cycle " + " -> ".join(cycle) + "\n" + "\n".join(why))


def test_the_core_imports_nothing_above_it():
    bad = [f"{path.relative_to(ROOT)} imports {target}"
           for path in sorted((ROOT / "twin" / "core").rglob("*.py"))
           for target in imports_of(path) if not (target == "twin.core" or target.startswith("twin.core."))]
    assert not bad, "twin.core must import only itself (and third-party packages): " + "; ".join(bad)


def test_nothing_below_the_application_imports_it():
    """twin, the controller, the ST runtime and the PLC client never import twin_app (a command's launcher may)."""
    bad = [f"{path.relative_to(ROOT)} imports {target}"
           for pkg in ("twin", "rapid_like", "structured_text", "plc_client") for path in sorted((ROOT / pkg).rglob("*.py"))
           if layer(module_name(path), path) != LAUNCHER_LAYER
           for target in imports_of(path) if target.split(".")[0] == "twin_app"]
    assert not bad, "; ".join(bad)


def test_the_structured_text_runtime_sits_beside_the_rapid_interpreter():
    """structured_text may use twin.core only; the PLC client may use it, never the other way round."""
    edges = package_edges()
    assert set(edges.get("structured_text", {})) <= {"twin.core"}, edges.get("structured_text")
    assert "structured_text" in edges["plc_client"]  # `plc check` / `plc run FILE.st`
