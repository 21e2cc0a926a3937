"""The syntax tree: what the parser builds and the checker annotates. Every node has the span where it starts.

The checker fills `Expr.ty` (the expression's data type, a `types.DataType`) and resolves names
(`Name.ref`), so the compiler never guesses.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .errors import Span
from .tokens import Lit


# -- type specifications (as written) ---------------------------------------------------------------
@dataclass(eq=False)
class TypeSpec:
    span: Span


@dataclass(eq=False)
class NamedType(TypeSpec):
    name: str


@dataclass(eq=False)
class StringType(TypeSpec):
    wide: bool
    length: "Expr | None"


@dataclass(eq=False)
class ArraySpec(TypeSpec):
    ranges: list[tuple["Expr", "Expr"]]
    elem: TypeSpec


@dataclass(eq=False)
class StructSpec(TypeSpec):
    fields: list["VarDecl"]


@dataclass(eq=False)
class EnumSpec(TypeSpec):
    values: list[tuple[str, Span, "Expr | None"]]
    base: str | None = None


@dataclass(eq=False)
class SubrangeSpec(TypeSpec):
    base: str
    lo: "Expr"
    hi: "Expr"


# -- expressions --------------------------------------------------------------------------------------
@dataclass(eq=False)
class Expr:
    span: Span

    def __post_init__(self):
        self.ty = None  # set by the checker


@dataclass(eq=False)
class Literal(Expr):
    lit: Lit


@dataclass(eq=False)
class Name(Expr):
    name: str

    def __post_init__(self):
        super().__post_init__()
        self.ref = None  # checker: a Symbol, or an enum value / constant


@dataclass(eq=False)
class Member(Expr):
    base: Expr
    name: str
    name_span: Span


@dataclass(eq=False)
class Index(Expr):
    base: Expr
    indexes: list[Expr]


@dataclass(eq=False)
class BitAccess(Expr):
    base: Expr
    bit: int


@dataclass(eq=False)
class Direct(Expr):
    area: str
    size: str
    index: tuple[int, ...]


@dataclass(eq=False)
class Unary(Expr):
    op: str  # "-", "+", "NOT"
    operand: Expr


@dataclass(eq=False)
class Binary(Expr):
    op: str  # "+", "-", "*", "/", "MOD", "**", "=", "<>", "<", "<=", ">", ">=", "AND", "OR", "XOR"
    left: Expr
    right: Expr
    op_span: Span


@dataclass(eq=False)
class Arg:
    span: Span
    name: str | None  # formal name, or None for a positional argument
    value: Expr
    output: bool = False  # `name => var`
    negated: bool = False  # `NOT name => var`


@dataclass(eq=False)
class Call(Expr):
    name: str
    args: list[Arg]

    def __post_init__(self):
        super().__post_init__()
        self.target = None  # checker: the function (a Pou or a standard function), or the FB type
        self.instance = None  # an FB call on `s.fb(...)` or `fbs[i](...)`: the instance expression


@dataclass(eq=False)
class ArrayInit(Expr):
    items: list[tuple["Expr | None", "Expr"]]  # (repeat count, value or nested init)


@dataclass(eq=False)
class StructInit(Expr):
    fields: list[tuple[str, Span, "Expr"]]


# -- statements -----------------------------------------------------------------------------------------
@dataclass(eq=False)
class Stmt:
    span: Span


@dataclass(eq=False)
class Assign(Stmt):
    target: Expr
    value: Expr


@dataclass(eq=False)
class CallStmt(Stmt):
    call: Call  # a function call whose result is dropped, or an FB instance call


@dataclass(eq=False)
class If(Stmt):
    branches: list[tuple[Expr, list[Stmt]]]
    orelse: list[Stmt] | None


@dataclass(eq=False)
class CaseItem:
    labels: list[tuple[Expr, Expr | None]]  # value, or range lo..hi
    body: list[Stmt]


@dataclass(eq=False)
class Case(Stmt):
    selector: Expr
    items: list[CaseItem]
    orelse: list[Stmt] | None


@dataclass(eq=False)
class For(Stmt):
    var: Name
    start: Expr
    end: Expr
    step: Expr | None
    body: list[Stmt]


@dataclass(eq=False)
class While(Stmt):
    cond: Expr
    body: list[Stmt]


@dataclass(eq=False)
class Repeat(Stmt):
    body: list[Stmt]
    cond: Expr


@dataclass(eq=False)
class Exit(Stmt):
    pass


@dataclass(eq=False)
class Continue(Stmt):
    pass


@dataclass(eq=False)
class Return(Stmt):
    pass


# -- declarations ---------------------------------------------------------------------------------------
@dataclass(eq=False)
class VarDecl:
    span: Span
    name: str
    spec: TypeSpec
    init: Expr | None
    section: str  # VAR, VAR_INPUT, VAR_OUTPUT, VAR_IN_OUT, VAR_GLOBAL, VAR_EXTERNAL, VAR_TEMP, FIELD
    constant: bool = False
    retain: bool = False
    location: tuple[str, str, tuple[int, ...]] | None = None
    location_span: Span | None = None


@dataclass(eq=False)
class TypeDecl:
    span: Span
    name: str
    spec: TypeSpec
    init: Expr | None


@dataclass(eq=False)
class Pou:
    span: Span
    kind: str  # PROGRAM, FUNCTION_BLOCK, FUNCTION
    name: str
    decls: list[VarDecl]
    body: list[Stmt]
    result: TypeSpec | None = None  # a FUNCTION's result type
    end_span: Span | None = None
    name_span: Span | None = None


@dataclass(eq=False)
class TaskDecl:
    span: Span
    name: str
    interval: Expr | None
    priority: Expr | None
    single: Expr | None = None


@dataclass(eq=False)
class ProgramConf:
    span: Span
    name: str
    task: str | None
    task_span: Span | None
    type_name: str
    type_span: Span
    args: list[Arg]
    retain: bool = False


@dataclass(eq=False)
class Resource:
    span: Span
    name: str
    globals: list[VarDecl]
    tasks: list[TaskDecl]
    programs: list[ProgramConf]


@dataclass(eq=False)
class Configuration:
    span: Span
    name: str
    globals: list[VarDecl]
    resources: list[Resource]


@dataclass(eq=False)
class SourceFile:
    file: str
    pous: list[Pou] = field(default_factory=list)
    types: list[TypeDecl] = field(default_factory=list)
    globals: list[VarDecl] = field(default_factory=list)
    configurations: list[Configuration] = field(default_factory=list)
