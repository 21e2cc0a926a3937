"""The package graph runs one way: `twin.core` at the bottom, the controller (`rapid_like`) and the front ends
above it (the Structured Text runtime `structured_text` beside `rapid_like`), the application (`twin_app`) on top. Built from the source (ast, imports inside functions too)."""
from __future__ import annotations

import ast
from pathlib import Path

from tests.conftest import ROOT

PACKAGES = ("twin", "twin_app", "rapid_like", "structured_text", "plc_client", "stations", "bench")
# A package's `__main__.py` is a launcher (like a console script): it belongs to the application layer.
LAUNCHER_LAYER = "twin_app"


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
    if path is not None and path.name == "__main__.py":
        return LAUNCHER_LAYER
    return module.split(".")[0]


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
    assert "twin" in edges["rapid_like"]  # rapid_like/station_host.py binds to twin.core
    assert "rapid_like" in edges["twin_app"]  # the cell assembly attaches the controller (an import in a module)
    assert any("station_host" in e for e in edges["twin_app"]["rapid_like"])
    assert find_cycle({"a": {"b": []}, "b": {"c": []}, "c": {"a": []}}) == ["a", "b", "c", "a"]


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


def test_front_ends_and_the_controller_do_not_import_the_application():
    bad = [f"{path.relative_to(ROOT)} imports {target}"
           for pkg in ("twin", "rapid_like", "structured_text", "plc_client") for path in sorted((ROOT / pkg).rglob("*.py"))
           if path.name != "__main__.py"
           for target in imports_of(path) if target.split(".")[0] == "twin_app"]
    assert not bad, "; ".join(bad)


def test_the_structured_text_runtime_sits_beside_the_rapid_interpreter():
    """structured_text may use twin.core only; the PLC client may use it, never the other way round."""
    edges = package_edges()
    assert set(edges.get("structured_text", {})) <= {"twin"}, edges.get("structured_text")
    assert not any(p.startswith("twin.") and not p.startswith("twin.core") for e in edges.get("structured_text", {}).values()
                   for p in [x.split(" -> ")[1] for x in e])
    assert "structured_text" in edges["plc_client"]  # `plc check` / `plc run FILE.st`
