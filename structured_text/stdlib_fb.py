"""The standard function blocks (IEC 61131-3 3rd ed., 6.6.3.5): bistables, edge detection, counters, timers.

Each is a Python class with the generated code's conventions: members `v_<name>` (lower case),
`_body()` runs one invocation, and a shared clock `clk.now` (ns) gives the time of the scan.

The algebra is the standard's own:
    SR  (set dominant):   Q1 := S1 OR (NOT R AND Q1)
    RS  (reset dominant): Q1 := NOT R1 AND (S OR Q1)
    R_TRIG: Q := CLK AND NOT M; M := CLK          F_TRIG: Q := NOT CLK AND NOT M; M := NOT CLK
    CTU:  R -> CV := 0;  else a rising edge of CU and CV < PVmax -> CV := CV + 1;  Q := CV >= PV
    CTD:  LD -> CV := PV; else a rising edge of CD and CV > PVmin -> CV := CV - 1; Q := CV <= 0
    CTUD: R -> 0; else LD -> PV; else one edge alone counts (up below PVmax, down above PVmin);
          QU := CV >= PV; QD := CV <= 0
The standard leaves PVmax and PVmin to the implementation (3rd ed. table 45, 2nd ed. table 35);
here, as in matiec/OpenPLC's library, PVmax is PV and PVmin is 0: CTU stops counting at PV, CTD at 0.
Timers follow the standard's timing diagrams; time is the scan's time, so a timer started at the
scan of t0 is due at the first scan at or after t0 + PT (the scan of the edge only starts the timing,
as in matiec's library: with PT = 0, Q changes one scan after the edge):
    TON: IN rising starts timing; ET := elapsed (at most PT); Q once ET = PT; IN FALSE resets Q, ET.
    TOF: Q := TRUE while IN; IN falling starts timing; Q FALSE once ET = PT; IN TRUE resets ET.
    TP:  IN rising (while not pulsing) starts a pulse of PT: Q TRUE, ET counts to PT; after it
         ET stays PT while IN is TRUE and returns to 0 when IN is FALSE.
"""
from __future__ import annotations

from . import types as ty


class Clock:
    """The PLC's clock: the scan's time in nanoseconds, set by the runtime before the tasks run."""

    __slots__ = ("now",)

    def __init__(self):
        self.now = 0


class StdFB:
    __slots__ = ("_clk",)
    MEMBERS: tuple = ()  # (name, type, section)

    def __init__(self, clk: Clock):
        self._clk = clk
        for name, t, _ in self.MEMBERS:
            setattr(self, "v_" + name.lower(), ty.default_value(t))


class SR(StdFB):
    __slots__ = ("v_s1", "v_r", "v_q1")
    MEMBERS = (("S1", ty.BOOL, "VAR_INPUT"), ("R", ty.BOOL, "VAR_INPUT"), ("Q1", ty.BOOL, "VAR_OUTPUT"))

    def _body(self):
        self.v_q1 = bool(self.v_s1 or (not self.v_r and self.v_q1))


class RS(StdFB):
    __slots__ = ("v_s", "v_r1", "v_q1")
    MEMBERS = (("S", ty.BOOL, "VAR_INPUT"), ("R1", ty.BOOL, "VAR_INPUT"), ("Q1", ty.BOOL, "VAR_OUTPUT"))

    def _body(self):
        self.v_q1 = bool(not self.v_r1 and (self.v_s or self.v_q1))


class R_TRIG(StdFB):
    __slots__ = ("v_clk", "v_q", "v_m")
    MEMBERS = (("CLK", ty.BOOL, "VAR_INPUT"), ("Q", ty.BOOL, "VAR_OUTPUT"), ("M", ty.BOOL, "VAR"))

    def _body(self):
        self.v_q = bool(self.v_clk and not self.v_m)
        self.v_m = bool(self.v_clk)


class F_TRIG(StdFB):
    __slots__ = ("v_clk", "v_q", "v_m")
    MEMBERS = (("CLK", ty.BOOL, "VAR_INPUT"), ("Q", ty.BOOL, "VAR_OUTPUT"), ("M", ty.BOOL, "VAR"))

    def _body(self):
        self.v_q = bool(not self.v_clk and not self.v_m)
        self.v_m = not self.v_clk


