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
from .values import Opaque, Record, record

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
    "ERR_SOCK_TIMEOUT": 1017,
    "ERR_SOCK_CLOSED": 1018,
    "ERR_SOCK_ADDR_INUSE": 1019,
    "ERR_SOCK_NET_UNREACH": 1020,
    "ERR_ALRDYCNT": 1021,
    "ERR_CNTNOTVAR": 1022,
    "ERR_INOMAX": 1023,
    "ERR_TP_MAXTIME": 1024,
    "ERR_TP_DIBREAK": 1025,
    "ERR_TP_DOBREAK": 1026,
    "ERR_TP_NO_CLIENT": 1027,
    "ERR_UI_INITVALUE": 1028,
    "ERR_UI_MAX": 1029,
    "ERR_UI_MIN": 1030,
    "ERR_UI_NOTINT": 1031,
    "ERR_RCVDATA": 1032,
    "ERR_WHLSEARCH": 1033,
    "ERR_PATH_STOP": 1034,
    "ERR_REFUNKDAT": 1035,
    "ERR_REFUNKPRC": 1036,
    "ERR_CALLPROC": 1037,
    "ERR_FILEOPEN": 1038,
    "ERR_FILEACC": 1039,
    "ERR_FILNOTFND": 1040,
    "ERR_NAME_INVALID": 1041,
    "ERR_OVERFLOW": 1042,
    "ERR_NUM_LIMIT": 1043,
    "ERR_INT_NOTVAL": 1044,
    "ERR_INT_MAXVAL": 1045,
    "ERR_STRTOVAL": 1046,
    "ERR_RANYBIN_EOF": 1047,
    "ERR_PID_MOVESTOP": 1048,
    "ERR_NOT_MOVETASK": 1049,
    "ERR_EXECPHR": 1050,
    "ERR_ARGDUPCND": 1051,
    "ERR_ARGNAME": 1052,
    "ERR_AXIS_PAR": 1053,
    "ERR_TASKNAME": 1054,
    "ERR_UNKINO": 1055,
    "ERR_NO_ALIASIO_DEF": 1056,
    "ERR_NORUNUNIT_WARN": 1057,
    "ERR_PATHDIST": 1058,
}
LONG_JMP_ALL_ERR = -1.0  # `ERROR (LONG_JMP_ALL_ERR)`: the handler takes every error raised to it
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
    data["edge"] = ("dionum", 2.0)  # ISignalDI/DO: either flank
    data["long_jmp_all_err"] = ("errnum", LONG_JMP_ALL_ERR)
    data["wait_max"] = ("num", WAIT_MAX)
    data["stempty"] = ("string", "")
    data["str_digit"] = ("string", "0123456789")
    data["str_upper"] = ("string", "ABCDEFGHIJKLMNOPQRSTUVWXYZ")
    data["str_lower"] = ("string", "abcdefghijklmnopqrstuvwxyz")
    data["str_white"] = ("string", " \t\n\r\v\f")
    for group in _ENUMS.values():
        for name, (t, v) in group.items():
            data[name.lower()] = (t, float(v))
    data["rob_1"] = ("mecunit", Opaque("mecunit"))
    return data


WAIT_MAX = 8388608.0  # "wait forever" for \MaxTime and \Time arguments (the manual's WAIT_MAX)
SIMULATED_DATE = (2024, 1, 1)  # CDate/CTime/GetTime: the simulated calendar starts here, at midnight, at t = 0

