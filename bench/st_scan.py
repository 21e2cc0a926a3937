"""Scan cost of the PLC in Structured Text against the Python PLC, side by side in one run.

    python -m bench st [--scans N] [--statements N] [--repeat R]

1. The ring rig's gripper PLC: the Python `CarefulGripSequence` (`plc_logic.cell_sequence`) and the same
   sequence in ST (`stations/ring_rig_plc/gripper.st` with its generated `io.st`), on the same input images:
   grips, holds and releases recorded from the Python PLC driving a small finger model (fingers that follow
   their setpoints at a bounded speed; a ring at 320 mm that pushes back). The ST row is the PLC's scan
   (input image into its located variables, the task, the outputs into the output image: the input images are
   encoded to register words beforehand); a second row adds
   the Modbus-layout binding (`plc_client.st_io.StLogic`: signal values in engineering units to register
   words and back), which a real PLC's fieldbus does in hardware. Both PLCs must go through the same phases.
2. A 2000-statement program (assignments, IFs, arithmetic on INT, DINT, REAL and BOOL, a timer): the cost
   per scan and per statement, and the time to check and compile it.
Target (issue 19): the gripper PLC's scan in ST within 2x of the Python PLC's.
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

CYCLE = 0.010


def _rig():
    from stations.ring_rig_plc import plc_logic as rig
    return rig


def st_logic():
    from plc_client.st_io import StLogic
    from stations.ring_rig_plc.demo import DEFAULT_STATION, ST_FILES
    from twin.frontends.modbus.register_map import build_map

    return StLogic([DEFAULT_STATION / f for f in ST_FILES], build_map(DEFAULT_STATION, "plc"))


def record_images(scans: int) -> list[tuple[float, dict]]:
    """The input images of `scans` scans of the Python gripper PLC driving a small finger model: a grip
    request at 0.1 s of every 6 s, a release request at 3 s."""
    from plc_client.scan import InputImage

    rig = _rig()
    seq = rig.cell_sequence()
    state = seq.initial_state()
    h = seq.handshake
    pos = {a: 350.0 for a in rig.AXES}
    setp = dict(pos)
    images = []
    for k in range(scans):
        t = k * CYCLE
        cyc = t % 6.0
        values = {h.grip_request: 0.1 <= cyc < 2.5, h.release_request: 3.0 <= cyc < 5.5, h.inside: False,
                  h.prepare_request: False, h.prepare_position: 0.0, "sim.time_ms": round(t * 1000.0)}
        for a, f, c, e in zip(rig.AXES, rig.FORCES, rig.CONTACTS, rig.EFFORTS):
            squeeze = max(0.0, 320.0 - pos[a])
            force = min(4000.0, 2500.0 * squeeze)
            values.update({f"{a}.actual": pos[a], f: force, c: squeeze > 0.0, e: force})
        images.append((t, values))
        out = seq(InputImage(values, t, CYCLE, k), state)
        for a in rig.AXES:
            if a in out:
                setp[a] = float(out[a])
            goal = max(setp[a], 320.0 - 4000.0 / 2500.0)  # the ring stops the finger
            step = 150.0 * CYCLE
            pos[a] = goal if abs(goal - pos[a]) <= step else pos[a] + (step if goal > pos[a] else -step)
    return images


def time_python(images, repeat: int) -> tuple[float, list]:
    from plc_client.scan import InputImage

    best, phases = float("inf"), []
    for _ in range(repeat):
        seq = _rig().cell_sequence()
        state = seq.initial_state()
        frames = [InputImage(v, t, CYCLE, k) for k, (t, v) in enumerate(images)]
        t0 = time.perf_counter()
        for frame in frames:
            seq(frame, state)
        best = min(best, (time.perf_counter() - t0) / len(frames))
    seq = _rig().cell_sequence()
    state = seq.initial_state()
    for k, (t, v) in enumerate(images):
        seq(InputImage(v, t, CYCLE, k), state)
        phases.append(int(state.phase))
    return best, phases


def time_st(images, repeat: int) -> tuple[float, float, list]:
    """(scan only, scan with the binding, the phases): the PLC's input images are encoded beforehand for the first.
    The signals the grip sequence does not read (the robot's joints, the cell's counters, ...) stand still at
    0, as a cell's image holds them all."""
    from plc_client.scan import InputImage

    logic = st_logic()
    rest = {e.name: (False if e.type == "bool" else 0) for e in logic.binding.input_entries}
    images = [(t, {**rest, **v}) for t, v in images]
    probe = logic.initial_state()
    encoded = []
    for t, v in images:
        words = logic.binding.input_image({n: v[n] for n in logic.inputs if n in v})
        encoded.append((round(t * 1e9), {probe._slot(a)[1]: w for a, w in words.items()}))
    scan_only = bound = float("inf")
    for _ in range(repeat):
        plc = logic.initial_state()
        inputs = plc.inputs
        t0 = time.perf_counter()
        for now, img in encoded:
            inputs.update(img)
            plc.scan_ns(now)
        scan_only = min(scan_only, (time.perf_counter() - t0) / len(encoded))
        plc = logic.initial_state()
        frames = [InputImage(v, t, CYCLE, k) for k, (t, v) in enumerate(images)]
        t0 = time.perf_counter()
        for frame in frames:
            logic(frame, plc)
        bound = min(bound, (time.perf_counter() - t0) / len(frames))
    plc = logic.initial_state()
    phases = []
    for now, img in encoded:
        plc.inputs.update(img)
        plc.scan_ns(now)
        phases.append(int(plc.get(f"{logic.instance}.phase")))
    return scan_only, bound, phases


