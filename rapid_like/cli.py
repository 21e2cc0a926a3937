"""`rapid`: run or check a RAPID program offline.

    rapid run MODULE... [--task DIR] [--data FILE.sys]... [--entry NAME] [--io TYPE:NAME,...]...
                        [--set NAME=VALUE[@T]]... [--answer VALUE]... [--cycles N]
                        [--max-time T] [--step S] [--loop-budget N] [--trace]
    rapid check MODULE... [--task DIR] [--data FILE.sys]... [--io TYPE:NAME,...]...

A task is every module given (`A.mod B.mod user.sys`), those of `--task DIR` (its .mod, .modx,
.sys and .prg files) and the `--data` files (modules that declare the station data a program
expects: tooldata, wobjdata, robtargets). Global data, routines and RECORD types of one module are
seen by all; LOCAL ones only in their own module. The USER module's clock1, reg1..reg5 and tool0,
wobj0, load0 are predefined.

Without any --io the I/O configuration is taken from the program: a name used as a signal (SetDO x,
WaitDI x, DOutput(x), ... or a name starting with di/do/ai/ao/gi/go) is a signal of that kind, and
`rapid check` says so. `rapid check` lists, as warnings with FILE:LINE, everything the program asks
for that the simulation only approximates (zones, VelSet, path control, ...).
`--answer` values answer the FlexPendant dialogs (TPReadFK: the key's number or text; TPReadNum: a
number; UIMessageBox: a button such as resYes or its number), one per dialog, in order.

`--io` plays the controller's I/O configuration (types DI, DO, AI, AO, GI, GO). Without --trace,
TPWrite lines go to stdout; with --trace every observable event is one JSON object per line.
Errors go to stderr as `FILE:LINE:COL: error: message` with the source line and a caret.
Without --max-time a run that is still going at 3600 simulated seconds ends there (time_limit),
and a program waiting for a signal that nothing scheduled can change is an error. A PulseDO still
running when the program ends (or stops, or fails) is completed by the I/O system: its edge is
traced at its time and the end (or error) line comes last, at the time of that edge. Exit status:
0 for a run that ends normally (completed, exit, stop, time_limit), 65 for a syntax or static
error, 70 for a runtime error, 66 when the file cannot be read, 2 for a usage error.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import nodes as n
from .controller import DEFAULT_LOOP_BUDGET, read_source, task_files
from .errors import RapidError
from .host import SIGNAL_KINDS, SignalInfo
from .offline import DEFAULT_STEP, DEFAULT_TIME_LIMIT, SignalChange, run_offline
from .parser import parse

EX_OK, EX_USAGE, EX_DATAERR, EX_NOINPUT, EX_SOFTWARE = 0, 2, 65, 66, 70


from twin.core.errors import UsageError  # noqa: E402  (the project's one: a TwinError)


def parse_io(items: list[str]) -> list[SignalInfo]:
    out: list[SignalInfo] = []
    seen: set[str] = set()
    for item in items:
        for part in filter(None, (p.strip() for p in item.split(","))):
            if ":" not in part:
                raise UsageError(f"--io {part!r}: expected TYPE:NAME, e.g. DI:diPartHeld")
            kind, name = (x.strip() for x in part.split(":", 1))
            kind = kind.upper()
            if kind not in SIGNAL_KINDS:
                raise UsageError(f"--io {part!r}: unknown signal type {kind!r} (use {', '.join(SIGNAL_KINDS)})")
            if not name or not (name[0].isalpha()) or not all(c.isalnum() or c == "_" for c in name):
                raise UsageError(f"--io {part!r}: {name!r} is not a valid signal name")
            if name.lower() in seen:
                raise UsageError(f"--io: signal {name} is configured twice")
            seen.add(name.lower())
            out.append(SignalInfo(name, kind))
    return out


def parse_set(items: list[str], signals: list[SignalInfo]) -> list[SignalChange]:
    known = {s.name.lower(): s for s in signals}
    out = []
    for item in items:
        if "=" not in item:
            raise UsageError(f"--set {item!r}: expected NAME=VALUE[@T]")
        name, rest = (x.strip() for x in item.split("=", 1))
        t = 0.0
        if "@" in rest:
            rest, ts = (x.strip() for x in rest.split("@", 1))
            try:
                t = float(ts)
            except ValueError:
                raise UsageError(f"--set {item!r}: time {ts!r} is not a number") from None
            if t < 0:
                raise UsageError(f"--set {item!r}: the time must be >= 0")
        words = {"true": 1.0, "false": 0.0, "high": 1.0, "low": 0.0}
        try:
            value = words[rest.lower()] if rest.lower() in words else float(rest)
        except ValueError:
            raise UsageError(f"--set {item!r}: value {rest!r} is not a number") from None
        if name.lower() not in known:
            raise UsageError(f"--set {item!r}: {name} is not a configured signal (configure it with --io)")
        sig = known[name.lower()]
        if sig.kind in ("DI", "DO") and value not in (0.0, 1.0):
            raise UsageError(f"--set {item!r}: a digital signal is 0 or 1")
        out.append(SignalChange(sig.name, value, t))
    return out


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rapid", description="Run RAPID programs against in-memory signals.")
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a program offline")
    chk = sub.add_parser("check", help="parse and check a program without running it")
    for sp in (run, chk):
        sp.add_argument("program", nargs="*", help="the task's modules (.mod, .modx, .sys, .prg)")
        sp.add_argument("--task", metavar="DIR", help="a task directory: every .mod/.modx/.sys/.prg in it")
        sp.add_argument("--data", action="append", default=[], metavar="FILE.sys",
                        help="a module of station data the program expects (tooldata, wobjdata, robtargets); "
                             "repeatable")
        sp.add_argument("--io", action="extend", nargs="+", default=[], metavar="TYPE:NAME,...",
                        help="configure I/O signals, e.g. DI:diPartHeld,AO:aoWidth (repeatable)")
        sp.add_argument("--entry", default=None, help="routine to start from (default: main, or the station's entry)")
        sp.add_argument("--station", metavar="DIR",
                        help="a station (folder or station.toml): its controller's I/O configuration and, for a "
                             "run, its robot (arm, tool, start pose, limits), moved by the cell's motion planner "
                             "on the station's step; without modules, the station's own program")
    run.add_argument("--set", action="extend", nargs="+", default=[], metavar="NAME=VALUE[@T]",
                     help="set a signal at simulated time T seconds (default 0); repeatable")
    run.add_argument("--max-time", type=float, default=None, metavar="T",
                     help="end the run at simulated time T, reason time_limit (without it: a program "
                          f"still running at {DEFAULT_TIME_LIMIT:g} s ends there, and one that waits for "
                          "a signal nothing changes is an error)")
    run.add_argument("--step", type=float, default=DEFAULT_STEP, metavar="S",
                     help="the controller's tick: a loop that used up its loop budget goes on S seconds "
                          f"later, or earlier at a --set change or a pulse edge (default {DEFAULT_STEP:g}, as a "
                          "station's step)")
    run.add_argument("--loop-budget", type=int, default=DEFAULT_LOOP_BUDGET, metavar="N",
                     help="loop iterations that consume no time run per tick before the loop waits for "
                          f"the next tick (default {DEFAULT_LOOP_BUDGET})")
    run.add_argument("--answer", action="append", default=[], metavar="VALUE",
                     help="the answer to the next FlexPendant dialog (TPReadFK, TPReadNum, UIMessageBox, ...); "
                          "repeatable, used in order")
    run.add_argument("--cycles", type=int, default=1, metavar="N",
                     help="run the entry routine N times, as continuous mode does; ExitCycle ends a cycle "
                          "(default 1)")
    run.add_argument("--trace", action="store_true",
                     help="print every event as one JSON object per line; the last line is the end (or "
                          "error) line, after the edges of any PulseDO still running when the program "
                          "ended (the I/O system completes them), at the time of the last edge")
    return p


def _program_first(argv: list[str]) -> list[str]:
    """Put the modules right after the sub-command, so `--io A B` lists never swallow them."""
    if len(argv) < 2 or argv[0] not in ("run", "check"):
        return argv
    rest = argv[1:]
    modules, others = [], []
    for i, a in enumerate(rest):
        after_data = i > 0 and rest[i - 1] in ("--data", "--task")
        if not a.startswith("-") and not after_data and a.lower().endswith((".mod", ".modx", ".prg", ".sys")):
            modules.append(a)
        else:
            others.append(a)
    return [argv[0], *modules, *others]


def main(argv: list[str] | None = None) -> int:
    """`rapid check|run ...`; any other error of the project's (a TwinError) is one line and exit status 2."""
    from twin.core.errors import TwinError, one_line

    try:
        return _main(argv)
    except TwinError as exc:
        print(f"rapid: {one_line(exc)}", file=sys.stderr)
        return 2


