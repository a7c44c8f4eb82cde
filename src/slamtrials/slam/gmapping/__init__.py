"""``gmapping``: GMapping's Rao-Blackwellized particle filter as its code behaves (spec/gmapping.md).

See :mod:`slamtrials.slam.gmapping.filter` for the algorithm and its documented choices.
"""

from __future__ import annotations

from slamtrials.slam.gmapping.config import PRESETS, GMappingConfig
from slamtrials.slam.gmapping.filter import GMapping

__all__ = ["GMapping", "GMappingConfig", "PRESETS"]
