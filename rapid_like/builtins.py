"""Built-ins: the signatures of RAPID's predefined instructions and functions, the pure functions
themselves (Offs, RelTool, Round, NumToStr, ...), the predefined data (v5..vmax, fine, z0..z200,
tool0, wobj0, load0) and the error numbers (ERR_DIVZERO, ERR_WAIT_MAXTIME, ...).

Signatures are lists of `nodes.Param`, the same shape as a user routine's, so the checker and the
evaluator match arguments to parameters with one piece of code (`match_args`). Instructions that
touch time, signals or motion are executed by the evaluator; only their signatures live here.
"""
from __future__ import annotations

import math
from decimal import ROUND_DOWN, ROUND_HALF_UP, Decimal, localcontext

from .nodes import Arg, Param
from .values import Record, record

# ---- error numbers (ERRNO values) ----------------------------------------------------------------
ERRORS = {
    "ERR_DIVZERO": 1001,
    "ERR_WAIT_MAXTIME": 1002,
    "ERR_ARGNOTPER": 1003,
    "ERR_FNCNORET": 1004,
    "ERR_ILLRAISE": 1005,
    "ERR_ILLDIM": 1006,
    "ERR_SIGSUPSEARCH": 1007,
    "ERR_STRTOOLNG": 1008,
    "ERR_OUTOFBND": 1009,
    "ERR_ROBLIMIT": 1010,
    "ERR_INVALID_VALUE": 1011,
    "ERR_NORUNUNIT": 1012,
    "ERR_AO_LIM": 1013,
    "ERR_GO_LIM": 1014,
    "ERR_ARGVALERR": 1015,
    "ERR_NOTPRES": 1016,
}
ERR_NAMES = {v: k for k, v in ERRORS.items()}
USER_ERRNO_BASE = 2000  # BookErrNo hands out numbers from here


# ---- predefined data -----------------------------------------------------------------------------
def _speeds() -> dict[str, Record]:
    out = {}
    for v in (5, 10, 20, 30, 40, 50, 60, 80, 100, 150, 200, 300, 400, 500, 600, 800, 1000, 1500, 2000,
              2500, 3000, 4000, 5000, 6000, 7000):
        out[f"v{v}"] = record("speeddata", v, 500, 5000, 1000)
    out["vmax"] = record("speeddata", 5000, 500, 5000, 1000)
    return out


def _zones() -> dict[str, Record]:
    out = {"fine": record("zonedata", True, 0, 0, 0, 0, 0, 0),
           "z0": record("zonedata", False, 0.3, 0.3, 0.3, 0.03, 0.3, 0.03),
           "z1": record("zonedata", False, 1, 1, 1, 0.1, 1, 0.1)}
    for z in (5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200):
        out[f"z{z}"] = record("zonedata", False, z, 1.5 * z, 1.5 * z, 0.15 * z, 1.5 * z, 0.15 * z)
    return out


def predefined_data() -> dict[str, tuple[str, object]]:
    """lower-case name -> (type, value) of the predefined constants."""
    data: dict[str, tuple[str, object]] = {}
    for k, v in _speeds().items():
        data[k] = ("speeddata", v)
    for k, v in _zones().items():
        data[k] = ("zonedata", v)
    data["tool0"] = ("tooldata", record("tooldata", True, [[0, 0, 0], [1, 0, 0, 0]],
                                        [0.001, [0, 0, 0.001], [1, 0, 0, 0], 0, 0, 0]))
    data["wobj0"] = ("wobjdata", record("wobjdata", False, True, "", [[0, 0, 0], [1, 0, 0, 0]],
                                        [[0, 0, 0], [1, 0, 0, 0]]))
    data["load0"] = ("loaddata", record("loaddata", 0, [0, 0, 0], [1, 0, 0, 0], 0, 0, 0))
    # stoppointdata for \Inpos (accepted, not simulated) and the stoppoint values of its `type`
    for name, value in (("inpos", 1), ("stoptime", 2), ("fllwtime", 3)):
        data[name] = ("num", float(value))
    for p in (20, 50, 100):
        data[f"inpos{p}"] = ("stoppointdata", record("stoppointdata", 1, True, [p, p, 0, 2], 0, 0, "", 0, 0))
    for t in ("0_5", "1_0", "1_5"):
        sec = float(t.replace("_", "."))
        data[f"stoptime{t}"] = ("stoppointdata", record("stoppointdata", 2, False, [0, 0, 0, 0], sec, 0, "", 0, 0))
        data[f"fllwtime{t}"] = ("stoppointdata", record("stoppointdata", 3, True, [0, 0, 0, 0], 0, sec, "", 0, 0))
    for name, num in ERRORS.items():
        data[name.lower()] = ("errnum", float(num))
    data["pi"] = ("num", math.pi)
    data["high"] = ("dionum", 1.0)
    data["low"] = ("dionum", 0.0)
    return data


