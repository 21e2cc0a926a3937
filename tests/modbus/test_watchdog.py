"""The comm-loss watchdog: silence for S seconds (wall clock in real time, simulated time in lockstep)
puts the gripper in the station's safe state and raises comm.lost; the next request clears it; the PLC
client's heartbeat keeps a quiet but healthy PLC from being taken for lost."""
from __future__ import annotations

import functools
import struct
import time
from pathlib import Path

import pytest

from modbus_helpers import RING_BENCH, ROOT, Raw, ServerProcess, pdu

L2, ADVANCE = 16, 0  # holding registers of the ring bench


def station(folder: Path, watchdog: str) -> Path:
    """The ring bench with a [watchdog] section."""
    text = (RING_BENCH / "station.toml").read_text()
    urdf = (ROOT / "stations" / "ring_rig" / "gripper3.urdf").as_posix()
    text = "\n".join(f'urdf = "{urdf}"' if line.startswith("urdf =") else line for line in text.splitlines())
    path = folder / "station.toml"
    path.write_text(text + "\n\n[watchdog]\n" + watchdog + "\n")
    return path


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def cell(tmp_path, watchdog: str):
    from twin_app.cell import open_cell

    twin = open_cell(station(tmp_path, watchdog))
    return twin, twin.watchdog


def grip(twin, setpoint: float = 0.30, steps: int = 150):
    for axis in ("L2", "L3", "L4"):
        twin.write(axis, setpoint)
    twin.step(steps)


# -- the watchdog in process, with an injected clock -------------------------------------------------------
def test_it_fires_after_the_timeout_of_silence_and_not_before_and_the_next_request_clears_it(tmp_path):
    twin, dog = cell(tmp_path, 'timeout = 0.5\nsafe_state = "stop"')
    with twin:
        clock = dog.clock = Clock()
        twin.step(2)
        assert not twin.read("comm.lost")  # nobody has talked yet: not armed
        clock.t = 10.0
        twin.step()
        assert not twin.read("comm.lost")
        dog.feed("modbus 127.0.0.1:1")
        clock.t = 10.499
        twin.step()
        assert not twin.read("comm.lost")
        clock.t = 10.5
        twin.step()
        assert twin.read("comm.lost") and dog.trips == 1
        clock.t = 20.0
        twin.step()
        assert dog.trips == 1  # raised once, not again while lost
        dog.feed("opcua session-1")  # any front end's request clears it
        assert not twin.read("comm.lost")


def test_in_simulated_time_it_fires_at_the_first_step_at_or_past_the_timeout(tmp_path):
    twin, dog = cell(tmp_path, "timeout = 0.1")
    with twin:
        twin.step(3)
        dog.feed("modbus x")  # at t = 0.036
        fired_at = None
        for _ in range(20):
            twin.step()
            if twin.read("comm.lost"):
                fired_at = twin.step_count
                break
        assert fired_at == 3 + 9  # 9 steps of 12 ms = 0.108 s >= 0.1 s; 8 steps = 0.096 s are not


def test_stop_freezes_the_fingers_where_they_are_while_without_the_watchdog_they_go_on(tmp_path):
    twin, dog = cell(tmp_path, 'timeout = 0.05\nsafe_state = "stop"')
    ref, _ = cell(tmp_path / ".." / tmp_path.name, "")  # the same station, no timeout
    with twin, ref:
        for t in (twin, ref):
            t.write("L2", 0.44)  # 110 mm of travel outwards: not there within the next steps
            t.step(3)
        dog.feed("plc")
        twin.step(5)  # 60 ms > 50 ms: lost during these steps
        assert twin.read("comm.lost")
        at_loss = twin.read("L2.actual")
        twin.step(150)
        ref.step(155)
        assert abs(twin.read("L2.actual") - at_loss) < 0.003
        assert abs(ref.read("L2.actual") - 0.44) < 0.002  # the reference went all the way
        assert at_loss < 0.40
        assert twin.read("L2") == pytest.approx(twin.read("L2.actual"), abs=0.003)


def test_open_drives_every_axis_to_its_open_setpoint(tmp_path):
    twin, dog = cell(tmp_path, 'timeout = 0.05\nsafe_state = "open"\nopen = { L2 = 0.34 }')
    with twin:
        grip(twin)
        assert twin.read("doGripped")
        dog.feed("plc")
        twin.step(200)
        assert twin.read("comm.lost") and not twin.read("doGripped")
        assert twin.read("L2.actual") == pytest.approx(0.34, abs=0.002)  # the station's open setpoint
        assert twin.read("L3.actual") == pytest.approx(0.33, abs=0.002)  # gripper.initial


def test_hold_keeps_squeezing_a_held_part_where_stop_lets_the_grip_relax(tmp_path):
    forces = {}
    for state in ("hold", "stop"):
        folder = tmp_path / state
        folder.mkdir()
        twin, dog = cell(folder, f'timeout = 0.05\nsafe_state = "{state}"')
        with twin:
            grip(twin)
            squeeze = twin.read("L2.force")
            assert twin.read("doGripped") and squeeze > 1.0
            dog.feed("plc")
            twin.step(100)
            assert twin.read("comm.lost")
            forces[state] = (squeeze, twin.read("L2.force"), twin.read("doGripped"), twin.read("L2"))
    squeeze, after, gripped, setpoint = forces["hold"]
    assert gripped and after > 0.5 * squeeze and setpoint == pytest.approx(0.30)
    squeeze, after, _, setpoint = forces["stop"]
    assert after < 0.5 * squeeze and setpoint > 0.31


