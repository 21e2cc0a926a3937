"""The OPC UA server in a process of its own, linked to the cell by the front-end adapter
(`twin.frontends.process`): the concurrency rule, the simulation and Modbus on one loop in one process and
every other front end in its own, is written there.

In the OPC UA process, `OpcUaProcess` runs the asyncua server (`server.OpcUaServer`) on that process's event
loop; asyncua's work (encoding the notifications of a thousand monitored items, its collector pauses) never
shares the simulation's interpreter. Through `Remote` (the adapter's view of the cell):

- cell -> server: every step's snapshot, in order, published into the address space (a value that lasts one
  step still reaches every subscription), stamped with its simulated time (`server.OpcUaServer.publish`).
- server -> cell: a write is validated in the simulation's process by the exchange (`SignalSpec.check`, the one
  validation) and answered with the status code its error's type maps to (`errors.status_of`); accepted,
  it is applied at the next step in arrival order with every other front end's writes. `Sim.Advance` is
  answered when its steps are done. Every request of a session feeds the comm-loss watchdog.
- one ordered channel: a write answered before a `Sim.Advance` is applied in the advance's first step, and
  what a client reads after an advance is its last step's: lockstep runs stay bit for bit. In lockstep a
  read first syncs with the cell (`Remote.sync`), so steps another front end ran (a Modbus client's
  `sim.advance`) are published here before the read is answered.
- OPC UA clients coming and going (`sessions`) are handed to the cell as `client_connected` / `client_gone`
  events, which the simulation's one events writer writes (`twin serve --events`), and logged there.
"""
from __future__ import annotations

import logging
from collections.abc import Sequence

from twin.core.errors import TwinError

from .address_space import Variable
from .errors import AdvanceRefused, status_of  # status_of: the one mapping of a refused write to a status code

log = logging.getLogger("twin.frontends.opcua")


class RemoteLink:
    """The server's link to the cell, in the OPC UA process (the adapter's `Remote`)."""

    def __init__(self, remote):
        self.remote = remote

    async def submit(self, changes: Sequence[tuple[Variable, object]]) -> str | None:
        """None when the cell accepted the writes (applied at its next step), else the Bad status code's name."""
        try:
            await self.remote.submit([(var.name, value) for var, value in changes])
        except TwinError as exc:
            return status_of(exc)
        return None

    async def advance(self, n: int) -> int:
        from twin.runtime.exchange import SimulationFault
        from twin.frontends.process import NotLockstep

        try:
            return await self.remote.advance(n)
        except NotLockstep as exc:
            raise AdvanceRefused("BadInvalidState", str(exc)) from None
        except SimulationFault as exc:
            raise AdvanceRefused("BadDeviceFailure", str(exc)) from None
        except TwinError as exc:  # the simulation is gone
            raise AdvanceRefused("BadDeviceFailure", str(exc)) from None

    async def sync(self) -> int:
        return await self.remote.sync()

    def feed(self, source: str, clock_only: bool = False) -> None:
        self.remote.feed(source, clock_only)

    def client(self, kind: str, **fields) -> None:
        """A client connected or gone (`sessions`): the event to the cell's events, a line to its log."""
        self.remote.event(kind, **fields)
        who = fields["peer"] + (f" as {fields['user']!r}" if fields.get("user") else "")
        if kind == "client_connected":
            access = "read only" if fields.get("access") == "read" else "read/write"
            self.remote.log(f"OPC UA: client {who} connected ({access}; {fields['connected']} connected)", logging.INFO)
        else:
            self.remote.log(f"OPC UA: client {who} disconnected ({fields['reason']}; {fields['connected']} connected)",
                            logging.INFO)


class OpcUaProcess:
    """The OPC UA front end as the adapter runs it in its own process (`process(options)`)."""

    def __init__(self, options: dict):
        self.options = options
        self.server = None

    async def start(self, remote):
        from .address_space import build_address_space
        from .serve import route_opcua_log
        from .server import OpcUaServer

        o = self.options
        route_opcua_log(lambda text, level: remote.log(text, level))
        link = RemoteLink(remote)
        space = build_address_space(remote.signals, remote.station)
        server = OpcUaServer(space, step_s=remote.dt, submit=link.submit, advance=link.advance,
                             security=o["security"], on_request=link.feed if o["watchdog"] else None,
                             clock_requests=remote.lockstep, on_client=link.client,
                             sync=link.sync if remote.lockstep else None)
        from .security import SecurityError

        try:
            await server.start(o["host"], o["port"])
        except SecurityError as exc:
            await server.close()
            raise TwinError(f"OPC UA security: {exc}") from None
        except OSError as exc:
            await server.close()
            raise OSError(exc.strerror or str(exc)) from None
        except BaseException:
            await server.close()
            raise
        self.server = server
        server.start_clock(remote.snapshot.time)
        await server.publish(remote.snapshot.values, remote.applied, remote.snapshot.time)
        self.remote = remote
        self._anchor = not remote.lockstep
        remote.subscribe(self._publish)
        return self.lines(o), self.endpoints(o)

    async def _publish(self, snapshot) -> None:
        if self._anchor:  # real time: the runner starts once every front end is ready; its first step anchors
            self._anchor = False  # the clock, so a SourceTimestamp is its step's due time (give or take the link)
            self.server.start_clock(snapshot.time)
        await self.server.publish(snapshot.values, self.remote.applied, snapshot.time)

    def lines(self, o) -> list[str]:
        server, security = self.server, o["security"]
        policies = ", ".join(security.policies_for(o["host"]))
        users = f", {len(security.accounts)} account(s), no anonymous" if security.accounts else ", anonymous"
        fed = f", feeds the watchdog ({o['watchdog']:g} s)" if o["watchdog"] else ""
        return [f"OPC UA: namespace {server.space.namespace_uri} (ns={server.ns}), {len(server.space)} "
                f"variables, security {policies}{users}{fed}", f"OPC UA listening on {server.endpoint}"]

    def endpoints(self, o) -> list[dict]:
        from urllib.parse import urlsplit

        url = urlsplit(self.server.endpoint)
        return [{"name": "opcua", "protocol": "opc.tcp", "host": o["host"], "port": url.port,
                 "url": self.server.endpoint}]

    async def close(self) -> int:
        if self.server is None:
            return 0
        await self.server.close()
        return self.server.requests


def process(options: dict) -> OpcUaProcess:
    return OpcUaProcess(options)