# Predefined *variables* (the USER system module's reg1 to reg5).
PREDEFINED_VARS: dict[str, str] = {f"reg{i}": "num" for i in range(1, 6)}


# ---- signatures ----------------------------------------------------------------------------------
def _sig(text: str) -> list[Param]:
    """Parse a compact signature: `num Value, \\num MaxTime, \\INOUT bool TimeFlag, \\switch High`."""
    params = []
    for part in filter(None, (p.strip() for p in text.split(","))):
        optional = part.startswith("\\")
        alts = []
        for alt in part.lstrip("\\").split("|"):
            words = alt.split()
            mode = "IN"
            if words[0] in ("INOUT", "VAR", "PERS"):
                mode, words = words[0], words[1:]
            alts.append(Param(None, words[1], words[0], mode, optional))  # type: ignore[arg-type]
        alts[0].alternatives = alts[1:]
        params.append(alts[0])
    return params


# The motion instructions' arguments, as in the RAPID manual:
#   MoveJ    [\Conc] ToPoint [\ID] Speed [\V]|[\T] Zone [\Z] [\Inpos] Tool [\WObj] [\TLoad]
#   MoveL    [\Conc] ToPoint [\ID] Speed [\V]|[\T] Zone [\Z] [\Inpos] Tool [\WObj] [\Corr] [\TLoad]
#   MoveC    [\Conc] CirPoint ToPoint [\ID] Speed [\V]|[\T] Zone [\Z] [\Inpos] Tool [\WObj] [\Corr] [\TLoad]
#   MoveAbsJ [\Conc] ToJointPos [\ID] [\NoEOffs] Speed [\V]|[\T] Zone [\Z] [\Inpos] Tool [\WObj] [\TLoad]
# Only \WObj and \V change what the host is asked to do (\V replaces the speeddata's v_tcp). The
# others only matter on a real controller and are accepted and ignored: \Conc (the program still
# waits for every motion: motions are not run concurrently with the next instructions), \ID
# (MultiMove synchronisation), \T (the motion's time), \Z (the zone size: zones are not blended),
# \Inpos (every motion ends in position anyway), \Corr (no path correction), \TLoad (the load
# is not simulated) and \NoEOffs (no external axes).
_MOVE_OPTS = (r"\switch Conc, \num ID, \num V | num T, \num Z, \stoppointdata Inpos, \wobjdata WObj, "
              r"\loaddata TLoad")
