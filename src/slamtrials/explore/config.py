"""Settings of the frontier explorer and of the paper's termination rule (pydantic models, SI units).

Lengths are metres, angles radians, times seconds (of simulated time). Both models are frozen and
reject unknown keys; :meth:`ExploreConfig.from_dict` and :meth:`TerminationConfig.from_dict` validate a
plain dict (e.g. loaded from YAML) and turn a ``pydantic.ValidationError`` into a one-line
:class:`~slamtrials.errors.ConfigError` that names the field, the value and the problem.

The defaults follow the paper's set-up (spec/simulation.md): a 0.15 m disc robot, 0.7 m/s and
70 deg/s at most, a 0.1 s control period, goals blacklisted after 30 s without progress, snapshots of
the map every 120 s (small buildings) or 600 s (large ones), compared by mean square error below 10.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from slamtrials.errors import ConfigError, validation_problems

__all__ = ["ExploreConfig", "RobotLimits", "TerminationConfig", "lethal_distance"]

_MODEL_CONFIG = ConfigDict(extra="forbid", frozen=True)
_Model = TypeVar("_Model", bound=BaseModel)


def _validate(cls: type[_Model], data: dict[str, Any], what: str) -> _Model:
    try:
        return cls.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(f"{what} config: " + validation_problems(exc)) from None


@dataclass(frozen=True)
class RobotLimits:
    """The robot the explorer drives: its footprint, motion limits and control period.

    These describe the simulated robot, so a trial takes them from ``sim.robot`` and ``sim.dt``
    (:meth:`slamtrials.trial.TrialConfig.robot_limits`); the defaults are the paper's robot.

    Attributes
    ----------
    radius:
        Footprint disc radius (m).
    max_linear_speed, max_angular_speed:
        Largest forward speed (m/s) and turn rate (rad/s).
    max_linear_accel, max_angular_accel:
        Largest linear (m/s^2) and angular (rad/s^2) acceleration.
    control_period:
        Time between commands (s).
    """

    radius: float = 0.15
    max_linear_speed: float = 0.7
    max_angular_speed: float = math.radians(70.0)
    max_linear_accel: float = 0.5
    max_angular_accel: float = math.radians(100.0)
    control_period: float = 0.1

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"RobotLimits.{name} must be a positive number, got {value!r}")


#: Names of the robot's limits that earlier versions took in the explore section; now refused there.
ROBOT_FIELDS = (
    "robot_radius",
    "max_linear_speed",
    "max_angular_speed",
    "max_linear_accel",
    "max_angular_accel",
    "control_period",
)


def lethal_distance(config: ExploreConfig, robot: RobotLimits) -> float:
    """Distance (m) from an occupied cell's edge below which a cell is lethal: radius + inflation margin."""
    return robot.radius + config.inflation_margin


