"""Core benchmark: simulation steps per second, and how the grip check's cost grows with the target group.

    python -m bench core [--steps N] [--targets 0,10,100,1000] [--no-motion] [--against REV [--rounds N]]

Table 1: for every shipped station, the twin's step against the raw physics of the very same world (its
`substeps` calls of pybullet's stepSimulation, nothing else), timed side by side in one run, alternating in
rounds so that a noisy machine slows both alike: microseconds per step, what the twin adds (us and as a ratio),
and how many times real time each runs headless. The cell rests as loaded, so once it has rested 0.3 s its loose
bodies are frozen (twin/core/stasis.py) for both columns. Then the ring rig in motion: a pick-and-place through
the simulation API, simulated against wall seconds, with the physics timed inside the twin's own step (what the twin
adds on top of the physics it runs, in motion).
With `--against REV` (a git revision of this repository, e.g. the commit before a change) only the ring rig's figures
are measured, for REV's twin and stations and for this tree's, alternately in separate processes for `--rounds`
rounds, and printed side by side: before and after in one run, a busy machine slowing both alike. The in-motion
line's x real time is also given in CPU time (the process's own thread), which a shared machine disturbs less.
Table 2: the four-finger gripper gripping its puck among N extra free cylinders of the target group,
scattered on the floor. Per step: the whole step, and the grip check (contacts of every finger with the
targets) done two ways side by side: ours (a broad-phase AABB query, then exact closest points only
against targets near a finger) and the naive one (closest points against every target).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

STATIONS = Path(__file__).resolve().parent.parent / "stations"
SHIPPED = sorted(p.parent.name for p in STATIONS.glob("*/station.toml"))


def twin_vs_physics(station: Path, steps: int, rounds: int = 5) -> dict[str, float]:
    """Median us per step of the twin's step and of the raw physics of the same world, in alternating rounds."""
    from twin.core import Twin

    with Twin.from_station(station) as twin:
        client, substeps = twin.world.client, twin.world.substeps
        twin.step(10)
        twin_us, raw_us = [], []
        for _ in range(rounds):
            t0 = time.perf_counter()
            twin.step(steps)
            twin_us.append((time.perf_counter() - t0) / steps * 1e6)
            t0 = time.perf_counter()
            for _ in range(steps * substeps):
                client.stepSimulation()
            raw_us.append((time.perf_counter() - t0) / steps * 1e6)
        twin_med, raw_med = statistics.median(twin_us), statistics.median(raw_us)
        return {"twin": twin_med, "physics": raw_med, "dt": twin.dt}


def ring_rig_in_motion(stations: Path = STATIONS) -> dict[str, float]:
    """A pick-and-place on the ring rig through the simulation API (grip, lift, carry, set down, release, with a
    second's pause at either end): the physics of a held 66 kg ring, moving. Seconds: `sim` simulated; `wall` and
    `cpu` of the whole run (the motions' planning included); `step`, `step_cpu` inside the twin's steps; `physics`,
    `physics_cpu` of the physics those steps ran (pybullet's substeps, timed inside the twin's step). The run is
    made twice, the same run (the twin is deterministic): once timed by the wall clock, once by the thread's CPU
    clock, so that each substep carries one clock's reading, not both (a CPU clock reading is a system call)."""
    wall = _pick_and_place(stations, time.perf_counter)
    cpu = _pick_and_place(stations, time.thread_time)
    return {"sim": wall["sim"], "wall": wall["run"], "cpu": cpu["run"], "step": wall["step"],
            "step_cpu": cpu["step"], "physics": wall["physics"], "physics_cpu": cpu["physics"]}


def _pick_and_place(stations: Path, clock) -> dict[str, float]:
    """`ring_rig_in_motion`'s run, timed by `clock`: the seconds of the whole run, of the twin's steps and of the
    physics inside them, and the seconds simulated."""
    from twin.core import Twin

    with Twin.from_station(stations / "ring_rig") as twin:
        physics, steps = [0.0], [0.0]
        substep = twin.world.substep_physics

        def timed_substep() -> None:  # the physics the twin runs, timed inside its own step
            t = clock()
            substep()
            physics[0] += clock() - t

        def step(n: int = 1) -> None:  # the twin's own step, timed
            t = clock()
            twin.step(n)
            steps[0] += clock() - t

        def go(instr, target, speed):
            twin.move(instr, target, speed)
            while twin.robot_busy:
                step()

        twin.world.substep_physics = timed_substep
        t0 = clock()
        step(round(1.0 / twin.dt))
        for name in ("L2", "L3", "L4"):
            twin.write(name, 0.319)
        step(round(1.0 / twin.dt))
        go("MoveL", "app_right", 1.0)
        go("MoveJ", "app_left", 3.0)
        go("MoveL", "grip_left", 0.5)
        for name in ("L2", "L3", "L4"):
            twin.write(name, 0.35)
        step(round(1.0 / twin.dt))
        go("MoveL", "app_left", 1.0)
        step(round(1.0 / twin.dt))
        return {"sim": twin.time, "run": clock() - t0, "step": steps[0], "physics": physics[0]}