def big_program(statements: int) -> str:
    """About `statements` statements: assignments and IFs on INT, DINT, REAL and BOOL, and one TON."""
    decl = ["PROGRAM Big", "VAR", "  i0, i1, i2, i3 : INT;", "  d0, d1 : DINT;", "  r0, r1, r2 : REAL;",
            "  b0, b1, b2 : BOOL;", "  t : TON;", "END_VAR"]
    body = ["t(IN := NOT t.Q, PT := T#50ms);"]
    k = 1
    while k < statements:
        m = k % 8
        if m == 0:
            body.append(f"i{k % 4} := i{(k + 1) % 4} + {k % 97};")
        elif m == 1:
            body.append(f"r{k % 3} := r{(k + 1) % 3} * 0.5 + {k % 13}.25;")
        elif m == 2:
            body.append(f"b{k % 3} := i{k % 4} > {k % 50} AND NOT b{(k + 1) % 3};")
        elif m == 3:
            body.append(f"IF b{k % 3} THEN d{k % 2} := d{(k + 1) % 2} + INT_TO_DINT(i{k % 4}); ELSE d{k % 2} := 0; END_IF;")
            k += 2  # an IF with its two assignments
        elif m == 6:
            body.append(f"i{k % 4} := (i{k % 4} * 3) MOD 1000;")
        else:
            body.append(f"r{k % 3} := MAX(r{k % 3}, INT_TO_REAL(i{k % 4})) - 1.0;")
        k += 1
    return "\n".join(decl + body + ["END_PROGRAM", ""])


def time_big(statements: int, repeat: int) -> tuple[float, float]:
    from structured_text.runtime import load

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "big.st"
        path.write_text(big_program(statements))
        t0 = time.perf_counter()
        load([path])
        build = time.perf_counter() - t0
        best = float("inf")
        for _ in range(repeat):
            plc = load([path])
            t0 = time.perf_counter()
            for k in range(200):
                plc.scan_ns(round(k * CYCLE * 1e9))
            best = min(best, (time.perf_counter() - t0) / 200)
    return best, build


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench st", description=__doc__.splitlines()[0])
    ap.add_argument("--scans", type=int, default=1200, help="scans of the gripper PLC (default 1200: two grip cycles)")
    ap.add_argument("--statements", type=int, default=2000, help="statements of the big program (default 2000)")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each, the best counts (default 3)")
    args = ap.parse_args(argv)
    images = record_images(args.scans)
    py, py_phases = time_python(images, args.repeat)
    st, bound, st_phases = time_st(images, args.repeat)
    def steps(phases):  # the sequence of phases, each once
        return [p for k, p in enumerate(phases) if k == 0 or phases[k - 1] != p]
    apart = sum(a != b for a, b in zip(py_phases, st_phases))
    same = (f"the same phases, {apart} scans apart: the ST PLC reads 0.1 mm register words" if
            steps(py_phases) == steps(st_phases) else "THE PHASES DIFFER")
    print(f"the ring rig's gripper PLC, {args.scans} scans on the same input images ({same})")
    print(f"  {'Python PLC (CarefulGripSequence)':<44} {py * 1e6:9.1f} us/scan")
    print(f"  {'Structured Text (gripper.st), the scan':<44} {st * 1e6:9.1f} us/scan   ST / Python: {st / py:.2f}"
          "  (target: within 2x)")
    print(f"  {'  + the Modbus-layout binding (StLogic)':<44} {bound * 1e6:9.1f} us/scan")
    big, build = time_big(args.statements, args.repeat)
    print(f"{args.statements}-statement program: {big * 1e6:9.1f} us/scan, {big * 1e9 / args.statements:6.0f} "
          f"ns/statement; check + compile {build * 1e3:.0f} ms")
    return 0