_INSTRUCTIONS = {
    "Incr": "INOUT num Name",
    "Decr": "INOUT num Name",
    "Add": "INOUT num Name, num AddValue",
    "SetDO": r"\num SDelay, signaldo Signal, num Value",
    "SetAO": "signalao Signal, num Value",
    "SetGO": "signalgo Signal, num Value",
    "Set": "signaldo Signal",
    "Reset": "signaldo Signal",
    "InvertDO": "signaldo Signal",
    "PulseDO": r"\switch High, \num PLength, signaldo Signal",
    "WaitTime": r"\switch InPos, num Time",
    "WaitDI": r"signaldi Signal, num Value, \num MaxTime, \INOUT bool TimeFlag",
    "WaitDO": r"signaldo Signal, num Value, \num MaxTime, \INOUT bool TimeFlag",
    "WaitUntil": r"\switch InPos, bool Cond, \num MaxTime, \INOUT bool TimeFlag, \num PollRate",
    "WaitRob": r"\switch InPos, \switch ZeroSpeed",
    "TPWrite": r"string String, \num Num | bool Bool | pos Pos | orient Orient",
    "TPErase": "",
    "MoveJ": "robtarget ToPoint, speeddata Speed, zonedata Zone, tooldata Tool, " + _MOVE_OPTS,
    "MoveL": "robtarget ToPoint, speeddata Speed, zonedata Zone, tooldata Tool, \\switch Corr, " + _MOVE_OPTS,
    "MoveC": "robtarget CirPoint, robtarget ToPoint, speeddata Speed, zonedata Zone, tooldata Tool, "
             "\\switch Corr, " + _MOVE_OPTS,
    "MoveAbsJ": "jointtarget ToJointPos, speeddata Speed, zonedata Zone, tooldata Tool, \\switch NoEOffs, "
                + _MOVE_OPTS,
    "Stop": r"\switch NoRegain",
    "Break": "",
    "ConfJ": r"\switch On, \switch Off",
    "ConfL": r"\switch On, \switch Off",
    "VelSet": "num Override, num Max",
    "AccSet": "num Acc, num Ramp",
    "BookErrNo": "INOUT errnum ErrorName",
    "ClkReset": "INOUT clock Clock",
    "ClkStart": "INOUT clock Clock",
    "ClkStop": "INOUT clock Clock",
}
INSTRUCTIONS: dict[str, list[Param]] = {k.lower(): _sig(v) for k, v in _INSTRUCTIONS.items()}

_FUNCTIONS = {
    "Offs": ("robtarget Point, num XOffset, num YOffset, num ZOffset", "robtarget"),
    "RelTool": (r"robtarget Point, num Dx, num Dy, num Dz, \num Rx, \num Ry, \num Rz", "robtarget"),
    "CRobT": (r"\tooldata Tool, \wobjdata WObj", "robtarget"),
    "CJointT": ("", "jointtarget"),
    "Present": ("any OptPar", "bool"),
    "Abs": ("num Input", "num"),
    "Round": (r"num Val, \num Dec", "num"),
    "Trunc": (r"num Val, \num Dec", "num"),
    "Sqrt": ("num Value", "num"),
    "Pow": ("num Base, num Exponent", "num"),
    "Exp": ("num Exponent", "num"),
    "Sin": ("num Angle", "num"),
    "Cos": ("num Angle", "num"),
    "Tan": ("num Angle", "num"),
    "ATan": ("num Value", "num"),
    "ATan2": ("num Y, num X", "num"),
    "ASin": ("num Value", "num"),
    "ACos": ("num Value", "num"),
    "OrientZYX": ("num ZAngle, num YAngle, num XAngle", "orient"),
    "EulerZYX": (r"\switch X | switch Y | switch Z, orient Rotation", "num"),
    "NumToStr": (r"num Val, num Dec, \switch Exp", "string"),
    "ValToStr": ("any Val", "string"),
    "StrLen": ("string Str", "num"),
    "StrPart": ("string Str, num ChPos, num Len", "string"),
    "Dist": ("pos Point1, pos Point2", "num"),
    "ClkRead": (r"clock Clock, \switch HighRes", "num"),
    "Dim": ("any ArrPar, num DimNo", "num"),
    "DOutput": ("signaldo Signal", "num"),
    "DInput": ("signaldi Signal", "num"),
    "AOutput": ("signalao Signal", "num"),
    "GOutput": ("signalgo Signal", "num"),
    "TestDI": ("signaldi Signal", "bool"),
}
FUNCTIONS: dict[str, tuple[list[Param], str]] = {k.lower(): (_sig(s), r) for k, (s, r) in _FUNCTIONS.items()}
PROPER_NAMES = {k.lower(): k for k in (*_INSTRUCTIONS, *_FUNCTIONS)}  # for messages: `Abs`, not `abs`


def param_table(params: list[Param]) -> dict[str, Param]:
    """{param key: param} over a signature's parameters and their `\\a | \\b` alternatives."""
    return {q.key: q for p in params for q in (p, *p.alternatives)}


