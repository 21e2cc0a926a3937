"""One error tree: everything the project raises for a user's mistake or a plant condition is a TwinError,
there is one UsageError, and each command prints one line for any of them (twin/core/errors.py)."""
from __future__ import annotations

import ast
import importlib
import subprocess
import sys

import pytest

from tests.app.test_package_graph import PACKAGES, module_name
from tests.conftest import ROOT, STATIONS
from twin.core.errors import TwinError

# exceptions that never reach a user: raised and caught inside one stage, each turned into a TwinError there
INTERNAL = {
    "rapid_like.values.TypeMismatch": "the interpreter turns it into an ExecError at the expression's span",
    "structured_text.stdlib_fn.SignatureError": "the checker turns it into a CheckError at the call",
    "structured_text.types.OperandError": "the checker turns it into a CheckError at the operand",
    "structured_text.rtlib.Fault": "the runtime turns it into a PlcFault naming the task",
}


def exception_classes():
    """(module.Class, class) of every exception class the project defines (AST-found, then imported)."""
    for pkg in PACKAGES:
        if pkg in ("bench",):
            continue
        for path in sorted((ROOT / pkg).rglob("*.py")):
            if path.name == "__main__.py":
                continue
            tree = ast.parse(path.read_text(encoding="utf-8"))
            names = [n.name for n in tree.body if isinstance(n, ast.ClassDef)
                     and (n.name.endswith(("Error", "Fault", "Refused")) or n.name == "Fault")]
            if not names:
                continue
            module = importlib.import_module(module_name(path))
            for name in names:
                cls = getattr(module, name)
                if isinstance(cls, type) and issubclass(cls, BaseException):
                    yield f"{module.__name__}.{name}", cls


def test_every_error_the_project_raises_on_purpose_is_a_twin_error():
    found = dict(exception_classes())
    assert len(found) > 30  # the scan sees the packages (SpecError, RapidError, StError, PlcClientError, ...)
    stray = sorted(name for name, cls in found.items() if not issubclass(cls, TwinError) and name not in INTERNAL)
    assert not stray, f"not TwinErrors: {stray}"
    for name in ("twin.runtime.faults.FaultError", "twin_app.plugins.LoadError", "twin.frontends.opcua.security.SecurityError",
                 "twin.frontends.opcua.address_space.AddressSpaceError", "twin_app.campaign.scenario.ScenarioError",
                 "twin_app.campaign.spec.SpecError", "rapid_like.errors.RapidError", "twin.frontends.modbus.register_map.MapError",
                 "plc_client.errors.PlcClientError", "structured_text.errors.StError", "twin.runtime.exchange.SimulationFault"):
        assert issubclass(found[name], TwinError), name


def test_there_is_one_usage_error():
    defined = [f"{path.relative_to(ROOT)}" for pkg in PACKAGES for path in sorted((ROOT / pkg).rglob("*.py"))
               for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
               if isinstance(node, ast.ClassDef) and node.name == "UsageError"]
    assert defined == ["twin/core/errors.py"]


def test_object_pose_names_the_object_it_does_not_have():
    from twin.core import Twin

    with Twin.from_station(STATIONS / "smart_gripper") as twin:
        with pytest.raises(TwinError, match="'tea_cup'") as caught:
            twin.object_pose("tea_cup")
    assert "cube" in str(caught.value)  # and says what the station has


def one_line_error(cmd: list[str]) -> tuple[int, str]:
    run = subprocess.run([sys.executable, "-m", *cmd], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert "Traceback" not in run.stderr, run.stderr
    lines = [line for line in run.stderr.splitlines() if not line.startswith("twin serve: loading station")]
    assert len(lines) == 1, run.stderr  # one line (beside the server's log line saying what it loads)
    return run.returncode, lines[0]


def test_each_command_prints_one_line_for_a_project_error(tmp_path):
    broken = tmp_path / "cell"
    broken.mkdir()
    text = (STATIONS / "smart_gripper" / "station.toml").read_text()
    (broken / "station.toml").write_text(text.replace('urdf = "smart_gripper.urdf"', f'urdf = "{(STATIONS / "smart_gripper" / "smart_gripper.urdf").as_posix()}"')
                                         + '\n[controller]\nprogram = "bad.mod"\n')
    (broken / "bad.mod").write_text("MODULE bad\n  PROC main()\n    TPWrite \"x\"\n  ENDPROC\nENDMODULE\n")  # no ';'
    code, err = one_line_error(["twin", "serve", str(broken), "--port", "0"])
    assert code == 2 and err.startswith("twin: ") and "bad.mod:3:" in err  # FILE:LINE:COL of the program
    code, err = one_line_error(["twin", "info", str(tmp_path / "nothing.urdf")])
    assert code == 2 and err.startswith("twin: error: ") and "nothing.urdf" in err
    # a station whose URDF names a mesh that is not there: its one error line, and nothing of a report before it
    meshless = tmp_path / "meshless"
    meshless.mkdir()
    urdf = (STATIONS / "smart_gripper" / "smart_gripper.urdf").read_text()
    box = '<collision><origin xyz="0 0 0.04"/><geometry><box size="0.06 0.12 0.08"/></geometry></collision>'
    assert box in urdf
    (meshless / "smart_gripper.urdf").write_text(urdf.replace(
        box, '<collision><geometry><mesh filename="meshes/pad.stl"/></geometry></collision>'))
    (meshless / "station.toml").write_text(text)
    run = subprocess.run([sys.executable, "-m", "twin", "info", str(meshless)], capture_output=True, text=True,
                         cwd=ROOT, timeout=120)
    assert run.returncode == 2 and run.stdout == "" and "meshes/pad.stl" in run.stderr, (run.stdout, run.stderr)
    code, err = one_line_error(["rapid_like", "run", str(broken / "bad.mod"), "--set", "x=1"])
    # a usage mistake exits 2 as argparse's own (and twin's, plc's) do, naming the option it is about
    assert code == 2 and err.startswith("rapid: error: ") and "--set" in err and "'x=1'" in err
    code, err = one_line_error(["plc_client", "--station", str(broken), "read", "no.such.signal"])
    assert code == 2 and err.startswith("plc: error: ")
