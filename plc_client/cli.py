"""The `plc` command: manual pokes at a running twin server, signals by name in engineering units.

    plc [--host H] [--port P] [--unit-id U] [--map FILE.json | --station DIR] COMMAND
        (without --map or --station: the map the server serves, read from it with function 20)
        read NAME...                      one line per signal: name, value, unit (an enumeration such as
                                          GrippedPart: its index, then its text: `GrippedPart  1  (ring)`)
        write NAME=VALUE...               checked first: one bad name or value and nothing is written;
                                          sim.advance goes last, after the other writes are answered
        watch NAME... [--interval S] [--count N]   a live view (one redrawn line on a terminal)
        run MODULE:NAME [--cycle S] [--seconds S | --scans N] [--speed X]   run PLC logic on a scan cycle
    plc check FILE.st...                  check Structured Text (IEC 61131-3): FILE:LINE:COL errors, exit 65
    plc run FILE.st... --offline --for S [--cycle MS] [--set NAME=VALUE[@T]] [--watch NAMES] --trace
                                          run Structured Text offline in simulated time (docs/plc-st.md);
                                          here --cycle is in milliseconds
        map                               the signals it knows: table, address, type, unit, range, access
        run [--station DIR]               the PLC logic the station names ([plugins] plc_logic)
    plc demo [--station DIR] [OPTIONS]    a station's demo ([plugins] plc_demo in its station.toml; without
                                          --station, the shipped station that has one: the main job)

E.g. a station's gripper PLC against `twin serve STATION --port 5020 --lockstep`:
    plc --station STATION run my_plc.py:gripper_plc

The global options may also follow the command (`plc read axis1 --port 5021`). Data goes to stdout; a
problem is one line on stderr, `plc: error: ...`, with exit status 2 for a user error (unknown name, bad
value, bad map, a map that is not the one the server serves) and 1 when the server cannot be reached or
refuses a request, or when `plc run`'s logic sets an output the server refuses.
"""
from __future__ import annotations

import argparse
import logging
import sys

from twin_app.cli_args import positive_float, positive_int
from twin.core.errors import TwinError, one_line
from twin.frontends.modbus.protocol import DEFAULT_PORT, TLS_PORT

from .checks import check_names, check_value, lookup, range_text
from .client import RegisterMap, Signal, TwinClient
from .errors import ConnectionFailedError, ModbusExceptionError, OutputRefusedError, PlcClientError, ValueTypeError

EXIT_USER, EXIT_CONNECTION = 2, 1
TRUE, FALSE = ("1", "true", "on", "yes", "high"), ("0", "false", "off", "no", "low")


class Parser(argparse.ArgumentParser):
    """argparse with the command's error style: one line on stderr, exit status 2."""

    def error(self, message: str):
        self.exit(EXIT_USER, f"{self.prog}: error: {message} (`{self.prog} --help` tells more)\n")


