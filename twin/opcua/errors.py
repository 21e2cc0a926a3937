"""Errors of the OPC UA front end that cross from the cell to the server."""
from __future__ import annotations

from twin.core.errors import TwinError


class AdvanceRefused(TwinError):
    """Sim.Advance cannot run now (real time, or the simulation faulted): `status` names the Bad status code."""

    def __init__(self, status: str, message: str):
        super().__init__(message)
        self.status = status
