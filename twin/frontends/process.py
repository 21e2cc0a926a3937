"""The one concurrency rule, and the adapter that keeps it.

**The rule.** The simulation and its Modbus front end run on one asyncio event loop in one process (a
request and a step never interleave: a read sees a completed step). Every other front end (OPC UA, the
live page, anything that does much Python work per step or per client) runs in a process of its own,
fed the published snapshots and handing its writes back through this adapter; it never shares the
simulation's interpreter, its GIL or its collector, so it can neither make a step late nor change a
setting of the simulation's process. `twin.runtime.pacing` is the only module that knows the wall clock.

    twin serve (SCHED_RR where allowed)               its own processes (spawned, ordinary scheduling)
    +------------------------------------------+      +------------------------------------------------+
    | one asyncio loop (+ the log's and        | unix | OPC UA: asyncua server, its loop    <- opc.tcp |
    | events' writer threads):                 |<====>|   (twin.frontends.opcua.cell_link)             |
    |  runner (twin.runtime.pacing) -> exchange| sock +------------------------------------------------+
    |  Modbus/TCP server            <- tcp     |<====>| page: viser server, its loop     <- http/ws    |
    |  watchdog, a FrontEndProcess per front   | unix |   (twin.frontends.view.process)                |
    |  end on the right, the recorder (rows    | sock +------------------------------------------------+
    |  kept as read, a pickle per 0.5 s group) |=====>| recorder's writer: encodes, appends -> FILE    |
    +------------------------------------------+ pipe |   (twin.observe.recording, own session)        |
      snapshots (changed values) ->   <- writes       +------------------------------------------------+
      (validated here), Sim.Advance, watchdog feeds, buttons

The recorder's writer is not fed through this adapter (a snapshot a step over it would cost more than the
encoding it saves: `python -m bench record`); it gets a pipe of its own, one message per half second of
simulated time, and writes what it received even when the simulation's process dies.

**The adapter.** `FrontEndProcess(name, "module:factory", options)` is a front end of a cell (the contract in
`twin_app.cell`). `start` spawns a clean interpreter (no pybullet, no loop copied) that calls
`factory(options)` and starts the object it returns with a `Remote`: the cell as that process sees it.

- cell -> process, after every step: the snapshot (step, simulated time, and the values that changed since
  the last one sent; the process keeps the whole table). Every step arrives, in order: a value that lasts
  one step still reaches an OPC UA subscription.
- process -> cell: `await remote.submit([(name, value), ...])` is validated in the simulation's process by
  the exchange (`SignalSpec.check`, the one validation) and queued for the next step; a refusal comes back
  as the same error type (`SignalRangeError`, `SignalTypeError`, `SimulationFault`, ...) with the same
  message, so each front end maps it to its protocol by type. `await remote.advance(n)` (lockstep) returns
  the step count when n more steps are done; `remote.feed(source, clock_only)` feeds the comm-loss
  watchdog; `remote.control(action)` pauses, resumes or steps the runner (the page's buttons);
  `remote.event(kind, **fields)` hands a client's coming and going (`client_connected`, `client_gone`,
  `client_refused`) to the cell's one events writer (`twin serve --events`), stamped with its step there;
  `await remote.sync()` returns once every step the cell had run when it was called has reached this
  process's subscribers (see the watermark below).
- One ordered channel each way, so a write answered before a `Sim.Advance` is applied in the advance's first
  step, and an advance's answer comes after its last step's snapshot: lockstep runs stay bit for bit. The
  simulation's side never waits for the process: it reads the channel in its event loop (no thread) and its
  writes are buffered by asyncio; a process that stops reading for `MAX_BACKLOG` bytes is cut off (logged)
  and the simulation goes on. If the process dies, the simulation goes on without it.
- The watermark. The process's snapshots trail the cell's by the channel, so steps another front end asked
  for (a Modbus client's `sim.advance`) may not have reached it when its own client asks next (on a loaded
  machine, often). So both processes map one watermark (a file in the adapter's private folder, unlinked
  once the process has connected) where the cell writes the step of every snapshot right after writing the
  snapshot into the channel, before any client can see that step done (and its complement: a value read
  while it is written does not match, and is read again). `sync` reads it and, when it is ahead
  of the process's last snapshot, waits for that snapshot: a lockstep front end `sync`s before it answers a
  read, so a client reads at least what it saw done anywhere. It needs no turn of the simulation's loop: a
  front end still answers while that loop is busy.

**Pipes, not shared memory (measured: `python -m bench adapter`).** One snapshot of the ring rig (75 signals,
one of them text) costs the simulation's process 26 us of CPU through a Unix socket (every value pickled,
1.3 kB) and 13 us written into a `multiprocessing.shared_memory` block under a sequence lock (doubles only,
600 B): 0.2 % and 0.1 % of a 12 ms step, the same for the step. Shared memory keeps only the newest snapshot
(a reader that looks late misses a step, and OPC UA must publish every step), holds no text, makes the
reader poll, and still needs a second channel, ordered with the snapshots, for writes and `Sim.Advance`. A
socket carries every step in order, text included, wakes the reader only when there is something to
read, and is the write channel too; the adapter sends only the values that changed, cheaper still. Only
the watermark, one word, is shared.
"""
from __future__ import annotations

