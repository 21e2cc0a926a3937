"""A faults file: the `[faults.NAME]` tables of a campaign file on their own, every one injected, for
`twin serve STATION --faults FILE` (and `plc_client.testing.twin_server(..., faults=FILE)`): the plant
faults of docs/campaigns.md in a served twin, so a commissioning check over Modbus meets them too.

    [faults.jam]
    kind = "finger_jammed"
    input = "axis1"
    position_mm = 326.0
    at = 0.5

Link faults (`link_lost`, `link_latency`) belong to the PLC's side of the link: wrap the check's I/O in
`plc_client.link.LinkFaults` instead; here they are refused.
"""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from .spec import LINK_KINDS, SpecError, _fault, _Station, read_toml


def load_fault_file(path: str | Path, twin) -> list:
    """The plant faults of `path`, checked against `twin`'s station (SpecError naming file and key)."""
    from twin.runtime.faults import FaultError

    from .scenario import ScenarioError, build_faults

    file = Path(path)
    data = read_toml(file)
    for key in data:
        if key != "faults":
            raise SpecError(file, key, "a faults file has only [faults.NAME] tables")
    tables = data.get("faults", {})
    if not isinstance(tables, dict):
        raise SpecError(file, "faults", "must be tables: [faults.NAME] with a kind")
    station = _Station(file, twin.station.file)
    specs = {name: _fault(file, name, table, station) for name, table in tables.items()}
    for name, spec in specs.items():
        if spec.kind in LINK_KINDS:
            raise SpecError(file, f"faults.{name}.kind", f"{spec.kind} is a fault of the PLC's link: inject it on the "
                                                         "client's side (plc_client.link.LinkFaults)")
    try:
        plant, _ = build_faults(SimpleNamespace(faults=specs), {"fault": list(specs)}, twin)
        for fault in plant:
            fault.check(twin)
    except (ScenarioError, FaultError) as exc:
        raise SpecError(file, "faults", str(exc)) from None
    return plant