def _globals(parser: argparse.ArgumentParser, suppress: bool) -> None:
    d = (lambda v: argparse.SUPPRESS) if suppress else (lambda v: v)
    g = parser.add_argument_group("connection and map")
    g.add_argument("--host", default=d("127.0.0.1"), help="the twin server's host (default 127.0.0.1)")
    g.add_argument("--port", type=int, default=d(None), help="its Modbus/TCP port (default 5020; with TLS 802)")
    g.add_argument("--unit-id", type=int, default=d(1), help="the Modbus unit id (default 1)")
    g.add_argument("--timeout", type=float, default=d(3.0), help="s to wait for an answer (default 3)")
    g.add_argument("--tls-cert", metavar="PEM", default=d(None),
                   help="Modbus/TCP Security: connect over TLS with this client certificate (with --tls-key, --tls-ca)")
    g.add_argument("--tls-key", metavar="PEM", default=d(None), help="the client certificate's private key")
    g.add_argument("--tls-ca", metavar="PEM", default=d(None), help="the CA the server's certificate must chain to")
    m = g.add_mutually_exclusive_group()
    m.add_argument("--map", metavar="FILE.json", default=d(None), help="the register map, from `twin map STATION --format json`")
    m.add_argument("--station", metavar="DIR", default=d(None), help="build the register map from this station")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="plc", description="Read, write and watch a twin server's signals by name.")
    _globals(parser, suppress=False)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    p = sub.add_parser("read", help="read signals: one line each, name value unit (enumerations: index, then (text))")
    p.add_argument("names", nargs="+", metavar="NAME")
    _globals(p, suppress=True)
    p.set_defaults(func=cmd_read)
    p = sub.add_parser("write", help="write signals in engineering units: NAME=VALUE (bools: 1/0, true/false, on/off)")
    p.add_argument("assignments", nargs="+", metavar="NAME=VALUE")
    _globals(p, suppress=True)
    p.set_defaults(func=cmd_write)
    p = sub.add_parser("watch", help="a live view of signals, sampled every --interval s")
    p.add_argument("names", nargs="+", metavar="NAME")
    p.add_argument("--interval", type=float, default=0.2, help="s between samples (default 0.2)")
    p.add_argument("--count", type=int, default=None, help="stop after this many samples (default: until Ctrl-C)")
    _globals(p, suppress=True)
    p.set_defaults(func=cmd_watch)
    p = sub.add_parser("run", help="run PLC logic (module:name or file.py:name) on a scan cycle against the server")
    p.add_argument("target", metavar="MODULE:NAME", nargs="?", default=None,
                   help="a logic with .inputs (e.g. a GripSequence), or a function without arguments that returns one "
                   "(package.module:name or file.py:name); default: the one the --station names in its [plugins] plc_logic")
    p.add_argument("--cycle", type=positive_float, default=0.010, help="scan cycle, s (default 0.010)")
    bound = p.add_mutually_exclusive_group()
    bound.add_argument("--seconds", type=positive_float, default=None, help="stop after this much PLC time")
    bound.add_argument("--scans", type=positive_int, default=None, help="stop after this many scans")
    p.add_argument("--speed", type=positive_float, default=None, metavar="X",
                   help="real time: the PLC's clock runs X times the wall clock, to match `twin serve --speed X` "
                        "(default: the server's speed, sim.speed_pct, else 1); no effect in lockstep")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--lockstep", dest="lockstep", action="store_true", default=None,
                      help="the server was started with --lockstep: each scan advances it one cycle (default: when the map has sim.advance)")
    mode.add_argument("--realtime", dest="lockstep", action="store_false", help="pace the scans against the wall clock")
    p.add_argument("--quiet", action="store_true", help="do not print the outputs' changes")
    _globals(p, suppress=True)
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("check", help="check Structured Text files (FILE.st ...): one FILE:LINE:COL line per error, exit 65")
    p.add_argument("files", nargs="+", metavar="FILE.st")
    p.set_defaults(func=cmd_check)
    p = sub.add_parser("map", help="the signals the map knows: table, address, type, unit, range, access")
    _globals(p, suppress=True)
    p.set_defaults(func=cmd_map)
    p = sub.add_parser("demo", add_help=False, help="a station's demo (its station.toml's [plugins] plc_demo); "
                       "without --station, the shipped one: the main job (`plc demo --help` lists its options)")
    p.set_defaults(func=cmd_demo, takes_options=True)
    return parser


def cmd_demo(args) -> int:
    from twin.core.errors import TwinError
    from twin_app.plugins import run_station_demo

    try:
        options = args.demo_options
        if args.station and not any(o == "--station" or o.startswith("--station=") for o in options):
            options = ["--station", args.station, *options]  # `plc --station DIR demo`
        return run_station_demo("plc_demo", options, prog="plc demo", parser_class=Parser, positional=False)
    except TwinError as exc:
        raise UsageError(str(exc)) from None


