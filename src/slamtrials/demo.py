"""The README's main job: a small campaign on bundled worlds, then its HTML report.

:func:`run_demo` runs :func:`slamtrials.campaign.small_campaign_config` (the paper's robot, online
GMapping, frontier exploration, the Section III-C run-count rule with a first batch of 5 runs and a cap
of 10 per world, on three small bundled buildings) with :func:`slamtrials.campaign.run_campaign` on a
local Dask cluster (one worker process per core by default), in the folder ``out``; then it writes the
report (:func:`slamtrials.report.build.build_report`, ``<out>/report/index.html``). On 2 cores the
campaign takes about 4 to 8 minutes. Calling it again on the same folder resumes an interrupted campaign
(a finished one is not run again) and rebuilds the report.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from slamtrials.campaign.demo import DEMO_WORLDS

__all__ = ["DEMO_WORLDS", "DemoResult", "run_demo", "demo_config"]


@dataclass(frozen=True)
class DemoResult:
    """What :func:`run_demo` did.

    Attributes
    ----------
    campaign:
        The campaign's :class:`~slamtrials.campaign.CampaignResult` (its ``summary`` is the paper's Table I).
    report:
        The report page, ``<out>/report/index.html``.
    confidence:
        Confidence level of the summary's intervals.
    """

    campaign: Any
    report: Path
    confidence: float


def demo_config(out: str | Path, worlds: Sequence[str] = DEMO_WORLDS, *, seed: int = 0):
    """The demo's :class:`~slamtrials.campaign.CampaignConfig` (:func:`~slamtrials.campaign.small_campaign_config`)."""
    from slamtrials.campaign import small_campaign_config

    return small_campaign_config(tuple(worlds), seed, output=str(out))


def run_demo(
    out: str | Path,
    worlds: Sequence[str] = DEMO_WORLDS,
    *,
    seed: int = 0,
    workers: int | None = None,
    scheduler: Any = None,
    trial_fn: Callable | None = None,
    on_event: Callable | None = None,
    repeats: int = 200,
    pdf: bool = True,
) -> DemoResult:
    """Run (or resume) the demo campaign in ``out`` and write its report.

    Parameters
    ----------
    out:
        The campaign folder (created; an existing demo campaign of the same settings is resumed).
    worlds:
        World entries (bundled names, floor-plan files or folders).
    seed:
        Root seed of the campaign.
    workers:
        Worker processes of the local Dask cluster (default: one per core).
    scheduler:
        A Dask scheduler address or ``distributed.Client`` instead of a local cluster.
    trial_fn:
        A stand-in for :func:`slamtrials.trial.run_trial` (tests: :class:`slamtrials.campaign.testing.FakeTrial`).
    on_event:
        Progress callback of the campaign (:class:`~slamtrials.campaign.CampaignEvent`).
    repeats:
        Samplings of the report's relation-sampling check (Fig. 3).
    pdf:
        Also save the report's figures as PDF.

    Raises
    ------
    ConfigError
        A bad world, bad ``workers``, or an ``out`` that holds something other than this demo campaign.
    """
    from slamtrials.campaign import run_campaign
    from slamtrials.report.build import build_report

    config = demo_config(out, worlds, seed=seed)
    result = run_campaign(config, out, scheduler=scheduler, workers=workers, trial_fn=trial_fn, on_event=on_event)
    page = build_report(result.folder, repeats=repeats, pdf=pdf)
    return DemoResult(result, page, config.runs.confidence)