def test_a_bad_watchdog_key_names_the_place(tmp_path):
    from twin.core.errors import StationError

    with pytest.raises(StationError, match="safe_state"):
        cell(tmp_path, 'safe_state = "drop"')
    with pytest.raises(StationError, match=r"watchdog\.open\.L9"):
        cell(tmp_path, "open = { L9 = 0.3 }")


# -- on the wire -----------------------------------------------------------------------------------------
def comm_lost(raw: Raw, address: int) -> int:
    return raw.request(pdu(2, address, 1))[2] & 1


@functools.lru_cache(maxsize=None)
def map_address(name: str) -> int:
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "twin", "map", str(RING_BENCH), "--format", "json"],
                         capture_output=True, text=True, check=True, cwd=ROOT).stdout
    return next(e["address"] for e in json.loads(out) if e["name"] == name)


def test_real_time_silence_raises_comm_lost_sets_the_safe_state_and_the_next_request_clears_it(tmp_path):
    lost = map_address("comm.lost")
    with ServerProcess(station(tmp_path, 'safe_state = "stop"'), "--watchdog", "0.3") as server:
        with Raw(server.port) as raw:
            assert raw.request(pdu(4, 12, 2)) == b"\x04\x04" + struct.pack(">I", 300)  # comm.watchdog_ms
            assert raw.request(pdu(6, L2, 44000)) == pdu(6, L2, 44000)  # open to 440 mm: a long way
            time.sleep(0.1)
            assert comm_lost(raw, lost) == 0
            time.sleep(0.6)  # silence
            server.wait_for(r"comm lost: no request for 0\.3\d* s .*safe state 'stop'")
            assert comm_lost(raw, lost) == 1  # the first request afterwards sees it ...
            server.wait_for(r"comm restored")
            time.sleep(0.05)
            assert comm_lost(raw, lost) == 0  # ... and clears it
            setpoint = struct.unpack(">H", raw.request(pdu(3, L2, 1))[2:])[0]
            assert 33100 < setpoint < 43500  # stopped where it was, not driving on to 440 mm


def test_in_lockstep_it_counts_simulated_time_not_the_wall_clock(tmp_path):
    lost = map_address("comm.lost")
    with ServerProcess(station(tmp_path, "timeout = 0.1"), "--lockstep") as server, Raw(server.port) as raw:
        raw.request(pdu(6, ADVANCE, 5))  # 60 ms of simulated time
        time.sleep(0.8)  # far longer than 0.1 s of wall clock, but only 0.06 s simulated
        assert comm_lost(raw, lost) == 0
        raw.request(pdu(6, ADVANCE, 20))  # 240 ms simulated without another request
        while raw.request(pdu(3, ADVANCE, 1)) != b"\x03\x02\x00\x00":  # polling sim.advance: the script's
            time.sleep(0.01)  # clock, not the controller's traffic: it does not feed the watchdog
        server.wait_for(r"comm lost: no request for 0\.108 s")  # fired at exactly 9 steps
        assert comm_lost(raw, lost) == 1  # the first other request sees it and clears it
        server.wait_for(r"comm restored")


def test_the_plc_clients_heartbeat_keeps_a_quiet_plc_alive_and_without_it_the_link_is_lost(tmp_path):
    from plc_client import TwinClient

    with ServerProcess(station(tmp_path, "timeout = 0.3"), "--watchdog", "0.3") as server:
        with TwinClient.connect("127.0.0.1", server.port, station=RING_BENCH) as plc:
            plc.write(L2=300.0)
            time.sleep(1.2)  # the PLC program is quiet
            assert plc.heartbeats >= 3
        assert not any("comm lost" in line for line in server.lines)
        with TwinClient.connect("127.0.0.1", server.port, station=RING_BENCH, heartbeat=None) as plc:
            plc.write(L2=300.0)
            time.sleep(0.8)
        server.wait_for("comm lost")


def test_the_robot_program_sees_the_lost_link_on_a_di(tmp_path):
    from twin_app.cell import open_cell

    (tmp_path / "watch.mod").write_text('MODULE watch\n  PROC main()\n    WaitDI diCommLost, 1;\n'
                                        '    TPWrite "link lost";\n  ENDPROC\nENDMODULE\n')
    path = station(tmp_path, "timeout = 0.05")
    path.write_text(path.read_text() + '\n[controller]\nprogram = "watch.mod"\nentry = "main"\n\n'
                    '[[controller.io]]\nname = "diCommLost"\ntype = "DI"\nsource = "comm.lost"\n')
    said = []
    with open_cell(path, on_event=lambda e: said.append(e.get("text")) if e.get("type") == "print" else None) as twin:
        twin.step(10)
        assert said == [] and not twin.read("diCommLost")
        twin.watchdog.feed("plc")
        twin.step(10)
        assert twin.read("diCommLost") and said == ["link lost"]
