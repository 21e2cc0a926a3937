"""Where scenarios run: a local pool of fresh processes, or a Dask cluster.

`LocalBackend(workers)`: every scenario in a process of its own, forked from a fork server that has
imported the simulation once, at most `workers` at a time. A scenario that kills its process (a native
crash, `os.abort()`) or outlives its timeout (it is killed) fails alone, with the reason; the others
run on. Where the fork server is not available (Windows), each scenario is a fresh interpreter instead
(`python -m twin_app.campaign.worker`).

`DaskBackend(address)`: the same isolation on each worker of an existing Dask cluster (`dask scheduler`,
`dask worker ADDRESS`): a task runs its scenario in a fresh local process, so a crash never takes a
worker down and the cluster needs no restarts. Dask is an optional dependency (`pip install
'gripper-twin[cluster]'`); the workers need gripper-twin installed and the station files at the same path.

Both call `on_result(index, envelope)` as results come; an envelope is {"measured": {...}, "wall": s,
"wall_run": s}. The measured values do not depend on the backend or the worker count.
"""
from __future__ import annotations

import contextlib
import multiprocessing
import os
import pickle
import signal
import subprocess
import sys
import tempfile
import time
import types
from collections.abc import Callable, Iterable
from multiprocessing.connection import wait
from pathlib import Path

OnResult = Callable[[int, dict], None]
LOG_TAIL = 1500  # characters of a dead process's output kept in its message


def _describe_exit(code: int | None) -> str:
    if code is None:
        return "still running"
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        return f"killed by {name} (exit status {code})"
    return f"exit status {code}"


def _tail(path: str) -> str:
    try:
        text = Path(path).read_text(errors="replace")
    except OSError:
        return ""
    text = "\n".join(line for line in text.splitlines() if line.strip() and "pybullet build time" not in line)
    return text[-LOG_TAIL:]


def crashed(code: int | None, log: str) -> dict:
    tail = _tail(log)
    return {"outcome": "crashed", "fault": "crashed",
            "message": f"the scenario's process died: {_describe_exit(code)}" + (f"; its last output: {tail}" if tail else "")}


def hung(timeout: float) -> dict:
    return {"outcome": "hung", "fault": "timeout",
            "message": f"no result within the scenario timeout of {timeout:g} s (wall); its process was killed"}


class _ForkJob:
    """One scenario in a process forked from the fork server."""

    def __init__(self, ctx, campaign, index: int, log: str, record_to: str | None = None):
        from .worker import child_main

        self.log = log
        self.reader, writer = ctx.Pipe(duplex=False)
        self.proc = ctx.Process(target=child_main, args=(campaign, index, writer, log, record_to), daemon=True)
        with _without_main_module():
            self.proc.start()
        writer.close()
        self.envelope: dict | None = None
        self.eof = False

    def waitables(self) -> list:
        return [self.reader, self.proc.sentinel]

    def poll(self) -> bool:
        """True when the job is over (a result, or a dead process)."""
        if self.envelope is None and not self.eof and self.reader.poll():
            try:
                self.envelope = self.reader.recv()
            except (EOFError, OSError):  # the process died without sending (its end of the pipe closed)
                self.eof = True
        if self.envelope is not None or self.eof:
            self.proc.join(5)
            return True
        return self.proc.exitcode is not None

    def result(self) -> dict:
        if self.envelope is not None:
            return self.envelope
        return {"measured": crashed(self.proc.exitcode, self.log)}

    def kill(self) -> None:
        if self.proc.is_alive():
            self.proc.kill()
        self.proc.join(5)

    def close(self) -> None:
        self.reader.close()


class _SpawnJob:
    """One scenario in a fresh interpreter (where this process may not fork children)."""

    def __init__(self, campaign, index: int, log: str, record_to: str | None = None):
        fd, self.src = tempfile.mkstemp(prefix="campaign-in-", suffix=".pkl")
        with os.fdopen(fd, "wb") as f:
            pickle.dump((campaign, index, record_to), f)
        self.dst = self.src + ".out"
        self.log = log
        with open(log, "wb") as out:
            self.proc = subprocess.Popen([sys.executable, "-m", "twin_app.campaign.worker", self.src, self.dst],
                                         stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT)

    def waitables(self) -> list:
        return []

    def poll(self) -> bool:
        return self.proc.poll() is not None

    def result(self) -> dict:
        try:
            with open(self.dst, "rb") as f:
                return pickle.load(f)
        except OSError:
            return {"measured": crashed(self.proc.returncode, self.log)}

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait(5)

    def close(self) -> None:
        for p in (self.src, self.dst):
            try:
                os.unlink(p)
            except OSError:
                pass


