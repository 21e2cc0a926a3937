"""Built-in instructions and functions as the evaluator runs them: signals, waits, pulses, motions,
TPWrite, clocks, and the functions that need the host or the calling frame (CRobT, Present, ...).

A mixin of `Interpreter`, kept apart so the evaluator's core (statements, expressions, ERROR
handlers) reads on its own. Each instruction `i_<name>` is a generator: those that wait yield a
`Wait` (a time, a poll, a signal, a motion, Stop); the others return at once. Arguments arrive
matched to the instruction's signature (`builtins.INSTRUCTIONS`): `arg(name)` evaluates one (a
value, a SignalRef, or a Ref for INOUT), `text(name)` gives it as written (for motion traces).
"""
from __future__ import annotations

import math
from typing import Callable

from . import builtins as B
from . import nodes as n
from .host import MotionRequest
from .runtime import ABSENT, PULSE, SDELAY, Frame, Wait, to_ns
from .values import SIGNAL_TYPES, Record, fmt_num, format_value, json_num, xyz


class InstructionsMixin:
    """Built-ins for `Interpreter` (which provides eval, coerce, lvalue, signal_arg, write, fail, host, now)."""

    # ---- built-in functions ---------------------------------------------------------------------
    def builtin_function(self, e: n.Call, f: Frame) -> object:
        key = e.key
        if key not in B.FUNCTIONS:
            raise self.fail(f"unknown function '{e.name}'", e.span)
        params, rtype = B.FUNCTIONS[key]
        bound = self.match(e.name, params, e.args, f, e.span)
        ptable = B.FUNCTION_PARAMS[key]

        def arg(name: str, default: object = None) -> object:
            a = bound.get(name)
            if a is None:
                return default
            ptype = ptable[name].type
            if ptype == "switch":
                return True
            if ptype in SIGNAL_TYPES:
                return self.signal_arg(a.value, f, SIGNAL_TYPES[ptype])
            if ptable[name].mode == "INOUT":
                return self.lvalue(a.value, f)  # type: ignore[arg-type]
            if ptype == "any":
                return self.eval(a.value, f)  # type: ignore[arg-type]
            return self.coerce(self.eval(a.value, f), ptype, a.value.span)  # type: ignore[union-attr]

        names = [p.key for p in params]
        if key == "present":
            a = bound["optpar"].value
            if not isinstance(a, n.Name) or a.key not in f.vars:
                raise self.fail("Present needs the name of an optional parameter", a.span if a else e.span)
            return f.vars[a.key].get() is not ABSENT
        if key == "crobt":
            return self.host.current_robtarget(arg("tool"), arg("wobj"))
        if key == "cjointt":
            return self.host.current_jointtarget()
        if key in ("doutput", "dinput", "aoutput", "goutput"):
            return float(self.host.read_signal(arg("signal").name))  # type: ignore[union-attr]
        if key == "testdi":
            return self.host.read_signal(arg("signal").name) == 1  # type: ignore[union-attr]
        impl = getattr(self, "f_" + key, None)
        if impl is not None:
            try:
                return impl(e, arg, bound)
            except (ValueError, OverflowError) as exc:
                raise self.fail(f"{e.name}: {exc}", e.span, "ERR_ARGVALERR") from None
        vals = [arg(k) for k in names]
        x = vals[0] if vals else None
        try:
            if key == "offs":
                return B.offs(*vals)
            if key == "reltool":
                return B.rel_tool(vals[0], vals[1], vals[2], vals[3], *(v or 0.0 for v in vals[4:]))
            if key == "abs":
                return abs(x)
            if key == "round":
                return B.rapid_round(x, arg("dec", 0.0))
            if key == "trunc":
                return B.rapid_trunc(x, arg("dec", 0.0))
            if key == "sqrt":
                if x < 0:
                    raise self.fail(f"Sqrt of a negative number ({fmt_num(x)})", e.span, "ERR_ARGVALERR")
                return math.sqrt(x)
            if key == "pow":
                return float(math.pow(vals[0], vals[1]))
            if key == "exp":
                return math.exp(x)
            if key == "sin":
                return _clean(math.sin(math.radians(x)))
            if key == "cos":
                return _clean(math.cos(math.radians(x)))
            if key == "tan":
                return _clean(math.tan(math.radians(x)))
            if key == "atan":
                return math.degrees(math.atan(x))
            if key == "atan2":
                return math.degrees(math.atan2(vals[0], vals[1]))
            if key in ("asin", "acos"):
                if not -1 <= x <= 1:
                    raise self.fail(f"{e.name} of {fmt_num(x)}: the value must be -1 to 1", e.span,
                                    "ERR_ARGVALERR")
                return _clean(math.degrees(math.asin(x) if key == "asin" else math.acos(x)))
            if key == "orientzyx":
                return B.orient_zyx(vals[0], vals[1], vals[2])
            if key == "eulerzyx":
                axis = "x" if "x" in bound else "y" if "y" in bound else "z" if "z" in bound else None
                if axis is None:
                    raise self.fail("EulerZYX needs one of \\X, \\Y or \\Z", e.span, "ERR_ARGVALERR")
                return B.euler_zyx(axis, arg("rotation"))
            if key == "numtostr":
                return self.string(B.num_to_str(vals[0], vals[1], bool(vals[2])), e.span)
            if key == "valtostr":
                return self.string(format_value(x), e.span)
            if key == "strlen":
                return float(len(x))
            if key == "strpart":
                s, start, length = vals[0], int(vals[1]), int(vals[2])
                if start < 1 or length < 0 or start - 1 + length > len(s):
                    raise self.fail(f"StrPart: characters {start} to {start + length - 1} are outside the "
                                    f"string of length {len(s)}", e.span, "ERR_OUTOFBND")
                return s[start - 1:start - 1 + length]
            if key == "dist":
                return B.dist(vals[0], vals[1])
            if key == "clkread":
                self.changes += 1  # depends on the time
                return x.read(self.now)
            if key == "dim":
                sizes = x.sizes() if isinstance(x, list) and hasattr(x, "sizes") else []
                d = int(vals[1])
                if not 1 <= d <= len(sizes):
                    raise self.fail(f"Dim: the array has {len(sizes)} dimension(s), not {fmt_num(vals[1])}",
                                    e.span, "ERR_OUTOFBND")
                return float(sizes[d - 1])
        except (ValueError, OverflowError) as exc:
            raise self.fail(f"{e.name}: {exc}", e.span, "ERR_ARGVALERR") from None
        raise self.fail(f"function {e.name} is not implemented", e.span)  # pragma: no cover

    # ---- instructions ---------------------------------------------------------------------------
    def builtin_instruction(self, s: n.ProcCall, f: Frame):
        key = s.key
        if key not in B.INSTRUCTIONS:
            raise self.fail(f"unknown instruction or procedure '{s.name}'", s.span)
        params = B.INSTRUCTIONS[key]
        bound = self.match(s.name, params, s.args, f, s.span)
        ptable = B.INSTRUCTION_PARAMS[key]

        def arg(name: str, default: object = None) -> object:
            a = bound.get(name)
            if a is None:
                return default
            p = ptable[name]
            if p.type == "switch":
                return True
            if p.type in SIGNAL_TYPES:
                return self.signal_arg(a.value, f, SIGNAL_TYPES[p.type])
            if p.mode == "INOUT":
                self.changes += 1  # the instruction may change the variable
                return self.lvalue(a.value, f)  # type: ignore[arg-type]
            if p.type == "any":
                return self.eval(a.value, f)  # type: ignore[arg-type]
            return self.coerce(self.eval(a.value, f), p.type, a.value.span)  # type: ignore[union-attr]

        def text(name: str, default: str = "") -> str:
            a = bound.get(name)
            return a.value.text if a is not None and a.value is not None else default

        arg.frame = f  # type: ignore[attr-defined]
        yield from getattr(self, "i_" + key)(s, arg, text, bound)

    # Each i_* is a generator (instructions that wait yield; the others return at once).
    def i_incr(self, s, arg, text, bound):
        ref = arg("name")
        ref.set(ref.get() + 1)
        yield from ()

    def i_decr(self, s, arg, text, bound):
        ref = arg("name")
        ref.set(ref.get() - 1)
        yield from ()

    def i_add(self, s, arg, text, bound):
        ref = arg("name")
        ref.set(ref.get() + arg("addvalue"))
        yield from ()

    def i_bookerrno(self, s, arg, text, bound):
        arg("errorname").set(float(self.next_user_errno))
        self.next_user_errno += 1
        yield from ()

    def i_clkreset(self, s, arg, text, bound):
        clock = arg("clock").get()
        clock.elapsed, clock.started = 0, (self.now if clock.started is not None else None)
        yield from ()

    def i_clkstart(self, s, arg, text, bound):
        clock = arg("clock").get()
        if clock.started is None:
            clock.started = self.now
        yield from ()

    def i_clkstop(self, s, arg, text, bound):
        clock = arg("clock").get()
        if clock.started is not None:
            clock.elapsed += self.now - clock.started
            clock.started = None
        yield from ()

    def i_setdo(self, s, arg, text, bound):
        """SetDO takes a dionum: as the RAPID manual's table says, 0 sets the output to 0 and any
        other value sets it to 1 (the trace shows the value the output gets: 0 or 1)."""
        sig, value, delay = arg("signal"), arg("value"), arg("sdelay")
        value = 0.0 if value == 0 else 1.0
        if delay is not None and not 0 <= delay <= 2000:
            raise self.fail(f"SetDO \\SDelay must be 0 to 2000 s, not {fmt_num(delay)}",
                            bound["sdelay"].value.span, "ERR_ARGVALERR")
        if delay:  # \SDelay: the program goes on, the output changes `delay` seconds later
            self.pulses.append((self.now + to_ns(delay), sig.name, value, SDELAY))
            self.changes += 1
        else:
            self.write(sig, value, bound["value"].value.span)
        yield from ()

    def i_setao(self, s, arg, text, bound):
        self.write(arg("signal"), arg("value"), bound["value"].value.span)
        yield from ()

    def i_setgo(self, s, arg, text, bound):
        self.write(arg("signal"), arg("value"), bound["value"].value.span)
        yield from ()

    def i_set(self, s, arg, text, bound):
        self.write(arg("signal"), 1.0)
        yield from ()

    def i_reset(self, s, arg, text, bound):
        self.write(arg("signal"), 0.0)
        yield from ()

    def i_invertdo(self, s, arg, text, bound):
        sig = arg("signal")
        self.write(sig, 0.0 if self.host.read_signal(sig.name) else 1.0)
        yield from ()

    def i_pulsedo(self, s, arg, text, bound):
        """PulseDO: the output goes to the pulse level now and back `\\PLength` (0.2 s) later; the
        program does not wait. Without \\High the pulse inverts the output (a 0 output pulses to 1, a
        1 output to 0); with \\High the output is 1 for the pulse length and then 0, whatever it was.

        A PulseDO on an output that is still pulsing (its pulse has not ended) restarts that pulse:
        the output is at the pulse level again (written, so traced, even though it does not change),
        the pulse length counts from the new instruction, and at its end the output goes back to the
        value it had before the *first* pulse (so two quick PulseDOs on a 0 output give one longer
        pulse and the output ends at 0, never stuck at 1). With \\High the restarted pulse ends at 0,
        as any \\High pulse does. SetDO/Set/Reset during a pulse write the output at once and do
        not cancel the pulse's end edge."""
        sig = arg("signal")
        length = arg("plength", 0.2)
        if not 0.001 <= length <= 2000:
            raise self.fail(f"PulseDO \\PLength must be 0.001 to 2000 s, not {fmt_num(length)}",
                            bound["plength"].value.span, "ERR_ARGVALERR")
        high = arg("high", False)
        running = next((p for p in self.pulses if p[1] == sig.name and p[3] == PULSE), None)
        self.pulses = [p for p in self.pulses if p[1] != sig.name]
        if high:
            level, back = 1.0, 0.0
        elif running is not None:  # still pulsing: restart the pulse, keep where it goes back to
            back = running[2]
            level = 1.0 - back
        else:  # invert the present value for the pulse length
            back = 1.0 if self.host.read_signal(sig.name) else 0.0
            level = 1.0 - back
        self.write(sig, level)
        self.pulses.append((self.now + to_ns(length), sig.name, back, PULSE))
        yield from ()

    def i_tpwrite(self, s, arg, text, bound):
        out = arg("string")
        for k in ("num", "bool", "pos", "orient"):
            v = arg(k)
            if v is not None:
                out += format_value(v)
        self.host.tp_write(out)
        self.emit({"type": "print", "text": out})
        yield from ()

    def i_tperase(self, s, arg, text, bound):
        yield from ()

    def i_stop(self, s, arg, text, bound):
        yield from self.pause(Wait("stop", what="Stop"))

    i_break = i_stop

    def i_velset(self, s, arg, text, bound):
        """VelSet: later motions run at Override % of their programmed speed (and take 100 / Override times a
        \\T), the TCP at most Max mm/s."""
        override, vmax = arg("override"), arg("max")
        if override <= 0 or vmax <= 0:
            raise self.fail("VelSet: Override and Max must be > 0", s.span, "ERR_ARGVALERR")
        self.velset = (override, vmax)
        yield from ()

    def i_accset(self, s, arg, text, bound):
        """AccSet Acc, Ramp: later motions accelerate at Acc % of the arm's limits, the acceleration rising at
        Ramp % of its normal rate (the manual's range: Acc 1 to 100, Ramp 10 to 100)."""
        acc, ramp = arg("acc"), arg("ramp")
        arg("finepointramp")
        if not 1 <= acc <= 100 or not 10 <= ramp <= 100:
            raise self.fail(f"AccSet: Acc must be 1 to 100 and Ramp 10 to 100, not {fmt_num(acc)}, {fmt_num(ramp)}",
                            s.span, "ERR_ARGVALERR")
        self.accset = (float(acc), float(ramp))
        yield from ()

    def _conf(self, s, bound, which: str):
        self.conf[which] = "off" not in bound  # \On (or no switch) turns monitoring on, \Off off
        yield from ()

    def i_confj(self, s, arg, text, bound):
        yield from self._conf(s, bound, "j")

    def i_confl(self, s, arg, text, bound):
        yield from self._conf(s, bound, "l")

    def i_gripload(self, s, arg, text, bound):
        """GripLoad: the payload's mass counts in the motions' acceleration from now on (load0: none)."""
        self.gripload = float(arg("load").fields["mass"])
        yield from ()

    def i_pathacclim(self, s, arg, text, bound):
        """PathAccLim: the TCP's acceleration along the path at most AccMax (m/s^2) while AccLim is TRUE (the
        deceleration limit is taken as the same bound: the planner's profiles are symmetric)."""
        on, dec_on = arg("acclim"), arg("decellim")
        limits = [v for flag, v in ((on, arg("accmax")), (dec_on, arg("decelmax"))) if flag and v is not None]
        if any(v < 0.1 for v in limits):
            raise self.fail("PathAccLim: AccMax and DecelMax must be at least 0.1 m/s2", s.span, "ERR_ARGVALERR")
        self.path_acc = min(limits) if limits else None
        yield from ()

    def i_waitrob(self, s, arg, text, bound):
        """WaitRob: wait until a \\Conc motion still running has ended."""
        for k in bound:
            arg(k)
        if arg("inpos") or arg("zerospeed"):  # the robot at rest at the end of its motions
            yield from self.wait_in_position(s, "WaitRob")
        handle = getattr(self, "concurrent", None)
        while handle is not None and not self.host.motion_done(handle):
            yield from self.pause(Wait("motion", None, "WaitRob", s.span))
        self.concurrent = None

    def _move_sync(self, s, arg, text, bound, instr: str):
        """MoveJSync/MoveLSync: the motion, then the PROC named by ProcName (called at the end point)."""
        yield from self._move(s, arg, text, bound, instr)
        name = arg("procname")
        r = self.routine_for(name.lower(), arg.frame)
        if r is None or r.kind != "PROC" or any(not p.optional for p in r.params):
            raise self.fail(f"{s.name}: no PROC without parameters named {name!r}", bound["procname"].value.span,
                            "ERR_REFUNKPRC")
        yield from self.invoke(r, Frame(r))

    def i_movejsync(self, s, arg, text, bound):
        yield from self._move_sync(s, arg, text, bound, "MoveJ")

    def i_movelsync(self, s, arg, text, bound):
        yield from self._move_sync(s, arg, text, bound, "MoveL")

    def i_movejdo(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveJ")
        self.write(arg("signal"), 0.0 if arg("value") == 0 else 1.0)

    def i_moveldo(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveL")
        self.write(arg("signal"), 0.0 if arg("value") == 0 else 1.0)

    def wait_in_position(self, s, what: str):
        """\\InPos: wait until the robot has come to rest at the end of the motions handed to it (the last
        one, a zone point, becomes a stop point)."""
        handle = self.last_motion
        while handle is not None and not self.host.motion_done(handle):
            wake = getattr(self.host, "motion_wake", lambda h, w: None)
            yield from self.pause(Wait("motion", wake(handle, "end"), f"{what} \\InPos", s.span))
        self.last_motion = None  # a stop point by the program's will: no corner path failure to warn of

    def i_waittime(self, s, arg, text, bound):
        if arg("inpos"):
            yield from self.wait_in_position(s, "WaitTime")
        t = arg("time")
        if t < 0:
            raise self.fail(f"WaitTime needs a time >= 0, not {fmt_num(t)}", bound["time"].value.span,
                            "ERR_ARGVALERR")
        until = self.now + to_ns(t)
        while self.now < until:
            yield from self.pause(Wait("time", until, f"WaitTime {fmt_num(t)}", s.span))

    def _wait_cond(self, s, arg, bound, test: Callable[[], bool], name: str, poll: int | None):
        maxtime = arg("maxtime")
        flag = arg("timeflag")
        deadline = None if maxtime is None else self.now + to_ns(maxtime)
        start = self.now
        k = 0
        while True:
            if test():
                if flag is not None:
                    flag.set(False)
                return
            if deadline is not None and self.now >= deadline:
                if flag is not None:
                    flag.set(True)
                    return
                raise self.fail(f"{name} timed out: \\MaxTime of {fmt_num(maxtime)} s ran out", s.span,
                                "ERR_WAIT_MAXTIME")
            if poll:
                k += 1
                at = start + k * poll
                while at <= self.now:
                    k += 1
                    at = start + k * poll
                if deadline is not None:
                    at = min(at, deadline)
                yield from self.pause(Wait("poll", at, name, s.span))
            else:
                yield from self.pause(Wait("signal", deadline, name, s.span))

    def i_waituntil(self, s, arg, text, bound):
        if arg("inpos"):
            yield from self.wait_in_position(s, "WaitUntil")
        cond = bound["cond"].value
        poll = to_ns(arg("pollrate", 0.1))
        if poll <= 0:
            raise self.fail("WaitUntil \\PollRate must be > 0", bound["pollrate"].value.span, "ERR_ARGVALERR")
        f = arg.frame
        yield from self._wait_cond(s, arg, bound, lambda: self.truth(cond, f), "WaitUntil", poll)

    def i_waitdi(self, s, arg, text, bound, name="WaitDI"):
        sig, value = arg("signal"), arg("value")
        yield from self._wait_cond(s, arg, bound, lambda: self.host.read_signal(sig.name) == value,
                                   f"{name} {sig.name}", None)

    def i_waitdo(self, s, arg, text, bound):
        yield from self.i_waitdi(s, arg, text, bound, "WaitDO")

    def _move(self, s, arg, text, bound, instr: str):
        target_key = "tojointpos" if instr == "MoveAbsJ" else "topoint"
        target = arg(target_key)
        via = arg("cirpoint") if instr == "MoveC" else None
        speed = arg("speed")
        for k in ("id", "t", "z", "inpos", "tload"):  # accepted and ignored (builtins._MOVE_OPTS), but evaluated
            if k in B.INSTRUCTION_PARAMS[s.key]:
                arg(k)
        params = B.INSTRUCTION_PARAMS[s.key]
        v = arg("v") if "v" in params else None
        if v is not None:  # \V: the TCP speed in mm/s, instead of the speeddata's v_tcp
            speed = speed.copy()
            speed.fields["v_tcp"] = v
        override, vmax = self.velset
        if (override, vmax) != (100.0, 5000.0):  # VelSet: override % of every speed, the TCP at most Max mm/s
            speed = speed.copy()
            f = speed.fields
            f["v_tcp"] = min(f["v_tcp"] * override / 100.0, vmax)
            for k in ("v_ori", "v_leax", "v_reax"):
                f[k] = f[k] * override / 100.0
        seconds = arg("t") if "t" in params else None
        if seconds is not None:
            if seconds <= 0:
                raise self.fail(f"{instr} \\T must be > 0 s, not {fmt_num(seconds)}", bound["t"].value.span,
                                "ERR_ARGVALERR")
            seconds = seconds * 100.0 / override
        zone_rec = arg("zone", self.predefined["fine"].value)  # (SearchL has none: it stops)
        # the instructions that act at the point (MoveJDO, MoveLSync, TriggL, SearchL, ...) stop there
        at_point = s.key not in ("movej", "movel", "movec", "moveabsj")
        inpos = arg("inpos") if "inpos" in params else None
        zsize = arg("z") if "z" in params else None
        tload = arg("tload") if "tload" in params else None
        tool = arg("tool")
        load = float(tload.fields["mass"]) if tload is not None else (
            float(tool.fields["tload"].fields["mass"]) + self.gripload)
        conf = self.conf["j"] if instr == "MoveJ" else self.conf["l"] if instr in ("MoveL", "MoveC") else False
        while self.stop_move:  # StopMove holds the motion until StartMove (from a TRAP)
            yield from self.pause(Wait("signal", None, f"{instr} held by StopMove", s.span))
        req = MotionRequest(
            instr=instr, target=target, via=via, speed=speed, zone=zone_rec, tool=tool,
            wobj=arg("wobj", self.predefined["wobj0"].value), target_name=text(target_key),
            via_name=text("cirpoint"), speed_name=text("speed"), zone_name=text("zone"),
            tool_name=text("tool"), wobj_name=text("wobj", "wobj0"), line=s.span.line,
            time=seconds, acc=self.accset, stop_point=bool(zone_rec.fields["finep"]) or inpos is not None or at_point,
            zone_size=zsize, load_kg=load, conf=conf, path_acc=self.path_acc, span=s.span)
        ev = {"type": "move", "instr": instr, "to": _target_json(target)}
        if via is not None:
            ev["via"] = _target_json(via)
        ev.update(speed=req.speed_name, zone=req.zone_name, tool=req.tool_name, wobj=req.wobj_name)
        self.emit(ev)
        while self.concurrent is not None and not self.host.motion_done(self.concurrent):  # a \\Conc one first
            yield from self.pause(Wait("motion", None, f"{instr} {req.target_name} after the \\Conc motion", s.span))
        handle = self.host.start_motion(req)
        self.active_tool, self.active_wobj = req.tool, req.wobj
        failed = getattr(self.host, "corner_failure", None)
        if failed is not None and self.last_motion is not None and self.corner_warning and failed(self.last_motion):
            self.emit({"type": "errlog", "level": "warning", "header": "Corner path failure",
                       "reason": f"line {s.span.line}: the motion before {instr} {req.target_name} ended at its zone "
                                 f"point as at a fine point (this motion came too late for a corner path)"})
        self.last_motion = handle
        if arg("conc"):  # \Conc: the program goes on at once, the motion runs on
            self.concurrent = handle
            return
        self.concurrent = None
        ready = getattr(self.host, "motion_ready", None)
        if ready is not None:  # a planning host: the program pointer runs one motion ahead
            wake = getattr(self.host, "motion_wake", lambda h, what: None)
            what = f"{instr} {req.target_name}"
            if not req.stop_point:
                while not ready(handle):
                    yield from self.pause(Wait("motion", wake(handle, "ready"), what, s.span))
                return
            while not self.host.motion_done(handle):
                yield from self.pause(Wait("motion", wake(handle, "end"), what, s.span))
            return
        zone = req.zone.fields
        in_zone = getattr(self.host, "motion_in_zone", None)
        radius = float(zone["pzone_tcp"]) if not zone["finep"] else 0.0
        if arg("z") is not None:  # \Z: the zone size in mm, instead of the zonedata's
            radius = float(arg("z"))
        previous, self.last_position = self.last_position, (
            xyz(target.fields["trans"]) if target.type == "robtarget" else None)
        if self.host.motion_done(handle):
            # A motion that is over at once (offline) took no time: it counts as a turn of a time-less
            # loop. In a polling loop (one that used up a whole tick, see interpreter.py) it takes the
            # time the robot would need, distance / v_tcp (at least 1 ms), so a loop of motions that
            # never waits runs at a robot's pace, at a bounded cost per simulated second.
            if self.polling:
                seconds = 0.0
                if previous is not None and self.last_position is not None and speed.fields["v_tcp"] > 0:
                    seconds = math.dist(previous, self.last_position) / float(speed.fields["v_tcp"])
                until = self.now + max(to_ns(seconds), to_ns(0.001))
                while self.now < until:
                    yield from self.pause(Wait("pace", until, f"{instr} {req.target_name}", s.span))
            else:
                yield from self.spin(f"{instr} {req.target_name}", s.span)
            return
        while True:
            if radius > 0 and in_zone is not None and in_zone(handle, radius):
                break  # a zone: the program goes on as the robot enters it
            yield from self.pause(Wait("motion", None, f"{instr} {req.target_name}", s.span))
            if self.host.motion_done(handle):
                break

    def i_movej(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveJ")

    def i_movel(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveL")

    def i_movec(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveC")

    def i_moveabsj(self, s, arg, text, bound):
        yield from self._move(s, arg, text, bound, "MoveAbsJ")


def _clean(x: float) -> float:
    r = round(x, 12)
    return 0.0 if r == 0 else r


def _target_json(t: Record) -> dict:
    if t.type == "jointtarget":
        rob = t.fields["robax"]
        return {"robax": [json_num(v) for v in rob.values()]}  # type: ignore[union-attr]
    trans, rot = t.fields["trans"], t.fields["rot"]
    return {"trans": [json_num(v) for v in trans.values()],  # type: ignore[union-attr]
            "rot": [json_num(v) for v in rot.values()]}  # type: ignore[union-attr]
