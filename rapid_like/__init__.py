"""rapid_like: an interpreter for a subset of ABB RAPID, built to be the robot controller of the twin.

Stages, one per module, dependencies pointing one way:

    tokens, lexer  ->  nodes, parser  ->  checker  ->  interpreter (+ instructions, runtime)
                   ->  controller  ->  offline, cli
    shared: values (types, records), builtins (signatures, predefined data, pure functions),
            errors (one base class with a span), host (the protocol the controller talks to)

- `parser.parse(source, file)` gives a `nodes.Module` (hand-written recursive descent).
- `checker.check(module, signals)` finds undefined names, arity and type errors before running.
- `controller.Controller(module, host, entry)` runs it cooperatively: call `tick(now)` once per
  simulation step. `host.Host` is the protocol a station binding implements; `host.InMemoryHost`
  is the offline one.
- `offline.run_offline(...)` and `cli.main(argv)` are the `rapid run` command.

The parser is hand-written recursive descent rather than lark: it reports the first error at its
true position with messages like "expected ENDIF to close the IF on line 4, found ENDPROC".
"""
from .controller import Controller, load_program
from .errors import CheckError, ExecError, LexError, ParseError, RapidError, Span
from .host import Host, InMemoryHost, MotionRequest, SignalInfo
from .parser import parse

__all__ = ["Controller", "load_program", "parse", "Host", "InMemoryHost", "MotionRequest", "SignalInfo",
           "RapidError", "LexError", "ParseError", "CheckError", "ExecError", "Span"]
