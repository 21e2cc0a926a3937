"""A running cell, assembled in one place: twin, controller, exchange, front ends, runner.

    from twin_app.cell import Cell
    from twin.frontends.modbus.front_end import ModbusFrontEnd

    with Cell("stations/my_cell")    as cell:          # twin + its RAPID controller as a Device
        cell.add_front_end(ModbusFrontEnd(port=5020))     # Modbus/TCP; OPC UA and the view plug in alike
        asyncio.run(cell.serve(lockstep=True, stop=stop)) # one runner steps the cell; Ctrl-C or `stop` ends it

What a `Cell` holds:
- `station` and `signals`: the station's static signal table (`twin.core.signal_table.station_signals`),
  derived from its files before anything runs. The cell checks that the running twin (with its
  controller's signals and the simulator's `sim.*`) has exactly this table, so `twin map`, the PLC
  client and every front end can rely on it without starting physics.
- `twin` (`twin.core.Twin`) and `controller`: the station's `[controller]` (a RAPID program, `rapid_like`)
  attached to the twin through the core's `Device` protocol; the core imports no controller.
- `watchdog` (`twin.runtime.watchdog`): the comm-loss watchdog, a device too; front ends `feed` it per request.
- `register_map`: the Modbus map of `signals` in the layout asked for (its CRC is published as `sim.map_crc` to
  every front end).
- `exchange` (`twin.runtime.exchange.Exchange`): the ONE way front ends see and change the cell.
- one runner (`twin.runtime.pacing`): real time (`speed` x the wall clock) or lockstep (steps on `sim.advance`).

The front-end contract (Modbus today; OPC UA and the web view plug in the same way):
1. A front end is an object with `name`, `async start(cell) -> list[str]` (bind, subscribe; returns
   lines for the log, e.g. "listening on 127.0.0.1:5020"; raises OSError when it cannot bind, TwinError
   when it does not fit the station: `serve` logs "error: ..." and exits 2), `async close()` and,
   optionally, `requests` (counted in the last log line). It feeds `cell.watchdog.feed(source)` for
   every request a client makes (the comm-loss watchdog). `cell.add_front_end(front)` before `serve`; `serve` starts them in order after the
   runner is set (so `exchange.runner` is known) and closes them in reverse order when stopped.
2. It reads `cell.exchange.snapshot` (step, time, every signal's value in SI units, `sim.*` included)
   or subscribes to every step with `cell.exchange.subscribe(on_snapshot=...)`. It never reads the twin.
3. It writes with `cell.exchange.submit([(name, value), ...])`, which validates every value the same
   way for all front ends (`SignalSpec.check`: SignalError for an output or unknown name,
   SignalTypeError for a wrong type, SignalRangeError out of range, SimulationFault once the simulation
   has stopped on an error; nothing of the batch is queued on error). Accepted writes take effect at
   the next step, together and in arrival order. `exchange.written(name)` reads an input back at once.
4. Time is the runner's: front ends never step the cell. In lockstep, writing N to `sim.advance` (or
   `cell.exchange.submit([("sim.advance", N)])`) runs N more steps; `sim.advance` reads the steps left.
5. The concurrency rule (`twin.frontends.process`): the simulation and its Modbus front end run on one asyncio
   event loop in one process, so a callback or a request handler never sees a step half done; every other
   front end (OPC UA, the live page) runs in a process of its own behind `FrontEndProcess`, fed the
   snapshots and handing its writes back through the exchange. Front ends use `cell.station` (names, units) and, for geometry only, `cell.twin` (never to
   step or write it).

In process (tests, the in-process demo, a campaign's scenario), a cell is also stepped directly:
`cell.read`, `cell.write` (validated, next step), `cell.step(n)`, `cell.time`, as the twin's simulation
API; more devices (fault injectors, recorders, monitors) go on `cell.twin.add_device` after the cell's
own. `Cell(..., publish=False)`: a headless cell stepped in process (no front end, nothing subscribed)
takes no snapshot per step, which costs a read of every signal; `cell.exchange.publish()` takes one on
demand, and serving the cell publishes every step again.
"""
from __future__ import annotations

import asyncio
import logging
import os
import signal as _signal
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from rapid_like.station_host import attach_controller
from twin.core.device import ObservingDevice
from twin.core.errors import StationError, TwinError
from twin.core.signal_table import SIM_MAP_CRC, SIM_NAMES, WATCHDOG_MS, station_signals
from twin.core.station import Station, load_station
from twin.core.twin import Twin
from twin.observe.events import CONTROLLER, FAULT, READY, STOPPED, Events
from twin.runtime.exchange import Exchange
from twin.frontends.modbus.log import announce as _announce, log as _log
from twin.frontends.modbus.register_map import RegisterMap, build_register_map
from twin.runtime.pacing import LockstepRunner, RealtimeRunner
from twin.runtime.watchdog import Watchdog


