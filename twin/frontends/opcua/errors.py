"""Errors of the OPC UA front end that cross from the cell to the server."""
from __future__ import annotations

from twin.core.errors import TwinError


class AdvanceRefused(TwinError):
    """Sim.Advance cannot run now (real time, or the simulation faulted): `status` names the Bad status code."""

    def __init__(self, status: str, message: str):
        super().__init__(message)
        self.status = status


def status_of(exc: TwinError) -> str:
    """The OPC UA status code for a write the one validation (`SignalSpec.check`, `Exchange.check`) refused,
    chosen by the error's type. The Variant's own data type is checked before (BadTypeMismatch), so a
    SignalTypeError here is a value of the right type the signal does not take (NaN, infinity, a text that
    is none of an enumeration's choices): BadOutOfRange, like a value outside the range."""
    from twin.core.errors import SignalError, SignalRangeError, SignalTypeError
    from twin.runtime.exchange import SimulationFault

    if isinstance(exc, SimulationFault):
        return "BadDeviceFailure"
    if isinstance(exc, (SignalRangeError, SignalTypeError)):
        return "BadOutOfRange"
    if isinstance(exc, SignalError):
        return "BadNotWritable"
    return "BadInternalError"