import asyncio
import importlib
import inspect
import logging
import mmap
import multiprocessing
import os
import pickle
import shutil
import socket
import struct
import sys
import tempfile
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from twin.core.errors import TwinError

log = logging.getLogger("twin.frontends.process")

MAX_BACKLOG = 64 << 20  # bytes queued for a process that does not read them: then it is cut off
START_TIMEOUT = 60.0  # s a process may take to start its front end
RUNNER_ACTIONS = ("pause", "resume", "single_step", "request")
CLIENT_EVENTS = ("client_connected", "client_gone", "client_refused")  # what a front end's process may report
_HEADER = struct.Struct("!I")
MARK_BYTES = 16  # the watermark: the step of the last snapshot written into the channel, then its complement


# -- the wire: length-prefixed pickles over a Unix socket, read and written by asyncio on both sides --------
def _frame(msg) -> bytes:
    data = pickle.dumps(msg, protocol=pickle.HIGHEST_PROTOCOL)
    return _HEADER.pack(len(data)) + data


async def _read(reader: asyncio.StreamReader):
    size = _HEADER.unpack(await reader.readexactly(_HEADER.size))[0]
    return pickle.loads(await reader.readexactly(size))


def _error_reply(exc: TwinError) -> tuple:
    return ("err", type(exc).__module__, type(exc).__qualname__, str(exc))


def error_from(reply: tuple) -> TwinError:
    """The error a refusal names, rebuilt in this process: same type, same message (a type this process cannot
    import, or not a `TwinError`: a plain `TwinError` with the message)."""
    _, module, qualname, message = reply
    cls = None
    try:
        cls = importlib.import_module(module)
        for part in qualname.split("."):
            cls = getattr(cls, part)
    except (ImportError, AttributeError):
        cls = None
    if not (isinstance(cls, type) and issubclass(cls, TwinError)):
        return TwinError(message)
    exc = cls.__new__(cls)
    Exception.__init__(exc, message)
    return exc


