"""The campaign shipped with the ring rig (stations/ring_rig_plc/campaign.toml): what it proves, and two of
its scenarios run (the whole of it is `twin campaign stations/ring_rig_plc/campaign.toml`)."""
import csv
import re

import pytest

from tests.conftest import STATIONS
from twin_app.campaign import LocalBackend, load_campaign, run_campaign
from twin_app.campaign.verdict import expectations

SHIPPED = STATIONS / "ring_rig_plc" / "campaign.toml"


def robot_plc_timeout() -> float:
    """s the robot program waits for the gripper PLC before it stops the cycle itself (its PLC_TIMEOUT)."""
    text = (STATIONS / "ring_rig_plc" / "ring_rig_plc.mod").read_text()
    return float(re.search(r"CONST num PLC_TIMEOUT := (\d+);", text).group(1))


FINGER_FAULTS = {"finger_jammed", "finger_force_lost"}


def test_it_covers_offsets_sizes_a_missing_ring_a_jammed_finger_a_dead_drive_and_a_link_loss():
    c = load_campaign(SHIPPED)
    assert c.driver.kind == "plc" and c.driver.ref == "stations.ring_rig_plc.plc_logic:cell_sequence"
    params = [s.params for s in c.scenarios]
    assert any(p.get("ring.offset_x_mm") for p in params) and any(p.get("ring.offset_y_mm") for p in params)
    assert any("ring.outer_diameter_mm" in p for p in params)
    kinds = {c.faults[p["fault"]].kind for p in params if p.get("fault", "none") != "none"}
    assert kinds == {"part_missing", "finger_jammed", "finger_force_lost", "force_stuck", "link_lost"}
    timeout = robot_plc_timeout()
    for sc in c.scenarios:  # every scenario says what the PLC must reach
        exp = expectations(c, sc)
        kind = c.faults[sc.params["fault"]].kind if sc.params.get("fault", "none") != "none" else None
        if kind in FINGER_FAULTS:
            # the PLC itself names the finger fault, well before the robot would give up on it
            assert exp["outcome"] == "stopped" and exp["fault"] == "cycle_fault"
            assert exp["plc_fault"] in ("jammed", "drive_lost", "lost")
            assert exp["cycle_time_max"] < timeout / 2
        elif kind == "force_stuck":  # a finger reading no force: never a grip, the sensor named
            assert (exp["outcome"], exp["grips"], exp["plc_fault"]) == ("stopped", 0, "force_reading")
        elif kind == "part_missing":  # no grip confirmed, the miss detected twice, the cycle stopped
            assert (exp["outcome"], exp["fault"], exp["grips"], exp["grip"], exp["plc_fault"]) == (
                "stopped", "cycle_fault", 0, "missed", "missed")
        else:  # outside and inside, no false alarm
            assert (exp["outcome"], exp["grip"], exp["grips"], exp["plc_fault"]) == ("completed", "confirmed", 2, "none")


def test_a_jammed_finger_and_a_dead_drive_are_found_by_the_plc_not_by_the_robots_timeout(tmp_path):
    """The finger-fault scenarios in lockstep with the physics: the PLC names the fault within seconds, never
    confirms a grip the fingers do not hold, and leaves the ring where it was (the old PLC pushed it 25 to
    60 mm across its pallet and waited for the robot's 30 s timeout)."""
    c = load_campaign(SHIPPED)
    faulty = {s.index: c.faults[s.params["fault"]] for s in c.scenarios
              if s.params.get("fault", "none") != "none" and c.faults[s.params["fault"]].kind in FINGER_FAULTS}
    assert len(faulty) >= 4
    result = run_campaign(c, LocalBackend(2), tmp_path, indices=sorted(faulty), quiet=True)
    assert result.counts == {"pass": len(faulty), "fail": 0, "error": 0}, [r["failures"] for r in result.records]
    rows = {int(r["index"]): r for r in csv.DictReader((tmp_path / "results.csv").open())}
    timeout = robot_plc_timeout()
    for i, fault in faulty.items():
        row = rows[i]
        assert row["outcome"] == "stopped" and float(row["time"]) < timeout / 4, row
        carrying = float(fault.keys.get("at", 0.0)) > 2.5  # the drive dies after the grip was confirmed
        if fault.kind == "finger_jammed":
            assert row["plc_faults"] == "jammed" and row["grips"] == "0"
        elif not carrying:
            assert row["plc_faults"] == "drive_lost" and row["grips"] == "0"
        else:  # the ring slipped out of the fingers (the physics' slip) and the PLC withdrew its grip
            assert row["plc_faults"] == "lost" and row["grips"] == "1" and row["slip"] == "true"
        if not carrying:  # the ring stays where it was: nobody pushed it across the pallet
            assert float(row["part_moved_mm"]) < 5.0, row
        if fault.kind == "finger_jammed":
            # never squeezed against the jam: each finger's true force stays far below its drive's 4000 N
            assert float(row["max_finger_force"]) < 1000.0


def test_the_nominal_cycle_and_the_missing_ring_reach_their_outcomes(tmp_path):
    c = load_campaign(SHIPPED)
    nominal = next(s.index for s in c.scenarios if s.name == "nominal")
    missing = next(s.index for s in c.scenarios if s.params.get("fault") == "ring_missing")
    result = run_campaign(c, LocalBackend(2), tmp_path, indices=[nominal, missing], quiet=True)
    assert result.counts == {"pass": 2, "fail": 0, "error": 0}, [r["failures"] for r in result.records]
    rows = {int(r["index"]): r for r in csv.DictReader((tmp_path / "results.csv").open())}
    assert rows[nominal]["grips"] == "2" and float(rows[nominal]["part_moved_mm"]) < 5.0
    assert rows[missing]["misses"] == "2" and rows[missing]["part_present"] == "false"
    assert float(rows[nominal]["time"]) == pytest.approx(15.2, abs=1.5)  # the demo's cycle time