class ExploreConfig(BaseModel):
    """Frontier exploration: costmap, frontiers, planner, path follower, goal bookkeeping, recovery.

    The robot itself (footprint, speed and acceleration limits, control period) is not set here but
    given as :class:`RobotLimits`; a trial takes them from its ``sim.robot`` section.

    Costmap (:mod:`slamtrials.explore.costmap`). ``d`` is the distance (m) from a cell's centre to the
    nearest occupied cell's edge. Cells with ``d < radius + inflation_margin`` are lethal; the
    others cost ``1 + wall_cost * exp(-(d - radius - inflation_margin) / cost_decay_distance)``
    per metre travelled, so paths keep to the middle of corridors and doors.

    Unknown cells are not traversable by default (``unknown_traversable=False``): frontier goals are
    known-free cells, so every goal can be reached through known space, and a frontier that can only
    be reached through unknown space (a room seen through a gap narrower than the robot, a laser ray
    leaking out of the building) counts as unreachable at once instead of costing a 30 s timeout.

    Planning is local first: a goal is searched in a window of half-size ``local_radius`` around the
    robot, which is the closest one in the whole map if the search settles it before reaching the
    window's edge; otherwise the whole map is searched. While the robot heads for a goal outside the
    window, the path found is kept (checked against each new local costmap) and the whole map is
    searched again only every ``global_replan_period``.

    Last resorts, when no frontier is reachable: if the robot is shut in (it reaches less than
    ``shut_in_share`` of the passable cells), a plan with the lethal margin ``relaxed_margin`` (for
    frontiers behind passages that only look too narrow), then view points within
    ``view_distance`` of frontiers the robot cannot reach (off by default: in our trials they cost a
    lot of time for little map).

    Backing out: when the path leads back the way the robot came (the end of its first straight
    stretch, at most ``max_reverse_distance`` along it, lies at least ``reverse_angle`` off the
    heading; e.g. after reaching a goal at a dead end), the robot stops and backs along that stretch at
    ``reverse_speed`` at most, then turns where the path turns
    (:mod:`slamtrials.explore.follower`). Every turn counts towards GMapping's ``angularUpdate``, so
    turning round at each dead end would cost the SLAM about 13 updates.

    Evidence layer (:mod:`slamtrials.explore.evidence`, on with ``evidence_layer``): the explorer
    counts the cells its own laser returns crossed and ended in, and plans on the SLAM map corrected
    by them. A map-free cell with no crossed or hit cell within ``evidence_free_distance`` is unknown
    (the halo of free space GMapping draws beyond the walls from beams that returned nothing). A
    map-free cell that returns hit at least ``evidence_min_hits`` times and in more than
    ``evidence_occupied_ratio`` of the beams through it, and that one of the explorer's beams without
    a return (between two that returned) crossed within ``evidence_no_return_range`` of the laser, is
    a wall (a gap such beams wore into a wall). Defaults: 0.15 m, three cells, enough for the map's
    best particle and the pose the explorer drove by to differ by a cell or two without free cells at
    the edge of what was seen turning unknown; 2 hits, so one stray return marks nothing; 0.25,
    GMapping's own ``occ_thresh``; 8 m, a few rooms' worth (each such beam costs its length in cells;
    ``paper``'s laser has none indoors). A scan goes into the layer only once the robot moved
    ``evidence_linear_step`` or turned ``evidence_angular_step`` since the last one that did; by
    default every scan does: the published map holds what every particle saw along the way, and with
    0.2 m and 0.2 rad free cells at the edges of what was seen went unvouched, turned unknown and
    became frontiers (office_small_01, seeds 1 to 3: two ``paper`` runs changed, the ``realistic``
    ones took 30 % longer), for a saving of a few per cent of the wall time.

    Scan filter (:mod:`slamtrials.explore.scanfilter`): the follower and the recovery ignore returns
    inside the robot's disc, and react to a return within ``scan_filter_range`` only if another return
    within ``scan_filter_window`` beams ends within ``scan_filter_distance`` of it. Isolated returns (a laser's spurious short readings, the
    ``realistic`` profile's things not in the map) would otherwise stop the robot wherever it goes.
    The defaults: 2 beams (1 degree with the paper's 0.5 degree laser) either side, so one dropout
    next to a real return does not drop it; 0.15 m, about 2.7 standard deviations of the difference of
    two readings of one surface at 2 m with the ``realistic`` range noise (0.033 m + 0.4 % of the
    range each), while a phantom beam's endpoint lies anywhere between the laser and the wall. A
    return must also lie within ``scan_filter_distance`` of a confirmed return of each of the
    ``scan_filter_scans - 1`` previous scans: adjacent phantoms often confirm each other where beams
    converge (next to the robot, where every beam starts), but seldom in three scans in a row, while
    whatever is really there stays (office_small_01, ``realistic``, seed 1: the robot fell back to
    creeping 20 times with the neighbours and one previous scan, 8 times with two, 2 times with ``paper``). ``scan_filter_range`` 3 m: the robot stops from full
    speed within 0.6 m, and beyond 3 m the returns of a wall seen at a grazing angle lie more than
    0.15 m apart, so filtering them would only take away walls.

    Recovery: the robot is stuck when, over ``stuck_time``, it moved less than ``stuck_ratio`` of what
    it was commanded to move (the simulator stops the robot on a collision), when it has followed a
    path for ``idle_time`` without getting ``idle_distance`` away, when the caller reported
    ``stall_steps`` collisions in a row, or when the laser kept it from moving forward for
    ``blocked_time``. It then moves away from the obstacle it touches (or backs off
    ``backoff_distance`` and turns ``recovery_turn`` towards the more open side), and replans.
    """

    model_config = _MODEL_CONFIG

    # --- costmap ---------------------------------------------------------------------------------
    inflation_margin: float = Field(0.05, ge=0.0, le=5.0, description="lethal margin added to the radius (m)")
    relaxed_margin: float = Field(
        0.0, ge=0.0, le=5.0, description="lethal margin of the last-resort plan through narrow passages (m)"
    )
    shut_in_share: float = Field(
        0.5,
        ge=0.0,
        le=1.0,
        description="plan through narrow passages only when the robot reaches less than this share of the passable cells",
    )
    wall_cost: float = Field(10.0, ge=0.0, le=100.0, description="extra cost factor at the edge of the lethal zone")
    cost_decay_distance: float = Field(0.25, gt=0.0, le=10.0, description="decay length of the wall cost (m)")
    unknown_traversable: bool = Field(False, description="let paths cross unknown cells (at unknown_cost)")
    unknown_cost: float = Field(5.0, ge=1.0, le=20.0, description="cost factor of an unknown cell when traversable")
    escape_radius: float = Field(
        0.6,
        ge=0.0,
        le=10.0,
        description="lethal/unknown cells within this distance of the robot may be crossed to get out (m)",
    )
    escape_cost: float = Field(
        50.0, ge=1.0, le=100.0, description="cost factor of crossing a lethal cell while escaping"
    )
    # --- frontiers -----------------------------------------------------------------------------------
    min_frontier_length: float = Field(
        0.5, ge=0.0, le=100.0, description="smallest frontier kept: cells x resolution (m)"
    )
    view_distance: float = Field(
        0.0,
        ge=0.0,
        le=30.0,
        description="last resort: look at frontiers the robot cannot reach from reachable cells this close (m); 0 = never",
    )
    min_unknown_area: float = Field(
        3.0, ge=0.0, le=1000.0, description="enclosed unknown pockets smaller than this make no frontier (m^2)"
    )
    evidence_layer: bool = Field(
        True,
        description="correct the SLAM map by the explorer's own laser returns before planning "
        "(free space no return vouches for unknown, gaps worn into walls closed)",
    )
    evidence_linear_step: float = Field(
        0.0,
        ge=0.0,
        le=10.0,
        description="a scan goes into the evidence layer once the robot moved this far since the last one (m) ...",
    )
    evidence_angular_step: float = Field(
        0.0, ge=0.0, le=math.pi, description="... or turned this far (rad); 0 and 0 = every scan"
    )
    evidence_free_distance: float = Field(
        0.15,
        ge=0.0,
        le=5.0,
        description="map-free cells farther than this from every cell the explorer's returns crossed or hit "
        "count as unknown (m)",
    )
    evidence_min_hits: int = Field(
        2,
        ge=1,
        le=1000,
        description="returns that must end in a map-free cell crossed by a beam without a return before it counts "
        "as a wall",
    )
    evidence_occupied_ratio: float = Field(
        0.25,
        ge=0.0,
        lt=1.0,
        description="... and the share of the beams crossing or ending in it that must end there",
    )
    evidence_no_return_range: float = Field(
        8.0,
        ge=0.0,
        le=100.0,
        description="cells a beam without a return crossed this close to the laser may count as walls (m); 0 = none",
    )
    # --- path follower ------------------------------------------------------------------------------
    smooth_paths: bool = Field(True, description="straighten the planner's 8-connected paths where that costs no more")
    lookahead_distance: float = Field(1.0, gt=0.0, le=10.0, description="pure-pursuit look-ahead (m)")
    rotate_in_place_angle: float = Field(
        math.radians(50.0), gt=0.0, le=math.pi, description="heading error above which the robot turns in place (rad)"
    )
    max_reverse_distance: float = Field(
        2.5,
        ge=0.0,
        le=100.0,
        description="back out along the path for at most this far instead of turning round (m); 0 = never",
    )
    reverse_speed: float = Field(
        0.35, gt=0.0, le=10.0, description="largest backing speed when backing out along the path (m/s)"
    )
    reverse_angle: float = Field(
        math.radians(120.0),
        ge=math.radians(90.0),
        le=math.pi,
        description="back out when the end of the path's first straight stretch lies at least this far from the heading (rad)",
    )
    narrow_speed: float = Field(
        0.25, gt=0.0, le=10.0, description="speed limit where the path's clearance is down to the lethal distance (m/s)"
    )
    narrow_clearance: float = Field(
        0.25, ge=0.0, le=10.0, description="clearance beyond the lethal distance from which full speed is allowed (m)"
    )
    obstacle_margin: float = Field(
        0.03, ge=0.0, le=1.0, description="clearance added to the radius when checking the scan ahead (m)"
    )
    stop_distance: float = Field(0.05, ge=0.0, le=2.0, description="distance kept from obstacles seen in the scan (m)")
    scan_filter_window: int = Field(
        2,
        ge=0,
        le=20,
        description="a scan return counts as an obstacle only if a return within this many beams on either side "
        "confirms it (isolated returns are dropped); 0 = every return counts",
    )
    scan_filter_range: float = Field(
        3.0,
        gt=0.0,
        le=100.0,
        description="only returns this close are filtered (m); farther ones are kept as they are",
    )
    scan_filter_scans: int = Field(
        3,
        ge=1,
        le=10,
        description="consecutive scans a return must be seen in: 1 = confirmed by its neighbouring beams only, "
        "n = also by a return of each of the n - 1 previous scans",
    )
    scan_filter_distance: float = Field(
        0.15, gt=0.0, le=5.0, description="largest distance between two scan endpoints that confirm each other (m)"
    )
    # --- goals ---------------------------------------------------------------------------------------
    local_radius: float = Field(
        10.0, gt=0.0, le=1000.0, description="half-size of the window around the robot searched for a goal first (m)"
    )
    global_coarsening: int = Field(
        2,
        ge=1,
        le=8,
        description="whole-map searches look at blocks of this many cells squared first (1 = full resolution only)",
    )
    global_replan_period: float = Field(
        15.0,
        gt=0.0,
        le=3600.0,
        description="while heading for a goal outside that window, search the whole map this often (s)",
    )
    replan_period: float = Field(3.0, gt=0.0, le=600.0, description="replan at least this often (s)")
    min_replan_interval: float = Field(
        1.0, ge=0.0, le=600.0, description="smallest time between event-driven replans (s)"
    )
    goal_tolerance: float = Field(0.3, gt=0.0, le=10.0, description="a goal is reached within this distance (m)")
    goal_timeout: float = Field(
        30.0, gt=0.0, le=3600.0, description="blacklist a goal after this long without progress (s)"
    )
    progress_distance: float = Field(
        0.25, gt=0.0, le=10.0, description="getting this much closer to the goal is progress (m)"
    )
    blacklist_radius: float = Field(
        0.5, ge=0.0, le=20.0, description="frontier cells this close to a failed or reached goal are skipped (m)"
    )
    turn_penalty: float = Field(
        1.0,
        ge=0.0,
        le=100.0,
        description="the turn needed to set off towards a goal counts as this much extra path per radian (m/rad); 0 = closest goal only",
    )
    goal_hysteresis: float = Field(
        0.75,
        gt=0.0,
        le=1.0,
        description="switch goal only if the new one costs less than this fraction of the current one",
    )
    blacklist_resets: int = Field(
        1, ge=0, le=100, description="times the failed-goal blacklist is cleared when nothing else is left"
    )
    initial_spin: bool = Field(
        True, description="turn a full circle at the start, to see behind the laser's blind sector"
    )
    # --- stuck detection and recovery ----------------------------------------------------------------
    stuck_time: float = Field(3.0, gt=0.0, le=600.0, description="window of the stuck test (s)")
    stuck_ratio: float = Field(
        0.3, gt=0.0, lt=1.0, description="stuck when moving less than this fraction of the commanded distance"
    )
    stuck_min_command: float = Field(
        0.15,
        gt=0.0,
        le=100.0,
        description="commanded distance over the window needed before the stuck test applies (m)",
    )
    idle_time: float = Field(
        8.0, gt=0.0, le=600.0, description="recover after following a path this long without moving idle_distance (s)"
    )
    idle_distance: float = Field(0.1, gt=0.0, le=10.0, description="see idle_time (m)")
    stall_steps: int = Field(
        3,
        ge=1,
        le=1000,
        description="recover after this many consecutive steps the caller reports as stalled (collisions)",
    )
    blocked_time: float = Field(
        2.0, gt=0.0, le=600.0, description="recover after being held still by the scan this long (s)"
    )
    backoff_distance: float = Field(
        0.25, ge=0.0, le=5.0, description="distance moved away (or backed off) in a recovery (m)"
    )
    backoff_speed: float = Field(0.15, gt=0.0, le=10.0, description="backing speed (m/s)")
    recovery_turn: float = Field(
        math.radians(90.0),
        ge=0.0,
        le=2.0 * math.pi,
        description="turn in place after backing off, when not touching anything (rad)",
    )
    max_recoveries_per_goal: int = Field(
        2, ge=1, le=100, description="blacklist a goal after this many recoveries on the way"
    )
    transient_reach: float = Field(
        0.25,
        ge=0.0,
        le=5.0,
        description="when the scan held the robot still, plan around the returns this close to its edge that the "
        "map shows no wall near (m; 0: off; slamtrials.explore.transient)",
    )
    transient_lifetime: float = Field(
        60.0, gt=0.0, le=3600.0, description="forget such a return after this long even if no scan saw it gone (s)"
    )

    @model_validator(mode="before")
    @classmethod
    def _no_robot_fields(cls, data: Any) -> Any:
        if isinstance(data, dict):
            found = [name for name in ROBOT_FIELDS if name in data]
            if found:
                raise ValueError(
                    f"{found[0]} is a property of the robot: set it in sim.robot (radius, speeds, "
                    "accelerations) or sim.dt (control period), not in the explore section"
                )
        return data

    @model_validator(mode="after")
    def _consistent(self) -> ExploreConfig:
        if self.min_replan_interval > self.replan_period:
            raise ValueError(
                f"min_replan_interval ({self.min_replan_interval:g} s) must not exceed replan_period ({self.replan_period:g} s)"
            )
        return self

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ExploreConfig:
        """Validate a plain dict; raise :class:`ConfigError` with a one-line message."""
        return _validate(cls, data, "explore")


