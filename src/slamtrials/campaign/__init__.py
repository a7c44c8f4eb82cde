"""The campaign: repeat runs per world until its mean errors are known, on Dask, with a durable store.

Per world, the paper's Section III-C loop (:mod:`~slamtrials.campaign.loop`) decides how many runs are
needed; every run (trial + evaluation, :mod:`~slamtrials.campaign.task`) is an independent Dask task
with its own seed (:mod:`~slamtrials.campaign.seeds`); results go to a SQLite catalog and run folders
(:mod:`~slamtrials.campaign.store`, :mod:`~slamtrials.campaign.runfiles`), so a campaign resumes after a
crash with the same results. :func:`replay_campaign` re-evaluates recorded runs with another SLAM
algorithm without simulating again.
"""

from __future__ import annotations

from slamtrials.campaign.config import CampaignConfig, MetricSettings, RunSettings
from slamtrials.campaign.demo import DEMO_WORLDS, small_campaign_config
from slamtrials.campaign.dump import dump_default_yaml
from slamtrials.campaign.events import REPLAY_NOTE, CampaignEvent, CampaignResult
from slamtrials.campaign.execute import run_campaign
from slamtrials.campaign.replay import replay_campaign
from slamtrials.campaign.seeds import run_seed
from slamtrials.campaign.status import CampaignStatus, campaign_status
from slamtrials.campaign.summary import WorldSummary, load_summary

__all__ = [
    "CampaignConfig",
    "MetricSettings",
    "RunSettings",
    "run_campaign",
    "replay_campaign",
    "campaign_status",
    "CampaignStatus",
    "load_summary",
    "WorldSummary",
    "dump_default_yaml",
    "small_campaign_config",
    "DEMO_WORLDS",
    "CampaignEvent",
    "CampaignResult",
    "REPLAY_NOTE",
    "run_seed",
]
