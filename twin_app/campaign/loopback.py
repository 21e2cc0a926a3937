"""A Dask cluster on this machine's loopback: a `dask scheduler` and N `dask worker` processes, for
trying the distributed backend, for tests and for `python -m bench campaign`.

    with loopback_cluster(workers=2) as address:
        run_campaign(campaign, DaskBackend(address), "out/")
"""
from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def loopback_cluster(workers: int = 2, startup_timeout: float = 90.0) -> Iterator[str]:
    """Start the scheduler and `workers` single-threaded worker processes on 127.0.0.1; yield the
    scheduler's address; stop them all afterwards (each in its own process group)."""
    import distributed

    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs: list[subprocess.Popen] = []
    logs = tempfile.TemporaryDirectory(prefix="dask-loopback-")

    def start(args: list[str], name: str) -> None:
        with open(os.path.join(logs.name, name + ".log"), "wb") as log:
            procs.append(subprocess.Popen([sys.executable, "-m", *args], stdout=log, stderr=subprocess.STDOUT,
                                          stdin=subprocess.DEVNULL, start_new_session=True))

    try:
        start(["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
              "scheduler")
        for k in range(workers):
            start(["distributed.cli.dask_worker", address, "--host", "127.0.0.1", "--nthreads", "1", "--nworkers", "1",
                   "--no-dashboard", "--name", f"worker-{k}"], f"worker-{k}")
        deadline = time.monotonic() + startup_timeout
        client = None
        while client is None:
            try:
                client = distributed.Client(address, timeout=5)
            except OSError:
                if time.monotonic() > deadline or any(p.poll() is not None for p in procs):
                    text = "".join(open(os.path.join(logs.name, f)).read()[-500:] for f in sorted(os.listdir(logs.name)))
                    raise RuntimeError(f"the loopback Dask cluster did not start: {text}") from None
                time.sleep(0.3)
        try:
            client.wait_for_workers(workers, timeout=max(1.0, deadline - time.monotonic()))
        finally:
            client.close()
        yield address
    finally:
        for p in procs:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(p.pid, signal.SIGKILL)
                p.wait(5)
        logs.cleanup()