# The built-ins' parameters by key, built once (the signatures never change).
INSTRUCTION_PARAMS: dict[str, dict[str, Param]] = {k: param_table(ps) for k, ps in INSTRUCTIONS.items()}
FUNCTION_PARAMS: dict[str, dict[str, Param]] = {k: param_table(ps) for k, (ps, _) in FUNCTIONS.items()}


# Functions the evaluator implements itself (they need the host, the frame or the program).
SPECIAL_FUNCTIONS = {"crobt", "cjointt", "present", "doutput", "dinput", "aoutput", "goutput", "testdi"}


def match_args(params: list[Param], args: list[Arg]) -> tuple[dict[str, Arg], str | None, Arg | None]:
    """Match call arguments to parameters. Returns ({param key: arg}, error message, arg at fault).

    Required arguments match required parameters in order (or by `Name := value`); optional ones
    (`\\Name`) match optional parameters by name, including `\\a | \\b` alternatives."""
    required = [p for p in params if not p.optional]
    optional: dict[str, Param] = {}
    for p in params:
        if p.optional:
            optional[p.key] = p
            for alt in p.alternatives:
                optional[alt.key] = alt
    bound: dict[str, Arg] = {}
    nreq = 0
    for a in args:
        if a.optional:
            p = optional.get(a.key or "")
            if p is None:
                return bound, f"no optional argument \\{a.name}", a
            if a.key in bound:
                return bound, f"optional argument \\{a.name} given twice", a
            group = [p] + p.alternatives
            for q in params:
                if q.optional and (q is p or p in q.alternatives):
                    group = [q] + q.alternatives
            for other in group:
                if other.key in bound:
                    choices = " | ".join("\\" + q.name for q in group)
                    return bound, f"\\{a.name} and \\{other.name} exclude each other (give one of {choices})", a
            if p.type == "switch" and a.value is not None and not a.conditional:
                return bound, f"\\{a.name} is a switch and takes no value", a
            if p.type != "switch" and a.value is None:
                return bound, f"\\{a.name} needs a value (\\{a.name}:=...)", a
            bound[p.key] = a
        elif a.name:
            match = [p for p in required if p.key == a.key]
            if not match:
                return bound, f"no parameter named {a.name}", a
            bound[match[0].key] = a
        else:
            while nreq < len(required) and required[nreq].key in bound:
                nreq += 1
            if nreq >= len(required):
                return bound, f"too many arguments (takes {len(required)})", a
            bound[required[nreq].key] = a
            nreq += 1
    missing = [p.name for p in required if p.key not in bound]
    if missing:
        return bound, f"missing argument {missing[0]} (takes {len(required)}: " + \
            ", ".join(p.name for p in required) + ")", None
    return bound, None, None


# ---- pure functions ------------------------------------------------------------------------------
def _dec_round(x: float, dec: int, mode: str) -> float:
    if not math.isfinite(x):
        return x
    q = Decimal(1).scaleb(-int(dec))
    with localcontext() as ctx:
        ctx.prec = 1000  # enough digits for any float (1E300 with 2 decimals)
        return float(Decimal(repr(float(x))).quantize(q, rounding=mode))


def rapid_round(x: float, dec: float = 0) -> float:
    return _dec_round(x, int(dec), ROUND_HALF_UP)


def rapid_trunc(x: float, dec: float = 0) -> float:
    return _dec_round(x, int(dec), ROUND_DOWN)


def num_to_str(x: float, dec: float, exp: bool = False) -> str:
    d = int(dec)
    if exp:
        s = f"{x:.{d}E}"
        mant, e = s.split("E")
        return f"{mant}E{int(e):+03d}"
    return f"{rapid_round(x, d):.{d}f}"


def qmul(a: list[float], b: list[float]) -> list[float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]


def qrotate(q: list[float], v: list[float]) -> list[float]:
    w, x, y, z = q
    norm = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    r = qmul(qmul([w, x, y, z], [0.0, *v]), [w, -x, -y, -z])
    return r[1:]


def _clean(x: float) -> float:
    r = round(x, 9)
    return 0.0 if r == 0 else r


# ---- poses: (trans [x, y, z] in mm, quaternion [q1, q2, q3, q4] with q1 = w) --------------------------
Pose = tuple[list[float], list[float]]


