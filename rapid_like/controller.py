"""The robot controller: a checked RAPID program, a Host, and a tick that whoever owns simulated
time calls once per step. No threads, no sleeps, no wall clock.

    ctl = Controller(module, host, entry="main", on_event=print, step=None, loop_budget=10_000)
    while ...:
        ctl.tick(now)          # simulated seconds; runs statements until the program must wait

`tick(now)` first writes the PulseDO edges that are due, then runs the program until it waits
(WaitTime, WaitUntil, WaitDI/WaitDO, a motion the host has not finished, Stop) or ends. Loop
iterations that consume no time run on at the same instant until the tick's `loop_budget` of them
is used up (10 000 by default); then the loop waits for the next tick, at which it is always ready
to go on. So a `FOR` that sums 1000 numbers ends at the instant it started, and a busy `WHILE`
never hangs the cell. Time is kept in integer nanoseconds, so five `WaitTime 0.2` end at exactly
1.0 s.

State: `state` is "running", "waiting", "stopped", "completed" or "error" (`error` holds the
ExecError); `end_reason` is "completed", "exit" or "stop" once the program has ended or stopped.
`stop()` halts it, `resume()` continues after a stop (or after a Stop instruction), `start()`
restarts it from the entry routine (VAR data re-initialised, PERS kept).

Events (`on_event(dict)`), each with `t` in seconds rounded to 1 us: output writes
`{"type": "DO"|"AO"|"GO", "signal", "value"}`, `{"type": "print", "text"}`, motions
`{"type": "move", "instr", "to", ["via"], "speed", "zone", "tool", "wobj"}`, and last
`{"type": "end", "reason"}` or `{"type": "error", "line", "message"}` (the column is in `error`).
Pulses outlive the program: a PulseDO (or SetDO \\SDelay) still running when the program ends,
stops or fails is completed by the I/O system at its time, and the end or error event follows
its last edge (so `t` never goes backwards and the end event is always the last one; the program
itself ended earlier, at the time of its last own event). `state` and `error` change at once.

A binding to a physics station implements `host.Host` (signals wired to the gripper, motions
driving the robot, `motion_done` true when the robot is in position) and calls `tick(now)` once
per control step, after applying its own inputs for `now`. Event-driven runners (the offline CLI)
use `next_wake_ns()` to jump straight to the next moment anything can happen.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from . import nodes as n
from .checker import check
from .errors import CheckError, ExecError, RapidError
from .host import Host
from .interpreter import NS, ExitCycleSignal, ExitSignal, Fatal, Interpreter, Propagate, Wait, to_ns
from .parser import parse
from .runtime import DEFAULT_LOOP_BUDGET, POLL_BUDGET  # time-less loop iterations per tick

RUNNING, WAITING, STOPPED, COMPLETED, ERROR = "running", "waiting", "stopped", "completed", "error"


def read_source(path: str | Path) -> str:
    """A .mod file's text: UTF-8 (with or without BOM), else Latin-1 as older controllers write it."""
    data = Path(path).read_bytes()
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def load_program(path: str | Path) -> n.Module:
    """Read and parse a .mod file (raises LexError/ParseError)."""
    return parse(read_source(path), str(path))


TASK_SUFFIXES = (".mod", ".modx", ".sys", ".prg")


def task_files(directory: str | Path) -> list[Path]:
    """The module files of a task directory (every .mod, .modx, .sys and .prg in it, and in its
    PROGMOD and SYSMOD folders as a RobotStudio backup lays them out), system modules first."""
    root = Path(directory)
    files = [p for p in sorted(root.rglob("*")) if p.is_file() and p.suffix.lower() in TASK_SUFFIXES]
    return sorted(files, key=lambda p: (p.suffix.lower() != ".sys", str(p)))


def load_task(paths: list[str | Path]) -> n.Task:
    """Read and parse the modules of one task (raises LexError/ParseError)."""
    return n.Task([load_program(p) for p in paths])


