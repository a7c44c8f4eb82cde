"""Karto's parameters under slam_toolbox's names, with the defaults of ``mapper_params_online_async.yaml``.

Units are SI (metres, radians, seconds). Where slam_toolbox hands a value to Karto squared (the two
variance penalties and ``loop_match_maximum_variance_coarse``), the parameter here is the value
slam_toolbox's YAML holds and the squaring happens where it is used, as in Karto's setters.

Parameters that are not Karto's matcher or graph settings: ``resolution``, ``max_laser_range`` and
``map_update_interval`` (slam_toolbox's, for the published map and the range threshold),
``min_pass_through`` and ``occupancy_threshold`` (Karto's occupancy-grid rule, slam_toolbox's code
defaults), ``initial_pose`` (slamtrials' own, as for GMapping) and ``optimizer`` (which program's
pose-graph solver). slam_toolbox's Ceres options are not parameters (see docs/karto.md).
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

__all__ = ["KartoConfig"]


class KartoConfig(BaseModel):
    """Parameters of :class:`~slamtrials.slam.karto.Karto` (slam_toolbox's names and defaults).

    Attributes
    ----------
    resolution:
        Cell size of the published map (m).
    max_laser_range:
        Karto's range threshold (m): readings beyond it are not used for the scan barycentre and are
        cut there in the map; it also sizes the correlation grids. Capped at the laser's ``range_max``.
    map_update_interval:
        Seconds (of recording time) between rebuilds of the published map from the graph's poses.
    minimum_time_interval:
        Seconds between nodes: slam_toolbox's gate lets a scan through only after this long, and Karto's
        HasMovedEnough makes a node of any scan this long after the last one.
    scan_throttle:
        slam_toolbox's gate (``shouldProcessScan``) before Karto's node rule: a scan gets through only if
        ``minimum_time_interval`` passed since the last scan that got through and the base moved, by
        odometry, at least ``sqrt(0.8) minimum_travel_distance`` since then (no heading test; the first
        scan passes, the next three do not). A scan that gets through becomes a node only if Karto's
        HasMovedEnough agrees (the laser moved ``minimum_travel_distance`` or turned
        ``minimum_travel_heading``), with Karto's own time rule of 3600 s, since slam_toolbox never hands
        the mapper ``minimum_time_interval``. False: Karto's HasMovedEnough alone (slam_karto), with
        ``minimum_time_interval`` as its time rule.
    use_scan_matching:
        Correct each node by scan matching (False: nodes at their odometry poses, no graph).
    use_scan_barycenter:
        Measure distances between scans from the barycentre of their end points, not the laser pose.
    minimum_travel_distance, minimum_travel_heading:
        A scan becomes a node when the laser moved this far (m) or turned this much (rad), by odometry,
        since the last node.
    scan_buffer_size, scan_buffer_maximum_scan_distance:
        The running buffer the sequential matcher matches against: at most this many recent nodes,
        first and last at most this far apart (m).
    link_match_minimum_response_fine:
        A near chain is linked when its fine match response exceeds this.
    link_scan_maximum_distance:
        Scans farther apart than this (m) are never linked; also the radius of the near-chain search.
    loop_search_maximum_distance:
        Loop-closure candidates lie within this distance (m) of the new scan.
    do_loop_closing:
        Search for loop closures.
    loop_match_minimum_chain_size:
        Least number of scans in a near chain or loop-closure chain.
    loop_match_maximum_variance_coarse:
        A loop closure's coarse match must have x and y variances below this value squared (m^2).
    loop_match_minimum_response_coarse, loop_match_minimum_response_fine:
        Least coarse and fine responses of a loop closure.
    correlation_search_space_dimension, correlation_search_space_resolution,
    correlation_search_space_smear_deviation:
        Sequential matcher: side of the searched square (m), cell size (m), smearing deviation (m).
    loop_search_space_dimension, loop_search_space_resolution, loop_search_space_smear_deviation:
        The same for the loop-closure matcher's coarse search.
    distance_variance_penalty, angle_variance_penalty:
        Standard deviations (m, rad) of the penalty for moving away from the search centre
        (a response is multiplied by ``max(1 - 0.2 d^2 / sigma^2, minimum)``).
    fine_search_angle_offset:
        Angular step (rad) of the fine pass (which searches +-half a coarse step).
    coarse_search_angle_offset, coarse_angle_resolution:
        Half-width and step (rad) of the coarse angular search.
    minimum_angle_penalty, minimum_distance_penalty:
        Floors of the penalty multipliers.
    use_response_expansion:
        When the coarse response is 0, widen the angular search by 20 degrees up to three times.
    min_pass_through, occupancy_threshold:
        Map: a cell is known after more than ``min_pass_through`` beams crossed it, occupied when
        hits / crossings exceeds ``occupancy_threshold``.
    initial_pose:
        Map-frame base pose (x, y, theta) of the first scan; None: the first odometry pose.
    optimizer:
        The pose-graph solver run after each loop closure: ``ceres`` (slam_toolbox's CeresSolver set-up,
        :mod:`.optimize`) or ``spa`` (slam_karto's SpaSolver, sparse_bundle_adjustment's ``doSPA(40)``,
        :mod:`.spa`).
    graph_frame:
        Which poses the graph's edges join and the optimizer's results are set as. ``base``
        (slam_toolbox): the scans' corrected base poses (its LinkInfo takes ``GetCorrectedPose``).
        ``laser`` (open_karto, slam_karto): the scans' laser poses (LinkInfo takes ``GetSensorPose``, and
        CorrectPoses sets each optimized pose with ``SetSensorPose``), while the optimizer starts from
        the base poses. With the laser mounted off the base's centre the two differ.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    resolution: float = Field(0.05, ge=0.005, le=1.0, description="published map cell size (m)")
    max_laser_range: float = Field(20.0, gt=0.0, le=1000.0, description="range threshold (m)")
    map_update_interval: float = Field(5.0, ge=0.0, le=1.0e6, description="seconds between map rebuilds")
    minimum_time_interval: float = Field(0.5, ge=0.0, le=1.0e6, description="least seconds between nodes")
    scan_throttle: bool = Field(True, description="slam_toolbox's scan gate before Karto's node rule")
    use_scan_matching: bool = Field(True, description="correct nodes by scan matching")
    use_scan_barycenter: bool = Field(True, description="distances between scans from their barycentres")
    minimum_travel_distance: float = Field(0.5, ge=0.0, le=1000.0, description="node after this travel (m)")
    minimum_travel_heading: float = Field(0.5, ge=0.0, le=2.0 * math.pi, description="node after this turn (rad)")
    scan_buffer_size: int = Field(10, ge=1, le=10_000, description="running buffer length (nodes)")
    scan_buffer_maximum_scan_distance: float = Field(10.0, gt=0.0, le=1000.0, description="running buffer extent (m)")
    link_match_minimum_response_fine: float = Field(
        0.1, ge=0.0, le=1.0, description="least response to link a near chain"
    )
    link_scan_maximum_distance: float = Field(
        1.5, gt=0.0, le=1000.0, description="largest distance of linked scans (m)"
    )
    loop_search_maximum_distance: float = Field(3.0, gt=0.0, le=1000.0, description="loop candidates within (m)")
    do_loop_closing: bool = Field(True, description="close loops")
    loop_match_minimum_chain_size: int = Field(10, ge=1, le=10_000, description="least scans in a chain")
    loop_match_maximum_variance_coarse: float = Field(
        3.0, gt=0.0, le=1000.0, description="coarse loop variance bound (sqrt of m^2)"
    )
    loop_match_minimum_response_coarse: float = Field(0.35, ge=0.0, le=1.0, description="least coarse loop response")
    loop_match_minimum_response_fine: float = Field(0.45, ge=0.0, le=1.0, description="least fine loop response")
    correlation_search_space_dimension: float = Field(0.5, gt=0.0, le=100.0, description="sequential search side (m)")
    correlation_search_space_resolution: float = Field(0.01, ge=0.001, le=1.0, description="sequential grid cell (m)")
    correlation_search_space_smear_deviation: float = Field(0.1, gt=0.0, le=10.0, description="sequential smearing (m)")
    loop_search_space_dimension: float = Field(8.0, gt=0.0, le=100.0, description="loop search side (m)")
    loop_search_space_resolution: float = Field(0.05, ge=0.001, le=1.0, description="loop grid cell (m)")
    loop_search_space_smear_deviation: float = Field(0.03, gt=0.0, le=10.0, description="loop smearing (m)")
    distance_variance_penalty: float = Field(0.5, gt=0.0, le=100.0, description="distance penalty deviation (m)")
    angle_variance_penalty: float = Field(1.0, gt=0.0, le=100.0, description="angle penalty deviation (rad)")
    fine_search_angle_offset: float = Field(0.00349, gt=0.0, le=math.pi, description="fine angular step (rad)")
    coarse_search_angle_offset: float = Field(0.349, gt=0.0, le=math.pi, description="coarse angular half-width (rad)")
    coarse_angle_resolution: float = Field(0.0349, gt=0.0, le=math.pi, description="coarse angular step (rad)")
    minimum_angle_penalty: float = Field(0.9, ge=0.0, le=1.0, description="angle penalty floor")
    minimum_distance_penalty: float = Field(0.5, ge=0.0, le=1.0, description="distance penalty floor")
    use_response_expansion: bool = Field(True, description="widen the angular search on a zero response")
    min_pass_through: int = Field(2, ge=0, le=1000, description="map: crossings before a cell is known")
    occupancy_threshold: float = Field(
        0.1, ge=0.0, lt=1.0, description="map: occupied when hits/crossings exceeds this"
    )
    initial_pose: tuple[float, float, float] | None = Field(
        None, description="base pose of the first scan; None: first odometry pose"
    )

    optimizer: Literal["ceres", "spa"] = Field("ceres", description="pose-graph solver: slam_toolbox's or slam_karto's")
    graph_frame: Literal["base", "laser"] = Field(
        "base", description="frame the graph's edges join and optimized poses set: slam_toolbox's or open_karto's"
    )

    @field_validator("initial_pose")
    @classmethod
    def _finite(cls, value: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
        if value is not None and not all(math.isfinite(v) for v in value):
            raise ValueError(f"initial_pose must be finite numbers, got {value}")
        return value

    @model_validator(mode="after")
    def _consistent(self) -> KartoConfig:
        # Karto's smearing kernel spans two deviations and must fit 0.5 to 10 cells (CorrelationGrid)
        for prefix, smear, cell in (
            (
                "correlation_search_space",
                self.correlation_search_space_smear_deviation,
                self.correlation_search_space_resolution,
            ),
            ("loop_search_space", self.loop_search_space_smear_deviation, self.loop_search_space_resolution),
        ):
            if not 0.5 * cell <= smear <= 10.0 * cell:
                raise ValueError(
                    f"{prefix}_smear_deviation ({smear} m) must be between 0.5 and 10 times "
                    f"{prefix}_resolution ({cell} m)"
                )
        if self.fine_search_angle_offset > 0.5 * self.coarse_angle_resolution:
            raise ValueError(
                f"fine_search_angle_offset ({self.fine_search_angle_offset} rad) must not exceed half of "
                f"coarse_angle_resolution ({self.coarse_angle_resolution} rad)"
            )
        if self.coarse_angle_resolution > self.coarse_search_angle_offset:
            raise ValueError(
                f"coarse_angle_resolution ({self.coarse_angle_resolution} rad) must not exceed "
                f"coarse_search_angle_offset ({self.coarse_search_angle_offset} rad)"
            )
        return self
