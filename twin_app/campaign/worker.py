"""The process that runs one scenario. Imported ahead by the process pool's fork server (so a fresh
process per scenario costs a fork, not an interpreter start and the imports), or run as
`python -m twin_app.campaign.worker IN OUT` (a fresh interpreter: where forking is not allowed, e.g. inside a
daemonic Dask worker). Its output (pybullet's, a native crash's) goes to a log the runner reads back when
the process dies.
"""
from __future__ import annotations

import os
import pickle
import sys
import time

from twin.core.native_output import quiet_native_output

with quiet_native_output(stdout=True, stderr=True):  # the banner pybullet prints when imported
    import numpy  # noqa: F401
    import pybullet  # noqa: F401

import plc_client.grip_sequence  # noqa: E402,F401
import plc_client.link  # noqa: E402,F401
import plc_client.scan  # noqa: E402,F401
import rapid_like.station_host  # noqa: E402,F401
import twin.core  # noqa: E402,F401
import twin.runtime.faults  # noqa: E402,F401

from .scenario import LAST_TIMING, run_scenario  # noqa: E402


def execute(campaign, index: int, record_to: str | None = None) -> dict:
    """Run one scenario; the envelope: measured values and wall times (s) of the whole and of the run."""
    t0 = time.perf_counter()
    measured = run_scenario(campaign, index, record_to)
    return {"measured": measured, "wall_run": time.perf_counter() - t0, "wall_load": LAST_TIMING.get("load"),
            "wall_sim": LAST_TIMING.get("sim")}


def redirect_output(log_path: str) -> None:
    """Send this process's descriptors 1 and 2 to `log_path` (native code writes there directly)."""
    fd = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    os.close(fd)


def child_main(campaign, index: int, conn, log_path: str, record_to: str | None = None) -> None:
    """Entry point of a forked scenario process: run, send the envelope, exit."""
    redirect_output(log_path)
    envelope = execute(campaign, index, record_to)
    conn.send(envelope)
    conn.close()


def main(argv: list[str]) -> int:
    """`python -m twin_app.campaign.worker IN OUT`: IN holds (campaign, index, record_to) pickled, OUT gets the
    envelope."""
    src, dst = argv
    with open(src, "rb") as f:
        campaign, index, record_to = pickle.load(f)
    envelope = execute(campaign, index, record_to)
    tmp = dst + ".part"
    with open(tmp, "wb") as f:
        pickle.dump(envelope, f)
    os.replace(tmp, dst)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
