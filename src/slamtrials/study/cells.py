"""A study's cells: the grid of its axes (and its named combinations) expanded into campaign configs.

A cell is the base campaign config with a few settings replaced (``sim.laser.max_range: 15``). The
product cells come first, in the order of the axes and their values (the last axis varies fastest),
named by their settings (``max_range=15,particles=30``: each key's last part, or the whole key where
two axes share a last part); the named combinations follow under their own names. Each cell's
config is validated as a campaign config, so a value out of its range is refused naming the cell and
the field. Every cell keeps the base's root seed and worlds: run ``i`` of world ``w`` has the same seed
(:func:`slamtrials.campaign.seeds.run_seed`) in every cell, and cells are compared run by run.
"""

from __future__ import annotations

import copy
import itertools
import re
from dataclasses import dataclass
from typing import Any

from slamtrials.campaign.config import CampaignConfig
from slamtrials.errors import ConfigError
from slamtrials.study.config import StudyConfig, set_key, value_text, written_campaign

__all__ = ["Cell", "expand_cells", "set_key", "cell_folder_name", "CELLS_DIR"]

#: Folder of the study that holds one campaign folder per cell.
CELLS_DIR = "cells"


@dataclass(frozen=True)
class Cell:
    """One cell of a study.

    Attributes
    ----------
    name:
        Unique name; the cell's campaign folder is ``cells/<name>`` (:func:`cell_folder_name`).
    settings:
        ``((dotted key, value), ...)``: what the cell sets over the base config, in axis order.
    combination:
        Whether it is a named combination (else a cell of the product of the axes).
    config:
        The cell's campaign config.
    """

    name: str
    settings: tuple[tuple[str, Any], ...]
    combination: bool
    config: CampaignConfig

    def value(self, key: str) -> Any:
        """The cell's value of ``key``, or None if it does not set it."""
        return dict(self.settings).get(key)

    def describe(self) -> str:
        """``key: value, key: value`` (all settings, in order)."""
        return ", ".join(f"{k}: {value_text(v)}" for k, v in self.settings)


def cell_folder_name(name: str) -> str:
    """The folder name of a cell (characters other than letters, digits and ``._=,+-`` replaced by ``_``)."""
    return re.sub(r"[^A-Za-z0-9._=,+-]", "_", name)


def _short_names(keys: list[str]) -> dict[str, str]:
    """Each key's last part, or the whole key where two keys share their last part."""
    last = [k.split(".")[-1] for k in keys]
    return {k: (s if last.count(s) == 1 else k) for k, s in zip(keys, last, strict=True)}


def _cell_config(base: dict[str, Any], settings: tuple[tuple[str, Any], ...], name: str) -> CampaignConfig:
    data = copy.deepcopy(base)
    for key, value in settings:
        set_key(data, key, value)
    try:
        return CampaignConfig.from_dict(data, source=f"cell {name}")
    except ConfigError as exc:
        raise ConfigError(
            f"{exc} (the cell's settings: {', '.join(f'{k}: {value_text(v)}' for k, v in settings)})"
        ) from None


def expand_cells(study: StudyConfig) -> list[Cell]:
    """The study's cells (see the module docstring).

    Raises
    ------
    ConfigError
        A value out of its range (naming the cell, the field and the value), or two cells of one name.
    """
    base_config = study.check()
    base = written_campaign(base_config)
    cells: list[Cell] = []
    if study.product and study.axes:
        keys = list(study.axes)
        short = _short_names(keys)
        for values in itertools.product(*(study.axes[k] for k in keys)):
            settings = tuple(zip(keys, values, strict=True))
            name = cell_folder_name(",".join(f"{short[k]}={value_text(v)}" for k, v in settings))
            cells.append(Cell(name, settings, False, _cell_config(base, settings, name)))
    for name, given in study.combinations.items():
        settings = tuple(given.items())
        cells.append(Cell(name, settings, True, _cell_config(base, settings, name)))
    names = [c.name for c in cells]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ConfigError(f"two cells are named {twice[0]}; rename the combination")
    return cells
