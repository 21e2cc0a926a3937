"""A cell: a station's twin together with its robot controller, when the station declares one.

This is what the servers and the demo run. It sits beside the core (the core never imports the
controller): the RAPID controller is attached to the twin as a device.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from .core import Twin


def add_watchdog(twin: Twin):
    """The comm-loss watchdog (`twin.watchdog`), before the controller so a DI may read `comm.lost`."""
    from .core.errors import StationError
    from .watchdog import Watchdog

    spec = twin.station.watchdog
    names = {i.name for i in twin.mechanism.inputs}
    for key in (spec.open if spec is not None else {}):
        if key not in names:
            raise StationError(str(twin.station.file), f"watchdog.open.{key}",
                               f"not an input of the gripper (its inputs: {', '.join(sorted(names))})")
    twin.watchdog = Watchdog.for_station(twin.station).attach(twin)
    return twin.watchdog


def open_cell(station: str | Path, on_event: Callable[[dict], None] | None = None, *,
              entry: str | None = None) -> Twin:
    """Load a station; if it has a `[controller]`, its RAPID program runs as the robot controller.

    `on_event` receives the controller's events (TPWrite lines, output writes, motions, the end or a
    runtime error; see `rapid_like.controller`); `entry` overrides the station's entry routine.
    A program that does not parse or check raises a `rapid_like` error naming file:line:column.
    """
    twin = Twin.from_station(station)
    twin.controller = None
    add_watchdog(twin)
    if twin.station.controller is not None:
        from rapid_like.station_host import attach_controller

        try:
            twin.controller = attach_controller(twin, on_event=on_event, entry=entry)
        except BaseException:
            twin.close()
            raise
    return twin