# -- the simulation's side -----------------------------------------------------------------------------
class FrontEndProcess:
    """A front end of a cell that runs in a process of its own (see the module docstring)."""

    def __init__(self, name: str, target: str, options: Mapping | None = None, *, local=None,
                 start_timeout: float = START_TIMEOUT):
        """`target`: "module:factory"; in the new process `factory(options)` returns the front end, an object with
        `async start(remote) -> (lines, endpoints)` (lines for the log, endpoints for the `ready` event; raises
        OSError when it cannot bind, TwinError when it does not fit) and `async close() -> int` (its request
        count).

        `local`: an optional companion in the simulation's process for what is not a signal (the page's frames:
        poses taken from the twin): `local.start(cell, send)`, `local.on_message(payload)` for what the process
        sends with `remote.send_local(payload)`, `local.after_snapshot(snapshot)` after every step (in the
        stepping thread; `send(payload)` reaches the process's `remote.on_local` subscribers), `local.close()`."""
        self.name, self.target, self.options, self.start_timeout = name, target, dict(options or {}), start_timeout
        self.local = local
        self.requests = 0
        self.process = None
        self.cell = None
        self._endpoints: list[dict] = []
        self._writer: asyncio.StreamWriter | None = None
        self._reader_task: asyncio.Task | None = None
        self._unsubscribe = None
        self._sent: dict[str, object] = {}
        self._accepted = 0  # write batches of the process the exchange accepted
        self._applied = 0  # ... and a step has applied (sent with every snapshot)
        self._last_step = -1
        self._waiting: list[tuple[int, int]] = []  # Sim.Advance: (target step, request id)
        self._started: asyncio.Future | None = None
        self._bye: asyncio.Future | None = None
        self._cut = False
        self._map: mmap.mmap | None = None
        self._mark: memoryview | None = None  # the watermark, as two int64 words

    # -- life cycle --------------------------------------------------------------------------------
    async def start(self, cell) -> list[str]:
        self.cell = cell
        loop = asyncio.get_running_loop()
        if self.local is not None:
            self.local.start(cell, lambda payload: self._send(("local", payload)))
        # the process connects to a socket only this user can reach (passing a socket to a spawned process
        # would start a thread here to hand it over)
        folder = tempfile.mkdtemp(prefix="twin-frontend-")
        address, mark = os.path.join(folder, "cell"), os.path.join(folder, "step")
        listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            with open(mark, "w+b") as f:  # the watermark (the process maps it before it connects)
                f.write(bytes(MARK_BYTES))
                f.flush()
                self._map = mmap.mmap(f.fileno(), MARK_BYTES)
                self._mark = memoryview(self._map).cast("q")
                _set_mark(self._mark, 0)
            listener.bind(address)
            listener.listen(1)
            listener.setblocking(False)
            ctx = multiprocessing.get_context("spawn")  # a clean interpreter: no pybullet, no event loop copied
            self.process = ctx.Process(target=child_main, name=f"twin-{self.name}", daemon=True,
                                       args=(self.target, address, mark))
            self.process.start()
            try:
                mine, _ = await asyncio.wait_for(loop.sock_accept(listener), self.start_timeout)
            except asyncio.TimeoutError:
                await self._end()
                raise TwinError(f"{self.name}: its process did not start within {self.start_timeout:g} s") from None
        finally:
            listener.close()
            shutil.rmtree(folder, ignore_errors=True)
        reader, self._writer = await asyncio.open_connection(sock=mine)
        self._started, self._bye = loop.create_future(), loop.create_future()
        ex, twin = cell.exchange, cell.exchange.twin
        runner = getattr(cell, "runner", None)
        self._send(("hello", {"name": self.name, "options": self.options, "station": twin.station.name,
                              "dt": twin.dt, "signals": tuple(ex.signals),
                              "mode": getattr(runner, "mode", "lockstep")}))
        self._send_snapshot(ex.snapshot)
        self._reader_task = asyncio.ensure_future(self._read_loop(reader))
        try:
            kind, lines, info = await asyncio.wait_for(asyncio.shield(self._started), self.start_timeout)
        except asyncio.TimeoutError:
            await self._end()
            raise TwinError(f"{self.name}: its process did not start within {self.start_timeout:g} s") from None
        if kind != "ready":
            await self._end()
            if kind == "oserror":
                raise OSError(lines)
            raise TwinError(lines) if kind == "twinerror" else TwinError(f"{self.name}: {lines}")
        self._endpoints = list(info)
        self._unsubscribe = ex.subscribe(on_snapshot=self._on_snapshot)
        self._send_snapshot(ex.snapshot)  # what changed while it started
        return list(lines)

    def endpoints(self) -> list[dict]:
        return self._endpoints

    async def close(self) -> None:
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
        if self._writer is not None and not self._cut:
            self._send(("stop",))
            try:
                self.requests = await asyncio.wait_for(asyncio.shield(self._bye), 10)
            except (asyncio.TimeoutError, asyncio.CancelledError):
                pass
        await self._end()

    async def _end(self) -> None:
        local, self.local = self.local, None
        if self._map is not None:
            self._mark.release()
            self._map.close()
            self._mark = self._map = None
        if local is not None:
            local.close()
        if self._writer is not None:
            self._writer.close()
        if self._reader_task is not None:
            self._reader_task.cancel()
            await asyncio.gather(self._reader_task, return_exceptions=True)
        if self.process is not None:  # no thread to wait in: look every 20 ms
            for _ in range(250):
                if not self.process.is_alive():
                    break
                await asyncio.sleep(0.02)
            if self.process.is_alive():
                self.process.terminate()
            self.process.join(2.0)
        self._fail_waiting()

    # -- cell -> process ---------------------------------------------------------------------------
    def _send(self, msg) -> bool:
        """Write a message into the channel; False when the process is gone or cut off."""
        w = self._writer
        if w is None or self._cut or w.is_closing():
            return False
        if w.transport.get_write_buffer_size() > MAX_BACKLOG:
            self._cut = True
            self.cell.log(f"{self.name}: its process stopped reading ({MAX_BACKLOG >> 20} MiB behind): cut off; "
                          "the simulation goes on without it", logging.WARNING)
            w.close()
            return False
        w.write(_frame(msg))
        return True

    def _send_snapshot(self, snapshot) -> None:
        sent = self._sent
        changed = {k: v for k, v in snapshot.values.items() if k not in sent or sent[k] != v
                   or type(sent[k]) is not type(v)}
        sent.update(changed)
        if snapshot.step != self._last_step:  # a step applied every batch accepted before it
            self._last_step, self._applied = snapshot.step, self._accepted
        if self._send(("snap", snapshot.step, snapshot.time, changed, self._applied)) and self._mark is not None:
            _set_mark(self._mark, snapshot.step)  # after the snapshot is in the channel, never before

    def _on_snapshot(self, snapshot) -> None:
        self._send_snapshot(snapshot)
        if self.local is not None:
            self.local.after_snapshot(snapshot)
        ex = self.cell.exchange
        if ex.fault:
            self._fail_waiting()
        elif self._waiting:
            step = snapshot.step
            done = [(t, i) for t, i in self._waiting if step >= t]
            if done:
                self._waiting = [w for w in self._waiting if step < w[0]]
                for _, i in done:
                    self._send(("reply", i, ("ok", step)))

    def _fail_waiting(self) -> None:
        from twin.runtime.exchange import SimulationFault

        waiting, self._waiting = self._waiting, []
        for _, i in waiting:
            self._send(("reply", i, _error_reply(SimulationFault(self.cell.exchange.twin.step_count))))

    # -- process -> cell ---------------------------------------------------------------------------
    async def _read_loop(self, reader: asyncio.StreamReader) -> None:
        try:
            while True:
                msg = await _read(reader)
                try:
                    self._handle(msg)
                except Exception as exc:  # noqa: BLE001 - a message's trouble must not stop the channel
                    self.cell.log(f"{self.name}: {msg[0]!r} from its process failed: {type(exc).__name__}: {exc}",
                                  logging.ERROR)
        except (asyncio.IncompleteReadError, ConnectionError, OSError):
            pass
        finally:
            if self._started is not None and not self._started.done():
                self._started.set_result(("failed", "its process ended before it started", ()))
            if self._bye is not None and not self._bye.done():
                self._bye.set_result(self.requests)
            if self._unsubscribe is not None:  # gone while serving
                self._unsubscribe()
                self._unsubscribe = None
                self.cell.log(f"{self.name}: its process is gone; the simulation goes on without it", logging.WARNING)

    def _handle(self, msg) -> None:
        kind = msg[0]
        if kind == "submit":
            _, i, writes = msg
            try:
                batch = self.cell.exchange.submit(writes)
                self._accepted += 1
                reply = ("ok", batch)
            except TwinError as exc:
                reply = _error_reply(exc)
            self._send(("reply", i, reply))
        elif kind == "advance":
            self._advance(msg[1], msg[2])
        elif kind == "feed":
            watchdog = getattr(self.cell, "watchdog", None)
            if watchdog is not None and watchdog.timeout:
                runner = self.cell.runner
                watchdog.feed(msg[1], bool(msg[2]) and getattr(runner, "mode", "") == "lockstep")
        elif kind == "control":
            _, action, args = msg
            runner = self.cell.runner
            if action in RUNNER_ACTIONS and runner is not None and hasattr(runner, action):
                getattr(runner, action)(*args)
                self.cell.exchange.publish()
        elif kind in ("ready", "oserror", "twinerror", "failed"):
            if not self._started.done():
                self._started.set_result(msg)
        elif kind == "local":
            if self.local is not None:
                self.local.on_message(msg[1])
        elif kind == "log":
            self.cell.log(msg[2], msg[1])
        elif kind == "event":
            _, event, fields = msg
            events = getattr(self.cell, "events", None)
            if event in CLIENT_EVENTS and events is not None:
                events.emit(event, **fields)
        elif kind == "bye":
            self.requests = msg[1]
            if not self._bye.done():
                self._bye.set_result(msg[1])

    def _advance(self, i: int, n: int) -> None:
        from twin.runtime.exchange import SimulationFault

        ex, runner = self.cell.exchange, self.cell.runner
        twin = ex.twin
        if runner is None or runner.mode != "lockstep":
            self._send(("reply", i, ("err", "twin.frontends.process", "NotLockstep",
                                     "Sim.Advance runs only in lockstep (twin serve --lockstep)")))
            return
        if ex.fault or getattr(runner, "failed", False):
            self._send(("reply", i, _error_reply(SimulationFault(twin.step_count))))
            return
        target = twin.step_count + runner.remaining + n
        if target <= twin.step_count:
            self._send(("reply", i, ("ok", twin.step_count)))
            return
        self._waiting.append((target, i))
        runner.request(n)
        ex.publish()  # sim.advance shows the steps to run