def pose_of(p: Record) -> Pose:
    """The trans and rot of a robtarget or pose record."""
    t, r = p.fields["trans"].fields, p.fields["rot"].fields  # type: ignore[union-attr]
    return [t["x"], t["y"], t["z"]], [r["q1"], r["q2"], r["q3"], r["q4"]]  # type: ignore[list-item]


def _unit(q: list[float]) -> list[float]:
    norm = math.sqrt(sum(c * c for c in q)) or 1.0
    return [c / norm for c in q]


def pose_mul(a: Pose, b: Pose) -> Pose:
    """a * b: the pose b (given in frame a) in a's reference frame."""
    ta, qa = a
    tb, qb = b
    d = qrotate(qa, tb)
    return [ta[0] + d[0], ta[1] + d[1], ta[2] + d[2]], _unit(qmul(_unit(qa), _unit(qb)))


def pose_inv(a: Pose) -> Pose:
    t, q = a
    w, x, y, z = _unit(q)
    qi = [w, -x, -y, -z]
    d = qrotate(qi, t)
    return [-d[0], -d[1], -d[2]], qi


def wobj_frame(wobj: Record) -> Pose:
    """A work object's object frame in the world: uframe * oframe (a robot-held or
    mechanically coupled user frame is taken as fixed)."""
    return pose_mul(pose_of(wobj.fields["uframe"]), pose_of(wobj.fields["oframe"]))  # type: ignore[arg-type]


def tool_frame(tool: Record) -> Pose:
    """A tool's TCP in the flange frame (its tframe)."""
    return pose_of(tool.fields["tframe"])  # type: ignore[arg-type]


def offs(p: Record, dx: float, dy: float, dz: float) -> Record:
    out = p.copy()
    t = out.fields["trans"].fields  # type: ignore[union-attr]
    t["x"], t["y"], t["z"] = t["x"] + dx, t["y"] + dy, t["z"] + dz
    return out


def rel_tool(p: Record, dx: float, dy: float, dz: float, rx: float = 0, ry: float = 0, rz: float = 0) -> Record:
    """Displace and rotate `p` in its own tool frame; rotations (degrees) about x, then the new y,
    then the new z."""
    out = p.copy()
    t = out.fields["trans"].fields  # type: ignore[union-attr]
    r = out.fields["rot"].fields  # type: ignore[union-attr]
    q = [r["q1"], r["q2"], r["q3"], r["q4"]]
    d = qrotate(q, [dx, dy, dz])
    t["x"], t["y"], t["z"] = (_clean(t["x"] + d[0]), _clean(t["y"] + d[1]), _clean(t["z"] + d[2]))
    for angle, axis in ((rx, 0), (ry, 1), (rz, 2)):
        if angle:
            h = math.radians(angle) / 2
            rq = [math.cos(h), 0.0, 0.0, 0.0]
            rq[1 + axis] = math.sin(h)
            q = qmul(q, rq)
    r["q1"], r["q2"], r["q3"], r["q4"] = (_clean(c) for c in q)
    return out


def orient_zyx(z: float, y: float, x: float) -> Record:
    """The orientation of rotations about z, then the new y, then the new x (degrees)."""
    q = [1.0, 0.0, 0.0, 0.0]
    for angle, axis in ((z, 2), (y, 1), (x, 0)):
        h = math.radians(angle) / 2
        rq = [math.cos(h), 0.0, 0.0, 0.0]
        rq[1 + axis] = math.sin(h)
        q = qmul(q, rq)
    return Record("orient", dict(zip(("q1", "q2", "q3", "q4"), (_clean(c) for c in q))))


def euler_zyx(axis: str, o: Record) -> float:
    """One angle (degrees) of an orientation's z-y-x Euler decomposition."""
    w, x, y, z = (o.fields[k] for k in ("q1", "q2", "q3", "q4"))
    norm = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    if axis == "z":
        a = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    elif axis == "y":
        a = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    else:
        a = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    return _clean(math.degrees(a))


def dist(a: Record, b: Record) -> float:
    fa, fb = a.fields, b.fields
    return math.sqrt(sum((fa[k] - fb[k]) ** 2 for k in ("x", "y", "z")))  # type: ignore[operator]
