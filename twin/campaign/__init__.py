"""Commissioning campaigns: a station, a driver (PLC logic, RAPID program or check), a matrix of parameters,
faults and expectations, run scenario by scenario in lockstep on a local pool or a Dask cluster.

    from twin.campaign import load_campaign, run_campaign, LocalBackend
    result = run_campaign(load_campaign("stations/ring_rig_plc/campaign.toml"), LocalBackend(2), "out/")

See docs/campaigns.md; the command is `twin campaign SPEC.toml`.
"""
from .backends import DaskBackend, LocalBackend
from .runner import CampaignResult, run_campaign
from .scenario import Context, run_scenario
from .spec import Campaign, Scenario, SpecError, load_campaign

__all__ = ["Campaign", "CampaignResult", "Context", "DaskBackend", "LocalBackend", "Scenario", "SpecError",
           "load_campaign", "run_campaign", "run_scenario"]