class NotLockstep(TwinError):
    """`advance` asked of a cell that runs in real time."""


# -- the front end's side (its own process) ---------------------------------------------------------
@dataclass(frozen=True)
class RemoteSnapshot:
    """A published step as the front end's process holds it (the exchange's `Snapshot`, by value)."""

    step: int
    time: float
    values: Mapping[str, object]

    def __getitem__(self, name: str):
        return self.values[name]


class Remote:
    """The cell as a front end's process sees it: its signal table, every step's snapshot, and the way back."""

    def __init__(self, hello: dict, writer: asyncio.StreamWriter, mark: memoryview | None = None):
        self.name, self.options = hello["name"], hello["options"]
        self.station, self.dt, self.mode = hello["station"], hello["dt"], hello["mode"]
        self.signals = hello["signals"]
        self._spec = {s.name: s for s in self.signals}
        self.snapshot = RemoteSnapshot(0, 0.0, MappingProxyType({}))
        self.applied = 0  # this process's write batches (accepted by `submit`) that the snapshot's step applied
        self._values: dict[str, object] = {}
        self._writer = writer
        self._subscribers: list[Callable[[RemoteSnapshot], None]] = []
        self._local: list[Callable[[object], None]] = []
        self._replies: dict[int, asyncio.Future] = {}
        self._next = 0
        self._mark = mark  # the watermark (see the module docstring)
        self._syncing: list[tuple[int, asyncio.Future]] = []  # `sync`: (step awaited, its future)

    @property
    def lockstep(self) -> bool:
        return self.mode == "lockstep"

    def spec(self, name: str):
        from twin.core.signals import SignalError

        try:
            return self._spec[name]
        except KeyError:
            raise SignalError(name, "no such signal") from None

    def subscribe(self, on_snapshot: Callable[[RemoteSnapshot], object]) -> Callable[[], None]:
        """`on_snapshot(snapshot)` for every step, in order, in this process's event loop; a coroutine function
        is awaited before the next message from the cell is read (so its steps stay in order)."""
        self._subscribers.append(on_snapshot)
        return lambda: self._subscribers.remove(on_snapshot) if on_snapshot in self._subscribers else None

    async def submit(self, writes: Iterable[tuple[str, object]]) -> list:
        """Queue writes for the cell's next step, validated there; the batch as queued, or the refusal's error."""
        return await self._ask("submit", list(writes))

    async def advance(self, n: int) -> int:
        """Lockstep: run n more steps; the step count once they are done."""
        return await self._ask("advance", int(n))

    async def sync(self) -> int:
        """Once every step the cell had run when this was called has been handed to the subscribers (and
        awaited): the step of the snapshot then. A read answered after it shows every step any front end had
        seen done before the read was asked for. Needs no turn of the simulation's loop (the watermark)."""
        step = self.cell_step()
        if step <= self.snapshot.step:
            return self.snapshot.step
        fut = asyncio.get_running_loop().create_future()
        self._syncing.append((step, fut))
        return await fut

    def cell_step(self) -> int:
        """The step of the last snapshot the cell has written into the channel (the watermark)."""
        mark = self._mark
        if mark is None:
            return self.snapshot.step
        while True:  # a value and its complement: a write seen halfway does not match, and is read again
            step, check = mark[0], mark[1]
            if check == ~step:
                return step
            os.sched_yield()  # the cell's process is between the two words

    def feed(self, source: str, clock_only: bool = False) -> None:
        """A client's request (the comm-loss watchdog; `twin.runtime.watchdog`)."""
        self._send(("feed", source, clock_only))

    def control(self, action: str, *args) -> None:
        """The runner's pause, resume, single_step or request(n) (the page's buttons)."""
        self._send(("control", action, args))

    def send_local(self, payload) -> None:
        """A message for the front end's companion in the simulation's process (`FrontEndProcess(local=...)`)."""
        self._send(("local", payload))

    def on_local(self, fn: Callable[[object], None]) -> None:
        """`fn(payload)` for every message the companion sends, in this process's event loop."""
        self._local.append(fn)

    def log(self, text: str, level: int = logging.WARNING) -> None:
        """A line in the simulation's log (as it is: say whose it is)."""
        self._send(("log", level, text))

    def event(self, kind: str, **fields) -> None:
        """A client connected, refused or gone (`CLIENT_EVENTS`): an event of `twin serve --events`, with the
        step and simulated time of the cell when it gets there."""
        self._send(("event", kind, fields))

    async def _ask(self, kind: str, arg):
        self._next += 1
        i = self._next
        fut = asyncio.get_running_loop().create_future()
        self._replies[i] = fut
        self._send((kind, i, arg))
        return await fut

    def _send(self, msg) -> None:
        if not self._writer.is_closing():
            self._writer.write(_frame(msg))

    async def _snap(self, step: int, time: float, changed: dict, applied: int) -> None:
        self._values.update(changed)
        self.applied = applied
        self.snapshot = RemoteSnapshot(step, time, MappingProxyType(dict(self._values)))
        for f in tuple(self._subscribers):
            try:
                done = f(self.snapshot)
                if inspect.isawaitable(done):
                    await done
            except Exception as exc:  # noqa: BLE001 - one step's trouble, said in one line; the next step comes
                self.log(f"{self.name}: step {step} could not be published: {type(exc).__name__}: {exc}",
                         logging.ERROR)
        if self._syncing:
            waiting, self._syncing = self._syncing, []
            for target, fut in waiting:
                if target > step:
                    self._syncing.append((target, fut))
                elif not fut.done():
                    fut.set_result(step)

    def _reply(self, i: int, reply: tuple) -> None:
        fut = self._replies.pop(i, None)
        if fut is None or fut.done():
            return
        if reply[0] == "ok":
            fut.set_result(reply[1])
        else:
            fut.set_exception(error_from(reply))

    def _gone(self) -> None:
        for fut in [*self._replies.values(), *(f for _, f in self._syncing)]:
            if not fut.done():
                fut.set_exception(TwinError("the simulation is gone"))
        self._replies.clear()
        self._syncing.clear()


