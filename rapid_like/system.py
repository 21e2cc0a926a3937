"""Built-ins beyond motion and plain I/O, as a mixin of the evaluator: FlexPendant dialogs answered
from a script, the event log (ErrWrite), ExitCycle, interrupt orders, path control, system and time
functions, group and analog I/O waits, pose maths, bits, strings and rawbytes.

Values in simulation (documented in docs/rapid.md):
- dialogs (TPReadFK, TPReadNum, UIMessageBox, UIMsgBox, UINumEntry, UIAlphaEntry) take the next
  `--answer` value; with none left a dialog with \\MaxTime times out after it (ERR_TP_MAXTIME), one
  without is the runtime error ERR_TP_NO_CLIENT naming the dialog;
- OpMode() is OP_AUTO, RunMode() RUN_CONT_CYCLE, RobOS() FALSE (not a real controller);
- CDate/CTime/GetTime count simulated time from 2024-01-01 00:00:00 (a Monday);
- GetSysInfo(\\LanIp) is 127.0.0.1 (sockets bound to it are reachable on loopback).
"""
from __future__ import annotations

import datetime
import math
import os

from . import builtins as B
from . import nodes as n
from . import strings as S
from .runtime import ExitCycleSignal, Frame, Ref, Wait, to_ns
from .values import (json_num, Aggregate, Opaque, RawBytes, Record, coerce, fmt_num, format_value, pos, record, xyz)

SYSINFO = {"serialno": "rapid_like-0001", "swversion": "rapid_like", "robottype": "simulated robot",
           "ctrlid": "rapid_like", "lanip": "127.0.0.1", "ctrllang": "en", "systemname": "rapid_like"}
_BUTTONS = {  # buttondata -> the btnres of each button, in order
    -1: [], 0: ["resOK"], 1: ["resAbort", "resRetry", "resIgnore"], 2: ["resOK", "resCancel"],
    3: ["resRetry", "resCancel"], 4: ["resYes", "resNo"], 5: ["resYes", "resNo", "resCancel"]}


