"""Modbus/TCP as a front end of a cell: the server (`server`) on a bridge (`bridge`) to the cell's exchange.

    front = ModbusFrontEnd(host="127.0.0.1", port=5020, unit_id=1)      # or ModbusFrontEnd.from_args(args)
    lines = await front.start(cell)     # ["station 'x': 69 entries, ...", "listening on HOST:PORT"]
    ...
    await front.close()

It follows the front-end contract of `twin_app.cell` (read snapshots, submit writes; never the twin):
`cell` is anything with `exchange` (a `twin.runtime.exchange.Exchange`), `register_map` (the generated map),
`station`, `twin` (for a device profile, which steps with it), `watchdog` (fed per request) and `runner`.
"""
from __future__ import annotations

import logging
from collections.abc import Callable

from twin.core.errors import StationError, TwinError

from .bridge import TwinBridge
from .log import log as _log
from .protocol import DEFAULT_PORT, MAX_CONNECTIONS, REQUESTS_PER_STEP, TLS_PORT
from .register_map import PLC_LAYOUT, POLL_HOLD
from .server import ModbusServer


class ModbusFrontEnd:
    name = "modbus"

    def __init__(self, *, host: str = "127.0.0.1", port: int = DEFAULT_PORT, unit_id: int | None = None,
                 frame_timeout: float = 1.0, requests_per_step: int = REQUESTS_PER_STEP,
                 max_connections: int = MAX_CONNECTIONS, idle_timeout: float = 0.0, allow=None,
                 read_only: bool = False, gaps: str = "error", watchdog: float | None = None, tls=None,
                 tls_port: int = TLS_PORT, tls_only: bool = False, profile: str | None = None,
                 map_unit_id: int | None = None, poll_hold: float = POLL_HOLD, log: Callable[..., None] = _log):
        """`unit_id`: the unit answered (default 1), with a profile the profile's (default: every unit but
        `map_unit_id`); `watchdog`: seconds (0: off; None: the station's); `tls`: an ssl.SSLContext for
        Modbus/TCP Security on `tls_port`; `profile`: a device profile (`twin.devices.robotiq.PROFILES`)."""
        self.host, self.port, self.unit_id, self.frame_timeout = host, port, unit_id, frame_timeout
        self.requests_per_step, self.max_connections, self.idle_timeout = requests_per_step, max_connections, idle_timeout
        self.allow, self.read_only, self.gaps, self.watchdog = allow, read_only, gaps, watchdog
        self.tls, self.tls_port, self.tls_only = tls, tls_port, tls_only
        self.profile_kind, self.map_unit_id, self.log = profile, map_unit_id, log
        self.poll_hold = poll_hold
        self.bridge: TwinBridge | None = None
        self.server: ModbusServer | None = None
        self.profile = None
        self.listening: list[tuple[str, str, int]] = []

    @classmethod
    def from_args(cls, args, tls=None) -> "ModbusFrontEnd":
        """From the parsed `twin serve` flags (`twin_app.cli_modbus.add_serve_arguments`)."""
        get = lambda name, default=None: getattr(args, name, default)  # noqa: E731
        return cls(host=args.host, port=args.port, unit_id=get("unit_id"), frame_timeout=get("frame_timeout", 1.0),
                   requests_per_step=get("requests_per_step", REQUESTS_PER_STEP),
                   max_connections=get("max_connections", MAX_CONNECTIONS), idle_timeout=get("idle_timeout", 0.0),
                   allow=get("allow"), read_only=get("read_only", False), gaps=get("gaps", "error"),
                   watchdog=get("watchdog"), tls=tls, tls_port=get("tls_port", TLS_PORT),
                   tls_only=get("tls_only", False) or get("no_modbus", False), profile=get("profile"),
                   map_unit_id=get("map_unit_id"), poll_hold=get("poll_hold", POLL_HOLD))

    @property
    def address(self) -> tuple[str, int] | None:
        """The first bound (host, port)."""
        return self.listening[0][1:] if self.listening else None

    async def start(self, cell) -> list[str]:
        """Bind and serve. Raises OSError ("cannot listen on HOST:PORT: why") when an address cannot be bound,
        TwinError when the profile does not fit the station."""
        if self.profile_kind:
            from twin.devices.robotiq import open_profile

            try:
                self.profile = open_profile(cell.twin, self.profile_kind)
            except StationError as exc:
                raise TwinError(f"--profile {self.profile_kind}: {exc}") from None
        runner = cell.runner
        lockstep = runner is not None and runner.mode == "lockstep"
        speed = 1.0 if lockstep or runner is None else runner.speed
        watchdog = getattr(cell, "watchdog", None)
        on_request = None
        if watchdog is not None:
            if self.watchdog is not None:
                cell.set_watchdog_timeout(self.watchdog)
            watchdog.log = lambda text: self.log(text, logging.WARNING)
            on_request = lambda peer, clock_only: watchdog.feed(  # noqa: E731
                f"modbus {peer}", clock_only=lockstep and clock_only)
        rmap = cell.register_map
        self.bridge = bridge = TwinBridge(cell.exchange, rmap)
        unit_id = 1 if self.unit_id is None else self.unit_id
        self.server = server = ModbusServer(
            rmap, bridge, unit_id=unit_id, frame_timeout=self.frame_timeout,
            requests_per_step=self.requests_per_step, step_period=cell.exchange.twin.dt / speed,
            max_connections=self.max_connections, idle_timeout=self.idle_timeout or None, allow=self.allow,
            read_only=self.read_only, gaps_zero=self.gaps == "zero" or rmap.layout == PLC_LAYOUT,
            identity=device_identity(cell.station, rmap),
            on_request=on_request, log=self.log, poll_hold=self.poll_hold, behind=(lambda: runner.last_late) if not lockstep and runner else None)
        server.on_event = getattr(getattr(cell, "events", None), "emit", None)
        lines = []
        if self.profile is not None:
            from .profile import MAP_UNIT_ID, serve_profile

            unit_id = MAP_UNIT_ID if self.map_unit_id is None else self.map_unit_id
            serve_profile(server, self.profile, bridge, unit_id=self.unit_id, map_unit_id=unit_id)
        port = self.port
        try:
            if not self.tls_only:
                self.listening.append(("", *await server.start(self.host, self.port)))
            if self.tls is not None:
                port = self.tls_port
                self.listening.append((" (Modbus/TCP Security, TLS)", *await server.start(self.host, port, ssl=self.tls)))
        except OSError as exc:
            await server.close()
            bridge.close()
            raise OSError(f"cannot listen on {self.host}:{port}: {exc.strerror or exc}") from None
        how = "lockstep (steps on sim.advance)" if lockstep else f"real time x{speed:g}"
        notes = [f"{len(rmap)} entries", f"{rmap.layout or 'signals'} layout", f"unit {unit_id}", how,
                 f"step {cell.exchange.twin.dt * 1000:g} ms"]
        if self.read_only:
            notes.append("read-only")
        if watchdog is not None and watchdog.timeout:
            notes.append(f"watchdog {watchdog.timeout:g} s ({watchdog.safe_state})")
        lines.append(f"station {cell.station.name!r}: " + ", ".join(notes))
        if self.profile is not None:
            where = f"unit {self.unit_id}" if self.unit_id is not None else f"every unit id but {unit_id}"
            lines.append(f"profile {self.profile.kind} on {where}")
        lines += [f"listening on {host}:{bound}{what}" for what, host, bound in self.listening]
        return lines

    def endpoints(self) -> list[dict]:
        """Where it listens, for the `ready` event (`twin.observe.events`)."""
        return [{"name": self.name, "protocol": "modbus/tcp+tls" if what else "modbus/tcp", "host": host, "port": port}
                for what, host, port in self.listening]

    @property
    def requests(self) -> int:
        return 0 if self.server is None else self.server.requests

    async def close(self) -> None:
        if self.server is not None:
            await self.server.close()
        if self.bridge is not None:
            self.bridge.close()


def device_identity(station, rmap):
    """What function 43/14 answers: vendor and product code (DeviceIdentity's), version, the station's name."""
    from importlib import metadata

    from .pdu import MAP_CRC_OBJECT, STATION_NAME_OBJECT, DeviceIdentity

    try:
        version = metadata.version("gripper-twin")
    except metadata.PackageNotFoundError:
        version = "0.1.0"
    name = station.name
    return DeviceIdentity(revision=version, product_name="gripper-twin Modbus/TCP server", model_name="twin serve",
                          user_application_name=name,
                          extended={STATION_NAME_OBJECT: name, MAP_CRC_OBJECT: f"{rmap.crc:08x}"})
