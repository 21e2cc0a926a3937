"""Wall time per simulated second of RAPID polling loops offline, side by side in one run.

    python -m bench rapid [--seconds S]

Programs: an idle time-less loop (`WHILE diGo = 0 DO ENDWHILE`), a busy one that changes data
every turn (`Incr n`), a `WaitUntil` (polls every 0.1 s), a loop with `WaitTime 0.01` and an ITimer
TRAP every 0.01 s. diGo is set at the end, so every loop runs for the whole S simulated seconds.
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
    args = ap.parse_args(argv)
    print(f"{'program':<22} {'simulated s':>11} {'wall s':>8} {'wall s per simulated s':>23}")
    for name, body in LOOPS.items():
        module = parse(program(body), name)
        t0 = time.perf_counter()
        out = run_offline(module, [SignalInfo("diGo", "DI")], [SignalChange("diGo", 1.0, args.seconds)])
        wall = time.perf_counter() - t0
        print(f"{name:<22} {out.t:>11.2f} {wall:>8.3f} {wall / max(out.t, 1e-9):>23.4f}")
    return 0
