"""Devices: what is stepped with the twin and may add signals of its own (the RAPID controller, the watchdog,
a recorder). The core knows them only through this protocol, so it never imports what drives it. Light: no
pybullet, so front ends and tools can name it without starting physics."""
from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

from .signals import SignalSpec

if TYPE_CHECKING:
    from .twin import Twin


class Device(Protocol):
    """Something stepped with the twin that adds signals of its own (e.g. the RAPID robot controller).

    The core knows devices only through this protocol, so it never imports what drives it.
    """

    signals: tuple[SignalSpec, ...]

    def read(self, name: str): ...

    def write(self, name: str, value) -> None: ...

    def before_step(self, twin: "Twin") -> None: ...

    def after_step(self, twin: "Twin") -> None: ...


class ObservingDevice:
    """A device with no signals of its own (a recorder, a fault injector, a monitor): it only hooks the steps.

    Subclasses override `before_step` / `after_step`; reading or writing a signal through it is a KeyError.
    """

    signals: tuple[SignalSpec, ...] = ()

    def read(self, name: str):
        raise KeyError(name)

    def write(self, name: str, value) -> None:
        raise KeyError(name)

    def before_step(self, twin: "Twin") -> None:
        pass

    def after_step(self, twin: "Twin") -> None:
        pass
