"""Campaign files: validation errors name the file, the key and the scenario; expansion; conditions."""
import textwrap
from pathlib import Path

import pytest

from twin_app.campaign import load_campaign, run_scenario
from twin_app.campaign.expressions import Expression, ExpressionError
from twin_app.campaign.spec import SpecError

BENCH_STATION = Path(__file__).resolve().parents[1] / "plc" / "stations" / "ring_bench"
HEAD = f"""
[campaign]
station = "{BENCH_STATION}"
[driver]
plc = "stations.ring_rig_plc.plc_logic:sequence"
[start]
grip_request = true
[run]
max_time = 5.0
done_when = "gripped"
stop_when = {{ missed = "grip_fault" }}
[faults.gone]
kind = "part_missing"
target = "ring"
"""


def write(tmp_path, body, head=HEAD):
    path = tmp_path / "c.toml"
    path.write_text(head + textwrap.dedent(body))
    return path


@pytest.mark.parametrize("body, key, words, scenario", [
    ("[matrix]\nring.offset_x_mm = 3\n", "matrix.ring.offset_x_mm", "must be a non-empty list", None),
    ("[matrix]\nring.offset_x_mm = ['ten']\n", "matrix.ring.offset_x_mm", "must be a finite number", None),
    ("[matrix]\nring.ofset_x_mm = [1.0]\n", "matrix.ring.ofset_x_mm", "did you mean 'offset_x_mm'", None),
    ("[matrix]\npuck.offset_x_mm = [1.0]\n", "matrix.puck.offset_x_mm", "unknown parameter", None),
    ("[[scenarios]]\nname = \"heavy\"\nring.mass_kg = -3.0\n", "scenarios[0].ring.mass_kg", "greater than 0", "heavy"),
    ("[[scenarios]]\nname = \"odd\"\nfault = \"jam\"\n", "scenarios[0].fault", "no fault 'jam'", "odd"),
    ("[[scenarios]]\nname = \"x\"\nexpect = { grip = \"maybe\" }\n", "scenarios[0].expect.grip", "must be one of", None),
    ("[expect]\noutcom = \"completed\"\n", "expect.outcom", "did you mean 'outcome'", None),
    ("[[expect.when]]\nif = \"ring.offset_x_mm > 1\"\ngrip = \"missed\"\n", "expect.when[0].if",
     "does not set", "base"),
    ("[[expect.when]]\nif = \"__import__('os')\"\n", "expect.when[0].if", "not allowed", None),
    ("[faults.jam]\nkind = \"finger_jammed\"\ninput = \"L7\"\n", "faults.jam.input", "no gripper input 'L7'", None),
    ("[faults.jam]\nkind = \"finger_jamed\"\n", "faults.jam.kind", "did you mean 'finger_jammed'", None),
    ("[faults.cut]\nkind = \"link_lost\"\nat = 1.0\n", "faults.cut.duration", "is required", None),
    ("[sample]\ncount = 3\nring.offset_x_mm = { uniform = [0, 1] }\n", "sample.seed", "is required", None),
    ("[sample]\ncount = 3\nseed = 1\nring.offset_x_mm = { gauss = [0, 1] }\n", "sample.ring.offset_x_mm.gauss",
     "unknown parameter", None),
    ("[matrix]\nsim.steps = [0.01]\n", "matrix.sim.steps", "sim.step (s) and sim.substeps", None),
])
def test_mistakes_name_the_file_the_key_and_the_scenario(tmp_path, body, key, words, scenario):
    path = write(tmp_path, body)
    with pytest.raises(SpecError) as info:
        load_campaign(path)
    err = info.value
    assert err.file == str(path) and err.key == key, str(err)
    assert words in str(err)
    assert str(err).startswith(f"{path}: {key}: ")
    if scenario:
        assert err.scenario == scenario and f"(scenario {scenario})" in str(err)


def test_a_driver_that_does_not_load_is_named(tmp_path):
    path = write(tmp_path, "", head=HEAD.replace("stations.ring_rig_plc.plc_logic:sequence", "stations.ring_rig_plc.plc_logic:sequense"))
    with pytest.raises(SpecError, match=r"driver.plc: 'stations.ring_rig_plc.plc_logic:sequense': stations.ring_rig_plc.plc_logic has no 'sequense'"):
        load_campaign(path)


