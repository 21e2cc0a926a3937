"""Core benchmark: simulation steps per second, and how the grip check's cost grows with the target group.

    python -m bench core [--steps N]

Table 1: for every shipped station, the twin's step against the raw physics of the very same world (its
`substeps` calls of pybullet's stepSimulation, nothing else), timed side by side in one run, alternating in
rounds so that a noisy machine slows both alike: microseconds per step, what the twin adds (us and as a ratio),
and how many times real time each runs headless. The cell rests as loaded, so once it has rested 0.3 s its loose
bodies are frozen (twin/core/stasis.py) for both columns. Then the ring rig in motion: a pick-and-place through
the simulation API, simulated against wall seconds, with the physics timed inside the twin's own step (what the twin
adds on top of the physics it runs, in motion).
Table 2: the four-finger gripper gripping its puck among N extra free cylinders of the target group,
scattered on the floor. Per step: the whole step, and the grip check (contacts of every finger with the
targets) done two ways side by side: ours (a broad-phase AABB query, then exact closest points only
against targets near a finger) and the naive one (closest points against every target).
"""
from __future__ import annotations

import argparse
import statistics
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


def ring_rig_in_motion() -> tuple[float, float, float]:
    """Simulated and wall seconds of a pick-and-place on the ring rig through the simulation API (grip, lift,
    carry, set down, release, with a second's pause at either end): the physics of a held 66 kg ring, moving; and the
    wall seconds of that physics, timed inside the twin's step."""
    from twin.core import Twin

    def go(twin, instr, target, speed):
        twin.move(instr, target, speed)
        while twin.robot_busy:
            twin.step()

    with Twin.from_station(STATIONS / "ring_rig") as twin:
        physics = [0.0]
        substep = twin.world.substep_physics

        def timed_substep() -> None:  # the physics the twin runs, timed inside its own step
            t = time.perf_counter()
            substep()
            physics[0] += time.perf_counter() - t

        twin.world.substep_physics = timed_substep
        t0 = time.perf_counter()
        twin.step(round(1.0 / twin.dt))
        for name in ("L2", "L3", "L4"):
            twin.write(name, 0.319)
        twin.step(round(1.0 / twin.dt))
        go(twin, "MoveL", "app_right", 1.0)
        go(twin, "MoveJ", "app_left", 3.0)
        go(twin, "MoveL", "grip_left", 0.5)
        for name in ("L2", "L3", "L4"):
            twin.write(name, 0.35)
        twin.step(round(1.0 / twin.dt))
        go(twin, "MoveL", "app_left", 1.0)
        twin.step(round(1.0 / twin.dt))
        return twin.time, time.perf_counter() - t0, physics[0]


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
    args = parser.parse_args(argv)
    print("The twin's step vs the raw physics of the same world (stepSimulation x substeps), headless, per step")
    print(f"{'station':<16}{'physics us':>12}{'twin us':>10}{'added us':>10}{'twin/physics':>14}{'physics x rt':>14}"
          f"{'twin x rt':>11}")
    for name in SHIPPED:
        r = twin_vs_physics(STATIONS / name, args.steps)
        rt = r["dt"] * 1e6
        print(f"{name:<16}{r['physics']:>12.0f}{r['twin']:>10.0f}{r['twin'] - r['physics']:>10.0f}"
              f"{r['twin'] / r['physics']:>14.2f}{rt / r['physics']:>14.1f}{rt / r['twin']:>11.1f}")
    print("(the cell at rest, as loaded: after 0.3 s at rest its loose bodies are frozen, twin/core/stasis.py)")
    sim, wall, physics = ring_rig_in_motion()
    print(f"ring_rig in motion (pick and place, simulation API): {sim:.1f} s simulated in {wall:.2f} s wall, "
          f"{sim / wall:.1f}x real time; physics {physics:.2f} s of it (timed inside the twin's step), "
          f"the twin adds {100 * (wall - physics) / physics:.0f} %")
    print()
    print("Grip check cost per step vs size of the target group (four_finger holding its puck)")
    print(f"{'targets':>8}{'step us':>10}{'check us (ours)':>17}{'check us (naive)':>18}{'naive/ours':>12}")
    for extra in (0, 10, 100, 1000):
        cost = grip_check_costs(extra, max(20, args.steps // (1 + extra // 100)))
        print(f"{extra + 1:>8}{cost['step']:>10.0f}{cost['ours']:>17.1f}{cost['naive']:>18.1f}"
              f"{cost['naive'] / cost['ours']:>12.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