def ring_rig_figures(stations: Path, steps: int) -> dict[str, float]:
    """The ring rig's figures of this benchmark (at rest: ring_rig and ring_rig_plc; in motion), for `--against`."""
    out = {}
    for name in ("ring_rig", "ring_rig_plc"):
        r = twin_vs_physics(stations / name, steps)
        out[name] = r["twin"] / r["physics"]
        out[name + " twin x rt"] = r["dt"] / r["twin"] * 1e6
    m = ring_rig_in_motion(stations)
    out.update({"motion x rt": m["sim"] / m["wall"], "motion x rt (cpu)": m["sim"] / m["cpu"],
                "motion adds %": 100 * (m["step"] - m["physics"]) / m["physics"],
                "motion adds % (cpu)": 100 * (m["step_cpu"] - m["physics_cpu"]) / m["physics_cpu"],
                "motion adds % with planning": 100 * (m["wall"] - m["physics"]) / m["physics"]})
    return out


def against(rev: str, rounds: int, steps: int) -> int:
    """REV's ring rig figures beside this tree's, measured alternately in fresh processes (module docstring)."""
    root = Path(__file__).resolve().parent.parent
    rows = ("ring_rig", "ring_rig twin x rt", "ring_rig_plc", "ring_rig_plc twin x rt", "motion x rt",
            "motion x rt (cpu)", "motion adds %", "motion adds % (cpu)", "motion adds % with planning")
    with tempfile.TemporaryDirectory(prefix="bench-core-") as tmp:
        archive = subprocess.run(["git", "-C", str(root), "archive", rev], capture_output=True, check=False)
        if archive.returncode:
            print(f"python -m bench core: --against {rev}: {archive.stderr.decode().strip()}", file=sys.stderr)
            return 2
        subprocess.run(["tar", "-x", "-C", tmp], input=archive.stdout, check=True)
        trees = {rev: Path(tmp), "this tree": root}
        figures: dict[str, list[dict]] = {label: [] for label in trees}
        code = ("import json, runpy, sys; m = runpy.run_path(sys.argv[1]); "
                "print(json.dumps(m['ring_rig_figures'](m['Path'](sys.argv[2]), int(sys.argv[3]))))")
        for _ in range(rounds):
            for label, tree in trees.items():  # this file's measurements, the tree's twin and stations
                env = {**os.environ, "PYTHONPATH": str(tree)}
                done = subprocess.run([sys.executable, "-c", code, __file__, str(tree / "stations"), str(steps)],
                                      cwd=tree, env=env, capture_output=True, text=True, check=True)
                figures[label].append(json.loads(done.stdout.strip().splitlines()[-1]))
    print(f"The ring rig, {rev} vs this tree, alternately in fresh processes, {rounds} rounds: median [min - max]")
    print(f"{'':<34}" + "".join(f"{label:>24}" for label in trees))
    names = {"ring_rig": "at rest ring_rig twin/physics", "ring_rig_plc": "at rest ring_rig_plc twin/physics",
             "ring_rig twin x rt": "at rest ring_rig twin x rt", "ring_rig_plc twin x rt": "at rest ring_rig_plc twin x rt",
             "motion x rt": "in motion x real time (wall)", "motion x rt (cpu)": "in motion x real time (CPU)",
             "motion adds %": "in motion, the twin's step adds (%)",
             "motion adds % (cpu)": "in motion, its step adds (% CPU)",
             "motion adds % with planning": "in motion, + planning (%)"}
    for row in rows:
        cells = []
        for label in trees:
            values = [f[row] for f in figures[label]]
            cells.append(f"{statistics.median(values):.2f} [{min(values):.2f}-{max(values):.2f}]")
        print(f"{names[row]:<34}" + "".join(f"{c:>24}" for c in cells))
    return 0