def _counters(suffix: str, t: ty.Elementary) -> dict:

    class CTU(StdFB):
        __slots__ = ("v_cu", "v_r", "v_pv", "v_q", "v_cv", "_cu_m")
        MEMBERS = (("CU", ty.BOOL, "VAR_INPUT"), ("R", ty.BOOL, "VAR_INPUT"), ("PV", t, "VAR_INPUT"),
                   ("Q", ty.BOOL, "VAR_OUTPUT"), ("CV", t, "VAR_OUTPUT"))

        def __init__(self, clk):
            super().__init__(clk)
            self._cu_m = False

        def _body(self):
            edge = self.v_cu and not self._cu_m
            self._cu_m = bool(self.v_cu)
            if self.v_r:
                self.v_cv = 0
            elif edge and self.v_cv < self.v_pv:
                self.v_cv += 1
            self.v_q = self.v_cv >= self.v_pv

    class CTD(StdFB):
        __slots__ = ("v_cd", "v_ld", "v_pv", "v_q", "v_cv", "_cd_m")
        MEMBERS = (("CD", ty.BOOL, "VAR_INPUT"), ("LD", ty.BOOL, "VAR_INPUT"), ("PV", t, "VAR_INPUT"),
                   ("Q", ty.BOOL, "VAR_OUTPUT"), ("CV", t, "VAR_OUTPUT"))

        def __init__(self, clk):
            super().__init__(clk)
            self._cd_m = False

        def _body(self):
            edge = self.v_cd and not self._cd_m
            self._cd_m = bool(self.v_cd)
            if self.v_ld:
                self.v_cv = self.v_pv
            elif edge and self.v_cv > 0:
                self.v_cv -= 1
            self.v_q = self.v_cv <= 0

    class CTUD(StdFB):
        __slots__ = ("v_cu", "v_cd", "v_r", "v_ld", "v_pv", "v_qu", "v_qd", "v_cv", "_cu_m", "_cd_m")
        MEMBERS = (("CU", ty.BOOL, "VAR_INPUT"), ("CD", ty.BOOL, "VAR_INPUT"), ("R", ty.BOOL, "VAR_INPUT"),
                   ("LD", ty.BOOL, "VAR_INPUT"), ("PV", t, "VAR_INPUT"), ("QU", ty.BOOL, "VAR_OUTPUT"),
                   ("QD", ty.BOOL, "VAR_OUTPUT"), ("CV", t, "VAR_OUTPUT"))

        def __init__(self, clk):
            super().__init__(clk)
            self._cu_m = self._cd_m = False

        def _body(self):
            up = self.v_cu and not self._cu_m
            down = self.v_cd and not self._cd_m
            self._cu_m, self._cd_m = bool(self.v_cu), bool(self.v_cd)
            if self.v_r:
                self.v_cv = 0
            elif self.v_ld:
                self.v_cv = self.v_pv
            elif not (up and down):
                if up and self.v_cv < self.v_pv:
                    self.v_cv += 1
                elif down and self.v_cv > 0:
                    self.v_cv -= 1
            self.v_qu = self.v_cv >= self.v_pv
            self.v_qd = self.v_cv <= 0

    out = {}
    for cls in (CTU, CTD, CTUD):
        name = cls.__name__ + suffix
        cls.__name__ = cls.__qualname__ = name
        out[name] = cls
    return out


class _Timer(StdFB):
    __slots__ = ("v_in", "v_pt", "v_q", "v_et", "_start", "_state", "_prev")
    MEMBERS = (("IN", ty.BOOL, "VAR_INPUT"), ("PT", ty.TIME, "VAR_INPUT"), ("Q", ty.BOOL, "VAR_OUTPUT"),
               ("ET", ty.TIME, "VAR_OUTPUT"))

    def __init__(self, clk):
        super().__init__(clk)
        self._start = 0
        self._state = 0  # 0 idle, 1 timing, 2 elapsed
        self._prev = False


class TON(_Timer):
    __slots__ = ()

    def _body(self):
        now = self._clk.now
        if self._state == 0 and not self._prev and self.v_in:  # the rising edge starts the timing
            self._state, self.v_q, self._start = 1, False, now
        elif not self.v_in:
            self.v_q, self.v_et, self._state = False, 0, 0
        elif self._state == 1:
            et = now - self._start
            if et >= self.v_pt:
                self._state, self.v_q, self.v_et = 2, True, self.v_pt
            else:
                self.v_et = et
        self._prev = bool(self.v_in)


class TOF(_Timer):
    __slots__ = ()

    def _body(self):
        now = self._clk.now
        if self._state == 0 and self._prev and not self.v_in:  # the falling edge starts the timing
            self._state, self._start = 1, now
        elif self.v_in:
            self.v_et, self._state = 0, 0
        elif self._state == 1:
            et = now - self._start
            if et >= self.v_pt:
                self._state, self.v_et = 2, self.v_pt
            else:
                self.v_et = et
        self.v_q = bool(self.v_in) or self._state == 1
        self._prev = bool(self.v_in)


class TP(_Timer):
    __slots__ = ()

    def _body(self):
        now = self._clk.now
        if self._state == 0 and self.v_in and not self._prev:  # the rising edge starts a pulse
            self._state, self._start, self.v_q = 1, now, True
        elif self._state == 1:
            et = now - self._start
            if et >= self.v_pt:
                self._state, self.v_q, self.v_et = 2, False, self.v_pt
            else:
                self.v_et = et
        if self._state == 2 and not self.v_in:
            self._state, self.v_et = 0, 0
        self._prev = bool(self.v_in)


STANDARD_FBS: dict[str, type] = {"SR": SR, "RS": RS, "R_TRIG": R_TRIG, "F_TRIG": F_TRIG,
                                 "TON": TON, "TOF": TOF, "TP": TP}
STANDARD_FBS.update(_counters("", ty.INT))
for _s in ("DINT", "LINT", "UDINT", "ULINT"):
    STANDARD_FBS.update(_counters("_" + _s, ty.ELEMENTARY[_s]))
for _alias, _real in (("TON_TIME", "TON"), ("TOF_TIME", "TOF"), ("TP_TIME", "TP")):
    STANDARD_FBS[_alias] = STANDARD_FBS[_real]
