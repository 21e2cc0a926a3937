"""The simulation core: station, mechanism, physics world, gripper logic, robot, signal table.

It imports pybullet and numpy, never sockets, asyncio or time: its clock is step count x dt.
"""

from .errors import MechanismError, MotionError, SignalError, SignalRangeError, StationError, TwinError
from .mechanism import Mechanism, load_mechanism
from .signals import SignalSpec
from .station import Station, load_station
from .twin import Twin

__all__ = ["Twin", "Station", "load_station", "Mechanism", "load_mechanism", "SignalSpec", "TwinError",
           "StationError", "MechanismError", "SignalError", "SignalRangeError", "MotionError"]