# -- commands ---------------------------------------------------------------------------------------------
def load_map(args) -> RegisterMap:
    """--map, --station, else the map the server at --host/--port serves (function 20)."""
    if args.map:
        return RegisterMap.from_json(args.map)
    if args.station:
        return RegisterMap.from_station(args.station)
    from .client import fetch_map

    tls = tls_files(args)
    if args.port is None:
        args.port = TLS_PORT if tls is not None else DEFAULT_PORT
    return fetch_map(args.host, args.port, args.unit_id, timeout=args.timeout, tls=tls)


def tls_files(args):
    """TlsFiles from --tls-cert/--tls-key/--tls-ca (all three, or none)."""
    from .client import TlsFiles

    given = [getattr(args, k, None) for k in ("tls_cert", "tls_key", "tls_ca")]
    if not any(given):
        return None
    if not all(given):
        raise UsageError("Modbus/TCP Security needs all of --tls-cert, --tls-key and --tls-ca")
    return TlsFiles(*given)


def connect(args, rmap: RegisterMap) -> TwinClient:
    tls = tls_files(args)
    if args.port is None:
        args.port = TLS_PORT if tls is not None else DEFAULT_PORT
    return TwinClient.connect(args.host, args.port, args.unit_id, map=rmap, timeout=args.timeout, tls=tls)


def cmd_read(args) -> int:
    rmap = load_map(args)
    signals = check_names(rmap, args.names)
    with connect(args, rmap) as client:
        values = client.read(*args.names)
    print_rows([read_row(s, values[s.name]) for s in signals])
    return 0


def read_row(s: Signal, value) -> tuple[str, str, str]:
    """name, value, unit; an enumeration shows the index it has on the wire, its text in the unit column."""
    if s.choices:
        if isinstance(value, str) and value in s.choices:
            return s.name, str(s.choices.index(value)), f"({value or 'none'})"
        return s.name, fmt(value), "(not one of the choices)"
    return s.name, fmt(value), s.unit


def cmd_write(args) -> int:
    rmap = load_map(args)
    values = {}
    for text in args.assignments:
        name, sep, raw = text.partition("=")
        if not sep or not name:
            raise UsageError(f"{text!r}: write takes NAME=VALUE")
        values[name.strip()] = parse_value(lookup(rmap, name.strip()), raw.strip())
    for name, value in values.items():
        check_value(rmap, name, value)
    with connect(args, rmap) as client:
        client.write(values)
    print_rows([(n, fmt(v), rmap[n].unit) for n, v in values.items()])
    return 0


def cmd_watch(args) -> int:
    rmap = load_map(args)
    signals = check_names(rmap, args.names)
    if args.interval <= 0:
        raise UsageError("--interval must be greater than 0")
    if args.count is not None and args.count < 1:
        raise UsageError("--count must be at least 1")
    tty = sys.stdout.isatty()
    with connect(args, rmap) as client:
        if not tty:
            print("t_s  " + "  ".join(s.name + (f"[{s.unit}]" if s.unit else "") for s in signals), flush=True)
        width = 0
        try:
            for t, values in client.poll(args.names, args.interval, args.count):
                cells = [f"{s.name}={fmt(values[s.name])}{(' ' + s.unit) if s.unit else ''}" for s in signals]
                if tty:
                    line = f"t={t:7.2f}s  " + "  ".join(cells)
                    sys.stdout.write("\r" + line.ljust(width))
                    width = max(width, len(line))
                else:
                    sys.stdout.write(f"{t:.3f}  " + "  ".join(fmt(values[s.name]) for s in signals) + "\n")
                sys.stdout.flush()
        except KeyboardInterrupt:
            pass
        finally:
            if tty:
                sys.stdout.write("\n")
    return 0