def test_not_toml_and_no_station(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[campaign\n")
    with pytest.raises(SpecError, match="is not valid TOML"):
        load_campaign(bad)
    path = write(tmp_path, "", head=HEAD.replace(str(BENCH_STATION), "nowhere"))
    with pytest.raises(SpecError, match="campaign.station: cannot be loaded"):
        load_campaign(path)


def test_matrix_list_and_samples_expand_in_order_and_samples_repeat(tmp_path):
    body = """
    [parameters]
    plc.speed = 20.0
    [matrix]
    ring.offset_x_mm = [-1.0, 1.0]
    fault = ["none", "gone"]
    [[scenarios]]
    name = "light"
    ring.mass_kg = 10.0
    [sample]
    count = 4
    seed = 11
    ring.offset_y_mm = { uniform = [-5.0, 5.0], round = 3 }
    plc.threshold = [150.0, 250.0]
    """
    a = load_campaign(write(tmp_path, body))
    names = [s.name for s in a.scenarios]
    assert names[:5] == ["ring.offset_x_mm=-1, fault=none", "ring.offset_x_mm=-1, fault=gone",
                         "ring.offset_x_mm=1, fault=none", "ring.offset_x_mm=1, fault=gone", "light"]
    assert len(names) == 9 and all(s.params["plc.speed"] == 20.0 for s in a.scenarios)
    drawn = [s.params for s in a.scenarios[5:]]
    assert all(-5.0 <= p["ring.offset_y_mm"] <= 5.0 and round(p["ring.offset_y_mm"], 3) == p["ring.offset_y_mm"] for p in drawn)
    assert {p["plc.threshold"] for p in drawn} <= {150.0, 250.0}
    b = load_campaign(write(tmp_path, body))
    assert [s.params for s in b.scenarios] == [s.params for s in a.scenarios]
    c = load_campaign(write(tmp_path, body.replace("seed = 11", "seed = 12")))
    assert [s.params for s in c.scenarios[5:]] != drawn


def test_conditions_read_values_and_refuse_code():
    e = Expression("abs(ring.offset_x_mm) > 30 and fault != 'none' or not gripped")
    assert e.names == {"ring.offset_x_mm", "fault", "gripped"}
    assert e.evaluate({"ring.offset_x_mm": -40, "fault": "gone", "gripped": True})
    assert not e.evaluate({"ring.offset_x_mm": 10, "fault": "gone", "gripped": True})
    for bad in ("open('x')", "x.__class__()", "[i for i in y]", "lambda: 1", "a if b else c"):
        with pytest.raises(ExpressionError):
            Expression(bad)


def test_parameters_reach_the_physics_and_the_plc(tmp_path):
    """A lighter, smaller ring and a faster PLC, read back from the scenario's run."""
    body = """
    [[scenarios]]
    ring.outer_diameter_mm = 630.0
    ring.inner_diameter_mm = 470.0
    plc.speed = 40.0
    [[scenarios]]
    ring.outer_diameter_mm = 630.0
    ring.inner_diameter_mm = 470.0
    plc.speed = 10.0
    """
    c = load_campaign(write(tmp_path, body))
    fast, slow = run_scenario(c, 0), run_scenario(c, 1)
    assert fast["outcome"] == slow["outcome"] == "completed"
    # the fingers close from 330 mm to the ring's outer radius 315 mm: 15 mm at 40 or 10 mm/s
    assert fast["time"] == pytest.approx(15.0 / 40.0, abs=0.1)
    assert slow["time"] == pytest.approx(15.0 / 10.0, abs=0.15)


def test_a_lost_link_trips_the_comm_loss_watchdog_and_the_plc_recovers(tmp_path):
    body = """
    [faults.cut]
    kind = "link_lost"
    at = 0.2
    duration = 1.0
    [matrix]
    fault = ["none", "cut"]
    """
    c = load_campaign(write(tmp_path, body, head=HEAD.replace("[run]\n", "[run]\nwatchdog = 0.3\n")))
    healthy, cut = run_scenario(c, 0), run_scenario(c, 1)
    assert healthy["comm_lost_trips"] == 0 and cut["comm_lost_trips"] == 1
    # the grip waited for the link, then completed
    assert cut["outcome"] == "completed" and cut["grips"] == 1 and cut["time"] > 1.2 > healthy["time"]


def test_drive_limits_and_the_simulation_step_are_parameters(tmp_path):
    body = """
    [[scenarios]]
    gripper.effort = 400.0
    plc.threshold = 600.0
    [[scenarios]]
    gripper.velocity_mm_s = 5.0
    sim.step = 0.006
    """
    head = HEAD.replace('done_when = "gripped"\n', 'done_when = "gripped and time >= 1.0"\n')
    c = load_campaign(write(tmp_path, body, head=head))
    weak, fine = run_scenario(c, 0), run_scenario(c, 1)
    # drives limited to 400 N press with 400 N at most: a PLC waiting for 600 N never confirms, it declares a miss
    assert weak["max_finger_force"] == pytest.approx(400.0, rel=0.01)
    assert (weak["outcome"], weak["fault"], weak["grip"]) == ("stopped", "missed", "missed")
    # a 6 ms step: twice the steps for the same simulated time; fingers at 5 mm/s take 2 s for their 10 mm
    assert fine["outcome"] == "completed"
    assert fine["steps"] == pytest.approx(fine["time"] / 0.006, abs=1)
    assert fine["time"] == pytest.approx(10.0 / 5.0, abs=0.2)
