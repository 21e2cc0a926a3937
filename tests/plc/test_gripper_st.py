"""The ring rig's gripper PLC in Structured Text (stations/ring_rig_plc/gripper.st) against its Python original
(plc_logic.cell_sequence, a CarefulGripSequence): both drive the same small plant (three fingers that follow
their setpoints at a bounded speed, a ring that stops them and pushes back by the drives' stiffness, a robot
that asks as ring_rig_plc.mod does), scan for scan. The ST PLC reads and writes only the located variables of
the generated declarations (`twin map --format st`), bound to the plant through the PLC layout's registers,
so the words it sees are the ones a Modbus master would hand it. Every scan's setpoints (in counts), answers
and fault must be the same: a second implementation, not a copy of expected numbers."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CELL = ROOT / "stations" / "ring_rig_plc"

DT = 0.012  # the cell's step; both PLCs scan once per step
AXES, FORCES, CONTACTS, EFFORTS = ("L2", "L3", "L4"), ("L2.force", "L3.force", "L5.force"), \
    ("L2.contact", "L3.contact", "L5.contact"), ("L2.effort", "L3.effort", "L4.effort")
FAULTS = {0: "none", 1: "missed", 2: "stuck", 3: "bad_request", 4: "jammed", 5: "drive_lost", 6: "timeout",
          7: "lost", 8: "force_reading"}


class Plant:
    """Three fingers (mm) following their setpoints at up to 150 mm/s, a ring between them (outside: its outer
    face at 320 mm; inside: the bore touched at 200 mm) that stops them; force = 400 N per mm of setpoint
    past the ring, up to 4000 N. `jam`: an axis stuck where it is (its drive pushes); `dead`: an axis with no
    drive (it stays, pushing nothing); `lose_at`: the ring is gone from that step on."""

    def __init__(self, ring: str | None = "outside", jam: int | None = None, dead: int | None = None,
                 lose_at: int | None = None):
        self.ring, self.jam, self.dead, self.lose_at = ring, jam, dead, lose_at
        self.pos = [350.0, 350.0, 350.0]
        self.sp = list(self.pos)
        self.k = 0

    def step(self) -> None:
        self.k += 1
        if self.lose_at is not None and self.k >= self.lose_at:
            self.ring = None
        for i in range(3):
            if i in (self.jam, self.dead):
                continue
            move = max(-150.0 * DT, min(150.0 * DT, self.sp[i] - self.pos[i]))
            p = self.pos[i] + move
            if self.ring == "outside":
                p = max(p, 320.0) if self.pos[i] >= 320.0 else p
            elif self.ring == "inside":
                p = min(p, 200.0) if self.pos[i] <= 200.0 else p
            self.pos[i] = p

    def signals(self) -> dict:
        out = {}
        for i, (a, f, c, e) in enumerate(zip(AXES, FORCES, CONTACTS, EFFORTS)):
            push = 0.0
            if self.ring == "outside" and self.pos[i] <= 320.0 + 1e-9:
                push = max(0.0, self.pos[i] - self.sp[i])
            elif self.ring == "inside" and self.pos[i] >= 200.0 - 1e-9:
                push = max(0.0, self.sp[i] - self.pos[i])
            force = min(4000.0, 400.0 * push) if i != self.dead else 0.0
            effort = force if i != self.jam else min(4000.0, 2500.0 * abs(self.sp[i] - self.pos[i]))
            out[f"{a}.actual"] = round(self.pos[i], 2)
            out[f] = round(force, 2)
            out[c] = force > 0.0
            out[e] = round(effort if i != self.dead else 0.0, 2)
        return out


class Robot:
    """ring_rig_plc.mod's side of the handshake: prepare to `ready`, grip (inside or not), release; each request
    held until diGripDone, then taken back until it falls."""

    def __init__(self, ready: float, inside: bool, jobs=("prepare", "grip", "release")):
        self.ready, self.inside, self.jobs = ready, inside, list(jobs)
        self.asking, self.waiting_low = None, False

    def outputs(self, done: bool) -> dict:
        if self.asking and not self.waiting_low and done:
            self.waiting_low = True
        elif self.waiting_low and not done:
            self.asking, self.waiting_low = None, False
        if self.asking is None and self.jobs:
            self.asking = self.jobs.pop(0)
        high = self.asking if not self.waiting_low else None
        return {"doPrepare": high == "prepare", "doGripRequest": high == "grip", "doReleaseRequest": high == "release",
                "doGripInside": self.inside, "aoFingerReady": self.ready}


def run_python(plant: Plant, robot: Robot, steps: int) -> list[tuple]:
    from stations.ring_rig_plc.plc_logic import cell_sequence

    seq = cell_sequence()
    state = seq.initial_state()
    trace, done = [], False
    for k in range(steps):
        inputs = {**plant.signals(), **robot.outputs(done), "sim.time_ms": round(k * DT * 1000)}
        out = seq(inputs, state)
        for i, a in enumerate(AXES):
            if a in out:
                plant.sp[i] = round(out[a] * 100) / 100
        done = out["diGripDone"]
        trace.append((tuple(round(v * 100) for v in plant.sp), out["diGripOk"], out["diGripFault"], done,
                      FAULTS[int(state.fault)]))
        plant.step()
    return trace


def run_st(plant: Plant, robot: Robot, steps: int, io: Path) -> list[tuple]:
    from plc_client.st_io import LocatedBinding
    from structured_text.runtime import load
    from twin.frontends.modbus.register_map import build_map

    plc = load([CELL / "gripper.st", io])
    binding = LocatedBinding(build_map(CELL, "plc"))  # the input image word by word as the master hands it over
    trace, done = [], False
    for k in range(steps):
        values = {**plant.signals(), **robot.outputs(done), "sim.time_ms": round(k * DT * 1000)}
        for address, word in binding.input_image(values).items():
            plc.write_located(address, word)
        plc.scan(k * DT)
        out = binding.output_values({v.address: plc.read_located(v.address) for v in binding.outputs})
        for i, a in enumerate(AXES):
            plant.sp[i] = out[a]
        done = out["diGripDone"]
        trace.append((tuple(round(v * 100) for v in plant.sp), out["diGripOk"], out["diGripFault"], done,
                      FAULTS[int(plc.get("plc.fault_code"))]))
        plant.step()
    return trace


@pytest.fixture(scope="module")
def io(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("io") / "io.st"
    path.write_text(subprocess.run([sys.executable, "-m", "twin", "map", str(CELL), "--format", "st", "--program",
                                    "gripper"], cwd=ROOT, capture_output=True, text=True, check=True).stdout)
    return path


SCENARIOS = {  # name: plant, robot, steps, the fault the sequence must end with, whether it held the ring
    "outside grip and release": (dict(ring="outside"), dict(ready=330.0, inside=False), 400, "none", True),
    "inside grip and release": (dict(ring="inside"), dict(ready=150.0, inside=True), 600, "none", True),
    "missed: no ring": (dict(ring=None), dict(ready=330.0, inside=False, jobs=("prepare", "grip")), 400, "missed", False),
    "finger 2 jammed": (dict(ring="outside", jam=1), dict(ready=330.0, inside=False, jobs=("grip",)), 300, "jammed", False),
    "finger 3 without drive": (dict(ring="outside", dead=2), dict(ready=330.0, inside=False, jobs=("grip",)), 300,
                               "drive_lost", False),
    "ring lost while held": (dict(ring="outside", lose_at=250), dict(ready=330.0, inside=False, jobs=("prepare", "grip")),
                             300, "lost", True),
    "prepare out of travel": (dict(ring="outside"), dict(ready=500.0, inside=False, jobs=("prepare",)), 30,
                              "bad_request", False),
}


@pytest.mark.parametrize("name", SCENARIOS)
def test_the_st_gripper_plc_does_what_the_python_one_does_scan_for_scan(name, io):
    plant_kw, robot_kw, steps, fault, held = SCENARIOS[name]
    python = run_python(Plant(**plant_kw), Robot(**robot_kw), steps)
    st = run_st(Plant(**plant_kw), Robot(**robot_kw), steps, io)
    for k, (a, b) in enumerate(zip(python, st)):
        assert a == b, f"{name}: scan {k} (t = {k * DT:.3f} s): python {a}, st {b}"
    assert python[-1][4] == fault
    assert any(row[1] for row in python) == held