def load_logic(target: str):
    """`package.module:name` or `path/to/file.py:name`: a logic object, or a factory returning one."""
    import importlib
    import importlib.util

    where, sep, attr = target.rpartition(":")
    if not sep or not where or not attr:
        raise UsageError(f"{target!r}: give MODULE:NAME or FILE.py:NAME")
    try:
        if where.endswith(".py"):
            spec = importlib.util.spec_from_file_location("plc_user_logic", where)
            if spec is None or not spec.loader:
                raise UsageError(f"{where}: cannot load this file")
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(where)
    except (ImportError, OSError) as exc:
        raise UsageError(f"{where}: cannot import: {exc}") from None
    obj = getattr(module, attr, None)
    if obj is None:
        raise UsageError(f"{where} has no {attr!r}")
    if not hasattr(obj, "inputs") and callable(obj):
        obj = obj()
    if not callable(obj) or not hasattr(obj, "inputs"):
        raise UsageError(f"{target}: not a PLC logic (a callable with .inputs, e.g. a GripSequence or an @plc_logic function)")
    return obj


def check_logic_signals(target: str, logic, rmap: RegisterMap) -> None:
    """Every signal the logic reads or writes must be in the map: else one error naming the logic and all
    the missing names (e.g. a logic on generic handshake names against a station whose robot program uses
    its own names)."""
    inputs = [n for n in logic.inputs if n not in rmap]
    outputs = [n for n in getattr(logic, "outputs", ()) if n not in rmap and n not in inputs]
    if not inputs and not outputs:
        return
    which = "the register map" + (f" ({rmap.source})" if rmap.source else "")
    parts = []
    if inputs:
        parts.append(f"reads {', '.join(inputs)}")
    if outputs:
        parts.append(f"writes {', '.join(outputs)}")
    raise UsageError(f"the logic {target} {' and '.join(parts)}, which {which} does not have "
                     "(is it the logic for this station?)")


def station_logic(args) -> str:
    """`plc run` without MODULE:NAME: the PLC logic the station names (`[plugins] plc_logic`), as a reference."""
    from twin.core.errors import TwinError
    from twin.core.station import load_station

    if not args.station:
        raise UsageError("run needs MODULE:NAME (or --station DIR of a station that names its PLC logic)")
    try:
        st = load_station(args.station)
    except TwinError as exc:
        raise UsageError(str(exc)) from None
    ref = st.plugins.get("plc_logic")
    if ref is None:
        raise UsageError(f"{st.file}: names no PLC logic ([plugins] plc_logic): give MODULE:NAME")
    where, sep, attr = ref.rpartition(":")
    if sep and where.endswith(".py"):
        ref = f"{(st.folder / where)}:{attr}"
    return ref


def cmd_run(args) -> int:
    if args.target is None:
        args.target = station_logic(args)
    logic = load_logic(args.target)
    rmap = load_map(args)
    check_logic_signals(args.target, logic, rmap)
    return _run_logic(args, logic, rmap)


def _run_logic(args, logic, rmap: RegisterMap) -> int:
    """Run `logic` on a scan cycle against the server (`plc run`), printing its outputs' changes."""
    from .client import ClientIO
    from .scan import ScanCycle
    from twin.frontends.modbus.register_map import SPEED_PCT

    with connect(args, rmap) as client:
        io = ClientIO(client, lockstep=args.lockstep)
        speed = args.speed
        if speed is None:  # real time: keep pace with the server, as fast as it runs
            pct = client.get(SPEED_PCT) if SPEED_PCT in rmap and not io.lockstep else 0
            speed = pct / 100.0 if pct else 1.0
        plc = ScanCycle(io, logic, cycle=args.cycle, speed=speed)
        how = "lockstep" if not plc.realtime else f"real time x{speed:g}"
        print(f"plc: {args.target} every {args.cycle * 1000:g} ms, {how}, against {args.host}:{args.port}",
              file=sys.stderr, flush=True)
        end = None if args.seconds is None else args.seconds - 1e-9
        try:
            while (args.scans is None or plc.scans < args.scans) and (end is None or plc.time < end):
                before = dict(plc.written)
                plc.scan()
                if not args.quiet:
                    changed = [(k, v) for k, v in plc.written.items()
                               if not isinstance(v, float) and before.get(k, None) != v]
                    if changed:
                        print(f"t={plc.time:8.3f}  " + "  ".join(f"{k}={fmt(v)}" for k, v in changed), flush=True)
        except KeyboardInterrupt:
            pass
        except OutputRefusedError as exc:  # the logic commanded what the process cannot do: stop, say what
            print(f"plc: error: {exc}; the PLC stopped", file=sys.stderr)
            return EXIT_CONNECTION
    if plc.realtime and plc.overruns:
        print(f"plc: {plc.overruns} of {plc.scans} scans overran the {args.cycle * 1000:g} ms cycle", file=sys.stderr)
    return 0


