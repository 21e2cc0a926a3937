"""Wall time per simulated second of RAPID polling loops offline, side by side in one run; and the ring rig's
robot cycle in the physics cell with the motion planner, each motion's time now and under the old model.

    python -m bench rapid [--seconds S] [--no-cycle] [--no-planning]

Programs: an idle time-less loop (`WHILE diGo = 0 DO ENDWHILE`), a busy one that changes data
every turn (`Incr n`), a `WaitUntil` (polls every 0.1 s), a loop with `WaitTime 0.01` and an ITimer
TRAP every 0.01 s. diGo is set at the end, so every loop runs for the whole S simulated seconds.

Planning cost: the wall time `twin.move` takes to plan a motion (IK along the path, its timing, its corner)
inside one simulation step, and the worst step's wall time, for the ring rig's cycle and a z50 square of MoveL,
with a path's IK samples solved all at once (motion.BATCH_IK) and one by one.
"""
from __future__ import annotations

import argparse
import time

from rapid_like.host import SignalInfo
from rapid_like.offline import SignalChange, run_offline
from rapid_like.parser import parse

LOOPS = {
    "idle WHILE": "WHILE diGo = 0 DO\n ENDWHILE",
    "busy WHILE (Incr)": "WHILE diGo = 0 DO\n Incr reg1;\n ENDWHILE",
    "WaitUntil": "WaitUntil diGo = 1;",
    "WaitTime 0.01 loop": "WHILE diGo = 0 DO\n WaitTime 0.01;\n Incr reg1;\n ENDWHILE",
    "ITimer 0.01 TRAP": "CONNECT irq WITH Tick;\n ITimer 0.01, irq;\n WaitDI diGo, 1;",
}


def program(body: str) -> str:
    return (f"MODULE Poll\n VAR intnum irq;\n PROC main()\n {body}\n ENDPROC\n TRAP Tick\n Incr reg2;\n ENDTRAP\n"
            f"ENDMODULE\n")


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench rapid", description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=5.0, help="simulated seconds per program (default 5)")
    ap.add_argument("--no-cycle", action="store_true", help="skip the ring rig's cycle in the physics cell")
    ap.add_argument("--no-planning", action="store_true", help="skip the planning cost (two cycles, two programs)")
    args = ap.parse_args(argv)
    print(f"{'program':<22} {'simulated s':>11} {'wall s':>8} {'wall s per simulated s':>23}")
    for name, body in LOOPS.items():
        module = parse(program(body), name)
        t0 = time.perf_counter()
        out = run_offline(module, [SignalInfo("diGo", "DI")], [SignalChange("diGo", 1.0, args.seconds)])
        wall = time.perf_counter() - t0
        print(f"{name:<22} {out.t:>11.2f} {wall:>8.3f} {wall / max(out.t, 1e-9):>23.4f}")
    if not args.no_cycle:
        ring_rig_cycle()
    if not args.no_planning:
        planning_cost()
    return 0


OLD_TCP_ACCELERATION = 10.0  # m/s^2: the one cap of the motion model before the planner (issue 22)
OLD_RAMP = 0.2  # s: its half-cosine ramps