class _ControllerState(ObservingDevice):
    """Tells the event stream when the robot controller's state changes (running, stopped, completed, error;
    a program waiting for a signal or a motion is running), after the step in which it did."""

    def __init__(self, controller, events: Events):
        self.controller, self.events, self.state = controller, events, None

    def after_step(self, twin) -> None:
        state = self.controller.state
        state = "running" if state == "waiting" else state
        if state != self.state:
            self.state = state
            self.events.emit(CONTROLLER, type="state", state=state)


class FrontEnd(Protocol):
    """What a cell serves through (see the module docstring)."""

    name: str

    async def start(self, cell: "Cell") -> list[str]: ...

    async def close(self) -> None: ...


def add_watchdog(twin: Twin) -> Watchdog:
    """The comm-loss watchdog (`twin.runtime.watchdog`) on a twin, before its controller so a DI may read `comm.lost`;
    the station's open setpoints must name gripper inputs."""
    spec = twin.station.watchdog
    names = {i.name for i in twin.mechanism.inputs}
    for key in (spec.open if spec is not None else {}):
        if key not in names:
            raise StationError(str(twin.station.file), f"watchdog.open.{key}",
                               f"not an input of the gripper (its inputs: {', '.join(sorted(names))})")
    return Watchdog.for_station(twin.station).attach(twin)