def cmd_check(args) -> int:
    from structured_text.cli import check_main
    return check_main(args.files)


def structured_text_command(argv: list[str]) -> list[str] | None:
    """`plc [globals] run FILE.st ...` or `plc check ...`: the Structured Text runtime's own command line
    (its --cycle is in milliseconds, as IEC tools give task intervals), else None."""
    for i, a in enumerate(argv):
        if a in ("run", "check"):
            rest = argv[i + 1:]
            if a == "check" or any(r.lower().endswith(".st") for r in rest if not r.startswith("-")):
                return [a] + rest
            return None
    return None


def run_st_against_twin(argv: list[str]) -> int:
    """`plc run FILE.st... --port P [--station DIR | --map FILE.json] [--cycle MS] [--for S | --scans N]
    [--lockstep | --realtime]`: a Structured Text PLC against a running twin (`twin serve --layout plc`), its
    located variables bound through the map's device ranges as on a Modbus master PLC (`plc_client.st_io`)."""
    p = Parser(prog="plc run", description="Run a Structured Text PLC against a running twin server (--layout plc).")
    p.add_argument("files", nargs="+", metavar="FILE.st")
    _globals(p, suppress=False)
    p.add_argument("--cycle", type=positive_float, default=10.0, metavar="MS", help="scan cycle in ms (default 10)")
    bound = p.add_mutually_exclusive_group()
    bound.add_argument("--for", dest="seconds", type=positive_float, default=None, metavar="S", help="PLC seconds to run")
    bound.add_argument("--scans", type=positive_int, default=None, help="scans to run")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--lockstep", dest="lockstep", action="store_true", default=None,
                      help="each scan advances the server one cycle (default: when the server runs in lockstep)")
    mode.add_argument("--realtime", dest="lockstep", action="store_false", help="pace the scans against the wall clock")
    p.add_argument("--speed", type=positive_float, default=None, metavar="X", help="real time: X times the wall clock")
    p.add_argument("--quiet", action="store_true", help="do not print the outputs' changes")
    args = p.parse_args([a for a in argv if a != "run"])
    logging.getLogger("pymodbus").setLevel(logging.CRITICAL)
    from structured_text.errors import PlcFault, StError

    from .st_io import StLogic

    try:
        rmap = RegisterMap.from_station(args.station, "plc") if args.station else load_map(args)
        logic = StLogic(args.files, rmap)
    except (ConnectionFailedError, ModbusExceptionError) as exc:
        print(f"plc: error: {exc}", file=sys.stderr)
        return EXIT_CONNECTION
    except StError as exc:
        print(exc.headline(), file=sys.stderr)
        return 65
    except (TwinError, OSError) as exc:
        print(f"plc: error: {exc}", file=sys.stderr)
        return EXIT_USER
    args.target, args.cycle = " ".join(args.files), args.cycle / 1000.0
    try:
        return _run_logic(args, logic, rmap)
    except PlcFault as exc:
        print(exc.headline(), file=sys.stderr)
        return 70
    except (ConnectionFailedError, ModbusExceptionError) as exc:
        print(f"plc: error: {exc}", file=sys.stderr)
        return EXIT_CONNECTION