class SystemMixin:
    # ---- FlexPendant dialogs ---------------------------------------------------------------------
    def _answer(self, s, what: str, arg, bound):
        """The next --answer for a dialog, or None after \\MaxTime when there is none (a generator)."""
        if self.answers:
            return self.answers.pop(0)
        maxtime = arg("maxtime")
        if maxtime is None:
            raise self.fail(f"{what}: no answer for this FlexPendant dialog (give one with --answer, or in the "
                            f"station's controller answers)", s.span, "ERR_TP_NO_CLIENT")
        until = self.now + to_ns(maxtime)
        while self.now < until:
            yield from self.pause(Wait("time", until, what, s.span))
        flag = arg("breakflag")
        if flag is not None:
            flag.set(float(B.ERRORS["ERR_TP_MAXTIME"]))
            return None
        raise self.fail(f"{what}: no answer within \\MaxTime", s.span, "ERR_TP_MAXTIME")

    def _dialog_event(self, instr: str, text: str, answer: object) -> None:
        self.emit({"type": "dialog", "instr": instr, "text": text,
                   "answer": json_num(answer) if isinstance(answer, float) else answer})

    def i_tpreadfk(self, s, arg, text, bound):
        keys = [arg(f"tpfk{i}") for i in range(1, 6)]
        prompt = arg("tptext")
        answer = yield from self._answer(s, f'TPReadFK "{prompt}"', arg, bound)
        if answer is None:
            arg("tpanswer").set(0.0)
            return
        choice = None
        if answer.strip().isdigit() and 1 <= int(answer) <= 5:
            choice = int(answer)
        else:
            for i, k in enumerate(keys, 1):
                if k and k.strip().lower() == answer.strip().lower():
                    choice = i
        if choice is None or not keys[choice - 1]:
            offered = ", ".join(f"{i}={k}" for i, k in enumerate(keys, 1) if k)
            raise self.fail(f'TPReadFK "{prompt}": the answer {answer!r} is not one of its keys ({offered})', s.span,
                            "ERR_ARGVALERR")
        arg("tpanswer").set(float(choice))
        self._dialog_event("TPReadFK", prompt, choice)

    def i_tpreadnum(self, s, arg, text, bound, name="TPReadNum"):
        prompt = arg("tptext")
        answer = yield from self._answer(s, f'{name} "{prompt}"', arg, bound)
        if answer is None:
            return
        value = self._number_answer(s, name, prompt, answer)
        arg("tpanswer").set(value)
        self._dialog_event(name, prompt, value)

    def i_tpreaddnum(self, s, arg, text, bound):
        yield from self.i_tpreadnum(s, arg, text, bound, "TPReadDnum")

    def _number_answer(self, s, name: str, prompt: str, answer: str) -> float:
        try:
            return float(answer)
        except ValueError:
            raise self.fail(f'{name} "{prompt}": the answer {answer!r} is not a number', s.span,
                            "ERR_ARGVALERR") from None

    def _button(self, s, name: str, prompt: str, answer: str, buttons: float | None) -> float:
        consts = B.predefined_data()
        a = answer.strip()
        for k in (a, "res" + a):
            if k.lower() in consts and consts[k.lower()][0] == "btnres":
                return float(consts[k.lower()][1])  # type: ignore[arg-type]
        if a.isdigit():
            choices = _BUTTONS.get(int(buttons if buttons is not None else 0), [])
            if 1 <= int(a) <= len(choices):
                return float(consts[choices[int(a) - 1].lower()][1])  # type: ignore[arg-type]
        raise self.fail(f'{name} "{prompt}": the answer {answer!r} is not a button (resOK, resYes, ... or its '
                        f'number on the dialog)', s.span, "ERR_ARGVALERR")

    def i_uimsgbox(self, s, arg, text, bound):
        prompt = " ".join(x for x in (arg(f"msgline{i}") for i in range(1, 6)) if x)
        answer = yield from self._answer(s, f'UIMsgBox "{prompt}"', arg, bound)
        if answer is None:
            return
        value = self._button(s, "UIMsgBox", prompt, answer, arg("buttons"))
        result = arg("result")
        if result is not None:
            result.set(value)
        self._dialog_event("UIMsgBox", prompt, value)

    def i_tpshow(self, s, arg, text, bound):
        arg("window")
        yield from ()

    # Dialog functions cannot wait (a FUNC cannot): without an answer they fail at once.
    def _function_answer(self, e, what: str):
        if not self.answers:
            raise self.fail(f"{what}: no answer for this FlexPendant dialog (give one with --answer, or in the "
                            f"station's controller answers)", e.span, "ERR_TP_NO_CLIENT")
        return self.answers.pop(0)

    def _message(self, arg) -> str:
        text = arg("message")
        if text is None and arg("msgarray") is not None:
            text = " ".join(arg("msgarray"))
        return text or arg("header") or ""

    def f_uimessagebox(self, e, arg, bound):
        prompt = self._message(arg)
        answer = self._function_answer(e, f'UIMessageBox "{prompt}"')
        btns = arg("btnarray")
        if btns is not None:
            a = answer.strip()
            choice = int(a) if a.isdigit() else next((i for i, b in enumerate(btns, 1) if b.lower() == a.lower()), 0)
            if not 1 <= choice <= len(btns):
                raise self.fail(f'UIMessageBox "{prompt}": the answer {answer!r} is not one of its buttons', e.span,
                                "ERR_ARGVALERR")
            value = float(choice)
        else:
            value = self._button(e, "UIMessageBox", prompt, answer, arg("buttons"))
        self._dialog_event("UIMessageBox", prompt, value)
        return value

    def f_uinumentry(self, e, arg, bound):
        prompt = self._message(arg)
        value = self._number_answer(e, "UINumEntry", prompt, self._function_answer(e, f'UINumEntry "{prompt}"'))
        lo, hi = arg("minvalue"), arg("maxvalue")
        if lo is not None and value < lo:
            raise self.fail(f"UINumEntry: the answer {fmt_num(value)} is below \\MinValue {fmt_num(lo)}", e.span,
                            "ERR_UI_MIN")
        if hi is not None and value > hi:
            raise self.fail(f"UINumEntry: the answer {fmt_num(value)} is above \\MaxValue {fmt_num(hi)}", e.span,
                            "ERR_UI_MAX")
        if arg("asinteger") and value != int(value):
            raise self.fail(f"UINumEntry \\AsInteger: the answer {fmt_num(value)} is not an integer", e.span,
                            "ERR_UI_NOTINT")
        self._dialog_event("UINumEntry", prompt, value)
        return value

    def f_uialphaentry(self, e, arg, bound):
        prompt = self._message(arg)
        answer = self.string(self._function_answer(e, f'UIAlphaEntry "{prompt}"'), e.span)
        self._dialog_event("UIAlphaEntry", prompt, answer)
        return answer

    # ---- event log, cycle ------------------------------------------------------------------------
    def i_errwrite(self, s, arg, text, bound):
        level = "warning" if arg("w") else "info" if arg("i") else "error"
        ev = {"type": "errlog", "level": level, "header": arg("header"), "reason": arg("reason")}
        for k in ("rl2", "rl3", "rl4"):
            if arg(k) is not None:
                ev[k] = arg(k)
        self.emit(ev)
        yield from ()

    def i_skipwarn(self, s, arg, text, bound):
        yield from ()

    def i_exitcycle(self, s, arg, text, bound):
        raise ExitCycleSignal()
        yield  # pragma: no cover

    def i_spystart(self, s, arg, text, bound):
        arg("file")
        yield from ()

    def i_spystop(self, s, arg, text, bound):
        yield from ()

    # ---- interrupts --------------------------------------------------------------------------------
    def _intno(self, arg, bound) -> int:
        return self.interrupts.number(arg("interrupt"), bound["interrupt"].value.span)

    def i_isignaldi(self, s, arg, text, bound):
        no = self._intno(arg, bound)
        trig = arg("triggvalue")
        if trig not in (0, 1, 2):
            raise self.fail(f"{s.name}: TriggValue must be 0, 1 or edge (2), not {fmt_num(trig)}",
                            bound["triggvalue"].value.span, "ERR_ARGVALERR")
        self.interrupts.signal_order(no, arg("signal").name, trig, bool(arg("single") or arg("singlesafe")))
        yield from ()

    i_isignaldo = i_isignaldi

    def i_isignalgi(self, s, arg, text, bound):
        no = self._intno(arg, bound)
        self.interrupts.signal_order(no, arg("signal").name, None, bool(arg("single") or arg("singlesafe")))
        yield from ()

    i_isignalgo = i_isignalgi

    def i_isignalai(self, s, arg, text, bound):
        """ISignalAI/AO: the interrupt occurs when the condition (AIO_ABOVE_HIGH ... AIO_ALWAYS) becomes
        true; DeltaValue, \\DPos and \\DNeg are accepted and not used."""
        no = self._intno(arg, bound)
        cond, high, low = int(arg("condition")), arg("highvalue"), arg("lowvalue")
        tests = {1: lambda v: v > high, 2: lambda v: v < high, 3: lambda v: v > low, 4: lambda v: v < low,
                 5: lambda v: low <= v <= high, 6: lambda v: v < low or v > high, 7: lambda v: True}
        if cond not in tests:
            raise self.fail(f"{s.name}: Condition must be AIO_ABOVE_HIGH ... AIO_ALWAYS (1 to 7), not {cond}",
                            bound["condition"].value.span, "ERR_ARGVALERR")
        self.interrupts.analog_order(no, arg("signal").name, tests[cond], bool(arg("single") or arg("singlesafe")))
        yield from ()

    i_isignalao = i_isignalai

    def i_itimer(self, s, arg, text, bound):
        no = self._intno(arg, bound)
        t = arg("time")
        if t <= 0:
            raise self.fail(f"ITimer needs a time > 0, not {fmt_num(t)}", bound["time"].value.span, "ERR_ARGVALERR")
        self.interrupts.timer_order(no, t, bool(arg("single") or arg("singlesafe")))
        yield from ()

    def i_ipers(self, s, arg, text, bound):
        no = self._intno(arg, bound)
        self.interrupts.pers_order(no, arg("name"))
        yield from ()

    def i_ierror(self, s, arg, text, bound):
        self._intno(arg, bound)
        yield from ()

    def i_idelete(self, s, arg, text, bound):
        self.interrupts.delete(int(arg("interrupt")))
        yield from ()

    def i_isleep(self, s, arg, text, bound):
        self.interrupts.sleep(self._intno(arg, bound), True)
        yield from ()

    def i_iwatch(self, s, arg, text, bound):
        self.interrupts.sleep(self._intno(arg, bound), False)
        yield from ()

    def i_idisable(self, s, arg, text, bound):
        self.interrupts.enabled = False
        yield from ()

    def i_ienable(self, s, arg, text, bound):
        self.interrupts.enabled = True
        yield from ()

    # ---- synchronisation ---------------------------------------------------------------------------
    def i_waittestandset(self, s, arg, text, bound):
        ref = arg("object")
        while ref.get():
            yield from self.pause(Wait("signal", None, f"WaitTestAndSet {text('object')}", s.span))
        ref.set(True)

    def f_testandset(self, e, arg, bound):
        ref = arg("object")
        was = ref.get()
        ref.set(True)
        return not was

    # ---- path control (docs/rapid.md: the host's robot stops on its path, twin.core.planner.PathClock) -------
    def i_stopmove(self, s, arg, text, bound):
        quick = bool(arg("quick"))
        arg("allmotiontasks")
        self.stop_move = True
        stop = getattr(self.host, "stop_path", None)
        if stop is not None:
            stop(quick)
        yield from ()

    def i_startmove(self, s, arg, text, bound):
        for k in bound:
            arg(k)
        self.stop_move = False
        start = getattr(self.host, "start_path", None)
        if start is not None:
            start()
        yield from ()

    i_stopmovereset = i_startmove
    i_startmoveretry = i_startmove

    def _standing(self, s, what: str):
        """Wait until the robot stands on its path (a StopMove's deceleration over)."""
        standing = getattr(self.host, "path_standing", None)
        while standing is not None and not standing():
            at = getattr(self.host, "stand_time", lambda: None)()
            yield from self.pause(Wait("motion", at, f"{what}: the robot stopping on its path", s.span))

    def i_clearpath(self, s, arg, text, bound):
        yield from self._standing(s, "ClearPath")
        clear = getattr(self.host, "clear_path", None)
        if clear is not None:
            clear()

    def i_storepath(self, s, arg, text, bound):
        arg("keepsync")
        stop = getattr(self.host, "stop_path", None)
        if stop is not None and not self.stop_move:  # the motion under way goes on to its end, then stands
            stop(False, True)
        yield from self._standing(s, "StorePath")
        store = getattr(self.host, "store_path", None)
        if store is not None:
            store()
        self.stored_paths.append(self.stop_move)  # the temporary path's motions run
        self.stop_move = False

    def i_restopath(self, s, arg, text, bound):
        if not self.stored_paths:
            raise self.fail("RestoPath: no path is stored (StorePath first)", s.span)
        yield from self._standing(s, "RestoPath")
        restore = getattr(self.host, "restore_path", None)
        if restore is not None:
            restore()
        self.stop_move = self.stored_paths.pop()

    def _accept(self, s, arg, text, bound):
        for k in bound:
            arg(k)
        yield from ()

    i_singarea = i_cirpathmode = i_pathresol = _accept
    i_gripload = i_worldacclim = i_pathacclim = i_pdispoff = i_pdispset = i_eoffsoff = _accept

    i_pdispon = i_eoffsset = i_eoffson = i_waitsynctask = _accept

    def i_searchl(self, s, arg, text, bound):
        """SearchL, approximately: the robot moves to ToPoint; the search hits when the signal is 1 at
        the start or at the end of the motion (SearchPoint := ToPoint), else ERR_WHLSEARCH."""
        sig = arg("signal")
        hit = self.host.read_signal(sig.name) == 1
        yield from self._move(s, arg, text, bound, "MoveL")
        hit = hit or self.host.read_signal(sig.name) == 1
        if not hit:
            raise self.fail(f"SearchL: {sig.name} did not change during the search", s.span, "ERR_WHLSEARCH")
        arg("searchpoint").set(arg("topoint"))

    # ---- triggers: TriggIO/TriggEquip/TriggInt set up, TriggL/TriggJ move and fire them at the end --------
    def _trigg(self, arg, entry) -> None:
        ref = arg("triggdata")
        dev = ref.get()
        dev.state = [entry]  # a triggdata holds the last trigger defined with it

    def i_triggio(self, s, arg, text, bound):
        out = next((arg(k) for k in ("dop", "gop", "aop") if arg(k) is not None), None)
        self._trigg(arg, ("io", out, arg("setvalue"), arg("distance")))
        yield from ()

    i_triggequip = i_triggio

    def i_triggint(self, s, arg, text, bound):
        no = self._intno(arg, bound)
        self._trigg(arg, ("int", no, None, arg("distance")))
        yield from ()

    def _trigg_move(self, s, arg, text, bound, instr: str):
        yield from self._move(s, arg, text, bound, instr)
        for key in ("trigg1", "t2", "t3", "t4", "t5", "t6", "t7", "t8"):
            data = arg(key)
            for kind, target, value, _distance in (data.state or []) if data is not None else []:
                if kind == "io" and target is not None:
                    self.write(target, float(value) if target.kind != "DO" else (0.0 if value == 0 else 1.0))
                elif kind == "int" and target in self.interrupts.traps:
                    self.interrupts.pending.append(target)

    def i_triggl(self, s, arg, text, bound):
        yield from self._trigg_move(s, arg, text, bound, "MoveL")

    def i_triggj(self, s, arg, text, bound):
        yield from self._trigg_move(s, arg, text, bound, "MoveJ")

    # ---- what only real hardware does: runs, and says so once in the event log ----------------------
    def hardware_note(self, s, what: str) -> None:
        """An instruction that only concerns the real robot's hardware: noted once per instruction in the
        event log (an errlog event of level info), never silently."""
        name = B.PROPER_NAMES.get(s.key, s.name)
        if name in self.hardware_noted:
            return
        self.hardware_noted.add(name)
        self.emit({"type": "errlog", "level": "info", "header": f"{name} in simulation",
                   "reason": f"line {s.span.line}: {what}"})

    def i_cornerpathwarning(self, s, arg, text, bound):
        """CornerPathWarning FALSE: no "corner path failure" warning when a zone point becomes a stop point."""
        self.corner_warning = bool(arg("status"))
        yield from ()

    def i_softact(self, s, arg, text, bound):
        self._accept_all(bound, arg)
        self.hardware_note(s, "soft servo changes how the real axes yield to external forces; the twin's arm "
                              "is position-controlled and keeps its stiffness")
        yield from ()

    def i_softdeact(self, s, arg, text, bound):
        self._accept_all(bound, arg)
        self.hardware_note(s, "soft servo is not simulated (the arm keeps its stiffness)")
        yield from ()

    def i_actunit(self, s, arg, text, bound):
        self._accept_all(bound, arg)
        self.hardware_note(s, "the twin has no external mechanical units to activate or deactivate")
        yield from ()

    i_deactunit = i_actunit

    def i_waitwobj(self, s, arg, text, bound):
        """WaitWObj: conveyor tracking waits for an object on the conveyor; the twin has no conveyor, so the
        work object is connected at once, where its frames say (TimeFlag FALSE)."""
        self._accept_all(bound, arg)
        if "timeflag" in bound:
            arg("timeflag").set(False)
        self.hardware_note(s, "the twin has no conveyor: the work object is taken as connected at once, at its "
                              "frames as written")
        yield from ()

    def i_dropwobj(self, s, arg, text, bound):
        self._accept_all(bound, arg)
        self.hardware_note(s, "the twin has no conveyor: nothing to drop")
        yield from ()

    def i_setleadthrough(self, s, arg, text, bound):
        self._accept_all(bound, arg)
        self.hardware_note(s, "lead-through (moving the arm by hand) needs the real arm; the twin's arm stays "
                              "under the program's control")
        yield from ()

    def _accept_all(self, bound, arg) -> None:
        for k in bound:
            arg(k)  # evaluated, for its errors

    def f_getmotortorque(self, e, arg, bound):
        """GetMotorTorque: the axis's torque (N m) as the physics arm's motor applies it now (0 offline)."""
        axis = int(arg("axisno"))
        if not 1 <= axis <= 6:
            raise self.fail(f"GetMotorTorque: AxisNo must be 1 to 6, not {axis}", e.span, "ERR_ARGVALERR")
        torque = getattr(self.host, "motor_torque", None)
        self.changes += 1  # depends on the time
        return float(torque(axis)) if torque is not None else 0.0

    # ---- directories ------------------------------------------------------------------------------
    def i_opendir(self, s, arg, text, bound):
        """OpenDir: the directory's entries, read from disk (HOME:/x is x in the current directory), in name order."""
        path = arg("path")
        local = path.split(":", 1)[1].lstrip("/") if ":" in path[:12] else path
        try:
            names = sorted(os.listdir(local or "."))
        except OSError:
            raise self.fail(f"OpenDir {path}: no such directory", s.span, "ERR_FILEACC") from None
        arg("dev").get().state = {"path": path, "names": names, "pos": 0}
        yield from ()

    def i_closedir(self, s, arg, text, bound):
        arg("dev").state = None
        yield from ()

    def f_readdir(self, e, arg, bound):
        st = arg("dev").state
        if not isinstance(st, dict) or "names" not in st:
            raise self.fail("ReadDir: the directory is not open (OpenDir it first)", e.span, "ERR_FILEACC")
        if st["pos"] >= len(st["names"]):
            return False
        arg("filename").set(st["names"][st["pos"]])
        st["pos"] += 1
        self.changes += 1
        return True

    # ---- files (iodev): written files go to the trace, read ones come from disk -----------------------
    def _path(self, arg) -> str:
        obj, name = arg("object"), arg("file")
        return f"{obj.rstrip('/')}/{name}" if name else obj

    def i_open(self, s, arg, text, bound):
        path = self._path(arg)
        dev = arg("iodevice").get()
        if arg("read"):
            local = path.split(":", 1)[1].lstrip("/") if ":" in path[:12] else path
            written = self.files.get(path)
            try:
                content = written if written is not None else open(local, encoding="latin-1").read()
            except OSError:
                raise self.fail(f"Open {path}: no such file to read", s.span, "ERR_FILEOPEN") from None
            dev.state = {"path": path, "mode": "read", "data": content, "pos": 0}
        else:
            if not arg("append"):
                self.files[path] = ""
            self.files.setdefault(path, "")
            dev.state = {"path": path, "mode": "write", "data": "", "pos": 0}
        yield from ()

    def _dev(self, arg, s, mode: str) -> dict:
        dev = arg("iodevice")
        dev = dev.get() if hasattr(dev, "get") else dev
        st = dev.state
        if not isinstance(st, dict) or st.get("mode") is None:
            raise self.fail("the I/O device is not open (Open it first)", s.span, "ERR_FILEACC")
        if st["mode"] != mode:
            raise self.fail(f"the file {st['path']} is open for {st['mode']}ing", s.span, "ERR_FILEACC")
        return st

    def i_writeanybin(self, s, arg, text, bound):
        """WriteAnyBin: the value, in the file as its RAPID literal on a line of its own (the twin's "binary"
        format: ReadAnyBin reads it back into data of the same type)."""
        st = self._dev(arg, s, "write")
        out = format_value(arg("data")) + "\n"
        self.files[st["path"]] = self.files.get(st["path"], "") + out
        self.emit({"type": "file", "file": st["path"], "text": out})
        yield from ()

    def i_readanybin(self, s, arg, text, bound):
        st = self._dev(arg, s, "read")
        ref = arg("data")
        arg("time")
        data, pos = st["data"], st["pos"]
        if pos >= len(data):
            raise self.fail(f"ReadAnyBin: end of file {st['path']}", s.span, "ERR_RANYBIN_EOF")
        end = data.find("\n", pos)
        end = len(data) if end < 0 else end
        line, st["pos"] = data[pos:end], end + 1
        try:
            ref.set(literal_value(line, ref.type))
        except Exception:  # noqa: BLE001 - text that is not a literal of the data's type
            raise self.fail(f"ReadAnyBin: {line[:40]!r} in {st['path']} is not {ref.type} data", s.span,
                            "ERR_RANYBIN_EOF") from None
        yield from ()

    def i_write(self, s, arg, text, bound):
        st = self._dev(arg, s, "write")
        out = arg("string")
        for k in ("num", "bool", "pos", "orient", "dnum"):
            v = arg(k)
            if v is not None:
                out += format_value(v)
        if not arg("nonewline"):
            out += "\n"
        self.files[st["path"]] = self.files.get(st["path"], "") + out
        self.emit({"type": "file", "file": st["path"], "text": out})
        yield from ()

    def i_close(self, s, arg, text, bound):
        arg("iodevice").get().state = None
        yield from ()

    def i_rewind(self, s, arg, text, bound):
        st = arg("iodevice").get().state
        if isinstance(st, dict):
            st["pos"] = 0
        yield from ()

    def f_readstr(self, e, arg, bound):
        st = self._dev(arg, e, "read")
        data, i = st["data"], st["pos"]
        if i >= len(data):
            return "EOF"
        j = data.find("\n", i)
        j = len(data) if j < 0 else j
        delim = arg("delim")
        if delim:
            k = S.str_find(data[i:j], 1, delim) - 1 + i
            j = min(j, k)
        line = data[i:j]
        st["pos"] = j + 1
        if arg("removecr"):
            line = line.rstrip("\r")
        return line[:80]

    def f_readnum(self, e, arg, bound):
        text = self.f_readstr(e, arg, bound)
        if text == "EOF":
            return 9.998e36  # the manual's EOF_NUM
        try:
            return float(text.strip().split()[0])
        except (ValueError, IndexError):
            raise self.fail(f"ReadNum: {text!r} is not a number", e.span, "ERR_RCVDATA") from None

    def f_isfile(self, e, arg, bound):
        import os
        path = arg("path")
        local = path.split(":", 1)[1].lstrip("/") if ":" in path[:12] else path
        return path in self.files or os.path.exists(local)

    # ---- group and analog waits --------------------------------------------------------------------
    def _compare(self, arg):
        value = arg("value")
        if arg("noteq"):
            return lambda v: v != value
        if arg("lt"):
            return lambda v: v < value
        if arg("gt"):
            return lambda v: v > value
        return lambda v: v == value

    def i_waitgi(self, s, arg, text, bound, name="WaitGI"):
        sig, test = arg("signal"), self._compare(arg)
        yield from self._wait_cond(s, arg, bound, lambda: test(self.host.read_signal(sig.name)), f"{name} {sig.name}",
                                   None)

    def i_waitgo(self, s, arg, text, bound):
        yield from self.i_waitgi(s, arg, text, bound, "WaitGO")

    def i_waitai(self, s, arg, text, bound, name="WaitAI"):
        sig, test = arg("signal"), self._compare(arg)
        at_timeout = arg("valueattimeout")
        maxtime = arg("maxtime")
        deadline = None if maxtime is None else self.now + to_ns(maxtime)
        while not test(self.host.read_signal(sig.name)):
            if deadline is not None and self.now >= deadline:
                if at_timeout is not None:
                    at_timeout.set(float(self.host.read_signal(sig.name)))
                raise self.fail(f"{name} {sig.name} timed out: \\MaxTime of {fmt_num(maxtime)} s ran out", s.span,
                                "ERR_WAIT_MAXTIME")
            yield from self.pause(Wait("signal", deadline, f"{name} {sig.name}", s.span))

    def i_waitao(self, s, arg, text, bound):
        yield from self.i_waitai(s, arg, text, bound, "WaitAO")

    # ---- bits -----------------------------------------------------------------------------------
    def _bit(self, bound, arg, key="bitpos") -> int:
        p = arg(key)
        if p != int(p) or not 1 <= p <= 8:
            raise self.fail(f"a bit position is 1 to 8, not {fmt_num(p)}", bound[key].value.span, "ERR_ARGVALERR")
        return int(p) - 1

    def i_bitset(self, s, arg, text, bound):
        ref = arg("bitdata")
        ref.set(float(int(ref.get()) | (1 << self._bit(bound, arg))))
        yield from ()

    def i_bitclear(self, s, arg, text, bound):
        ref = arg("bitdata")
        ref.set(float(int(ref.get()) & ~(1 << self._bit(bound, arg)) & 0xFF))
        yield from ()

    def f_bitcheck(self, e, arg, bound):
        return bool(int(arg("bitdata")) >> self._bit(bound, arg) & 1)

    # ---- rawbytes --------------------------------------------------------------------------------
    def _raw(self, value) -> RawBytes:
        if isinstance(value, Ref):
            value = value.get()
        return value.state  # type: ignore[union-attr]

    def i_clearrawbytes(self, s, arg, text, bound):
        raw = self._raw(arg("rawdata"))
        start = arg("fromindex", 1.0)
        del raw.data[max(int(start) - 1, 0):]
        yield from ()

    def i_packrawbytes(self, s, arg, text, bound):
        raw = self._raw(arg("rawdata"))
        value = arg("value")
        start = int(arg("startindex"))
        intx = arg("intx")
        try:
            data = S.pack(value, int(intx) if intx is not None else None, bool(arg("float4")), bool(arg("hex1")),
                          bool(arg("network")))
        except (ValueError, TypeError, OverflowError) as exc:
            raise self.fail(f"PackRawBytes: {exc}", s.span, "ERR_ARGVALERR") from None
        if not 1 <= start <= len(raw.data) + 1 or start - 1 + len(data) > S.RAWBYTES_MAX:
            raise self.fail(f"PackRawBytes: StartIndex {start} is outside the rawbytes (length {len(raw.data)}, "
                            f"at most {S.RAWBYTES_MAX})", bound["startindex"].value.span, "ERR_OUTOFBND")
        raw.data[start - 1:start - 1 + len(data)] = data
        yield from ()

    def i_unpackrawbytes(self, s, arg, text, bound):
        raw = self._raw(arg("rawdata"))
        start = int(arg("startindex"))
        target = arg("value")
        intx, ascii_len = arg("intx"), arg("ascii")
        try:
            value = S.unpack(raw.data, start, int(intx) if intx is not None else None, bool(arg("float4")),
                             int(ascii_len) if ascii_len is not None else None, bool(arg("hex1")),
                             bool(arg("network")))
        except IndexError:
            raise self.fail(f"UnpackRawBytes: bytes from {start} are outside the rawbytes (length {len(raw.data)})",
                            bound["startindex"].value.span, "ERR_OUTOFBND") from None
        except ValueError as exc:
            raise self.fail(f"UnpackRawBytes: {exc}", s.span, "ERR_ARGVALERR") from None
        target.set(self.coerce(value, target.type, bound["value"].value.span))
        yield from ()

    def i_copyrawbytes(self, s, arg, text, bound):
        src, dst = self._raw(arg("fromrawdata")), self._raw(arg("torawdata"))
        i, j = int(arg("fromindex")) - 1, int(arg("toindex")) - 1
        count = arg("noofbytes")
        chunk = src.data[i:] if count is None else src.data[i:i + int(count)]
        if j > len(dst.data) or j + len(chunk) > S.RAWBYTES_MAX:
            raise self.fail("CopyRawBytes: ToIndex is outside the rawbytes", bound["toindex"].value.span,
                            "ERR_OUTOFBND")
        dst.data[j:j + len(chunk)] = chunk
        yield from ()

    def f_rawbyteslen(self, e, arg, bound):
        return float(len(self._raw(arg("rawdata")).data))

    # ---- system and time functions -----------------------------------------------------------------
    def _clock(self) -> datetime.datetime:
        self.changes += 1  # depends on the time
        return datetime.datetime(*B.SIMULATED_DATE) + datetime.timedelta(microseconds=self.now // 1000)

    def f_cdate(self, e, arg, bound):
        return self._clock().strftime("%Y-%m-%d")

    def f_ctime(self, e, arg, bound):
        return self._clock().strftime("%H:%M:%S")

    def f_gettime(self, e, arg, bound):
        t = self._clock()
        if arg("wday"):
            return float(t.isoweekday())
        if arg("hour"):
            return float(t.hour)
        if arg("min"):
            return float(t.minute)
        if arg("sec"):
            return float(t.second)
        raise self.fail("GetTime needs one of \\WDay, \\Hour, \\Min or \\Sec", e.span, "ERR_ARGVALERR")

    def f_getsysinfo(self, e, arg, bound):
        for k in bound:
            return SYSINFO.get(k, "")
        return SYSINFO["serialno"]

    def f_opmode(self, e, arg, bound):
        return float(B.predefined_data()["op_auto"][1])  # type: ignore[arg-type]

    def f_runmode(self, e, arg, bound):
        return float(B.predefined_data()["run_cont_cycle"][1])  # type: ignore[arg-type]

    def f_isstopmoveact(self, e, arg, bound):
        return self.stop_move

    def f_gettaskname(self, e, arg, bound):
        no = arg("taskno")
        if no is not None:
            no.set(1.0)
        return "T_ROB1"

    def f_robos(self, e, arg, bound):
        return False

    def f_taskrunrob(self, e, arg, bound):
        return True

    f_taskrunmec = f_taskrunrob

    def f_ismechunitactive(self, e, arg, bound):
        return True

    def f_cspeedoverride(self, e, arg, bound):
        return 100.0

    def f_maxrobspeed(self, e, arg, bound):
        return 5000.0

    # ---- I/O ---------------------------------------------------------------------------------------
    def f_ginput(self, e, arg, bound):
        return float(self.host.read_signal(arg("signal").name))

    f_ainput = f_ginput

    # ---- pose maths --------------------------------------------------------------------------------
    def f_posemult(self, e, arg, bound):
        return _pose_record(B.pose_mul(B.pose_of(arg("pose1")), B.pose_of(arg("pose2"))))

    def f_poseinv(self, e, arg, bound):
        return _pose_record(B.pose_inv(B.pose_of(arg("pose"))))

    def f_posevect(self, e, arg, bound):
        t, q = B.pose_of(arg("pose"))
        d = B.qrotate(q, list(xyz(arg("pos"))))
        return pos(*(B._clean(t[i] + d[i]) for i in range(3)))

    def f_defframe(self, e, arg, bound):
        p1, p2, p3 = (list(xyz(arg(k).fields["trans"])) for k in ("originp1", "originp2", "originp3"))
        origin = int(arg("origin", 1.0))
        x = _unit([b - a for a, b in zip(p1, p2)])
        v = [c - a for a, c in zip(p1, p3)]
        along = sum(a * b for a, b in zip(v, x))
        y = _unit([vi - along * xi for vi, xi in zip(v, x)])
        if x is None or y is None:
            raise self.fail("DefFrame: the three points are on one line", e.span, "ERR_FRAME")
        z = [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]
        o = p1 if origin != 2 else [a + along * xi for a, xi in zip(p1, x)]
        return _pose_record((o, _quat_from_axes(x, y, z)))

    def f_calcjointt(self, e, arg, bound):
        """CalcJointT without kinematics: the present joints (rapid check warns)."""
        return self.host.current_jointtarget()

    def f_calcrobt(self, e, arg, bound):
        """CalcRobT without kinematics: the present TCP of the tool (rapid check warns)."""
        return self.host.current_robtarget(arg("tool"), arg("wobj"))

    def f_cpos(self, e, arg, bound):
        return self.host.current_robtarget(arg("tool"), arg("wobj")).fields["trans"]

    def f_ctool(self, e, arg, bound):
        return self.active_tool.copy()

    def f_cwobj(self, e, arg, bound):
        return self.active_wobj.copy()

    def f_vectmagn(self, e, arg, bound):
        return math.sqrt(sum(c * c for c in xyz(arg("vector"))))

    def f_dotprod(self, e, arg, bound):
        return sum(a * b for a, b in zip(xyz(arg("vector1")), xyz(arg("vector2"))))

    def f_norient(self, e, arg, bound):
        o = arg("rotation")
        q = [o.fields[k] for k in ("q1", "q2", "q3", "q4")]
        norm = math.sqrt(sum(c * c for c in q)) or 1.0
        return Record("orient", dict(zip(("q1", "q2", "q3", "q4"), (c / norm for c in q))))

    # ---- strings and bytes ---------------------------------------------------------------------------
    def _chpos(self, e, bound, arg, s: str) -> int:
        p = arg("chpos")
        if p != int(p) or not 1 <= p <= len(s) + 1:
            raise self.fail(f"{e.name}: ChPos {fmt_num(p)} is outside the string (1 to {len(s) + 1})",
                            bound["chpos"].value.span, "ERR_OUTOFBND")
        return int(p)

    def f_strfind(self, e, arg, bound):
        s = arg("str")
        return float(S.str_find(s, self._chpos(e, bound, arg, s), arg("set"), bool(arg("notinset"))))

    def f_strmatch(self, e, arg, bound):
        s = arg("str")
        return float(S.str_match(s, self._chpos(e, bound, arg, s), arg("pattern")))

    def f_strmemb(self, e, arg, bound):
        s = arg("str")
        p = self._chpos(e, bound, arg, s)
        return p <= len(s) and s[p - 1] in arg("set")

    def f_strorder(self, e, arg, bound):
        return S.str_order(arg("str1"), arg("str2"), arg("order"))

    def f_strmap(self, e, arg, bound):
        return S.str_map(arg("str"), arg("frommap"), arg("tomap"))

    def f_strtoval(self, e, arg, bound):
        ref = arg("val")
        try:
            value = literal_value(arg("str"), ref.type)
        except Exception:  # noqa: BLE001 - any text that is not a literal of the type gives FALSE
            return False
        ref.set(value)
        self.changes += 1
        return True

    def _byte_format(self, arg) -> str:
        return next((k for k in ("hex", "okt", "bin", "char") if arg(k)), "dec")

    def f_strtobyte(self, e, arg, bound):
        try:
            return float(S.str_to_byte(arg("constr"), self._byte_format(arg)))
        except ValueError as exc:
            raise self.fail(f"StrToByte: {exc}", e.span, "ERR_ARGVALERR") from None

    def f_bytetostr(self, e, arg, bound):
        return S.byte_to_str(int(arg("bitdata")), self._byte_format(arg))

    def f_dnumtostr(self, e, arg, bound):
        return self.string(B.num_to_str(arg("val"), arg("dec"), bool(arg("exp"))), e.span)

    def f_numtodnum(self, e, arg, bound):
        return arg("value")

    def f_dnumtonum(self, e, arg, bound):
        v = arg("value")
        return float(int(v)) if arg("integer") else v

    def f_dectohex(self, e, arg, bound):
        try:
            return f"{int(arg('str')):X}"
        except ValueError:
            raise self.fail(f"DecToHex: {arg('str')!r} is not a decimal number", e.span, "ERR_ARGVALERR") from None

    def f_hextodec(self, e, arg, bound):
        try:
            return str(int(arg("str"), 16))
        except ValueError:
            raise self.fail(f"HexToDec: {arg('str')!r} is not a hexadecimal number", e.span, "ERR_ARGVALERR") from None

    def _bits(self, arg, *keys) -> list[int]:
        return [int(arg(k)) & 0xFF for k in keys]

    def f_bitand(self, e, arg, bound):
        a, b = self._bits(arg, "bitdata1", "bitdata2")
        return float(a & b)

    def f_bitor(self, e, arg, bound):
        a, b = self._bits(arg, "bitdata1", "bitdata2")
        return float(a | b)

    def f_bitxor(self, e, arg, bound):
        a, b = self._bits(arg, "bitdata1", "bitdata2")
        return float(a ^ b)

    def f_bitneg(self, e, arg, bound):
        return float(~int(arg("bitdata")) & 0xFF)

    def f_bitlsh(self, e, arg, bound):
        return float((int(arg("bitdata")) << int(arg("shiftsteps"))) & 0xFF)

    def f_bitrsh(self, e, arg, bound):
        return float((int(arg("bitdata")) & 0xFF) >> int(arg("shiftsteps")))


def literal_value(text: str, t: str) -> object:
    """A RAPID literal (`12.5`, `TRUE`, `"abc"`, `[1,2,3]`) as a value of type `t` (StrToVal)."""
    from .parser import Parser
    from .lexer import lex

    p = Parser(lex(text, "<StrToVal>"), text, "<StrToVal>")
    e = p.expression()
    if p.tok.kind.name != "EOF":
        raise ValueError(text)

    def value(x: n.Expr) -> object:
        if isinstance(x, (n.NumLit, n.StrLit, n.BoolLit)):
            return x.value
        if isinstance(x, n.Unary) and x.op in "+-" and isinstance(x.operand, n.NumLit):
            return -x.operand.value if x.op == "-" else x.operand.value
        if isinstance(x, n.Aggregate):
            return Aggregate(value(i) for i in x.items)
        raise ValueError(text)
    return coerce(value(e), t)


def _unit(v: list[float]) -> list[float] | None:
    norm = math.sqrt(sum(c * c for c in v))
    return [c / norm for c in v] if norm > 1e-9 else None


def _quat_from_axes(x, y, z) -> list[float]:
    """The quaternion [q1..q4] of the rotation whose columns are the axes x, y, z."""
    m00, m10, m20 = x
    m01, m11, m21 = y
    m02, m12, m22 = z
    tr = m00 + m11 + m22
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = [0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s]
    elif m00 > m11 and m00 > m22:
        s = math.sqrt(1.0 + m00 - m11 - m22) * 2
        q = [(m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s]
    elif m11 > m22:
        s = math.sqrt(1.0 + m11 - m00 - m22) * 2
        q = [(m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s]
    else:
        s = math.sqrt(1.0 + m22 - m00 - m11) * 2
        q = [(m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s]
    if q[0] < 0:
        q = [-c for c in q]
    return q


def _pose_record(p) -> Record:
    t, q = p
    return record("pose", [B._clean(c) for c in t], [B._clean(c) for c in q])
