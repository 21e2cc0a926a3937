"""A `twin serve STATION --opcua 0` subprocess, and asyncua client helpers."""
from __future__ import annotations

import sys
from pathlib import Path

from asyncua import Client, ua

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "modbus"))
from modbus_helpers import ROOT, ServerProcess  # noqa: E402  (the `twin serve` subprocess both suites use)

RING_RIG = ROOT / "stations" / "ring_rig"
NAMESPACE = "urn:gripper-twin:station:"
FOLDERS = ("Gripper", "Fingers", "Robot", "Targets", "Controller", "Sim")


class OpcUaServerProcess(ServerProcess):
    """`twin serve STATION --port 0 --opcua 0 ARGS...`; `url` is the OPC UA endpoint, `port` Modbus's (None with
    --no-modbus). Its stderr is collected line by line in `lines`, to the end."""

    def __init__(self, station, *args: str, cert_dir=None):
        extra = ["--opcua-cert-dir", str(cert_dir)] if cert_dir is not None else []
        env = {"XDG_DATA_HOME": str(ROOT / ".pytest_cache" / "opcua-certs")} if cert_dir is None else {}
        self._start([sys.executable, "-m", "twin", "serve", str(station), "--port", "0", "--opcua", "0", *extra, *args],
                    env=env, timeout=90)
        self.url = self.endpoint("opcua")["url"]
        modbus = [f for f in self.ready["front_ends"] if f["name"] == "modbus"]
        self.host, self.port = (modbus[0]["host"], modbus[0]["port"]) if modbus else ("127.0.0.1", None)


async def namespace(client: Client, station: str = "ring_rig") -> int:
    return await client.get_namespace_index(NAMESPACE + station)


def node(client: Client, ns: int, name: str):
    return client.get_node(ua.NodeId(name, ns))


CHUNK = 50  # steps per Sim.Advance call (see `advance`)


async def advance(client: Client, ns: int, steps: int) -> int:
    """Sim.Advance(steps), in calls of at most CHUNK steps: returns sim.step once the steps are done. asyncua
    answers a connection's requests in order, and its client's keep-alive read gives up after 1 s: a call
    that runs longer on a loaded machine would cost the connection (docs/opcua.md)."""
    sim, method = node(client, ns, "Sim"), ua.NodeId("Sim.Advance", ns)
    step = await sim.call_method(method, ua.Variant(min(steps, CHUNK), ua.VariantType.UInt32))
    for done in range(CHUNK, steps, CHUNK):
        step = await sim.call_method(method, ua.Variant(min(CHUNK, steps - done), ua.VariantType.UInt32))
    return step


async def write_status(n, value, vtype=None) -> str:
    """Write one value; the name of the status code the server answered ('Good' when accepted)."""
    dv = ua.DataValue(ua.Variant(value, vtype) if vtype is not None else ua.Variant(value))
    result = await n.session.write(ua.WriteParameters(NodesToWrite=[
        ua.WriteValue(NodeId=n.nodeid, AttributeId=ua.AttributeIds.Value, Value=dv)]))
    return result[0].name
