"""The shipped campaign with the gripper PLC in Structured Text (`twin campaign ... --plc "gripper.st io.st"`):
the same verdict per scenario as with the Python PLC, from physics and signals. Its seven scenarios that name a
PLC fault here, one test each (each PLC runs it in process, in lockstep); all fifteen agree in a full run
(docs/plc-on-real-hardware.md)."""
import csv
import subprocess
import sys

import pytest

from tests.conftest import STATIONS
from twin_app.campaign import LocalBackend, load_campaign, run_campaign
from twin_app.campaign.cli import with_plc

SHIPPED = STATIONS / "ring_rig_plc" / "campaign.toml"
VERDICT = ("outcome", "fault", "grips", "misses", "grip", "plc_faults", "part_present")


def verdicts(campaign, out, indices) -> dict[str, tuple]:
    result = run_campaign(campaign, LocalBackend(1), out, indices=indices, quiet=True)
    assert result.counts["error"] == 0, [r.get("message") for r in result.records]
    return {r["index"]: tuple(r[c] for c in VERDICT) for r in csv.DictReader((out / "results.csv").open())}


# every scenario that names a PLC fault: missed, jammed and drive lost (each while preparing and while gripping),
# lost, force reading; the full cycles and link losses only add run time (the demo's test runs a full cycle)
FAULTED = [(sc.name, sc.expect["plc_fault"]) for sc in load_campaign(SHIPPED).scenarios if "plc_fault" in sc.expect]


@pytest.mark.parametrize("scenario, fault", FAULTED, ids=[f"{i}-{f}" for i, (_, f) in enumerate(FAULTED)])
def test_the_st_and_the_python_gripper_plc_give_the_same_verdicts(tmp_path, scenario, fault):
    """One fault scenario at a time; the fault each PLC names is the one the campaign expects."""
    python = load_campaign(SHIPPED)
    st = with_plc(python, "gripper.st io.st")
    picked = [sc.index for sc in python.scenarios if sc.name == scenario]
    assert len(picked) == 1
    a = verdicts(python, tmp_path / "python", picked)
    b = verdicts(st, tmp_path / "st", picked)
    assert a == b
    assert {v[5] for v in a.values()} == {fault}


def test_a_campaign_refuses_a_plc_it_cannot_find():
    out = subprocess.run([sys.executable, "-m", "twin", "campaign", str(SHIPPED), "--plc", "nowhere.st", "--list"],
                         capture_output=True, text=True)
    assert out.returncode == 2 and "nowhere.st: no such file" in out.stderr
