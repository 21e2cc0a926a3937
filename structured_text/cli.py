"""`plc check` and `plc run FILE.st --offline`: Structured Text from the command line, no twin needed.

    plc check FILE.st [FILE.st ...]
    plc run FILE.st [...] --offline --for SECONDS [--cycle MS] [--set NAME=VALUE[@T]]...
                          [--watch NAME,...] [--warm-restart T]... [--loop-budget N] [--trace]

The files make one PLC program (POUs, TYPEs, globals and at most one CONFIGURATION, in any file).
Scan k runs at t = k x cycle; `--cycle` is in milliseconds (default 10; with a CONFIGURATION, the
greatest common divisor of its task intervals). `--for S` runs the scans with t < S. `--set` makes
a variable (or a located input) take VALUE at the first scan at or after T seconds (default 0),
before that scan runs; `--warm-restart T` power-cycles the PLC before the scan at T (RETAIN
variables keep their values). With --trace, every watched variable (default: all elementary
variables of the program instances) gives one JSON line on scan 0 and whenever it changed:
`{"t": 0.03, "scan": 3, "name": "cnt", "value": 3}`.

Errors go to stderr as `FILE:LINE:COL: error: MESSAGE`. Exit status: 0 ok, 65 a syntax or static
error, 70 a runtime error (the PLC went to STOP), 66 a file that cannot be read, 2 a usage error.
"""
from __future__ import annotations

import argparse
import json
import math
import re
import sys

from .errors import PlcFault, StError
from .lexer import parse_duration

EX_OK, EX_USAGE, EX_DATAERR, EX_NOINPUT, EX_SOFTWARE = 0, 2, 65, 66, 70


from twin.core.errors import UsageError  # noqa: E402  (the project's one: a TwinError)


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):
        self.exit(EX_USAGE, f"{self.prog}: error: {message}\n")


def is_st_file(arg: str) -> bool:
    return arg.lower().endswith(".st")


def _load_files(paths: list[str]):
    from .runtime import read_source
    sources = {}
    for p in paths:
        try:
            sources[p] = read_source(p)
        except (OSError, UnicodeDecodeError) as exc:
            raise FileNotFoundError(f"{p}: cannot read: {exc}") from None
    return sources


def check_main(argv: list[str]) -> int:
    ap = _Parser(prog="plc check", description="Check Structured Text files: syntax, names, types.")
    ap.add_argument("files", nargs="+", metavar="FILE.st")
    args = ap.parse_args(argv)
    from .runtime import compile_files
    try:
        sources = _load_files(args.files)
        compile_files(args.files, sources)
    except FileNotFoundError as exc:
        print(f"plc: error: {exc}", file=sys.stderr)
        return EX_NOINPUT
    except StError as exc:
        print(exc.headline(), file=sys.stderr)
        return EX_DATAERR
    return EX_OK


def seconds(text: str) -> float:
    """`0.5`, `0.5s`, `500ms`, `T#500ms` -> seconds."""
    t = text.strip()
    if "#" in t:
        t = t.split("#", 1)[1]
    try:
        return float(t)
    except ValueError:
        pass
    ns = parse_duration(t)
    if ns is None:
        raise UsageError(f"{text!r} is not a time (seconds, or e.g. 500ms, T#1s)")
    return ns / 1e9


def run_main(argv: list[str]) -> int:
    ap = _Parser(prog="plc run", description="Run Structured Text offline: simulated time, no twin.")
    ap.add_argument("files", nargs="+", metavar="FILE.st")
    ap.add_argument("--offline", action="store_true", help="run without a twin (without it, `plc run` binds to one)")
    ap.add_argument("--for", dest="duration", required=False, metavar="SECONDS", help="simulated seconds to run")
    ap.add_argument("--cycle", metavar="MS", default=None,
                    help="scan cycle in milliseconds (default 10; with a CONFIGURATION the GCD of its task intervals)")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="NAME=VALUE[@T]")
    ap.add_argument("--watch", action="append", default=[], metavar="NAME,...")
    ap.add_argument("--warm-restart", dest="restarts", action="append", default=[], metavar="T",
                    help="a warm restart (power cycle, RETAIN kept) before the scan at T seconds")
    ap.add_argument("--loop-budget", type=int, default=None, metavar="N",
                    help="loop iterations per scan before the scan counts as endless (default 1000000)")
    ap.add_argument("--trace", action="store_true", help="JSON lines of the watched variables' changes")
    args = ap.parse_args(argv)
    try:
        return _run(args)
    except UsageError as exc:
        print(f"plc run: error: {exc}", file=sys.stderr)
        return EX_USAGE
    except FileNotFoundError as exc:
        print(f"plc: error: {exc}", file=sys.stderr)
        return EX_NOINPUT


