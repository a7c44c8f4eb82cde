"""The README's main job: a small campaign on bundled worlds that finishes in about 10 minutes on 2 cores.

:func:`small_campaign_config` is the paper's set-up (robot, laser, odometry, online GMapping with the
``paper`` preset, frontier exploration, snapshot termination, relation sampling, 99 % confidence and
+-0.02 m / +-0.02 rad margins) on three small bundled buildings, with a smaller first batch and a lower
cap than the paper's (``initial`` 5 instead of 10, ``max_runs`` 10) so that it ends quickly. A run of
one of these worlds takes about 20-35 s of one core with online GMapping, so the first batches (15 runs)
take about 4 minutes on 2 cores and the cap bounds the whole campaign at 30 runs (about 8 minutes).
Pass ``initial=10, max_runs=60`` for the paper's rule.
"""

from __future__ import annotations

from collections.abc import Sequence

from slamtrials.campaign.config import CampaignConfig

__all__ = ["DEMO_WORLDS", "small_campaign_config", "DEMO_INITIAL_RUNS", "DEMO_MAX_RUNS"]

#: Three small bundled worlds of different kinds (office, lab, house; 110 to 180 m^2 of free space).
DEMO_WORLDS = ("office_small_01", "lab_small_01", "house_small_01")
DEMO_INITIAL_RUNS = 5
DEMO_MAX_RUNS = 10


def small_campaign_config(
    worlds: Sequence[str] = DEMO_WORLDS,
    seed: int = 0,
    *,
    initial: int = DEMO_INITIAL_RUNS,
    max_runs: int = DEMO_MAX_RUNS,
    output: str | None = None,
    **overrides,
) -> CampaignConfig:
    """The demo campaign config (see the module docstring).

    Parameters
    ----------
    worlds:
        World entries (catalog names, files or folders).
    seed:
        Root seed.
    initial, max_runs:
        First batch and cap of the run-count rule.
    output:
        Campaign folder to record in the config.
    **overrides:
        Other top-level sections of :class:`CampaignConfig` as plain dicts (e.g. ``slam={"algorithm": "odometry"}``).

    Raises
    ------
    ConfigError
        A bad value.
    """
    runs = {"initial": initial, "max_runs": max_runs, **overrides.pop("runs", {})}
    return CampaignConfig.from_dict(
        {"worlds": list(worlds), "seed": seed, "output": output, "runs": runs, **overrides},
        source="small campaign config",
    )
