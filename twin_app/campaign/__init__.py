"""Commissioning campaigns: a station, a driver (PLC logic, RAPID program or check), a matrix of parameters,
faults and expectations, run scenario by scenario in lockstep on a local pool or a Dask cluster.

    from twin_app.campaign import load_campaign, run_campaign, LocalBackend
    result = run_campaign(load_campaign("stations/my_cell/campaign.toml"), LocalBackend(2), "out/")

See docs/campaigns.md; the command is `twin campaign SPEC.toml`.
"""

_LAZY = {"DaskBackend": ".backends", "LocalBackend": ".backends", "CampaignResult": ".runner", "run_campaign": ".runner", "Context": ".scenario", "run_scenario": ".scenario", "Campaign": ".spec", "Scenario": ".spec", "SpecError": ".spec", "load_campaign": ".spec"}

__all__ = ["Campaign", "CampaignResult", "Context", "DaskBackend", "LocalBackend", "Scenario", "SpecError",
           "load_campaign", "run_campaign", "run_scenario"]


def __getattr__(name: str):
    """Import lazily, so building the `twin` command's parser (`campaign.cli`) costs nothing (`twin map`)."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(name)