class Controller:
    def __init__(self, program: n.Module | n.Task, host: Host, entry: str = "main",
                 on_event: Callable[[dict], None] | None = None, step: float | None = None,
                 autostart: bool = True, loop_budget: int = DEFAULT_LOOP_BUDGET,
                 answers: list[str] | None = None, cycles: int = 1, infer_signals: bool = False):
        """`loop_budget`: how many loop iterations that consume no time the program may run in one
        tick before it hands control back (until the next tick). `step`: for event-driven runners,
        the time of the next tick after a loop used up its budget (`next_wake_ns` reports it); the
        loop goes on at whichever tick comes first. With None (a binding ticking at a fixed rate)
        it goes on at the next tick."""
        self.program = program
        self.host = host
        self.on_event = on_event
        self.step_ns = to_ns(step) if step else None
        signals = {s.name.lower(): s for s in host.signals()}
        self.checker = check(program, signals, infer_signals=infer_signals)
        routine = next((r for r in program.routines if r.key == entry.lower() and not r.local), None)
        if routine is None:
            names = ", ".join(r.name for r in program.routines) or "none"
            raise CheckError(f"no routine named '{entry}' to start from (routines: {names})", None)
        if routine.kind != "PROC" or any(not p.optional for p in routine.params):  # (a TRAP is no entry either)
            raise CheckError(f"the entry routine {routine.name} must be a PROC without parameters", routine.span)
        self.entry = routine.name
        self.interp = Interpreter(program, host, self._emit, loop_budget=loop_budget, answers=answers)
        self.cycles = max(1, int(cycles))  # ExitCycle, or the entry routine's end, starts the next cycle
        self.cycle = 0
        self.now = 0
        self.state = STOPPED
        self.end_reason: str | None = None
        self.error: RapidError | None = None
        self.wait: Wait | None = None
        self._gen = None
        self._ended_reported = False
        self._started = False
        if autostart:
            self.start()

    # ---- control ---------------------------------------------------------------------------------
    def start(self) -> None:
        """(Re)start from the entry routine; VAR data are re-initialised, PERS data kept."""
        if self._gen is not None:
            self._gen.close()
        self.state, self.end_reason, self.error, self.wait = RUNNING, None, None, None
        self._ended_reported = False
        self._gen = None
        self.cycle = 0

    def stop(self) -> None:
        """Halt the program where it is (resume() continues, start() restarts)."""
        if self.state in (RUNNING, WAITING):
            self.state, self.end_reason = STOPPED, "stop"

    def resume(self) -> None:
        """Continue after stop() or a Stop instruction."""
        if self.state == STOPPED and self._gen is not None:
            if self.wait is not None and self.wait.kind == "stop":
                self.wait = None
            self.state, self.end_reason = RUNNING, None
            self._ended_reported = False

    @property
    def finished(self) -> bool:
        """Nothing more will happen without start()/resume(): ended, stopped or failed, no pulse pending."""
        return self.state in (STOPPED, COMPLETED, ERROR) and not self.interp.pulses

    # ---- time ------------------------------------------------------------------------------------
    def tick(self, now: float) -> None:
        self.tick_ns(to_ns(now))

    def tick_ns(self, now: int) -> None:
        self.now = now
        self.interp.now = now
        self.interp.apply_pulses()
        if self.state in (RUNNING, WAITING):
            self._run()
        self._report_end()

    def next_wake_ns(self) -> int | None:
        """The earliest time the program or a pulse needs a tick, or None (only a signal change can
        wake it)."""
        times = [p[0] for p in self.interp.pulses]
        due = self.interp.interrupts.next_due()
        if due is not None and self.state in (RUNNING, WAITING):
            times.append(due)
        if self.state == RUNNING:
            times.append(self.now)
        elif self.state == WAITING and self.wait is not None and self.wait.at is not None:
            times.append(self.wait.at)
        return min(times) if times else None

    # ---- internals -------------------------------------------------------------------------------
    def _emit(self, event: dict) -> None:
        if self.on_event is not None:
            self.on_event({"t": round(self.now / NS, 6), **event})

    def _ready(self, w: Wait) -> bool:
        if self.interp.interrupts.pending and w.kind != "stop":
            return True  # a TRAP runs while the program waits
        if w.kind in ("time", "poll", "io", "pace"):
            return self.now >= (w.at or 0)
        if w.kind == "step":
            return True  # a loop that used up its budget goes on at the next tick, whenever it comes
        if w.kind == "stop":
            return False
        return True  # signal, motion: re-evaluate on every tick

    def _run(self) -> None:
        while True:
            try:
                if self._gen is None:
                    self.interp.init_data(keep_pers=self._started)
                    self._started = True
                    self._gen = self.interp.run(self.entry)
                self.interp.interrupts.poll()
                if self.wait is not None and not self._ready(self.wait):
                    self.state = WAITING
                    self.interp.suspensions += 1
                    return
                # a new tick: a new loop budget, a small one for a loop that used up the last tick's
                polling = self.wait is not None and self.wait.kind in ("step", "pace")
                self.interp.spins = 0
                self.interp.polling = polling
                self.interp.tick_budget = min(self.interp.loop_budget, POLL_BUDGET) if polling else \
                    self.interp.loop_budget
                while True:
                    self.wait = None
                    w = next(self._gen)
                    if w.kind == "step" and self.step_ns:
                        w.at = self.now + self.step_ns
                    self.wait = w
                    if w.kind == "stop":
                        self.state, self.end_reason = STOPPED, "stop"
                        return
                    if w.kind in ("time", "poll", "io", "pace") and self._ready(w):
                        continue
                    self.state = WAITING
                    self.interp.suspensions += 1
                    return
            except StopIteration:
                if self._next_cycle():
                    continue
                self.state, self.end_reason = COMPLETED, "completed"
            except ExitCycleSignal:
                if self._next_cycle():
                    continue
                self.state, self.end_reason = COMPLETED, "exit_cycle"
            except ExitSignal:
                self.state, self.end_reason = COMPLETED, "exit"
            except (Fatal, Propagate) as e:
                self._fail(e.error)
            except ExecError as e:
                self._fail(e)
            except RecursionError:
                self._fail(ExecError("routine calls nested too deeply (endless recursion?)", None, 0))
            self._gen = None if self.state == ERROR else self._gen
            if self.state in (COMPLETED, ERROR):
                self.interp.close_sockets()
            return

    def _next_cycle(self) -> bool:
        """Start the entry routine again, at once (data keep their values), when cycles remain."""
        self.cycle += 1
        if self.cycle >= self.cycles:
            return False
        self._gen = self.interp.run(self.entry)
        self.wait = None
        return True

    def _fail(self, err: ExecError) -> None:
        self.state, self.error, self.wait = ERROR, err, None
        self._report_end()

    def _report_end(self) -> None:
        """The last event, once the program has ended (completed, EXIT, Stop, an error) and the
        pulses it started are over: the I/O system finishes a running PulseDO (and a pending SetDO
        \\SDelay) after the program ends, as a real controller's does, so their edges come first,
        at their own times, and the end or error event last, at the time of the last edge."""
        if self._ended_reported or self.interp.pulses or self.state not in (STOPPED, COMPLETED, ERROR):
            return
        self._ended_reported = True
        if self.state == ERROR:
            span = self.error.span if self.error else None
            self._emit({"type": "error", "line": span.line if span else 0,
                        "message": self.error.message if self.error else ""})
        else:
            self._emit({"type": "end", "reason": self.end_reason or "completed"})