# RAPID's predefined symbolic constants, by the type that holds them (values as this interpreter numbers them).
_ENUMS: dict[str, dict[str, tuple[str, float]]] = {
    "socketstatus": {n: ("socketstatus", i) for i, n in enumerate(
        ("SOCKET_CREATED", "SOCKET_CONNECTED", "SOCKET_BOUND", "SOCKET_LISTENING", "SOCKET_CLOSED"), 1)},
    "opmode": {"OP_UNDEF": ("symnum", 0), "OP_AUTO": ("symnum", 1), "OP_MAN_PROG": ("symnum", 2),
               "OP_MAN_TEST": ("symnum", 3)},
    "runmode": {n: ("symnum", i) for i, n in enumerate(
        ("RUN_UNDEF", "RUN_CONT_CYCLE", "RUN_INSTR_FWD", "RUN_INSTR_BWD", "RUN_SIM", "RUN_STEP_MOVE"))},
    "btnres": {n: ("btnres", i) for i, n in enumerate(
        ("resUnkwn", "resOK", "resAbort", "resRetry", "resIgnore", "resCancel", "resYes", "resNo"))},
    "buttondata": {"btnNone": ("buttondata", -1), **{n: ("buttondata", i) for i, n in enumerate(
        ("btnOK", "btnAbrtRtryIgn", "btnOKCancel", "btnRetryCancel", "btnYesNo", "btnYesNoCancel"))}},
    "icondata": {n: ("icondata", i) for i, n in enumerate(
        ("iconNone", "iconInfo", "iconWarning", "iconError", "iconQuestion"))},
    "tpnum": {"TP_LATEST": ("tpnum", 1), "TP_PROGRAM": ("tpnum", 2), "TP_SCREENVIEWER": ("tpnum", 3)},
    "inttypes": {"USINT": ("num", 1), "UINT": ("num", 2), "UDINT": ("num", 4), "ULINT": ("num", 8),
                 "SINT": ("num", -1), "INT": ("num", -2), "DINT": ("num", -4), "LINT": ("num", -8)},
    "errdomain": {n: ("errdomain", i) for i, n in enumerate(
        ("COMMON_ERR", "OP_STATE", "SYSTEM_ERR", "HARDWARE_ERR", "PROGRAM_ERR", "MOTION_ERR", "OPERATOR_ERR",
         "IO_COM_ERR", "USER_DEF_ERR", "SYNCHRO_ERR", "PROCESS_ERR", "CFG_ERR"))},
    "aiotrigg": {n: ("num", i) for i, n in enumerate(
        ("AIO_ABOVE_HIGH", "AIO_BELOW_HIGH", "AIO_ABOVE_LOW", "AIO_BELOW_LOW", "AIO_BETWEEN", "AIO_OUTSIDE",
         "AIO_ALWAYS"), 1)},
    "errtype": {"TYPE_ALL": ("errtype", 0), "TYPE_STATE": ("errtype", 1), "TYPE_WARN": ("errtype", 2),
                "TYPE_ERR": ("errtype", 3)},
}


# Predefined *variables*: the USER system module's reg1 to reg5 and clock1.
PREDEFINED_VARS: dict[str, str] = {**{f"reg{i}": "num" for i in range(1, 6)}, "clock1": "clock"}


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
_TP_BREAK = r"\num MaxTime, \signaldi DIBreak, \signaldo DOBreak, \INOUT errnum BreakFlag"
_UI_BREAK = (r"\num MaxTime, \signaldi DIBreak, \switch DIPassive, \signaldo DOBreak, \switch DOPassive, "
             r"\INOUT errnum BreakFlag")
