"""Scripted commissioning checks: a twin server for a station on a free loopback port, and a client to it.

As a context manager, anywhere:

    from plc_client.testing import twin_server

    with twin_server("stations/my_cell", lockstep=True) as server:
        with server.client() as plc:
            plc.write(axis1=320.0); plc.advance(100); assert plc.get("axis1.actual") < 330.0

As pytest fixtures (in your `conftest.py`: `pytest_plugins = ["plc_client.testing"]`, and name the station):

    @pytest.fixture
    def plc_station():
        return "stations/my_cell"

    def test_fingers_close(twin_client):          # a connected TwinClient; the server is lockstep
        twin_client.write(axis1=320.0)
        twin_client.advance(100)
        assert twin_client.get("axis1.actual") == pytest.approx(320.0, abs=0.5)

`plc_server` gives the running server (`.host`, `.port`, `.map`, `.client()`, `.events`: what the server
says happened, `twin serve --events`, docs/events.md), `plc_lockstep` (default True) chooses lockstep or
real time. See docs/commissioning-checks.md.

A PLC in Structured Text, in lockstep against the station (`twin serve --layout plc`), its located variables
bound through the map's device ranges (`plc_client.st_io`):

    def test_press(st_plc):
        run = st_plc("press.st", program="press")     # program=: the station's declarations come along
        run.cycle.run_until(lambda inputs, plc: run.get("done"), timeout=10.0)
        assert run.client.get("axis1.force") >= 200.0
"""
from __future__ import annotations

import contextlib
import json
import os
import socket
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from .client import ClientIO, RegisterMap, TwinClient
from .errors import PlcClientError
from .events import EventLog

LOOPBACK = "127.0.0.1"


class ServerStartError(PlcClientError):
    """`twin serve` did not come up (its stderr is in the message)."""


@dataclass
class TwinServer:
    """A running `twin serve` subprocess."""

    station: Path
    host: str
    port: int
    unit_id: int
    lockstep: bool
    map: RegisterMap
    process: subprocess.Popen

    def client(self, timeout: float = 3.0) -> TwinClient:
        """A new connected client (close it, or use it in a `with`)."""
        return TwinClient.connect(self.host, self.port, self.unit_id, map=self.map, timeout=timeout)

    def io(self, client: TwinClient, local: dict | None = None) -> ClientIO:
        """The scan-cycle I/O for `client`: lockstep when the server is. `local`: signals the check holds
        itself (e.g. the robot's handshake bits, when the check plays the robot)."""
        return ClientIO(client, lockstep=self.lockstep, local=local)

    def plc_args(self) -> list[str]:
        """The global options of the `plc` command for this server (with a map file written once)."""
        return ["--host", self.host, "--port", str(self.port), "--unit-id", str(self.unit_id), "--map", str(self.map_file)]

    @property
    def map_file(self) -> Path:
        path = getattr(self, "_map_file", None)
        if path is None:
            fd, name = tempfile.mkstemp(prefix=f"twin-map-{self.port}-", suffix=".json")
            with os.fdopen(fd, "w") as f:
                f.write(self.map_json)
            path = self._map_file = Path(name)
        return path

    map_json: str = ""
    events: "EventLog | None" = None  # `twin serve --events`: what happened (docs/events.md)
    log: Path | None = None  # the server's log (stderr): for people, not parsed

    def endpoint(self, name: str = "modbus", protocol: str | None = None) -> dict:
        """A front end's address as the `ready` event gives it (`name`: modbus, opcua, view)."""
        return self.events.endpoint(name, protocol)

    @property
    def running(self) -> bool:
        return self.process.poll() is None


