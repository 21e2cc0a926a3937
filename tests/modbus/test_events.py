"""`twin serve --events FILE`: the machine interface a harness reads instead of the log (docs/events.md).

A real server in lockstep, a raw Modbus client, a RAPID program that talks: every event is checked against
what the test itself did (its own socket's address, the steps it asked for, the program's text and waits,
the watchdog's time rounded up to whole steps), and the server runs with `--log-level error`, so nothing
here could come from reading the log."""
from __future__ import annotations

import json

import pytest

from modbus_helpers import RING_BENCH, ROOT, Raw, ServerProcess, pdu

ADVANCE = 0  # holding register of sim.advance (the first entry of every map)
PROGRAM = """MODULE talk
  PROC main()
    TPWrite "hello";
    WaitTime 0.06;
    ErrWrite \\W, "Heads up", "a reason";
    TPWrite "bye";
  ENDPROC
ENDMODULE
"""


def station(folder):
    text = (RING_BENCH / "station.toml").read_text()
    urdf = (ROOT / "stations" / "ring_rig" / "gripper3.urdf").as_posix()
    text = "\n".join(f'urdf = "{urdf}"' if line.startswith("urdf =") else line for line in text.splitlines())
    (folder / "talk.mod").write_text(PROGRAM)
    path = folder / "station.toml"
    path.write_text(text + '\n\n[watchdog]\ntimeout = 0.1\n\n[controller]\nprogram = "talk.mod"\nentry = "main"\n')
    return path


def advance(raw: Raw, steps: int) -> None:
    """sim.advance = steps, then poll it until they have run (requests that do not feed the watchdog)."""
    raw.request(pdu(6, ADVANCE, steps))
    while raw.request(pdu(3, ADVANCE, 1)) != b"\x03\x02\x00\x00":
        pass


def test_a_harness_learns_the_port_the_clients_the_robots_words_the_comm_loss_and_the_stop(tmp_path):
    with ServerProcess(station(tmp_path), "--lockstep", "--log-level", "error") as server:
        modbus = server.endpoint("modbus")
        assert modbus["protocol"] == "modbus/tcp" and modbus["host"] == "127.0.0.1" and modbus["port"] > 0
        with Raw(modbus["port"]) as raw:
            me = "127.0.0.1:%d" % raw.sock.getsockname()[1]
            hello = server.events.wait("client_connected", where=lambda e: e["peer"] == me)
            assert hello is not None and hello["front_end"] == "modbus" and hello["connected"] == 1
            advance(raw, 20)  # 240 ms simulated; only sim.advance traffic: the watchdog (0.1 s) fires
            said = [e for e in server.events.new() + server.events.seen if e["event"] == "controller"]
            lost = server.events.wait("comm_lost", timeout=1)
            raw.request(pdu(3, 16, 1))  # a PLC's own request: the link is back
            back = server.events.wait("comm_restored", timeout=5)
        gone = server.events.wait("client_gone", timeout=5, where=lambda e: e["peer"] == me)
        assert server.stop() == 0
    # the program's words, in order, at the simulated times its WaitTime gives them
    said = list({id(e): e for e in said}.values())
    prints = [(e["t"], e["text"]) for e in said if e["type"] == "print"]
    assert [text for _, text in prints] == ["hello", "bye"]
    assert prints[1][0] - prints[0][0] == pytest.approx(0.06, abs=1e-9)
    errlog = next(e for e in said if e["type"] == "errlog")
    assert (errlog["level"], errlog["header"], errlog["reason"], errlog["t"]) == ("warning", "Heads up", "a reason", prints[1][0])
    ends = [e for e in said if e["type"] in ("end", "error")]
    assert len(ends) == 1 and ends[0]["reason"] == "completed" and ends[0]["t"] == prints[1][0]
    states = [e["state"] for e in said if e["type"] == "state"]
    assert states == ["running", "completed"]  # its state changes, after the steps they happened in
    # armed by the first sim.advance at t = 0, the watchdog fires at the first step at or after 0.1 s: 9 x 12 ms
    assert lost["t"] == pytest.approx(0.108) and lost["silent_s"] == pytest.approx(0.108) and lost["timeout_s"] == 0.1
    assert back["source"] == f"modbus {me}" and back["t"] == pytest.approx(0.24)
    assert gone["connected"] == 0
    events = server.events.seen
    assert events[0]["event"] == "ready" and events[-1]["event"] == "stopped" and events[-1]["steps"] == 20
    times = [e["t"] for e in events]
    assert times == sorted(times)  # simulated time never goes back
    assert not any("twin serve: [t=" in line for line in server.lines)  # --log-level error: the log said none of it


def test_events_to_stdout_are_json_lines_and_a_bad_events_file_is_one_line(tmp_path):
    import subprocess
    import sys

    bad = subprocess.run([sys.executable, "-m", "twin", "serve", str(RING_BENCH), "--port", "0",
                          "--events", str(tmp_path / "no" / "such" / "dir" / "ev.jsonl")],
                         capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--events" in bad.stderr
    proc = subprocess.Popen([sys.executable, "-m", "twin", "serve", str(RING_BENCH), "--port", "0", "--lockstep",
                             "--events", "-"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, cwd=ROOT)
    try:
        ready = json.loads(proc.stdout.readline())
        assert ready["event"] == "ready" and ready["front_ends"][0]["port"] > 0
        with Raw(ready["front_ends"][0]["port"]):
            pass
        proc.terminate()
        rest = [json.loads(line) for line in proc.stdout]
    finally:
        proc.kill() if proc.poll() is None else None
        proc.wait(10)
    assert [e["event"] for e in rest] == ["client_connected", "client_gone", "stopped"]