def _run(args) -> int:
    from .runtime import DEFAULT_LOOP_BUDGET, Plc, compile_files
    if not args.offline:
        raise UsageError("this runs Structured Text offline: add --offline (simulated time, no twin)")
    if args.duration is None:
        raise UsageError("--for SECONDS is required")
    duration = seconds(args.duration)
    if not duration > 0:
        raise UsageError(f"--for {args.duration}: the run's length is greater than 0 s")
    sources = _load_files(args.files)
    try:
        compiled = compile_files(args.files, sources)
    except StError as exc:
        print(exc.headline(), file=sys.stderr)
        return EX_DATAERR
    plc = Plc(compiled, args.loop_budget or DEFAULT_LOOP_BUDGET)
    if args.cycle is not None:
        try:
            cycle_ms = float(args.cycle)
        except ValueError:
            raise UsageError(f"--cycle {args.cycle!r}: milliseconds, e.g. 10") from None
        if cycle_ms <= 0:
            raise UsageError("--cycle must be greater than 0 ms")
        cycle_ns = round(cycle_ms * 1e6)
    else:
        cycle_ns = plc.base_cycle() or 10_000_000
    # the scans
    n_scans = max(0, math.ceil(round(duration * 1e9) / cycle_ns - 1e-9))
    sets = []
    for item in args.sets:
        name, sep, rest = item.partition("=")
        if not sep or not name.strip():
            raise UsageError(f"--set {item!r}: expected NAME=VALUE[@T]")
        value, at, when = rest.rpartition("@") if "@" in rest else (rest, "", "0")
        t_ns = round(seconds(when) * 1e9)
        try:
            ref = plc.resolve(name.strip())
        except KeyError as exc:
            raise UsageError(f"--set {name.strip()}: {exc.args[0]}") from None
        sets.append((t_ns, len(sets), ref, value.strip()))
    sets.sort(key=lambda s: (s[0], s[1]))
    restarts = sorted(round(seconds(r) * 1e9) for r in args.restarts)
    watch = []
    names = [w.strip() for item in args.watch for w in item.split(",") if w.strip()]
    if not names:
        names = default_watch(plc)
    for name in names:
        try:
            watch.append((name, plc.resolve(name)))
        except KeyError as exc:
            raise UsageError(f"--watch {name}: {exc.args[0]}") from None
    from .runtime import coerce
    for t_ns, _, ref, value in sets:
        try:
            coerce(ref.type, value)
        except ValueError as exc:
            raise UsageError(f"--set {ref.name}={value}: {exc}") from None
    last: dict[str, object] = {}
    out = sys.stdout
    si = ri = 0
    for k in range(n_scans):
        now = k * cycle_ns
        while ri < len(restarts) and restarts[ri] <= now:
            plc.warm_restart()
            ri += 1
        while si < len(sets) and sets[si][0] <= now:
            _, _, ref, value = sets[si]
            ref.set(value)
            si += 1
        try:
            plc.scan_ns(now)
        except PlcFault as exc:
            out.flush()
            print(exc.headline(), file=sys.stderr)
            return EX_SOFTWARE
        if args.trace:
            t = now / 1e9
            for name, ref in watch:
                v = ref.json()
                if k == 0 or last.get(name, _MISSING) != v or type(last.get(name)) is not type(v):
                    last[name] = v
                    out.write(json.dumps({"t": t, "scan": k, "name": name, "value": v}) + "\n")
    out.flush()
    return EX_OK


_MISSING = object()


def default_watch(plc) -> list[str]:
    """Every elementary variable of every program instance (unqualified when there is one instance), then the
    elementary globals."""
    names = []
    single = len(plc.program.instances) == 1
    for inst in plc.program.instances:
        for s in inst.pou.symbols.values():
            if s.section == "VAR_EXTERNAL" or s.type.kind in ("fb", "program", "array", "struct"):
                continue
            names.append(s.name if single else f"{inst.name}.{s.name}")
    for s in plc.program.globals.values():
        if s.type.kind not in ("fb", "program", "array", "struct") and not s.constant and s.name not in names:
            names.append(s.name)
    return names

