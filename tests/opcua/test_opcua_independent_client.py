"""The OPC UA server against a client outside Python's asyncua: node-opcua (Node.js, from the npm registry).

The test installs node-opcua-client into tests/opcua/node_client (once; about 30 s) and runs check.js there:
browse, read, a refused out-of-range, wrong-typed and output write, setpoint writes, Sim.Advance in lockstep and
a subscription that sees doGripped rise. Skipped, with the reason, where Node.js or npm is missing or the
package cannot be installed."""
from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from opcua_helpers import RING_RIG, OpcUaServerProcess

NODE_CLIENT = Path(__file__).resolve().parent / "node_client"


@pytest.fixture(scope="module")
def node_opcua() -> Path:
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        pytest.skip("node/npm not installed: the independent node-opcua client cannot run")
    if not (NODE_CLIENT / "node_modules" / "node-opcua-client").is_dir():
        r = subprocess.run([npm, "install", "--no-audit", "--no-fund", "--no-package-lock"], cwd=NODE_CLIENT,
                           capture_output=True, text=True, timeout=600)
        if r.returncode != 0:
            pytest.skip("npm could not install node-opcua-client: " + (r.stderr.strip().splitlines() or ["?"])[-1])
    return Path(node)


def test_node_opcua_browses_reads_writes_advances_and_subscribes(node_opcua):
    with OpcUaServerProcess(RING_RIG, "--lockstep", "--no-modbus") as server:
        r = subprocess.run([str(node_opcua), "check.js", server.url, "ring_rig"], cwd=NODE_CLIENT,
                           capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    result = [line for line in r.stdout.splitlines() if line.startswith("RESULT ")]  # node-opcua logs to stdout too
    assert result, r.stdout + r.stderr
    out = json.loads(result[-1][len("RESULT "):])
    ns = out["ns"]
    assert ns >= 2
    assert {"Gripper", "Fingers", "Robot", "Targets", "Controller", "Sim"} <= set(out["folders"])
    assert {f"ns={ns};s={n}" for n in ("Active", "L2", "L3", "L4", "doGripped", "GrippedPart", "L2.actual")} <= set(out["gripper"])
    assert out["L2_datatype"] == "ns=0;i=11"  # Double
    assert out["before"] == {"L2": 0.35, "doGripped": False}  # the station's initial setpoint, not gripped
    assert out["refused"] == {"out_of_range": "BadOutOfRange", "wrong_type": "BadTypeMismatch", "output": "BadNotWritable"}
    assert out["revised_sampling"] == 12  # 0 requested: revised to the step
    assert out["accepted"] == ["Good"] * 3
    assert out["advance"] == {"status": "Good", "step": [200]}
    after = out["after"]
    assert after["doGripped"] is True and after["GrippedPart"] == "ring" and after["step"] == 200
    assert abs(after["L2_actual"] - 0.32) < 0.002  # stopped on the ring's 320 mm outer radius
    assert out["subscription"][0] is False and True in out["subscription"]