_FMT = r"\switch Hex | switch Okt | switch Bin | switch Char"
_RAW = r"\num IntX | switch Float4 | switch Hex1"
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
    "Stop": r"\switch NoRegain | switch AllMoveTasks",
    "Break": "",
    "ConfJ": r"\switch On, \switch Off",
    "ConfL": r"\switch On, \switch Off",
    "VelSet": "num Override, num Max",
    "AccSet": r"num Acc, num Ramp, \num FinePointRamp",
    "SingArea": r"\switch Wrist | switch Arm | switch LockAxis4 | switch Off",
    "CirPathMode": r"\switch PathFrame | switch ObjectFrame | switch CirPointOri | switch Wrist45 | switch Wrist46 "
                   r"| switch Wrist56",
    "PathResol": "num PathSampleTime",
    "GripLoad": "loaddata Load",
    "WorldAccLim": r"\num On | switch Off",
    "PathAccLim": r"bool AccLim, \num AccMax, bool DecelLim, \num DecelMax",
    "MoveJDO": r"robtarget ToPoint, \num ID, speeddata Speed, \num T, zonedata Zone, tooldata Tool, \wobjdata WObj, "
               r"signaldo Signal, num Value, \loaddata TLoad",
    "MoveLDO": r"robtarget ToPoint, \num ID, speeddata Speed, \num T, zonedata Zone, tooldata Tool, \wobjdata WObj, "
               r"signaldo Signal, num Value, \loaddata TLoad",
    "StopMove": r"\switch Quick, \switch AllMotionTasks",
    "StartMove": r"\switch AllMotionTasks",
    "StartMoveRetry": "",
    "StopMoveReset": r"\switch AllMotionTasks",
    "ClearPath": "",
    "StorePath": r"\switch KeepSync",
    "RestoPath": "",
    "PDispOff": "",
    "PDispSet": "pose DispFrame",
    "EOffsOff": "",
    "ErrWrite": r"\switch W | switch I, string Header, string Reason, \string RL2, \string RL3, \string RL4",
    "ExitCycle": "",
    "SkipWarn": "",
    "TPReadFK": "INOUT num TPAnswer, string TPText, string TPFK1, string TPFK2, string TPFK3, string TPFK4, "
                "string TPFK5, " + _TP_BREAK,
    "TPReadNum": "INOUT num TPAnswer, string TPText, " + _TP_BREAK,
    "TPReadDnum": "INOUT dnum TPAnswer, string TPText, " + _TP_BREAK,
    "TPShow": "num Window",
    "UIMsgBox": r"\string Header, string MsgLine1, \string MsgLine2, \string MsgLine3, \string MsgLine4, "
                r"\string MsgLine5, \num Buttons, \num Icon, \string Image, \INOUT btnres Result, " + _UI_BREAK,
    "WaitTestAndSet": "INOUT bool Object",
    "WaitGI": r"signalgi Signal, \switch NotEQ | switch LT | switch GT, num Value, \num MaxTime, "
              r"\INOUT bool TimeFlag",
    "WaitGO": r"signalgo Signal, \switch NotEQ | switch LT | switch GT, num Value, \num MaxTime, "
              r"\INOUT bool TimeFlag",
    "WaitAI": r"signalai Signal, \switch LT | switch GT, num Value, \num MaxTime, \INOUT num ValueAtTimeout",
    "WaitAO": r"signalao Signal, \switch LT | switch GT, num Value, \num MaxTime, \INOUT num ValueAtTimeout",
    "IDelete": "intnum Interrupt",
    "ISleep": "intnum Interrupt",
    "IWatch": "intnum Interrupt",
    "IEnable": "",
    "IDisable": "",
    "ISignalDI": r"\switch Single | switch SingleSafe, signaldi Signal, num TriggValue, intnum Interrupt",
    "ISignalDO": r"\switch Single | switch SingleSafe, signaldo Signal, num TriggValue, intnum Interrupt",
    "ISignalGI": r"\switch Single | switch SingleSafe, signalgi Signal, intnum Interrupt",
    "ISignalGO": r"\switch Single | switch SingleSafe, signalgo Signal, intnum Interrupt",
    "ITimer": r"\switch Single | switch SingleSafe, num Time, intnum Interrupt",
    "IPers": "INOUT any Name, intnum Interrupt",
    "IError": r"errdomain ErrorDomain, \num ErrorId, errtype ErrorType, intnum Interrupt",
    "SocketCreate": r"INOUT socketdev Socket, \switch UDP",
    "SocketConnect": r"INOUT socketdev Socket, string Address, num Port, \num Time",
    "SocketBind": "INOUT socketdev Socket, string LocalAddress, num LocalPort",
    "SocketListen": "INOUT socketdev Socket",
    "SocketAccept": r"INOUT socketdev Socket, INOUT socketdev ClientSocket, \INOUT string ClientAddress, \num Time",
    "SocketSend": r"INOUT socketdev Socket, \string Str | rawbytes RawData | byte{} Data, \num NoOfBytes",
    "SocketReceive": r"INOUT socketdev Socket, \INOUT string Str | INOUT rawbytes RawData | INOUT byte{} Data, "
                     r"\num ReadNoOfBytes, \INOUT num NoRecBytes, \num Time",
    "SocketClose": "INOUT socketdev Socket",
    "ClearRawBytes": r"INOUT rawbytes RawData, \num FromIndex",
    "PackRawBytes": r"any Value, INOUT rawbytes RawData, \switch Network, num StartIndex, "
                    r"\num IntX | switch Float4 | switch ASCII | switch Hex1",
    "UnpackRawBytes": r"rawbytes RawData, \switch Network, num StartIndex, INOUT any Value, "
                      r"\num IntX | switch Float4 | num ASCII | switch Hex1",
    "CopyRawBytes": r"rawbytes FromRawData, num FromIndex, INOUT rawbytes ToRawData, num ToIndex, \num NoOfBytes",
    "BitSet": "INOUT byte BitData, num BitPos",
    "BitClear": "INOUT byte BitData, num BitPos",
    "Open": r"string Object, \string File, INOUT iodev IODevice, \switch Read | switch Write | switch Append, "
            r"\switch Bin",
    "Close": "INOUT iodev IODevice",
    "CornerPathWarning": "bool Status",
    "SoftAct": r"\mecunit MechUnit, num Axis, num Softness, \num Ramp",
    "SoftDeact": r"\num Ramp",
    "ActUnit": "mecunit MechUnit",
    "DeactUnit": "mecunit MechUnit",
    "WaitWObj": r"INOUT wobjdata WObj, \num RelDist, \num PolRange, \num MaxTime, \INOUT bool TimeFlag",
    "DropWObj": "wobjdata WObj",
    "SetLeadThrough": r"\switch On | switch Off",
    "WriteAnyBin": "iodev IODevice, any Data",
    "ReadAnyBin": r"iodev IODevice, INOUT any Data, \num Time",
    "OpenDir": "INOUT dir Dev, string Path",
    "CloseDir": "dir Dev",
    "Rewind": "INOUT iodev IODevice",
    "Write": r"iodev IODevice, string String, \num Num | bool Bool | pos Pos | orient Orient | dnum Dnum, "
             r"\switch NoNewLine",
    "PDispOn": r"\switch Rot, \robtarget ExeP, robtarget ProgPoint, tooldata Tool, \wobjdata WObj",
    "EOffsSet": "extjoint EAxOffs",
    "EOffsOn": r"\extjoint ExeP, robtarget ProgPoint",
    "WaitSyncTask": r"\switch InPos, syncident SyncID, tasks{} TaskList, \num TimeOut",
    "SearchL": r"\switch Stop | switch PStop | switch SStop | switch Sup, signaldi Signal, \switch Flanks, "
               r"INOUT robtarget SearchPoint, robtarget ToPoint, \num ID, speeddata Speed, \num V | num T, "
               r"tooldata Tool, \wobjdata WObj, \loaddata TLoad",
    "MoveJSync": r"robtarget ToPoint, \num ID, speeddata Speed, \num T, zonedata Zone, tooldata Tool, "
                 r"\wobjdata WObj, string ProcName, \loaddata TLoad",
    "MoveLSync": r"robtarget ToPoint, \num ID, speeddata Speed, \num T, zonedata Zone, tooldata Tool, "
                 r"\wobjdata WObj, string ProcName, \loaddata TLoad",
    "ISignalAI": r"\switch Single | switch SingleSafe, signalai Signal, num Condition, num HighValue, num LowValue, "
                 r"num DeltaValue, \switch DPos | switch DNeg, intnum Interrupt",
    "ISignalAO": r"\switch Single | switch SingleSafe, signalao Signal, num Condition, num HighValue, num LowValue, "
                 r"num DeltaValue, \switch DPos | switch DNeg, intnum Interrupt",
    "TriggIO": r"INOUT triggdata TriggData, num Distance, \switch Start | switch Time, "
               r"\signaldo DOp | signalgo GOp | signalao AOp | num ProcID, num SetValue, \num DODelay",
    "TriggEquip": r"INOUT triggdata TriggData, num Distance, \switch Start, num EquipLag, "
                  r"\signaldo DOp | signalgo GOp | signalao AOp | num ProcID, num SetValue, \INOUT bool Inhib",
    "TriggInt": r"INOUT triggdata TriggData, num Distance, \switch Start | switch Time, intnum Interrupt",
    "TriggL": r"\switch Conc, robtarget ToPoint, \num ID, speeddata Speed, \num T, triggdata Trigg1, "
              r"\triggdata T2, \triggdata T3, \triggdata T4, \triggdata T5, \triggdata T6, \triggdata T7, "
              r"\triggdata T8, zonedata Zone, \stoppointdata Inpos, tooldata Tool, \wobjdata WObj, "
              r"\loaddata TLoad",
    "TriggJ": r"\switch Conc, robtarget ToPoint, \num ID, speeddata Speed, \num T, triggdata Trigg1, "
              r"\triggdata T2, \triggdata T3, \triggdata T4, \triggdata T5, \triggdata T6, \triggdata T7, "
              r"\triggdata T8, zonedata Zone, \stoppointdata Inpos, tooldata Tool, \wobjdata WObj, "
              r"\loaddata TLoad",
    "SpyStart": "string File",
    "SpyStop": "",
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
    "GInput": ("signalgi Signal", "num"),
    "AInput": ("signalai Signal", "num"),
    "StrFind": (r"string Str, num ChPos, string Set, \switch NotInSet", "num"),
    "StrMatch": ("string Str, num ChPos, string Pattern", "num"),
    "StrMemb": ("string Str, num ChPos, string Set", "bool"),
    "StrOrder": ("string Str1, string Str2, string Order", "bool"),
    "StrMap": ("string Str, string FromMap, string ToMap", "string"),
    "StrToVal": ("string Str, INOUT any Val", "bool"),
    "StrToByte": ("string ConStr, " + _FMT, "byte"),
    "ByteToStr": ("byte BitData, " + _FMT, "string"),
    "DnumToStr": (r"dnum Val, num Dec, \switch Exp", "string"),
    "NumToDnum": ("num Value", "dnum"),
    "DnumToNum": (r"dnum Value, \switch Integer", "num"),
    "DecToHex": ("string Str", "string"),
    "HexToDec": ("string Str", "string"),
    "BitAnd": ("byte BitData1, byte BitData2", "byte"),
    "BitOr": ("byte BitData1, byte BitData2", "byte"),
    "BitXOr": ("byte BitData1, byte BitData2", "byte"),
    "BitNeg": ("byte BitData", "byte"),
    "BitLSh": ("byte BitData, num ShiftSteps", "byte"),
    "BitRSh": ("byte BitData, num ShiftSteps", "byte"),
    "BitCheck": ("byte BitData, num BitPos", "bool"),
    "GetSysInfo": (r"\switch SerialNo | switch SWVersion | switch RobotType | switch CtrlId | switch LanIp "
                   r"| switch CtrlLang | switch SystemName", "string"),
    "GetTime": (r"\switch WDay | switch Hour | switch Min | switch Sec", "num"),
    "CDate": ("", "string"),
    "CTime": ("", "string"),
    "OpMode": ("", "symnum"),
    "RunMode": (r"\num TaskRef", "symnum"),
    "IsStopMoveAct": (r"\switch FromMoveTask | switch FromNonMoveTask", "bool"),
    "GetTaskName": (r"\INOUT num TaskNo, \switch MecTaskNo", "string"),
    "RobOS": ("", "bool"),
    "TaskRunRob": ("", "bool"),
    "TaskRunMec": ("", "bool"),
    "IsMechUnitActive": ("mecunit MechUnit", "bool"),
    "CSpeedOverride": (r"\switch CTask", "num"),
    "MaxRobSpeed": ("", "num"),
    "PoseMult": ("pose Pose1, pose Pose2", "pose"),
    "PoseInv": ("pose Pose", "pose"),
    "PoseVect": ("pose Pose, pos Pos", "pos"),
    "DefFrame": (r"robtarget OriginP1, robtarget OriginP2, robtarget OriginP3, \num Origin", "pose"),
    "CPos": (r"\tooldata Tool, \wobjdata WObj", "pos"),
    "CTool": ("", "tooldata"),
    "CalcJointT": (r"\switch UseCurWObjPos, robtarget Rob_target, tooldata Tool, \wobjdata WObj", "jointtarget"),
    "CalcRobT": (r"jointtarget Joint_target, tooldata Tool, \wobjdata WObj", "robtarget"),
    "CWObj": ("", "wobjdata"),
    "VectMagn": ("pos Vector", "num"),
    "DotProd": ("pos Vector1, pos Vector2", "num"),
    "NOrient": ("orient Rotation", "orient"),
    "SocketGetStatus": ("socketdev Socket", "socketstatus"),
    "SocketPeek": ("socketdev Socket", "num"),
    "GetMotorTorque": (r"\mecunit MecUnit, num AxisNo", "num"),
    "ReadDir": ("dir Dev, INOUT string FileName", "bool"),
    "RawBytesLen": ("rawbytes RawData", "num"),
    "TestAndSet": ("INOUT bool Object", "bool"),
    "ReadStr": (r"iodev IODevice, \string Delim, \switch RemoveCR, \switch DiscardHeaders, \num Time", "string"),
    "ReadNum": (r"iodev IODevice, \string Delim, \num Time", "num"),
    "IsFile": (r"string Path, \switch Directory | switch Fifo | switch RegFile | switch BlockSpec "
               r"| switch CharSpec", "bool"),
    "UIMessageBox": (r"\string Header, \string Message | string{} MsgArray, \switch Wrap, \num Buttons | "
                     r"string{} BtnArray, \num DefaultBtn, \num Icon, \string Image, " + _UI_BREAK, "btnres"),
    "UINumEntry": (r"\string Header, \string Message | string{} MsgArray, \switch Wrap, \num Icon, "
                   r"\num InitValue, \num MinValue, \num MaxValue, \switch AsInteger, " + _UI_BREAK, "num"),
    "UIAlphaEntry": (r"\string Header, \string Message | string{} MsgArray, \switch Wrap, \num Icon, "
                     r"\string InitString, " + _UI_BREAK, "string"),
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


def zone_names() -> set[str]:
    """The predefined zonedata names (fine, z0 ... z200)."""
    return set(_zones())
