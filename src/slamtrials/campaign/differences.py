"""What differs between the settings of two campaigns (a campaign and its replay, or any two compared).

:func:`setting_differences` lists every setting that differs, one :class:`SettingDifference` per leaf
of the config (``slam.preset``, ``slam.params.particles``, ``metric.margin_t``, ``sim.odometry.alpha``,
...), so that ``campaign replay`` and ``compare`` can say what the two sets of results differ by before
showing them. The SLAM parameters are compared as the algorithm actually ran them: the preset's values
with the overrides on top (``slam.params.particles: 40 -> 80``), when both campaigns run the same
algorithm; across algorithms the parameters are not comparable and only the overrides are listed.
``output`` and ``replay_of`` (where the results are, not how they were made) are left out.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from slamtrials.campaign.config import CampaignConfig
from slamtrials.campaign.store import ABSENT, CampaignStore, differing_fields
from slamtrials.errors import ConfigError

__all__ = ["SettingDifference", "setting_differences", "campaign_differences"]

#: Fields that say where a campaign is, not how its results were made.
_NOT_SETTINGS = ("output", "replay_of")


@dataclass(frozen=True)
class SettingDifference:
    """One setting whose value differs between campaign A and campaign B.

    Attributes
    ----------
    field:
        Dotted name of the setting in the campaign config (``slam.params.particles``).
    a, b:
        Its value in A and in B (plain JSON values; :data:`~slamtrials.campaign.store.ABSENT` when one
        side has no such setting).
    """

    field: str
    a: Any
    b: Any

    def __str__(self) -> str:
        return f"{self.field}: {_show(self.a)} -> {_show(self.b)}"


def _show(value: Any) -> str:
    if value == ABSENT:
        return ABSENT
    if isinstance(value, str):
        return value
    return json.dumps(value)


def _settings(config: CampaignConfig, resolve: bool) -> dict[str, Any]:
    """The config's JSON form without :data:`_NOT_SETTINGS`; the SLAM parameters resolved if ``resolve``."""
    data = config.model_dump(mode="json", exclude=set(_NOT_SETTINGS))
    if resolve:
        data["slam"]["params"] = config.slam.resolved().model_dump(mode="json")
    return data


def setting_differences(a: CampaignConfig, b: CampaignConfig) -> list[SettingDifference]:
    """Every setting that differs from ``a`` to ``b``, sorted by field name (see the module docstring).

    The SLAM parameters are resolved (preset + overrides) when both run the same algorithm and both
    resolve; otherwise (another algorithm, or one not installed here) the overrides are compared as
    stored.
    """
    resolve = a.slam.algorithm == b.slam.algorithm
    if resolve:
        try:
            first, second = _settings(a, True), _settings(b, True)
        except ConfigError:
            resolve = False
    if not resolve:
        first, second = _settings(a, False), _settings(b, False)
    return [SettingDifference(k, x, y) for k, x, y in differing_fields(first, second)]


def campaign_differences(folder_a: str | Path, folder_b: str | Path) -> list[SettingDifference]:
    """:func:`setting_differences` of the stored configs of the campaigns in ``folder_a`` and ``folder_b``.

    Raises
    ------
    ConfigError
        A folder holds no campaign.
    """
    with CampaignStore.open(folder_a) as store:
        a = store.config()
    with CampaignStore.open(folder_b) as store:
        b = store.config()
    return setting_differences(a, b)