def _set_mark(mark: memoryview, step: int) -> None:
    """The watermark: the step, then its complement (each an aligned 8-byte word, written whole)."""
    mark[0] = step
    mark[1] = ~step


def child_main(target: str, address: str, mark: str | None = None) -> None:
    """The front end's process: run the front end `target` names until the cell says stop (or is gone)."""
    watermark = None
    if mark is not None:  # mapped before connecting: the cell unlinks it once the process has connected
        with open(mark, "rb") as f:
            watermark = memoryview(mmap.mmap(f.fileno(), MARK_BYTES, access=mmap.ACCESS_READ)).cast("q")
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.connect(address)
    try:
        asyncio.run(_child(target, sock, watermark))
    except KeyboardInterrupt:
        pass


async def _child(target: str, sock: socket.socket, mark: memoryview | None = None) -> None:
    reader, writer = await asyncio.open_connection(sock=sock)
    msg = await _read(reader)
    remote = Remote(msg[1], writer, mark)
    stop = asyncio.Event()

    async def read_loop() -> None:  # from the start: a front end may ask the cell while it starts
        try:
            while True:
                msg = await _read(reader)
                kind = msg[0]
                if kind == "snap":
                    await remote._snap(*msg[1:])
                    await asyncio.sleep(0)  # clients are answered between two steps, even when steps queue up
                elif kind == "reply":
                    remote._reply(msg[1], msg[2])
                elif kind == "local":
                    for fn in tuple(remote._local):
                        fn(msg[1])
                elif kind == "stop":
                    break
        except (asyncio.IncompleteReadError, ConnectionError, OSError):
            pass
        finally:
            remote._gone()
            stop.set()

    reading = asyncio.ensure_future(read_loop())
    front = None
    try:
        module, _, factory = target.partition(":")
        front = getattr(importlib.import_module(module), factory)(remote.options)
        lines, endpoints = await front.start(remote)
    except OSError as exc:
        remote._send(("oserror", str(exc), ()))
        front = None
    except TwinError as exc:
        remote._send(("twinerror", str(exc), ()))
        front = None
    except Exception as exc:  # noqa: BLE001 - said to the simulation's log, in one line
        remote._send(("failed", f"{type(exc).__name__}: {exc}", ()))
        front = None
    else:
        remote._send(("ready", list(lines), list(endpoints)))
    requests = 0
    try:
        if front is not None:
            await stop.wait()
    finally:
        reading.cancel()
        if front is not None:
            try:
                requests = int(await front.close() or 0)
            except Exception as exc:  # noqa: BLE001
                print(f"{remote.name}: close failed: {type(exc).__name__}: {exc}", file=sys.stderr)
        try:
            remote._send(("bye", requests))
            await writer.drain()
            writer.close()
        except (ConnectionError, OSError):
            pass
