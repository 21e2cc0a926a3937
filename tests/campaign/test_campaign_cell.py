"""A campaign's scenario runs the cell `twin serve` runs (twin_app.cell.Cell: the twin, the station's RAPID
controller and the comm-loss watchdog), in process and headless: same signals, same `sim.*`, and a cell
that does not publish snapshots steps exactly like one that does."""
from __future__ import annotations

import textwrap

from tests.conftest import STATIONS
from twin.core.signal_table import station_signals
from twin_app.campaign import load_campaign
from twin_app.campaign.scenario import run_scenario
from twin_app.cell import Cell

CELL = STATIONS / "ring_rig_plc"


def campaign(tmp_path, body: str):
    (tmp_path / "checks.py").write_text(textwrap.dedent('''
        def look(ctx):
            ctx.cell.step(50)
            return {"names": [s.name for s in ctx.cell.signals], "step": ctx.cell.read("sim.step"),
                    "time_ms": ctx.cell.read("sim.time_ms"), "watchdog_ms": ctx.cell.read("comm.watchdog_ms"),
                    "robot_started": ctx.cell.read("rapid.running")}
        '''))
    path = tmp_path / "campaign.toml"
    path.write_text(f'[campaign]\nname = "cell"\nstation = "{CELL.as_posix()}"\n' + textwrap.dedent(body))
    return load_campaign(path)


def test_a_check_function_gets_the_served_cell_with_its_sim_signals_and_watchdog(tmp_path):
    c = campaign(tmp_path, """
        [driver]
        check = "checks.py:look"
        [run]
        max_time = 5.0
        watchdog = 0.4
        """)
    r = run_scenario(c, 0)
    assert r["outcome"] == "completed", r
    # the signal table `twin map` and every front end publish for this station, sim.* included
    assert r["names"] == [s.name for s in station_signals(CELL)]
    assert r["step"] == 50 and r["time_ms"] == 600  # 50 steps of 12 ms
    assert r["watchdog_ms"] == 400 and r["robot_started"] is True


def test_conditions_may_name_the_simulators_signals(tmp_path):
    c = campaign(tmp_path, """
        [driver]
        rapid = true
        [run]
        max_time = 5.0
        done_when = "sim.time_ms >= 300"
        """)
    r = run_scenario(c, 0)
    assert r["outcome"] == "completed" and r["steps"] == 25, r  # 25 steps of 12 ms


def test_a_cell_that_does_not_publish_steps_exactly_like_one_that_does():
    with Cell(CELL) as served, Cell(CELL, publish=False) as headless:
        for cell in (served, headless):
            cell.write("fullAutoRun", True)  # the robot program runs its cycle; the fingers are written below
        for k in range(6):
            for cell in (served, headless):
                cell.write("L2", 0.330 - 0.004 * k)
                cell.step(40)
            assert [served.read(s.name) for s in served.signals] == [headless.read(s.name) for s in headless.signals]
        assert headless.exchange.snapshot.step == 0 and served.exchange.snapshot.step == 240
        assert headless.exchange.publish().values == served.exchange.snapshot.values  # one on demand, the same