def free_port(host: str = LOOPBACK) -> int:
    """A port the OS has just handed out (bound to port 0, then released)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def twin_command() -> list[str]:
    return [sys.executable, "-m", "twin"]


@contextlib.contextmanager
def twin_server(station: str | Path, *, lockstep: bool = True, speed: float | None = None, host: str = LOOPBACK,
                port: int = 0, unit_id: int = 1, startup_timeout: float = 30.0,
                extra_args: list[str] = (), faults: str | Path | None = None, layout: str = "") -> Iterator[TwinServer]:
    """Start `twin serve STATION` on loopback, wait until it listens, and stop it afterwards.

    port 0 (the default): the server binds a free port and says which (no race with other tests).
    lockstep: the server only steps when told (`sim.advance`): the same run gives the same result. Else it
    runs in real time, or at `speed` times real time. `faults`: a faults file (`[faults.NAME]` tables as in a
    campaign, docs/campaigns.md) whose plant faults the served twin meets (`twin serve --faults`). `layout`:
    the register map's (`twin serve --layout`; "plc" for a PLC with located variables).
    """
    station = Path(station)
    rmap = RegisterMap.from_station(station, layout)
    mode = ["--lockstep"] if lockstep else ["--realtime", *(["--speed", f"{speed:g}"] if speed else [])]
    with tempfile.NamedTemporaryFile(mode="w+", prefix="twin-serve-", suffix=".log", delete=False) as log:
        log_path = Path(log.name)
        events_path = log_path.with_suffix(".events.jsonl")
        proc = subprocess.Popen([*twin_command(), "serve", str(station), "--host", host, "--port", str(port),
                                 "--unit-id", str(unit_id), *mode, "--events", str(events_path),
                                 *(["--faults", str(faults)] if faults else []),
                                 *(["--layout", layout] if layout else []), *extra_args],
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=log)
    server = None
    try:
        events = EventLog(events_path, proc)
        ready = events.wait("ready", startup_timeout)
        if ready is None:
            _stop(proc)
            text = log_path.read_text(errors="replace").strip()
            raise ServerStartError(f"`twin serve {station}` did not start: {text[-2000:] or 'no output'}")
        modbus = events.endpoint("modbus")
        server = TwinServer(station, modbus["host"], modbus["port"], unit_id, lockstep, rmap, proc,
                            map_json=json.dumps(rmap.as_list()), events=events, log=log_path)
        yield server
    finally:
        _stop(proc)
        log_path.unlink(missing_ok=True)
        events_path.unlink(missing_ok=True)
        mf = getattr(server, "_map_file", None)
        if mf is not None:
            mf.unlink(missing_ok=True)


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=5)


# -- pytest fixtures (load with `pytest_plugins = ["plc_client.testing"]`) ---------------------------------
try:
    import pytest
except ImportError:  # pragma: no cover - the fixtures need pytest, the context manager does not
    pytest = None

if pytest is not None:

    @pytest.fixture
    def plc_lockstep() -> bool:
        """Override to run the server in real time (False)."""
        return True

    @pytest.fixture
    def plc_station():
        """Override with the station (folder or station.toml) the checks run against."""
        pytest.fail("define a `plc_station` fixture returning the station to serve (see docs/commissioning-checks.md)")

    @pytest.fixture
    def plc_server(plc_station, plc_lockstep) -> Iterator[TwinServer]:
        """A `twin serve` of `plc_station` on a free loopback port, stopped after the test."""
        with twin_server(plc_station, lockstep=plc_lockstep) as server:
            yield server

    @pytest.fixture
    def twin_client(plc_server) -> Iterator[TwinClient]:
        """A TwinClient connected to `plc_server`."""
        with plc_server.client() as client:
            yield client

    @pytest.fixture
    def st_plc(plc_station, tmp_path):
        """`st_plc(*files, program=None, cycle=0.010)` -> a `StPlcRun`: the ST PLC of `files` scanning in lockstep
        against `plc_station` served with the PLC layout (one server per test). With `program`, the station's
        declarations (`twin map --format st --program PROGRAM`) are added to the files."""
        with contextlib.ExitStack() as stack:
            def start(*files, program: str | None = None, cycle: float = 0.010) -> StPlcRun:
                server = stack.enter_context(twin_server(plc_station, lockstep=True, layout="plc"))
                files = [Path(f) for f in files]
                if program is not None:
                    from twin.frontends.modbus.plc_export import to_structured_text

                    io = tmp_path / f"io_{program}.st"
                    io.write_text(to_structured_text(server.map, program=program), encoding="utf-8")
                    files.append(io)
                return stack.enter_context(StPlcRun(server, files, cycle))
            yield start


class StPlcRun:
    """An ST PLC on a scan cycle against a lockstep server: `.cycle` (the `ScanCycle`: scan, run, run_until),
    `.client` (a TwinClient: the twin's signals by name), `.get(name)` (a variable of the PLC's program instance),
    `.plc` (the runtime)."""

    def __init__(self, server: TwinServer, files: list[Path], cycle: float):
        from .scan import ScanCycle
        from .st_io import StLogic

        self.server, self.logic = server, StLogic(files, server.map)
        self.client = server.client()
        self.cycle = ScanCycle(ClientIO(self.client, lockstep=True), self.logic, cycle=cycle)
        self.plc = self.cycle.state

    def get(self, name: str):
        return self.plc.get(f"{self.logic.instance}.{name}")

    def __enter__(self) -> "StPlcRun":
        return self

    def __exit__(self, *exc) -> None:
        self.client.close()