class Cell:
    """A station's twin with its controller, the exchange its front ends use, and (while served) one runner."""

    def __init__(self, station: str | Path | Station, on_event: Callable[[dict], None] | None = None, *,
                 entry: str | None = None, log: Callable[..., None] = _log, announce: Callable[[str], None] = _announce,
                 publish: bool = True, events: Events | None = None, layout: str = ""):
        """Load a station (a folder, a station.toml, or a `Station`, e.g. one with a campaign's parameters
        applied); if it has a `[controller]`, its RAPID program runs as the robot controller.

        `on_event` receives the controller's events (TPWrite lines, output writes, motions, the end or a
        runtime error; see `rapid_like.controller`); `entry` overrides the station's entry routine.
        A program that does not parse or check raises a `rapid_like` error naming file:line:column.
        `publish=False`: in-process steps take no snapshot (see the module docstring).
        `events`: the machine interface (`twin.observe.events`, `twin serve --events`): the cell, its controller,
        its watchdog and its front ends write what happens there.
        `layout`: the register map's (`twin.frontends.modbus.register_map.LAYOUTS`; default the signals layout, `twin serve
        --layout plc` the PLC's).
        """
        self.publishing = publish
        self.events = events if events is not None else Events()
        self.station = station if isinstance(station, Station) else load_station(station)
        self.signals = station_signals(self.station)
        self.register_map: RegisterMap = build_register_map(self.signals, self.station.name, layout)
        self.log, self.announce = log, announce  # log(text, level); announce: shown at every log level
        self.twin = Twin(self.station)
        twin = self.twin
        self.events.clock = lambda: (twin.step_count, twin.time)
        self.controller = None
        try:
            self.watchdog = self._add_watchdog()  # before the controller, so a DI may read comm.lost
            self.watchdog.on_event = self.events.emit
            if self.station.controller is not None:
                self.controller = attach_controller(self.twin, on_event=self._controller_event(on_event), entry=entry)
                if self.events.enabled:
                    self.twin.add_device(_ControllerState(self.controller, self.events))
            self.exchange = Exchange(self.twin, log=log, constants={
                SIM_MAP_CRC: self.register_map.crc, WATCHDOG_MS: round((self.watchdog.timeout or 0) * 1000)})
            self.exchange.on_fault = lambda message: self.events.emit(FAULT, message=message)
            if self.exchange.signals != self.signals:
                raise TwinError(f"station {self.station.name!r}: the running cell's signal table differs from the "
                                "static one (twin.core.signal_table)")
        except BaseException:
            self.twin.close()
            raise
        self.front_ends: list[FrontEnd] = []
        self.runner = None

    def _controller_event(self, on_event: Callable[[dict], None] | None) -> Callable[[dict], None] | None:
        """The controller's events go to `on_event` and, stamped with their own simulated time, to `events`."""
        events = self.events
        if not events.enabled:
            return on_event

        def both(event: dict) -> None:
            if on_event is not None:
                on_event(event)
            fields = dict(event)
            t = fields.pop("t", None)
            events.emit(CONTROLLER, t=t, **fields)
        return both

    def _add_watchdog(self) -> Watchdog:
        return add_watchdog(self.twin)

    def set_watchdog_timeout(self, seconds: float | None) -> None:
        """Change the watchdog's time (None or 0: off), as `twin serve --watchdog S` does."""
        self.watchdog.timeout = seconds or None
        self.exchange.constants[WATCHDOG_MS] = round((self.watchdog.timeout or 0) * 1000)

    # -- in process: the simulation API of the whole cell ---------------------------------------------
    @property
    def time(self) -> float:
        return self.twin.time

    @property
    def dt(self) -> float:
        return self.twin.dt

    @property
    def step_count(self) -> int:
        return self.twin.step_count

    def spec(self, name: str):
        return self.exchange.spec(name)

    def read(self, name: str):
        """A signal's present value (the twin's, the controller's or the simulator's)."""
        return self.exchange.read(name)

    def write(self, name: str, value) -> None:
        """Write an input; it takes effect at the next step (checked like any front end's write)."""
        if self.exchange.spec(name).name in SIM_NAMES:
            self.exchange.submit([(name, value)])
        else:
            self.twin.write(name, value)

    def step(self, n: int = 1) -> None:
        """Run n steps in process (queued front-end writes first), publishing each (unless `publish=False`)."""
        step, publish = self.exchange.step, self.publishing
        for _ in range(n):
            step(reraise=True, publish=publish)

    # -- served -----------------------------------------------------------------------------------------
    def add_front_end(self, front: FrontEnd) -> None:
        self.front_ends.append(front)

    def pace(self, *, lockstep: bool = False, speed: float = 1.0, priority: bool = False):
        """Make the runner (it does not run yet): lockstep, or `speed` x real time (`priority`: with real-time
        scheduling where the OS allows it, see `twin.runtime.pacing`)."""
        self.publishing = True  # front ends read every step's snapshot
        self.runner = (LockstepRunner(self.exchange.step) if lockstep
                       else RealtimeRunner(self.exchange.step, self.dt, speed, priority=priority))
        self.exchange.runner = self.runner
        self.exchange.publish()
        return self.runner

    async def serve(self, *, lockstep: bool = False, speed: float = 1.0, paused: bool = False,
                    stop: asyncio.Event | None = None, priority: bool = False) -> int:
        """Start the front ends and run until `stop` is set (or SIGINT/SIGTERM). Returns the exit code
        (2 when a front end cannot start). A simulation fault keeps the front ends serving the last state.
        `paused` (real time): the runner waits for `runner.resume()` (the view's Run button). `priority` (real
        time; `twin serve`): real-time scheduling for the simulation's thread where the OS allows it."""
        loop = asyncio.get_running_loop()
        loop.set_exception_handler(lambda _loop, ctx: self.log(f"event loop: {ctx.get('message')}: "
                                                               f"{ctx.get('exception')!r}", logging.DEBUG))
        stop = stop or asyncio.Event()
        for sig in (_signal.SIGINT, _signal.SIGTERM):
            try:
                loop.add_signal_handler(sig, stop.set)
            except (NotImplementedError, RuntimeError, ValueError):  # not the main thread, or Windows
                pass
        runner = self.pace(lockstep=lockstep, speed=speed, priority=priority and not lockstep)
        if not lockstep:
            self.watchdog.clock = runner.clock  # real time: the wall clock; lockstep: simulated time
            if paused:
                runner.pause()
        started: list[FrontEnd] = []
        try:
            for front in self.front_ends:
                try:
                    lines = await front.start(self)
                except (OSError, TwinError) as exc:
                    self.log(f"error: {exc}", logging.ERROR)
                    self.events.emit(STOPPED, steps=self.twin.step_count, requests=0, error=str(exc))
                    return 2
                started.append(front)
                for line in [lines] if isinstance(lines, str) else lines:
                    self.announce(line)
            self.exchange.publish()  # what the front ends changed (e.g. the watchdog's time)
            self.events.emit(READY, pid=os.getpid(), station=self.station.name, lockstep=lockstep,
                             front_ends=[e for f in started for e in getattr(f, "endpoints", lambda: [])()])
            task = asyncio.ensure_future(runner.run())
            stopper = asyncio.ensure_future(stop.wait())
            await asyncio.wait({task, stopper}, return_when=asyncio.FIRST_COMPLETED)
            if task.done() and task.exception() is not None:
                self.log(f"error: the runner failed: {task.exception()!r}", logging.ERROR)
            if task.done() and not stop.is_set():
                await stop.wait()  # faulted: keep serving the last state until stopped
            runner.stop()
            for t in (task, stopper):
                if not t.done():
                    t.cancel()
            await asyncio.gather(task, stopper, return_exceptions=True)
        finally:
            for front in reversed(started):
                await front.close()
        late = f", {runner.late_steps} late" if not lockstep else ""
        requests = sum(getattr(f, "requests", 0) for f in started)
        self.events.emit(STOPPED, steps=self.twin.step_count, requests=requests,
                         **({} if lockstep else {"late_steps": runner.late_steps}))
        self.announce(f"stopped after {self.twin.step_count} steps ({self.twin.time:.3f} s simulated{late}, "
                      f"{requests} requests)")
        return 0

    # -- life cycle -------------------------------------------------------------------------------------
    def close(self) -> None:
        self.twin.close()

    def __enter__(self) -> "Cell":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def open_cell(station: str | Path, on_event: Callable[[dict], None] | None = None, *,
              entry: str | None = None) -> Cell:
    """A `Cell` for a station (see `Cell`)."""
    return Cell(station, on_event, entry=entry)
