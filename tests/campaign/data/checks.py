"""Check functions for the crash/hang campaign: most scenarios close a finger for a moment; one kills its
own process the way a native crash would, one never returns."""
import os
import time


def close_finger(ctx):
    mode = ctx.params.get("var.mode", "ok")
    if mode == "crash":
        os.abort()
    if mode == "hang":
        while True:
            time.sleep(0.1)
    ctx.twin.write("L2", 0.325)
    ctx.twin.step(40)
    ctx.measure("l2_mm", round(ctx.twin.read("L2.actual") * 1000.0, 6))
