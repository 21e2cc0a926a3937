"""The simulation core: station, mechanism, physics world, gripper logic, robot, signal table.

It imports pybullet and numpy, never sockets, asyncio or time: its clock is step count x dt.
"""

from .errors import (MechanismError, MotionError, SignalError, SignalRangeError, SignalTypeError, StationError,
                     TwinError)

__all__ = ["Twin", "Station", "load_station", "Mechanism", "load_mechanism", "SignalSpec", "TwinError",
           "StationError", "MechanismError", "SignalError", "SignalRangeError", "SignalTypeError",
           "MotionError", "station_signals"]

_LAZY = {"Twin": ".twin", "Station": ".station", "load_station": ".station", "Mechanism": ".mechanism",
         "load_mechanism": ".mechanism", "SignalSpec": ".signals", "station_signals": ".signal_table"}


def __getattr__(name: str):
    """Import lazily, so `twin info` and the CLIs do not pay for (or print) pybullet's import."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(name)
