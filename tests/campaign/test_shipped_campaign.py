"""The campaign shipped with the ring rig (stations/ring_rig_plc/campaign.toml): what it proves, and two of
its scenarios run (the whole of it is `twin campaign stations/ring_rig_plc/campaign.toml`)."""
import csv

import pytest

from tests.conftest import STATIONS
from twin_app.campaign import LocalBackend, load_campaign, run_campaign
from twin_app.campaign.verdict import expectations

SHIPPED = STATIONS / "ring_rig_plc" / "campaign.toml"


def test_it_covers_offsets_sizes_a_missing_ring_a_jammed_finger_and_a_link_loss():
    c = load_campaign(SHIPPED)
    assert c.driver.kind == "plc" and c.driver.ref == "stations.ring_rig_plc.plc_logic:cell_sequence"
    params = [s.params for s in c.scenarios]
    assert any(p.get("ring.offset_x_mm") for p in params) and any(p.get("ring.offset_y_mm") for p in params)
    assert any("ring.outer_diameter_mm" in p for p in params)
    kinds = {c.faults[p["fault"]].kind for p in params if p.get("fault", "none") != "none"}
    assert kinds == {"part_missing", "finger_force_lost", "link_lost"}
    for sc in c.scenarios:  # every scenario says what the PLC must reach
        exp = expectations(c, sc)
        faulty = sc.params.get("fault", "none") != "none" and c.faults[sc.params["fault"]].kind != "link_lost"
        if faulty:  # no grip confirmed, the cycle stopped (a missing ring: the miss detected twice)
            assert (exp["outcome"], exp["fault"], exp["grips"]) == ("stopped", "cycle_fault", 0)
            assert exp["grip"] in ("missed", "none")
        else:
            assert (exp["outcome"], exp["grip"], exp["grips"]) == ("completed", "confirmed", 2)  # outside and inside


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