def check_with_map(argv: list[str]) -> int:
    """`plc check FILE.st... --station DIR | --map FILE.json | --port P`: also every located variable against
    the map's PLC layout, the ranges a Modbus master moves (`plc_client.st_io`)."""
    p = Parser(prog="plc check", description="Check Structured Text files, and their located variables against "
                                             "a register map's PLC layout.")
    p.add_argument("files", nargs="+", metavar="FILE.st")
    _globals(p, suppress=False)
    args = p.parse_args([a for a in argv if a != "check"])
    try:
        if args.station:
            rmap = RegisterMap.from_station(args.station, "plc")
        else:
            rmap = load_map(args)
    except (ConnectionFailedError, ModbusExceptionError) as exc:
        print(f"plc: error: {exc}", file=sys.stderr)
        return EXIT_CONNECTION
    except TwinError as exc:
        print(f"plc: error: {exc}", file=sys.stderr)
        return EXIT_USER
    from .st_io import check_against_map

    return check_against_map(args.files, rmap)


def cmd_map(args) -> int:
    rmap = load_map(args)
    rows = [("name", "table", "address", "type", "unit", "range", "access")]
    for s in rmap:
        rows.append((s.name, s.table, str(s.address) if s.count == 1 else f"{s.address}-{s.address + s.count - 1}",
                     s.type, s.unit, range_text(s), "rw" if s.writable else "r"))
    print_rows(rows, header=True)
    return 0


# -- values and output -------------------------------------------------------------------------------------
def parse_value(s: Signal, text: str):
    """A command-line value for a signal: bools as 1/0, true/false, on/off; choices by text; else a number."""
    low = text.lower()
    if s.type == "bool":
        if low in TRUE:
            return True
        if low in FALSE:
            return False
        raise ValueTypeError(s.name, f"needs 1 or 0 (true/false, on/off), not {text!r}")
    if s.choices and text in s.choices:
        return text
    try:
        value = float(text)
    except ValueError:
        raise ValueTypeError(s.name, f"needs a number{' in ' + s.unit if s.unit else ''}, not {text!r}") from None
    return int(value) if value.is_integer() and s.type != "float32" and s.scale == 1.0 else value


def fmt(value) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return f"{value:.3f}".rstrip("0").rstrip(".") if abs(value) < 1e6 else f"{value:.6g}"
    if value == "":
        return '""'
    return str(value)


def print_rows(rows, header: bool = False) -> None:
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    for i, row in enumerate(rows):
        print("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
        if header and i == 0:
            print("  ".join("-" * w for w in widths))


from twin.core.errors import UsageError  # noqa: E402  (the project's one: a TwinError, exit status 2)


def main(argv: list[str] | None = None) -> int:
    from twin_app.plugins import parse_command_line

    argv = sys.argv[1:] if argv is None else argv
    st = structured_text_command(argv)
    if st is not None and st[0] == "check" and any(a.split("=")[0] in ("--station", "--map", "--port") for a in argv):
        return check_with_map(argv)
    if st is not None and st[0] == "run" and "--offline" not in argv and not set(argv) & {"-h", "--help"}:
        return run_st_against_twin(argv)
    if st is not None and not (len(st) == 2 and st[1] in ("-h", "--help") and st[0] == "run"):
        from structured_text.cli import check_main, run_main
        return (check_main if st[0] == "check" else run_main)(st[1:])
    args = parse_command_line(build_parser(), argv)  # a station's demo keeps its own options
    logging.getLogger("pymodbus").setLevel(logging.CRITICAL)  # its own log lines would repeat ours
    try:
        return args.func(args)
    except (ConnectionFailedError, ModbusExceptionError) as exc:
        print(f"plc: {one_line(exc)}", file=sys.stderr)
        return EXIT_CONNECTION
    except TwinError as exc:  # PlcClientError, MapError, a station's or a program's error: one line
        print(f"plc: {one_line(exc)}", file=sys.stderr)
        return EXIT_USER
    except BrokenPipeError:  # `plc watch ... | head`
        return 0
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
