"""Scan cost of the PLC in Structured Text against the Python PLC, side by side in one run.

    python -m bench st [--scans N] [--statements N] [--repeat R]

1. A grip sequence: the ring rig's Python PLC (`CarefulGripSequence`, the careful watch included) and a
   grip sequence in ST of the same size (bench/st/grip_sequence.st: three fingers, ramps, press, miss,
   release margin, prepare, finger watch, timeout, lost part), on the same input images: a grip, a hold, a
   release and a prepare move recorded from the Python PLC driving a small finger model (fingers that follow
   their setpoints at a bounded speed; a ring at 320 mm that pushes back at 2500 N/mm). Each scan of the ST
   PLC includes copying the image into its located inputs and its outputs back, as its scan does.
2. A 2000-statement program (assignments, IFs, arithmetic on INT, REAL and BOOL, a timer): the cost per scan and
   per statement.
Target (issue 19): the ST grip sequence's scan within 2x of the Python PLC's.
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent
GRIP_ST = HERE / "st" / "grip_sequence.st"
CYCLE = 0.010


def record_images(scans: int) -> list[tuple[float, dict]]:
    """The input images of `scans` scans of the Python grip sequence driving a small finger model."""
    from plc_client.scan import InputImage
    from stations.ring_rig_plc import plc_logic as rig

    seq = rig.sequence()
    state = seq.initial_state()
    h = seq.handshake
    pos = {a: 330.0 for a in rig.AXES}
    setp = dict(pos)
    requests = {h.grip_request: False, h.release_request: False, h.inside: False}
    images = []
    for k in range(scans):
        t = k * CYCLE
        phase_t = t % 6.0
        requests[h.grip_request] = 0.1 <= phase_t < 2.5
        requests[h.release_request] = 3.0 <= phase_t < 5.5
        values = dict(requests)
        values["link.ok"] = True
        for a, f, c, e in zip(rig.AXES, rig.FORCES, rig.CONTACTS, rig.EFFORTS):
            squeeze = max(0.0, 320.0 - pos[a])
            force = 2500.0 * squeeze
            values[f"{a}.actual"] = pos[a]
            values[f] = force
            values[c] = squeeze > 0.0
            values[e] = force
        images.append((t, values))
        out = seq(InputImage(values, t, CYCLE, k), state)
        for a in rig.AXES:
            if a in out:
                setp[a] = float(out[a])
            goal = max(setp[a], 320.0 - 4000.0 / 2500.0)  # the ring stops the finger (a stiff servo on it)
            step = 60.0 * CYCLE
            pos[a] = goal if abs(goal - pos[a]) <= step else pos[a] + (step if goal > pos[a] else -step)
    return images


def st_images(images: list[tuple[float, dict]]) -> list[tuple[int, dict]]:
    """The same images as the ST PLC's located inputs (OpenPLC: %IX100.x bits, %IW100.. words; 0.1 mm, N)."""
    from stations.ring_rig_plc import plc_logic as rig

    out = []
    for t, v in images:
        img = {("X", (100, 0)): v["grip_request"], ("X", (100, 1)): v["release_request"],
               ("X", (100, 2)): v["grip_inside"], ("X", (100, 3)): False, ("X", (100, 7)): v["link.ok"],
               ("W", (109,)): 3300}
        for i, (a, f, c, e) in enumerate(zip(rig.AXES, rig.FORCES, rig.CONTACTS, rig.EFFORTS)):
            img[("X", (100, 4 + i))] = v[c]
            img[("W", (100 + i,))] = round(v[f"{a}.actual"] * 10.0)
            img[("W", (103 + i,))] = min(32767, round(v[f]))
            img[("W", (106 + i,))] = min(32767, round(v[e]))
        out.append((round(t * 1e9), img))
    return out


def time_python(images, repeat: int) -> float:
    from plc_client.scan import InputImage
    from stations.ring_rig_plc import plc_logic as rig

    best = float("inf")
    for _ in range(repeat):
        seq = rig.sequence()
        state = seq.initial_state()
        frames = [InputImage(v, t, CYCLE, k) for k, (t, v) in enumerate(images)]
        t0 = time.perf_counter()
        for frame in frames:
            seq(frame, state)
        best = min(best, (time.perf_counter() - t0) / len(frames))
    return best


def time_st(paths, images, repeat: int) -> float:
    from structured_text.runtime import load

    best = float("inf")
    for _ in range(repeat):
        plc = load(paths)
        inputs = plc.inputs
        t0 = time.perf_counter()
        for now, img in images:
            inputs.update(img)
            plc.scan_ns(now)
        best = min(best, (time.perf_counter() - t0) / len(images))
    return best


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


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench st", description=__doc__.splitlines()[0])
    ap.add_argument("--scans", type=int, default=1200, help="scans of the grip sequence (default 1200: two cycles)")
    ap.add_argument("--statements", type=int, default=2000, help="statements of the big program (default 2000)")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each, the best counts (default 3)")
    args = ap.parse_args(argv)
    images = record_images(args.scans)
    py = time_python(images, args.repeat)
    st = time_st([GRIP_ST], st_images(images), args.repeat)
    lines = sum(1 for _ in GRIP_ST.open())
    print(f"grip sequence, {args.scans} scans on the same input images")
    print(f"  {'Python PLC (CarefulGripSequence)':<40} {py * 1e6:9.1f} us/scan")
    print(f"  {f'Structured Text ({lines} lines, compiled)':<40} {st * 1e6:9.1f} us/scan")
    print(f"  ST / Python: {st / py:.2f}  (target: within 2x)")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "big.st"
        path.write_text(big_program(args.statements))
        t0 = time.perf_counter()
        from structured_text.runtime import load
        load([path])
        build = time.perf_counter() - t0
        big = time_st([path], [(round(k * CYCLE * 1e9), {}) for k in range(200)], args.repeat)
    print(f"{args.statements}-statement program: {big * 1e6:9.1f} us/scan, {big * 1e9 / args.statements:6.0f} ns/statement"
          f"; check + compile {build * 1e3:.0f} ms")
    return 0