def old_duration(traj) -> float:
    """The motion's time under the old model: the same cruise speed (speed limits did not change), ramps of at
    least 0.2 s as half cosines lengthened to keep the TCP's peak acceleration under 10 m/s^2."""
    import math

    cruise = 1.0 / traj.profile.rate if traj.profile.rate > 0 else 0.0
    if cruise <= 0:
        return 0.0
    knots = traj._knots
    kin = traj.kin
    step = max(1, len(knots) // 64)
    poses = [kin.fk(q) for q in knots[::step]] + [kin.fk(knots[-1])]
    s = list(traj._s[::step]) + [1.0]
    per_s = max((a.distance(b) / max(s1 - s0, 1e-12) for a, b, s0, s1 in zip(poses, poses[1:], s, s[1:])),
                default=0.0)
    need = math.pi / 2 * per_s / OLD_TCP_ACCELERATION
    ramp = max(OLD_RAMP, need / cruise)
    if ramp > cruise:
        ramp = cruise = max(math.sqrt(need), min(OLD_RAMP, cruise))
    return cruise + ramp


def _timed_cycle(station, entry: str) -> tuple[float, list[float], list[float], list[float], list]:
    """Run `entry` in the physics cell of `station` to its end: (simulated cycle s, wall s of every step, wall s
    and CPU s of planning every motion (twin.move: IK along the path, timing, the corner), the trajectories)."""
    from twin_app.cell import open_cell

    steps, planning, cpu, seen = [], [], [], []
    with open_cell(station, entry=entry) as cell:
        twin = cell.twin
        move = twin.move

        def timed_move(*args, **kwargs):
            t0, c0 = time.perf_counter(), time.thread_time()
            try:
                return move(*args, **kwargs)
            finally:
                planning.append(time.perf_counter() - t0)
                cpu.append(time.thread_time() - c0)

        twin.move = timed_move
        while cell.controller.state not in ("completed", "error"):
            t0 = time.perf_counter()
            cell.step()
            steps.append(time.perf_counter() - t0)
            traj = twin.robot.trajectory
            if traj is not None and (not seen or seen[-1] is not traj):
                seen.append(traj)
        assert cell.controller.state == "completed", cell.controller.error
        return cell.time, steps, planning, cpu, seen


SQUARE = """MODULE Square
  PERS tooldata tG := [TRUE,[[0,0,350],[1,0,0,0]],[20,[0,0,150],[1,0,0,0],0,0,0]];
  CONST robtarget p0 := [[1500,-300,900],[0,1,0,0],[-1,0,-1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    MoveJ p0, v1000, fine, tG;
    MoveL Offs(p0,400,0,0), v500, z50, tG;
    MoveL Offs(p0,400,600,0), v500, z50, tG;
    MoveL Offs(p0,0,600,0), v500, z50, tG;
    MoveL p0, v500, fine, tG;
  ENDPROC
ENDMODULE
"""


def planning_cost() -> None:
    """Wall time of planning a motion (inside one simulation step) and the worst step, the ring rig's cycle and a
    z50 square of MoveL, with the path's samples solved at once (now) and one by one (the old solve)."""
    import shutil
    import tempfile
    from pathlib import Path

    from twin.core import motion

    stations = Path(__file__).resolve().parent.parent / "stations"
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copytree(stations / "ring_rig", Path(tmp) / "rig")
        shutil.copytree(stations / "robots", Path(tmp) / "robots")
        toml = Path(tmp) / "rig" / "station.toml"
        toml.write_text(toml.read_text().replace('program = "ring_rig.mod"', 'program = "square.mod"'))
        (Path(tmp) / "rig" / "square.mod").write_text(SQUARE)
        runs = [("ring rig cycle", stations / "ring_rig", "Path_FullAutoRun"), ("z50 square", Path(tmp) / "rig", "main")]
        print(f"\nplanning a motion inside one step (wall ms; CPU ms of this thread, which other processes on the "
              f"machine do not inflate), and the steps' wall time")
        print(f"{'program':<16} {'IK':<12} {'motions':>7} {'mean':>6} {'max':>6} {'CPU mean':>9} {'CPU max':>8} "
              f"{'worst step':>11} {'steps > 12 ms':>13}")
        results = {}
        for label, station, entry in runs:
            for batch in (False, True):
                motion.BATCH_IK = batch
                try:
                    cycle, steps, planning, cpu, seen = _timed_cycle(station, entry)
                finally:
                    motion.BATCH_IK = True
                results[label, batch] = (cycle, [t.duration for t in seen])
                late = sum(1 for s in steps if s > 0.012)
                print(f"{label:<16} {'all at once' if batch else 'one by one':<12} {len(planning):>7} "
                      f"{1000 * sum(planning) / len(planning):>6.2f} {1000 * max(planning):>6.2f} "
                      f"{1000 * sum(cpu) / len(cpu):>9.2f} {1000 * max(cpu):>8.2f} "
                      f"{1000 * max(steps):>11.2f} {late:>13}")
        for label, _, _ in runs:
            (c0, d0), (c1, d1) = results[label, False], results[label, True]
            diff = max((abs(a - b) for a, b in zip(d0, d1)), default=0.0)
            print(f"{label}: cycle {c0:.3f} s one by one, {c1:.3f} s all at once; motions' durations differ by at "
                  f"most {diff * 1000:.3f} ms")


def ring_rig_cycle() -> None:
    """The ring rig's Path_FullAutoRun in the physics cell: its cycle time, and where the motions' time went."""
    from pathlib import Path

    from twin_app.cell import open_cell

    STATIONS = Path(__file__).resolve().parent.parent / "stations"

    seen, t0 = [], time.perf_counter()
    with open_cell(STATIONS / "ring_rig", entry="Path_FullAutoRun") as cell:
        while cell.controller.state != "completed":
            cell.step()
            traj = cell.twin.robot.trajectory
            if traj is not None and (not seen or seen[-1] is not traj):
                seen.append(traj)
        cycle, wall = cell.time, time.perf_counter() - t0
    print(f"\nring rig cycle (Path_FullAutoRun, physics cell): {cycle:.3f} s simulated, {wall:.2f} s wall")
    print(f"{'motion':<28} {'now s':>7} {'old model s':>12}")
    now = old = 0.0
    for traj in seen:
        a, b = traj.duration, old_duration(traj)
        now, old = now + a, old + b
        print(f"{traj.kind + ' ' + traj.name:<28} {a:>7.3f} {b:>12.3f}")
    print(f"{'all motions':<28} {now:>7.3f} {old:>12.3f}   (the cycle under the old model: about "
          f"{cycle - now + old:.2f} s)")
    print("why: the old model ramped every motion as a half cosine over at least 0.2 s, the TCP under 10 m/s^2; the "
          "planner gives each axis its own acceleration limit ([robot] accel_deg, x 0.91 for the gripper's 20 kg) "
          "in S-curves whose acceleration takes 0.1 s to build up: the 1.6 m MoveJ between the pallets gets "
          "faster, the 400 mm moves up and down (mostly ramp) slower")
