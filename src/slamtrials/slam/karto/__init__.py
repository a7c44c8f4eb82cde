"""``karto``: Karto-style graph SLAM (open_karto as slam_toolbox runs it); see docs/karto.md.

See :mod:`slamtrials.slam.karto.algorithm` for the algorithm and its documented choices.
"""

from __future__ import annotations

from slamtrials.slam.karto.algorithm import Karto
from slamtrials.slam.karto.config import KartoConfig

__all__ = ["Karto", "KartoConfig"]