def crowded_station(folder: Path, extra: int) -> Path:
    text = (STATIONS / "four_finger" / "station.toml").read_text()
    text = text.replace('urdf = "gripper4.urdf"', f'urdf = "{STATIONS / "four_finger" / "gripper4.urdf"}"')
    side = max(1, int(extra ** 0.5) + 2)
    spots = [(0.3 + 0.12 * (k % side), -0.5 + 0.12 * (k // side)) for k in range(side * side)]
    spots = [(x, y) for x, y in spots if abs(x - 0.5) > 0.1 or abs(y) > 0.1]  # clear of the loose box
    for k in range(extra):
        x, y = spots[k]
        text += (f'\n[[targets]]\nname = "c{k}"\nshape = "cylinder"\nradius = 0.03\nheight = 0.04\n'
                 f'xyz = [{x:.3f}, {y:.3f}, 0.02]\ndensity = 1000.0\n')
    path = folder / f"crowded_{extra}.toml"
    path.write_text(text)
    return path


def naive_check(gripper) -> None:
    c, d = gripper.client, gripper.spec.contact_distance
    for links in gripper.finger_links.values():
        for link in links:
            for uid in gripper.targets.values():
                c.getClosestPoints(gripper.body, uid, d, linkIndexA=link)


def grip_check_costs(extra: int, steps: int) -> dict[str, float]:
    from twin.core import Twin

    with tempfile.TemporaryDirectory() as tmp, Twin.from_station(crowded_station(Path(tmp), extra)) as twin:
        for f in ("F1", "F2", "F3", "F4"):
            twin.write(f, 0.0)
        twin.step(150)
        assert twin.read("doGripped"), "the puck should be gripped"
        t0 = time.perf_counter()
        twin.step(steps)
        step_us = (time.perf_counter() - t0) / steps * 1e6
        t0 = time.perf_counter()
        for _ in range(steps):
            for finger in twin.gripper.finger_links:
                twin.gripper._touching(finger)
        ours_us = (time.perf_counter() - t0) / steps * 1e6
        t0 = time.perf_counter()
        for _ in range(steps):
            naive_check(twin.gripper)
        naive_us = (time.perf_counter() - t0) / steps * 1e6
        return {"step": step_us, "ours": ours_us, "naive": naive_us}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench core")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--against", metavar="REV", help="a git revision: its ring rig figures beside this tree's")
    parser.add_argument("--rounds", type=int, default=3, help="with --against: rounds of alternation (default 3)")
    parser.add_argument("--targets", default="0,10,100,1000",
                        help="extra targets beside the puck, one grip-check row each (default 0,10,100,1000)")
    parser.add_argument("--no-motion", action="store_true", help="skip the ring rig in motion")
    args = parser.parse_args(argv)
    if args.against:
        return against(args.against, args.rounds, args.steps)
    extras = [int(x) for x in args.targets.split(",") if x.strip()]
    print("The twin's step vs the raw physics of the same world (stepSimulation x substeps), headless, per step")
    print(f"{'station':<16}{'physics us':>12}{'twin us':>10}{'added us':>10}{'twin/physics':>14}{'physics x rt':>14}"
          f"{'twin x rt':>11}")
    for name in SHIPPED:
        r = twin_vs_physics(STATIONS / name, args.steps)
        rt = r["dt"] * 1e6
        print(f"{name:<16}{r['physics']:>12.0f}{r['twin']:>10.0f}{r['twin'] - r['physics']:>10.0f}"
              f"{r['twin'] / r['physics']:>14.2f}{rt / r['physics']:>14.1f}{rt / r['twin']:>11.1f}")
    print("(the cell at rest, as loaded: after 0.3 s at rest its loose bodies are frozen, twin/core/stasis.py)")
    if not args.no_motion:
        m = ring_rig_in_motion()
        print(f"ring_rig in motion (pick and place, simulation API): {m['sim']:.1f} s simulated in {m['wall']:.3f} s "
              f"wall, {m['sim'] / m['wall']:.1f}x real time ({m['sim'] / m['cpu']:.1f}x in CPU time); its steps took "
              f"{m['step']:.3f} s, their physics {m['physics']:.3f} s (timed inside the twin's step): the twin's step "
              f"adds {100 * (m['step'] - m['physics']) / m['physics']:.0f} % on top of its physics "
              f"({100 * (m['step_cpu'] - m['physics_cpu']) / m['physics_cpu']:.0f} % in CPU time); planning the "
              f"four motions and the rest of the run {m['wall'] - m['step']:.3f} s more "
              f"({100 * (m['wall'] - m['physics']) / m['physics']:.0f} % over the physics with it)")
    print()
    print("Grip check cost per step vs size of the target group (four_finger holding its puck)")
    print(f"{'targets':>8}{'step us':>10}{'check us (ours)':>17}{'check us (naive)':>18}{'naive/ours':>12}")
    for extra in extras:
        cost = grip_check_costs(extra, max(min(20, args.steps), args.steps // (1 + extra // 100)))
        print(f"{extra + 1:>8}{cost['step']:>10.0f}{cost['ours']:>17.1f}{cost['naive']:>18.1f}"
              f"{cost['naive'] / cost['ours']:>12.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
