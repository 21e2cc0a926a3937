"""Interrupts: CONNECT, ISignalDI/DO/GI/GO, ITimer, IPers, ISleep/IWatch, IEnable/IDisable, IDelete,
and the TRAP routines they run.

An interrupt number is handed out by CONNECT (the intnum variable gets it) and tied to a TRAP
routine. An order (ISignalDI, ITimer, ...) then says when it occurs. The controller polls the
orders at every tick, and a signal written by the program itself is polled at once, so an
ISignalDO sees the program's own SetDO. An interrupt that occurs is queued; the program runs its
TRAP routine before its next statement, or at once while it waits (WaitTime, WaitDI, a motion, a
socket): the wait goes on after the TRAP returns. A TRAP is not interrupted by another one; an
error in a TRAP stops the program (a TRAP has no caller to raise it to).

Edges, as the manual defines them: ISignalDI/DO with 1 occurs when the signal goes from 0 to 1,
with 0 when it goes from 1 to 0, with `edge` (2) at either; a signal that already has the value
when the order is given does not trigger it. ISignalGI/GO occur at every change of the group's
value. ISignalAI/AO occur when their condition becomes true. ITimer occurs `Time` seconds after the order, then every `Time` seconds (once with \\Single).
IPers occurs when the persistent's value changes. IError orders are accepted and never occur.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from . import nodes as n
from .errors import ExecError, Span
from .runtime import Fatal, Frame, Propagate, Ref, to_ns


@dataclass
class Order:
    kind: str  # signal, timer, pers, error
    single: bool = False
    signal: str = ""
    trigger: float = 1.0  # 0, 1 or 2 (edge); None for a group's any change
    last: object = None
    period: int = 0
    due: int = 0
    ref: Ref | None = None
    asleep: bool = False


@dataclass
class InterruptTable:
    interp: object
    traps: dict[int, n.Routine] = field(default_factory=dict)
    orders: dict[int, Order] = field(default_factory=dict)
    pending: list[int] = field(default_factory=list)
    next_no: int = 1
    enabled: bool = True
    in_trap: bool = False

    # ---- instructions ------------------------------------------------------------------------
    def connect(self, ref: Ref, trap: n.Routine, span: Span) -> None:
        no = ref.get()
        if no and int(no) in self.traps:
            raise self.interp.fail(f"CONNECT {ref.name}: the interrupt is already connected (to "  # type: ignore
                                   f"{self.traps[int(no)].name}); IDelete it first", span, "ERR_ALRDYCNT")
        number = self.next_no
        self.next_no += 1
        self.traps[number] = trap
        ref.set(float(number))

    def number(self, value: float, span: Span) -> int:
        no = int(value)
        if no not in self.traps:
            raise self.interp.fail("the interrupt is not connected to a TRAP routine (CONNECT it first)",  # type: ignore
                                   span, "ERR_UNKINO")
        return no

    def order(self, no: int, order: Order) -> None:
        self.orders[no] = order

    def signal_order(self, no: int, signal: str, trigger: float | None, single: bool) -> None:
        self.order(no, Order("signal", single, signal, trigger, self.interp.host.read_signal(signal)))  # type: ignore

    def analog_order(self, no: int, signal: str, test, single: bool) -> None:
        o = Order("analog", single, signal, last=False)
        o.ref = test  # type: ignore[assignment]
        self.order(no, o)

    def timer_order(self, no: int, seconds: float, single: bool) -> None:
        period = max(1, to_ns(seconds))
        self.order(no, Order("timer", single, period=period, due=self.interp.now + period))  # type: ignore

    def pers_order(self, no: int, ref: Ref) -> None:
        self.order(no, Order("pers", ref=ref, last=_snapshot(ref.get())))

    def delete(self, no: int) -> None:
        self.traps.pop(no, None)
        self.orders.pop(no, None)
        self.pending = [p for p in self.pending if p != no]

    def sleep(self, no: int, asleep: bool) -> None:
        if no in self.orders:
            self.orders[no].asleep = asleep

    # ---- detection -----------------------------------------------------------------------------
    def poll(self) -> None:
        """Queue the interrupts whose condition has occurred since the last poll."""
        if not self.orders:
            return
        now = self.interp.now  # type: ignore[attr-defined]
        for no, o in list(self.orders.items()):
            fired = False
            if o.kind == "signal":
                value = self.interp.host.read_signal(o.signal)  # type: ignore[attr-defined]
                if value != o.last:
                    fired = o.trigger is None or o.trigger == 2 or value == o.trigger
                    o.last = value
            elif o.kind == "analog":
                now_true = bool(o.ref(self.interp.host.read_signal(o.signal)))  # type: ignore[misc, attr-defined]
                fired, o.last = now_true and not o.last, now_true
            elif o.kind == "timer":
                while o.due <= now:
                    fired = True
                    o.due += o.period
                    if o.single:
                        break
            elif o.kind == "pers" and o.ref is not None:
                value = _snapshot(o.ref.get())
                if value != o.last:
                    fired, o.last = True, value
            if fired and not o.asleep and self.enabled:
                self.pending.append(no)
                self.interp.changes += 1  # type: ignore[attr-defined]
                if o.single:
                    del self.orders[no]

    def next_due(self) -> int | None:
        times = [o.due for o in self.orders.values() if o.kind == "timer"]
        return min(times) if times else None

    # ---- execution -----------------------------------------------------------------------------
    def service(self):
        """Run the TRAP routines of the queued interrupts (a generator: a TRAP may wait)."""
        if self.in_trap or not self.enabled:
            return
        while self.pending:
            no = self.pending.pop(0)
            trap = self.traps.get(no)
            if trap is None:
                continue
            self.in_trap = True
            try:
                yield from self.interp.invoke(trap, Frame(trap))  # type: ignore[attr-defined]
            except Propagate as p:
                raise Fatal(p.error) from None
            except ExecError as err:
                raise Fatal(err) from None
            finally:
                self.in_trap = False


def _snapshot(v: object) -> object:
    return v.copy() if hasattr(v, "copy") and not isinstance(v, (str, float, int, bool)) else v
