"""SLAM algorithms behind one protocol: the registry, the occupancy-grid builder, the odometry
baseline, ``gmapping`` and ``karto``.

``make_algorithm("odometry", record.laser)`` builds an algorithm; feed it frames with ``process`` and read
``trajectory()`` and ``occupancy()``. Third-party algorithms register with :func:`register_algorithm` or
the ``slamtrials.slam`` entry-point group. See :mod:`slamtrials.slam.base`.
"""

from __future__ import annotations

from slamtrials.slam.base import (
    ALGORITHMS,
    ENTRY_POINT_GROUP,
    FREE,
    OCCUPIED,
    UNKNOWN,
    ChildProcessAlgorithm,
    OccupancyGrid,
    SlamAlgorithm,
    get_algorithm,
    known_algorithms,
    make_algorithm,
    register_algorithm,
    resolve_config,
)
from slamtrials.slam.gmapping import GMapping, GMappingConfig
from slamtrials.slam.gridmap import GridMap
from slamtrials.slam.karto import Karto, KartoConfig
from slamtrials.slam.odometry import OdometryConfig, OdometrySlam

__all__ = [
    "ALGORITHMS",
    "ENTRY_POINT_GROUP",
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "OccupancyGrid",
    "SlamAlgorithm",
    "ChildProcessAlgorithm",
    "get_algorithm",
    "known_algorithms",
    "make_algorithm",
    "register_algorithm",
    "resolve_config",
    "GridMap",
    "GMapping",
    "GMappingConfig",
    "Karto",
    "KartoConfig",
    "OdometryConfig",
    "OdometrySlam",
]