class TerminationConfig(BaseModel):
    """The paper's termination rule (:class:`~slamtrials.explore.termination.SnapshotTermination`).

    Every ``small_period`` (``large_period`` for large environments) seconds of simulated time, take a
    snapshot of the map as a grey image (occupied 0, free 255, unknown ``unknown_grey``), align the
    previous snapshot inside it by the map origins, downscale both by ``downscale`` (block mean), and
    stop when their mean square error, summed over ``channels`` identical colour channels, is below
    ``mse_threshold``. Also stop after ``max_snapshots`` snapshots, or at ``max_time``.

    Small or large: the environment is large when its free area is at least ``size_threshold`` m^2.
    The default, 1,000 m^2, is the paper's border between its small published buildings (100 to
    1,000 m^2) and its large campus buildings (1,000 to 30,000 m^2). Unless the caller gives the
    area, the known free area of the map at the time of each snapshot is used, so the period grows to
    ``large_period`` once the mapped part of a building passes the threshold.
    """

    model_config = _MODEL_CONFIG

    small_period: float = Field(120.0, gt=0.0, le=1e5, description="snapshot period of small environments (s)")
    large_period: float = Field(600.0, gt=0.0, le=1e5, description="snapshot period of large environments (s)")
    size_threshold: float = Field(
        1000.0, gt=0.0, le=1e7, description="free area from which an environment is large (m^2)"
    )
    mse_threshold: float = Field(
        10.0, ge=0.0, le=1e6, description="stop when the snapshot MSE is below this (grey^2, summed over channels)"
    )
    channels: int = Field(
        3, ge=1, le=4, description="colour channels the MSE is summed over (grey images: identical channels)"
    )
    downscale: int = Field(4, ge=1, le=64, description="block size of the downscaling (cells)")
    max_snapshots: int = Field(19, ge=2, le=100000, description="stop after this many snapshots")
    max_time: float = Field(10800.0, gt=0.0, le=1e7, description="hard cap on simulated time (s)")
    unknown_grey: int = Field(205, ge=0, le=255, description="grey level of unknown cells (ROS map_server's 205)")

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TerminationConfig:
        """Validate a plain dict; raise :class:`ConfigError` with a one-line message."""
        return _validate(cls, data, "termination")
