"""Campaigns: parameter sweeps and Monte Carlo dispersions of a system, run on Dask
(`neighbor-cosim campaign SPEC --out DIR`): `spec` reads and checks the TOML spec and gives
each run its values, `worker` runs one on a worker, `runner` schedules them and keeps the
results (see docs/campaigns.md)."""
from .runner import main, run_campaign, summarize
from .spec import CampaignSpec, load_spec

__all__ = ["CampaignSpec", "load_spec", "run_campaign", "summarize", "main"]
