"""Errors of the OPC UA front end that cross from the cell to the server."""
from __future__ import annotations


class AdvanceRefused(Exception):
    """Sim.Advance cannot run now (real time, or the simulation faulted): `status` names the Bad status code."""

    def __init__(self, status: str, message: str):
        super().__init__(message)
        self.status = status
