"""Offline runs: a program against an in-memory host, with simulated time advanced from event to
event (a WaitTime's end, a WaitUntil poll, a `--set` change, a pulse edge). Nothing waits on the
wall clock.

Loops that consume no time run up to the controller's loop budget per tick (10 000 iterations);
a loop that uses it up goes on at the next tick: one `step` (0.012 s) later, or earlier at a
`--set` change or a pulse edge, so `WHILE di1 = 0 DO ENDWHILE` leaves at exactly the time di1 is
set. A busy loop that changed nothing in a whole tick (no assignment, no output, no loop variable,
no clock read) and ended it at the same loop would do exactly the same at every tick until an
input changes, so the runner skips straight to the next `--set`, pulse edge or time limit.

`--set` changes at time T are applied before the program runs at T.

Without an I/O configuration (`infer_signals`: the signals are the program's own guesses) nothing
drives the inputs, so a wait that nothing scheduled can end ends the run, reason "blocked" (the
trace names the wait and its line): a dry run up to where the program waits for the cell. With an
I/O configuration it is the runtime error "waits forever".

Pulses outlive the program. On a real controller the I/O system times a PulseDO, so a pulse that
is still running when the program ends (completes, EXITs, executes Stop, or fails with a runtime
error) still ends at its time and the output goes back to where it was; a pending SetDO \\SDelay
is applied too. The run therefore goes on until those edges are written, and the trace's last line,
`end` or `error`, comes after them at the time of the last edge: `t` never goes backwards and the
end line is always last. So `PulseDO \\PLength:=1, do1; WaitTime 0.3; EXIT;` traces do1=1 at 0,
do1=0 at 1.0 and `{"t": 1.0, "type": "end", "reason": "exit"}`; the program's own last event (here
none after 0.3) tells when the program itself ended. A time limit cuts everything, pending edges
included. `Outcome.t` is the end line's time.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from twin.core.defaults import DEFAULT_STEP

from . import nodes as n
from .controller import DEFAULT_LOOP_BUDGET, ERROR, WAITING, Controller
from .errors import ExecError
from .host import InMemoryHost, SignalInfo
from .interpreter import NS, to_ns


@dataclass(frozen=True)
class SignalChange:
    """`--set NAME=VALUE@T`: set signal `name` to `value` at `t` seconds."""

    name: str
    value: float
    t: float = 0.0


@dataclass
class Outcome:
    reason: str  # completed, exit, exit_cycle, stop, time_limit, blocked, error
    t: float
    error: ExecError | None = None
    host: InMemoryHost | None = None
    events: list[dict] = field(default_factory=list)
    waiting: tuple = ()  # blocked: (what it waits for, its Span)


DEFAULT_TIME_LIMIT = 3600.0


def run_offline(module: n.Module | n.Task, signals: list[SignalInfo], changes: list[SignalChange] = (),
                entry: str = "main", max_time: float | None = None, step: float = DEFAULT_STEP,
                on_event: Callable[[dict], None] | None = None,
                default_limit: float = DEFAULT_TIME_LIMIT, loop_budget: int = DEFAULT_LOOP_BUDGET,
                answers: list[str] | None = None, cycles: int = 1, infer_signals: bool = False,
                host=None, grid: float | None = None) -> Outcome:
    """Run `module` from `entry` until it ends, fails or `max_time` passes. Raises CheckError for
    static errors (nothing has run then).

    `host`: a host other than the in-memory one (a station's, offline_cell.py; its `bind_clock` gets the
    controller's clock). `grid`: tick only at multiples of it (s), as a station's controller is ticked once
    per simulation step, so waits end at the same ticks as in the cell.

    Without `max_time`, a program that waits for something nothing scheduled can change is a
    runtime error ("waits forever"), and one that keeps running ends at `default_limit`."""
    events: list[dict] = []

    def emit(ev: dict) -> None:
        events.append(ev)
        if on_event is not None:
            on_event(ev)

    signals = list(signals)
    if infer_signals:  # no I/O configuration: the signals the program uses, as the checker infers them
        from .checker import check

        signals += check(module, {s.name.lower(): s for s in signals}, infer_signals=True).inferred
    if host is None:
        host = InMemoryHost(signals)
    names = {s.name.lower(): s.name for s in signals}
    pending = sorted(((to_ns(c.t), i, c) for i, c in enumerate(changes)), key=lambda x: (x[0], x[1]))
    ctl = Controller(module, host, entry, on_event=emit, step=grid or step, loop_budget=loop_budget,
                     answers=answers, cycles=cycles)
    if hasattr(host, "bind_clock"):
        host.bind_clock(lambda: ctl.now / NS)
    grid_ns = to_ns(grid) if grid else None
    limit = None if max_time is None else to_ns(max_time)
    fallback = to_ns(default_limit)

    def apply(now: int) -> None:
        while pending and pending[0][0] <= now:
            _, _, c = pending.pop(0)
            host.set_input(names[c.name.lower()], c.value)

    def tick(now: int) -> bool:
        """Tick the controller; True when it only went round a loop that changed nothing."""
        before, changes_before = ctl.wait, ctl.interp.changes
        ctl.tick_ns(now)
        after = ctl.wait
        return (ctl.state == WAITING and before is not None and after is not None and before.kind == "step"
                and after.kind == "step" and after.span == before.span and after.what == before.what
                and ctl.interp.changes == changes_before)

    now = 0
    apply(now)
    idle = tick(now)
    while not ctl.finished:
        # an idle loop: only an input or a pulse can matter
        wake = min((p[0] for p in ctl.interp.pulses), default=None) if idle else ctl.next_wake_ns()
        times = [t for t in (wake, pending[0][0] if pending else None) if t is not None]
        if idle and not times:
            now = limit if limit is not None else fallback
            break
        if not times:
            if limit is not None:
                now = limit
                break
            w = ctl.wait
            what = w.what if w else "the program"
            if infer_signals:  # no I/O configuration: nothing drives the inputs, the dry run ends here
                ctl.now = now
                emit({"t": round(now / NS, 6), "type": "end", "reason": "blocked", "waiting": what,
                      "line": w.span.line if w and w.span else 0})
                return Outcome("blocked", now / NS, None, host, events, (what, w.span if w else None))
            err = ExecError(f"{what} waits forever: nothing scheduled can change what it waits for "
                            f"(give a --set for it, or --max-time)", w.span if w else None, 0)
            ctl.now = now
            ctl._fail(err)
            return Outcome("error", now / NS, err, host, events)
        nxt = max(min(times), now + 1)
        if grid_ns:  # the next tick of the cell's controller at or after it
            nxt = -(-nxt // grid_ns) * grid_ns
        end = limit if limit is not None else fallback
        if nxt > end:
            now = end
            break
        now = nxt
        apply(now)
        idle = tick(now)
    else:
        if ctl.state == ERROR:
            return Outcome("error", now / NS, ctl.error, host, events)  # type: ignore[arg-type]
        return Outcome(ctl.end_reason or "completed", now / NS, None, host, events)
    ctl.now = now
    emit({"t": round(now / NS, 6), "type": "end", "reason": "time_limit"})
    return Outcome("time_limit", now / NS, None, host, events)
