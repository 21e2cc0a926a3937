"""The syntax tree. Every node carries the Span of its first token, and expressions also keep the
source text they were written as (motion traces report `v1000`, not its value).

Named `nodes` rather than `ast` so it never shadows the standard library module.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .errors import Span


# ---- expressions -------------------------------------------------------------------------------
@dataclass
class Expr:
    span: Span
    text: str


@dataclass
class NumLit(Expr):
    value: float


@dataclass
class StrLit(Expr):
    value: str


@dataclass
class BoolLit(Expr):
    value: bool


@dataclass
class Name(Expr):
    name: str  # as written

    @property
    def key(self) -> str:
        return self.name.lower()


@dataclass
class Component(Expr):
    """`record.field`"""

    obj: Expr
    field: str
    field_span: Span


@dataclass
class Index(Expr):
    """`array{i}` or `array{i, j}` (1-based)."""

    obj: Expr
    indices: list[Expr]


@dataclass
class Unary(Expr):
    op: str  # "-", "+", "NOT"
    operand: Expr
    op_span: Span


@dataclass
class Binary(Expr):
    op: str  # "+", "-", "*", "/", "DIV", "MOD", "=", "<>", "<", "<=", ">", ">=", "AND", "OR", "XOR"
    left: Expr
    right: Expr
    op_span: Span


@dataclass
class Aggregate(Expr):
    """`[a, b, c]`: typed by where it is used (a robtarget, a pos, ...)."""

    items: list[Expr]


@dataclass
class Arg:
    """One argument of a call. Required: `expr` or `name := expr`; optional: `\\Name:=expr` or a switch `\\Name`;
    conditional: `\\Name?Param`, passed on only when the caller's optional parameter `Param` (the
    `value`, a Name) is present."""

    span: Span
    value: Expr | None
    name: str | None = None
    optional: bool = False
    conditional: bool = False

    @property
    def key(self) -> str | None:
        return self.name.lower() if self.name else None


@dataclass
class Call(Expr):
    """A function call `Name(args)`."""

    name: str
    args: list[Arg]

    @property
    def key(self) -> str:
        return self.name.lower()


# ---- statements --------------------------------------------------------------------------------
@dataclass
class Stmt:
    span: Span


@dataclass
class Assign(Stmt):
    target: Expr  # Name or Component
    value: Expr


@dataclass
class ProcCall(Stmt):
    name: str
    args: list[Arg]

    @property
    def key(self) -> str:
        return self.name.lower()


@dataclass
class If(Stmt):
    branches: list[tuple[Expr, list[Stmt]]]
    orelse: list[Stmt] | None = None
    compact: bool = False


@dataclass
class While(Stmt):
    cond: Expr
    body: list[Stmt]


@dataclass
class For(Stmt):
    var: str
    var_span: Span
    start: Expr
    stop: Expr
    step: Expr | None
    body: list[Stmt]


@dataclass
class Test(Stmt):
    subject: Expr
    cases: list[tuple[list[Expr], list[Stmt]]]
    default: list[Stmt] | None = None


@dataclass
class Return(Stmt):
    value: Expr | None = None


@dataclass
class Exit(Stmt):
    pass


@dataclass
class Retry(Stmt):
    pass


@dataclass
class TryNext(Stmt):
    pass


@dataclass
class Raise(Stmt):
    errno: Expr | None = None


@dataclass
class Goto(Stmt):
    label: str
    label_span: Span


@dataclass
class Label(Stmt):
    """`name:` marks a place GOTO can jump to (in the same block or a block around the GOTO)."""

    name: str


@dataclass
class Connect(Stmt):
    """`CONNECT intno WITH trap;`: an interrupt number is tied to a TRAP routine."""

    target: Expr
    trap: str
    trap_span: Span


@dataclass
class LocalDecl(Stmt):
    """A data declaration inside a routine; it is (re)initialised each time execution reaches it."""

    decl: "DataDecl"


# ---- declarations ------------------------------------------------------------------------------
@dataclass
class DataDecl:
    span: Span
    storage: str  # VAR, PERS or CONST
    type: str  # lower-case type name
    type_span: Span
    name: str
    init: Expr | None = None
    local: bool = False
    dims: list[Expr] = field(default_factory=list)  # array sizes, e.g. {3} or {2, 3}
    module: str = ""  # the module that declares it (module data only)

    @property
    def key(self) -> str:
        return self.name.lower()


@dataclass
class Param:
    span: Span
    name: str
    type: str  # lower-case type name; "switch" for a switch
    mode: str = "IN"  # IN, VAR, PERS, INOUT
    optional: bool = False
    alternatives: list["Param"] = field(default_factory=list)  # `\num a | num b`

    @property
    def key(self) -> str:
        return self.name.lower()


@dataclass
class Routine:
    span: Span
    kind: str  # PROC, FUNC or TRAP
    name: str
    params: list[Param]
    body: list[Stmt]
    error_handler: list[Stmt] | None = None
    return_type: str | None = None
    local: bool = False
    end_span: Span | None = None  # its ENDPROC / ENDFUNC / ENDTRAP
    error_list: list[Expr] | None = None  # `ERROR (ERR_A, ERR_B)`: the handler takes only these
    undo: list[Stmt] | None = None  # the UNDO section
    module: str = ""  # the module that declares it

    @property
    def key(self) -> str:
        return self.name.lower()


@dataclass
class RecordDecl:
    """`RECORD name  type comp; ...  ENDRECORD`: a user-defined record type."""

    span: Span
    name: str
    fields: list[tuple[str, str, Span]]  # (component name, lower-case type, span)
    local: bool = False
    module: str = ""

    @property
    def key(self) -> str:
        return self.name.lower()


@dataclass
class Module:
    span: Span
    name: str
    data: list[DataDecl]
    routines: list[Routine]
    file: str = "<input>"
    source: str = ""
    records: list[RecordDecl] = field(default_factory=list)
    attributes: list[str] = field(default_factory=list)  # SYSMODULE, NOSTEPIN, ...


@dataclass
class Task:
    """The modules of one RAPID task, loaded together: global data, routines and record types of
    one module are seen by the others; LOCAL ones only in their own module."""

    modules: list[Module]

    @property
    def routines(self) -> list[Routine]:
        return [r for m in self.modules for r in m.routines]

    @property
    def data(self) -> list[DataDecl]:
        return [d for m in self.modules for d in m.data]

    @property
    def records(self) -> list[RecordDecl]:
        return [r for m in self.modules for r in m.records]

    @property
    def span(self) -> Span:
        return self.modules[0].span
