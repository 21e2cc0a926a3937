"""A cell: a station's twin together with its robot controller, when the station declares one.

This is what the servers and the demo run. It sits beside the core (the core never imports the
controller): the RAPID controller is attached to the twin as a device.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from .core import Twin


def open_cell(station: str | Path, on_event: Callable[[dict], None] | None = None) -> Twin:
    """Load a station; if it has a `[controller]`, its RAPID program runs as the robot controller."""
    twin = Twin.from_station(station)
    if twin.station.controller is not None:
        from rapid_like.station_host import attach_controller

        twin.controller = attach_controller(twin, on_event=on_event)
    else:
        twin.controller = None
    return twin