def _main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    args = build_parser().parse_args(_program_first(argv))
    out, err = sys.stdout, sys.stderr
    paths = list(args.program)
    station = None
    if args.station:
        from twin.core.errors import TwinError
        from twin.core.station import load_station

        try:
            station = load_station(args.station)
        except (TwinError, OSError) as e:
            print(f"rapid: error: --station {args.station}: {e}", file=err)
            return EX_USAGE
        if station.controller is None:
            print(f"rapid: error: --station {args.station}: the station has no [controller]", file=err)
            return EX_USAGE
        if not paths and not args.task:
            paths = [str(station.controller.program), *(str(m) for m in station.controller.modules)]
            if args.entry is None:
                args.entry = station.controller.entry
            if args.command == "run" and not args.answer:
                args.answer = list(station.controller.answers)
    if args.entry is None:
        args.entry = "main"
    if args.task:
        if not Path(args.task).is_dir():
            print(f"{args.task}: error: --task needs a directory", file=err)
            return EX_NOINPUT
        paths += [str(p) for p in task_files(args.task)]
    paths += args.data
    if not paths:
        print("rapid: error: give the program's modules (or --task DIR)", file=err)
        return EX_USAGE
    sources: dict[str, str] = {}
    for p in paths:
        try:
            sources[p] = read_source(p)
        except OSError as e:
            print(f"{p}: error: cannot read the program: {e.strerror or e}", file=err)
            return EX_NOINPUT
    first = paths[0]
    try:
        if args.command == "run" and args.cycles < 1:
            raise UsageError("--cycles must be >= 1")
        signals = parse_io(args.io)
        if station is not None:
            from .offline_cell import station_signals

            configured = {s.name.lower() for s in signals}
            signals += [s for s in station_signals(station) if s.name.lower() not in configured]
        changes = parse_set(args.set, signals) if args.command == "run" else []
        if args.command == "run":
            if args.max_time is not None and args.max_time < 0:
                raise UsageError("--max-time must be >= 0")
            if args.step <= 0:
                raise UsageError("--step must be > 0")
            if args.loop_budget < 1:
                raise UsageError("--loop-budget must be >= 1")
    except UsageError as e:
        print(f"rapid: error: {e}", file=err)
        return EX_USAGE

    def report(e: RapidError) -> None:
        text = e.render(sources.get(e.span.file) if e.span else None)
        if e.span is None:
            text = f"{first}: {text}"
        print(text, file=err)

    infer = not args.io and station is None
    try:
        program = n.Task([parse(sources[p], p) for p in paths])
        if len(program.modules) == 1:
            program = program.modules[0]  # type: ignore[assignment]
        if args.command == "check":
            from .checker import check
            from .controller import Controller
            from .host import InMemoryHost
            checker = check(program, {s.name.lower(): s for s in signals}, infer_signals=infer)
            routines = [r for r in checker.task.routines if not r.local]
            if args.entry != "main" or any(r.key == "main" for r in routines):
                Controller(program, InMemoryHost(signals + checker.inferred), args.entry, autostart=False)
            else:  # a library module: fine to check, but no task can start from it alone
                span = checker.task.span
                checker.warnings.insert(0, (span, "no routine main: the task cannot start from these modules "
                                                  "(add the module with main, or give --entry)"))
            for span, message in sorted(checker.warnings, key=lambda w: (w[0].file, w[0].line, w[0].col)):
                print(f"{span.file}:{span.line}:{span.col}: warning: {message}", file=out)
            return EX_OK

        def on_event(ev: dict) -> None:
            if args.trace:
                out.write(json.dumps(ev) + "\n")
            elif ev["type"] == "print":
                out.write(ev["text"] + "\n")
            elif ev["type"] == "errlog":
                out.write(f"[event log, {ev['level']}] {ev['header']}: {ev['reason']}\n")

        host, grid = None, None
        if station is not None:
            from .offline_cell import OfflineStationHost

            host, grid = OfflineStationHost(station, extra=[s for s in signals if s.name not in
                                                            {i.name for i in station.controller.io}]), station.step
        outcome = run_offline(program, signals, changes, args.entry, args.max_time, args.step, on_event,
                              loop_budget=args.loop_budget, answers=args.answer, cycles=args.cycles,
                              infer_signals=infer, host=host, grid=grid)
    except RapidError as e:
        report(e)
        return EX_DATAERR
    out.flush()
    moves = getattr(outcome.host, "moves", None) if station is None else None
    if moves:  # no arm: say once that the motions took no time (docs/rapid.md, "Offline without a station")
        span = moves[0].span
        where = f"{span.file}:{span.line}:{span.col}" if span else first
        print(f"{where}: note: {moves[0].instr} and the motions after it take no time without --station (there is "
              f"no arm to plan them; in a polling loop a motion takes distance / v_tcp): give --station DIR for "
              f"the cell's timing", file=err)
    if outcome.reason == "blocked":
        what, span = outcome.waiting
        where = f"{span.file}:{span.line}:{span.col}" if span else first
        print(f"{where}: note: {what} waits for an input that nothing drives; the run ends here at "
              f"{outcome.t:g} s (configure the I/O with --io and give --set to go on)", file=err)
    if outcome.error is not None:
        report(outcome.error)
        return EX_SOFTWARE
    return EX_OK
