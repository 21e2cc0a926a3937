"""structured_text: an IEC 61131-3 Structured Text runtime, the virtual PLC in its own language.

Stages, one per module, dependencies pointing one way:

    tokens, lexer  ->  nodes, parser  ->  checker (types, stdlib_fn, stdlib_fb)  ->  compiler (rtlib)
                   ->  runtime (the PLC: images, tasks, scan)  ->  cli (`plc check`, `plc run FILE.st --offline`)
    shared: errors (one base class with a span), values (trace values)

    plc = load(["main.st"])          # parse, check, compile; StError with FILE:LINE:COL
    plc.write_located("%IX0.0", True); plc.scan(0.01); plc.get("main.cnt")

The parser is hand-written recursive descent (docs/plc-st.md says why not blark); the checked
program is compiled to Python source once, so a scan runs plain Python.
"""
from .errors import CheckError, LexError, ParseError, PlcFault, Span, StError
from .parser import parse
from .runtime import Plc, compile_files, load

__all__ = ["load", "compile_files", "parse", "Plc", "StError", "LexError", "ParseError", "CheckError",
           "PlcFault", "Span"]