@contextlib.contextmanager
def _without_main_module():
    """multiprocessing re-imports the parent's main module in every child it starts (pytest's, a Dask
    worker's: seconds each); a scenario process needs only `twin_app.campaign.worker`, so it is told of no
    main module."""
    main = sys.modules.get("__main__")
    sys.modules["__main__"] = types.ModuleType("__main__")
    try:
        yield
    finally:
        sys.modules["__main__"] = main


def _may_fork() -> bool:
    """Whether this process may start children. A daemonic process (a Dask worker under its nanny) may
    not, unless it says it is not daemonic: it may, since it waits for each of its scenario processes
    (themselves daemonic: they die with it)."""
    me = multiprocessing.current_process()
    if me.daemon:
        try:
            me.daemon = False
        except AssertionError:  # a process object that has started its own: leave it alone
            return False
    return True


def _fork_context():
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(["twin_app.campaign.worker"])
    return ctx


class LocalBackend:
    """A pool of `workers` fresh processes, one per scenario, each with a wall-clock `timeout` (s)."""

    name = "local"

    def __init__(self, workers: int = 1, timeout: float | None = None):
        if workers < 1:
            raise ValueError(f"at least one worker, not {workers}")
        self.workers, self.timeout = int(workers), timeout

    def run(self, campaign, indices: Iterable[int], on_result: OnResult, record: dict | None = None) -> None:
        """`record`: index -> a file to record that scenario's run into (twin.observe.recording)."""
        timeout = self.timeout if self.timeout is not None else campaign.timeout
        pending = list(indices)
        record = record or {}
        forking = _may_fork() and "forkserver" in multiprocessing.get_all_start_methods()
        ctx = _fork_context() if forking else None
        running: dict[int, tuple[object, float, float]] = {}
        logdir = tempfile.TemporaryDirectory(prefix="campaign-logs-")
        try:
            while pending or running:
                while pending and len(running) < self.workers:
                    index = pending.pop(0)
                    log = os.path.join(logdir.name, f"{index}.log")
                    rec = record.get(index)
                    job = _ForkJob(ctx, campaign, index, log, rec) if forking else _SpawnJob(campaign, index, log, rec)
                    t0 = time.monotonic()
                    running[index] = (job, t0, t0 + timeout)
                now = time.monotonic()
                next_deadline = min(d for _, _, d in running.values())
                waitables = [w for job, _, _ in running.values() for w in job.waitables()]
                pause = max(0.0, min(next_deadline - now, 0.05 if not waitables else 1.0))
                if waitables:
                    wait(waitables, timeout=pause)
                else:
                    time.sleep(min(pause, 0.02))
                now = time.monotonic()
                for index, (job, t0, deadline) in list(running.items()):
                    if job.poll():
                        envelope = job.result()
                    elif now >= deadline:
                        job.kill()
                        envelope = {"measured": hung(timeout)}
                    else:
                        continue
                    job.close()
                    del running[index]
                    envelope["wall"] = now - t0
                    on_result(index, envelope)
        finally:
            for job, _, _ in running.values():
                job.kill()
                job.close()
            logdir.cleanup()


def run_isolated(campaign, index: int, timeout: float) -> dict:
    """One scenario in a fresh local process with a timeout (what a Dask task runs)."""
    out: dict = {}
    LocalBackend(1, timeout).run(campaign, [index], lambda i, env: out.update(env))
    return out


class DaskBackend:
    """Runs the scenarios on a Dask cluster at `address` (e.g. tcp://10.0.0.5:8786)."""

    name = "dask"

    def __init__(self, address: str, timeout: float | None = None, connect_timeout: float = 10.0):
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise RuntimeError("the Dask backend needs Dask: pip install 'gripper-twin[cluster]'") from None
        self.address, self.timeout, self.connect_timeout = address, timeout, connect_timeout

    def run(self, campaign, indices: Iterable[int], on_result: OnResult) -> None:
        from distributed import Client, as_completed

        timeout = self.timeout if self.timeout is not None else campaign.timeout
        indices = list(indices)
        try:
            client = Client(self.address, timeout=self.connect_timeout)
        except (OSError, TimeoutError) as exc:
            raise RuntimeError(f"cannot connect to the Dask scheduler at {self.address}: {exc}") from None
        try:
            remote = client.scatter(campaign, broadcast=True)
            futures = {client.submit(run_isolated, remote, i, timeout, key=f"scenario-{i}-{os.getpid()}-{time.time_ns()}",
                                     pure=False, retries=0): i for i in indices}
            for future in as_completed(futures):
                index = futures[future]
                try:
                    envelope = future.result()
                except Exception as exc:  # noqa: BLE001 - a lost worker: the scenario's result, named
                    envelope = {"measured": {"outcome": "crashed", "fault": "worker_lost",
                                             "message": f"the Dask task failed: {type(exc).__name__}: {exc}"}}
                on_result(index, envelope)
        finally:
            client.close()
