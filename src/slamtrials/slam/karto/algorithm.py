"""``karto``: graph-based SLAM as open_karto behaves when slam_toolbox runs it (online, asynchronous mode).

Per frame (:meth:`Karto.process`):

1. the frame's base pose is predicted from the last node: its corrected pose composed with the
   odometry motion since it (Karto's "corrected pose" of a new scan);
2. the frame becomes a node when it is the first, or it passes slam_toolbox's gate (at least
   ``minimum_time_interval`` seconds since the last node and a base travel of ``sqrt(0.8)
   minimum_travel_distance`` by odometry; not the 2nd to 4th frame) and then Karto's HasMovedEnough
   (the time interval passed, or the laser turned ``minimum_travel_heading`` or moved
   ``minimum_travel_distance``); without the gate (``scan_throttle`` False) Karto's rule alone;
3. a node's laser pose is corrected by matching its scan against the running buffer of recent nodes
   (:mod:`.scanmatch`); it is linked to the previous node and to the buffer's node nearest to it,
   matched against the near chains of earlier passes that the graph already connects to it (linked
   when the response is high enough), and set to the covariance-weighted mean of those matches
   (Karto's AddEdges);
4. loop closure: every chain of earlier nodes near it that the graph does not link to it is matched
   coarsely with the loop matcher, then finely; on success the node is linked to the chain's nearest
   node and the whole graph is optimized (:mod:`.optimize`), which moves every node (TryCloseLoop);
5. every ``map_update_interval`` seconds the published map is rebuilt from the nodes' poses
   (:mod:`.mapbuild`).

Frames. Nodes hold base poses; matching works on laser poses (base composed with the laser's mount),
with beams aimed from the laser's angles rounded to float32 (as a ROS LaserScan carries them). Edges join
base poses as slam_toolbox links corrected poses, or laser poses as open_karto does (``graph_frame``).
The map frame starts on the first frame's odometry pose, or ``initial_pose``.

Estimates. :meth:`Karto.process` returns the online estimate: a node's corrected pose once it is
processed, else the prediction of step 1. :meth:`Karto.trajectory` returns the final estimate: the
nodes' optimized poses, every other frame carried there by odometry from the node nearest in time (as
the Freiburg evaluator scores a graph that has poses at its nodes only).

Randomness: none; the ``rng`` given to :meth:`Karto.reset` is not drawn from. Results depend only on the
inputs and the C library's sin and cos (no BLAS: see :mod:`.sparsechol`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import ConfigError
from slamtrials.geometry import compose, compose1, inverse, ominus, ominus1, wrap_angle1
from slamtrials.record import LaserGeometry, Reading, Trajectory
from slamtrials.slam.base import OccupancyGrid, register_algorithm
from slamtrials.slam.karto.config import KartoConfig
from slamtrials.slam.karto.correlation import KT_TOLERANCE
from slamtrials.slam.karto.graph import PoseGraph, ScanNode
from slamtrials.slam.karto.loopclosure import find_loop_closure_chain, find_near_chains
from slamtrials.slam.karto.mapbuild import NodeMap
from slamtrials.slam.karto.optimize import information, optimize_pose_graph
from slamtrials.slam.karto.scanmatch import (
    MatcherSettings,
    MatchResult,
    ScanMatcher,
    barycentre,
    local_points,
    scan_points,
)
from slamtrials.slam.karto.spa import optimize_spa

__all__ = ["Karto", "LoopCheck"]

#: slam_toolbox's gate: a scan passes when its squared travel is at least this share of the squared
#: minimum travel distance ("within 10% for correction error"), and not before the fifth scan
_GATE_DISTANCE_FACTOR = 0.8
_GATE_FIRST_SCANS = 5
#: Karto's own ``MinimumTimeInterval`` (s), which slam_toolbox's ``SMapper::configure`` never overrides
_KARTO_DEFAULT_TIME_INTERVAL = 3600.0


def _mat3(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """3 x 3 product written out (no BLAS)."""
    out = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            out[i, j] = a[i, 0] * b[0, j] + a[i, 1] * b[1, j] + a[i, 2] * b[2, j]
    return out


def weighted_mean(means: list[NDArray[np.float64]], covariances: list[NDArray[np.float64]]) -> NDArray[np.float64]:
    """Karto's ComputeWeightedMean: poses weighted by their information matrices, headings averaged
    through their cosines and sines."""
    infos = [information(c) for c in covariances]
    total = np.zeros((3, 3))
    for info in infos:
        total = total + info
    spread = information(total)
    out = np.zeros(3)
    sum_c = sum_s = 0.0
    for pose, info in zip(means, infos):
        weight = _mat3(spread, info)
        for i in range(3):
            out[i] += weight[i, 0] * pose[0] + weight[i, 1] * pose[1] + weight[i, 2] * pose[2]
        sum_c += math.cos(float(pose[2]))
        sum_s += math.sin(float(pose[2]))
    out[2] = math.atan2(sum_s / len(means), sum_c / len(means))
    return out


@dataclass(frozen=True)
class LoopCheck:
    """One loop-closure candidate tried by TryCloseLoop (a diagnostic; what slam_toolbox logs as "COARSE
    RESPONSE", "var" and "FINE RESPONSE").

    Attributes
    ----------
    node:
        Index of the new node.
    first, last:
        Indices of the candidate chain's first and last node (consecutive).
    coarse_response:
        The loop matcher's response (unpenalised, no fine pass).
    variance_x, variance_y:
        Its position variances (m^2, map frame).
    fine_response:
        The sequential matcher's response from the coarse pose; NaN when the coarse gates failed.
    accepted:
        The closure was accepted (linked, then the graph optimized).
    jump:
        Distance (m) the loop match moved the node's laser position (0 when not accepted).
    """

    node: int
    first: int
    last: int
    coarse_response: float
    variance_x: float
    variance_y: float
    fine_response: float
    accepted: bool
    jump: float


@register_algorithm
class Karto:
    """Karto graph SLAM (registry name ``karto``; see the module docstring).

    Parameters
    ----------
    config:
        Validated :class:`~slamtrials.slam.karto.config.KartoConfig`.
    laser:
        The laser's geometry (:class:`~slamtrials.record.LaserGeometry` or its dict form).

    Attributes
    ----------
    updates:
        Nodes added since :meth:`reset`.
    loop_closures:
        Loop closures accepted since :meth:`reset`.
    loop_checks:
        Every loop-closure candidate tried since :meth:`reset` (:class:`LoopCheck`), in order.
    timings:
        ``[(node index, seconds)]``: wall time of every node's processing (matching, linking, loop
        closing and optimizing).
    optimizations:
        ``[(nodes, edges, seconds, iterations)]`` of every optimizer run.
    """

    name: ClassVar[str] = "karto"
    Config: ClassVar[type[KartoConfig]] = KartoConfig
    PRESETS: ClassVar[dict[str, dict[str, Any]]] = {
        # slam_toolbox's defaults; named so trial configs, whose preset defaults to "paper", can say
        # just `algorithm: karto` (the seed paper ran GMapping only)
        "paper": {},
        "slam_toolbox": {},
        # slam_karto's config/mapper_params.yaml, which are open_karto's own defaults; slam_karto has no
        # scan gate before Karto's node rule, and leaves Karto's default range threshold (12 m)
        "slam_karto": {
            "scan_throttle": False,
            "minimum_time_interval": 3600.0,
            "minimum_travel_distance": 0.2,
            "minimum_travel_heading": 0.174,
            "scan_buffer_size": 70,
            "scan_buffer_maximum_scan_distance": 20.0,
            "link_match_minimum_response_fine": 0.8,
            "link_scan_maximum_distance": 10.0,
            "loop_search_maximum_distance": 4.0,
            "loop_match_maximum_variance_coarse": 0.4,
            "loop_match_minimum_response_coarse": 0.8,
            "loop_match_minimum_response_fine": 0.8,
            "correlation_search_space_dimension": 0.3,
            "correlation_search_space_smear_deviation": 0.03,
            "distance_variance_penalty": 0.3,
            "angle_variance_penalty": 0.349,
            "use_response_expansion": False,
            "max_laser_range": 12.0,
            "optimizer": "spa",
            "graph_frame": "laser",
        },
    }

    def __init__(self, config: KartoConfig, laser: LaserGeometry | dict[str, Any]):
        laser = laser if isinstance(laser, LaserGeometry) else LaserGeometry.from_dict(laser)
        self.config = config
        # slam_toolbox and slam_karto take the beam angles from a sensor_msgs/LaserScan, which holds
        # angle_min and angle_increment as float32: Karto aims every beam from those rounded values (up to
        # 1e-7 rad off, 2 um at 20 m: enough to move a point into the next cell now and then)
        self.laser = replace(
            laser,
            angle_min=float(np.float32(laser.angle_min)),
            angle_increment=float(np.float32(laser.angle_increment)),
        )
        self.mount = np.asarray(laser.mount, dtype=np.float64)
        self.unmount = inverse(self.mount)
        self.range_threshold = min(float(config.max_laser_range), laser.range_max)
        c = config
        settings = MatcherSettings(
            coarse_search_angle_offset=c.coarse_search_angle_offset,
            coarse_angle_resolution=c.coarse_angle_resolution,
            fine_search_angle_offset=c.fine_search_angle_offset,
            distance_variance=c.distance_variance_penalty**2,
            angle_variance=c.angle_variance_penalty**2,
            minimum_distance_penalty=c.minimum_distance_penalty,
            minimum_angle_penalty=c.minimum_angle_penalty,
            use_response_expansion=c.use_response_expansion,
        )
        self.sequential = ScanMatcher(
            c.correlation_search_space_dimension,
            c.correlation_search_space_resolution,
            c.correlation_search_space_smear_deviation,
            self.range_threshold,
            settings,
        )
        self.loop_matcher = ScanMatcher(
            c.loop_search_space_dimension,
            c.loop_search_space_resolution,
            c.loop_search_space_smear_deviation,
            self.range_threshold,
            settings,
        )
        self.reset(np.random.default_rng(0))

    # ------------------------------------------------------------------ state

    def reset(self, rng: np.random.Generator) -> None:
        """Forget every frame (Karto draws no random numbers; ``rng`` is not used)."""
        c = self.config
        self.updates = 0
        self.loop_closures = 0
        self.loop_checks: list[LoopCheck] = []
        self.timings: list[tuple[int, float]] = []
        self.optimizations: list[tuple[int, int, float, int]] = []
        self.graph = PoseGraph()
        self.running: list[int] = []
        self.map = NodeMap(
            c.resolution,
            self.laser,
            max_urange=self.range_threshold,
            min_pass_through=c.min_pass_through,
            occupancy_threshold=c.occupancy_threshold,
        )
        self._last_map_t = -math.inf
        self._t: list[float] = []
        self._odometry: list[NDArray[np.float64]] = []
        # slam_toolbox's gate: time and odometry pose of the last scan it let through
        self._gate_t = -math.inf
        self._gate_odometry = np.zeros(3)
        self._anchor: list[int] = []
        self._estimates: list[NDArray[np.float64]] = []
        # The optimizer's own copy of every node's base pose, its starting point. As slam_toolbox's
        # CeresSolver keeps one (AddNode stores the scan's corrected pose when the vertex is added, right
        # after sequential matching; Compute starts from it and overwrites it with its result), a pose
        # set on a node afterwards (AddEdges' weighted mean, a loop closure's match) is not seen by it.
        self._solver_poses: list[NDArray[np.float64]] = []
        # per node: its reference position (_references) and the pose object it was computed for
        self._reference_rows = np.zeros((0, 2))
        self._reference_poses: list[NDArray[np.float64]] = []
        # per node: the pose its map-frame points and barycentre were computed at, and those
        self._world: dict[
            int, tuple[NDArray[np.float64], tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]]
        ] = {}

    # ------------------------------------------------------------------ helpers

    def _laser_pose(self, index: int) -> NDArray[np.float64]:
        return compose1(self.graph.nodes[index].pose, self.mount)

    def _base_pose(self, laser_pose: NDArray[np.float64]) -> NDArray[np.float64]:
        return compose1(laser_pose, self.unmount)

    def _world_points(self, index: int) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Node ``index``'s map-frame points ``x, y [B]`` and barycentre ``[2]`` (NaN if it has none),
        computed as Karto does whenever a scan's pose is set (LocalizedRangeScan::Update); kept until the
        node's pose changes."""
        node = self.graph.nodes[index]
        cached = self._world.get(index)
        if cached is not None and cached[0] is node.pose:  # a node's pose is replaced, never changed in place
            return cached[1]
        laser_pose = self._laser_pose(index)
        x, y = scan_points(laser_pose, node.readings, self.laser.angle_min, self.laser.angle_increment)
        points = (x, y, barycentre(x, y, node.within))
        self._world[index] = (node.pose, points)
        return points

    def _references(self) -> NDArray[np.float64]:
        """``[N, 2]`` every node's reference position: its points' barycentre or its laser position (a view
        of a cache; rows are recomputed only for nodes whose pose was replaced since)."""
        nodes = self.graph.nodes
        n = len(nodes)
        if self._reference_rows.shape[0] < n:
            grown = np.zeros((max(2 * self._reference_rows.shape[0], n, 64), 2))
            grown[: self._reference_rows.shape[0]] = self._reference_rows
            self._reference_rows = grown
        rows, poses = self._reference_rows, self._reference_poses
        use_barycentre = self.config.use_scan_barycenter
        for k in range(n):
            node = nodes[k]
            if k < len(poses) and poses[k] is node.pose:
                continue
            reference = compose1(node.pose, self.mount)[:2]
            if use_barycentre:
                centre = self._world_points(k)[2]
                if not np.isnan(centre[0]):
                    reference = centre
            rows[k] = reference
            if k < len(poses):
                poses[k] = node.pose
            else:
                poses.append(node.pose)
        return rows[:n]

    def _points(self, indexes: list[int]) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
        return [self._world_points(i)[:2] for i in indexes]

    def _own_points(
        self, laser_pose: NDArray[np.float64], node: ScanNode
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """A scan's points in the frame of ``laser_pose``, as Karto's lookup tables take them: its map-frame
        points at that pose, brought back into the laser frame."""
        x, y = scan_points(laser_pose, node.readings, self.laser.angle_min, self.laser.angle_increment)
        return local_points(laser_pose, x, y)

    def _match(
        self,
        matcher: ScanMatcher,
        laser_pose: NDArray[np.float64],
        index: int,
        base: list[int],
        *,
        penalize: bool,
        refine: bool = True,
    ) -> MatchResult:
        lx, ly = self._own_points(laser_pose, self.graph.nodes[index])
        return matcher.match(laser_pose, lx, ly, self._points(base), penalize=penalize, refine=refine)

    def _scan_node(
        self,
        frame_index: int,
        t: float,
        odometry: NDArray[np.float64],
        pose: NDArray[np.float64],
        ranges: NDArray[np.float64],
    ) -> ScanNode:
        # The matcher's points are Karto's unfiltered point readings (LocalizedRangeScan::GetPointReadings()
        # with its default wantFiltered = false, as FindValidPoints and GridIndexLookup::ComputeOffsets call
        # it): every reading, also those beyond the range threshold. Only the barycentre is taken over the
        # filtered ones, the readings within the range threshold (m_PointReadings). Points are computed
        # from these where they are used (_world_points, _own_points), with Karto's arithmetic.
        has_point = np.isfinite(ranges) & (ranges > self.laser.range_min) & (ranges < self.laser.range_max)
        return ScanNode(
            frame=frame_index,
            t=t,
            odometry=odometry,
            pose=pose,
            ranges=np.asarray(ranges, dtype=np.float32),
            readings=np.where(has_point, ranges, np.nan),
            within=has_point & (ranges <= self.range_threshold),
        )

    def _is_node(self, t: float, odometry: NDArray[np.float64]) -> bool:
        """slam_toolbox's scan gate (``shouldProcessScan``, when ``scan_throttle``), then Karto's
        HasMovedEnough against the last node."""
        c = self.config
        if not self.graph.nodes:
            self._gate_t, self._gate_odometry = t, odometry
            return True
        if c.scan_throttle:
            # the first scan passes; scans 2 to 4 (counted from 1) never do
            if len(self._t) + 1 < _GATE_FIRST_SCANS:
                return False
            if t - self._gate_t < c.minimum_time_interval:
                return False
            dx, dy = odometry[0] - self._gate_odometry[0], odometry[1] - self._gate_odometry[1]
            # "check moved enough, within 10% for correction error": base poses, distance only
            if dx * dx + dy * dy < _GATE_DISTANCE_FACTOR * c.minimum_travel_distance**2:
                return False
            # the gate's reference moves on every scan it lets through, node or not
            self._gate_t, self._gate_odometry = t, odometry
            # slam_toolbox hands the mapper every Karto parameter but this one, so Karto keeps its default
            time_interval = _KARTO_DEFAULT_TIME_INTERVAL
        else:
            time_interval = c.minimum_time_interval
        last = self.graph.nodes[-1]
        if t - last.t >= time_interval:
            return True
        before = compose1(last.odometry, self.mount)
        now = compose1(odometry, self.mount)
        if abs(wrap_angle1(now[2] - before[2])) >= c.minimum_travel_heading:
            return True
        dx, dy = now[0] - before[0], now[1] - before[1]
        return dx * dx + dy * dy >= c.minimum_travel_distance**2 - KT_TOLERANCE

    # ------------------------------------------------------------------ graph building (Karto's MapperGraph)

    def _link_chain(
        self, chain: list[int], index: int, laser_mean: NDArray[np.float64], covariance: NDArray[np.float64]
    ) -> None:
        """LinkChainToScan: link the chain's node nearest to node ``index`` if near enough."""
        reference = self._references()
        here = reference[index]
        closest, best = -1, math.inf
        for k in chain:
            dx, dy = reference[k, 0] - here[0], reference[k, 1] - here[1]
            if dx * dx + dy * dy < best:
                closest, best = k, dx * dx + dy * dy
        if closest >= 0 and best < self.config.link_scan_maximum_distance**2 + KT_TOLERANCE:
            self._link(closest, index, laser_mean, self._base_pose(laser_mean), covariance)

    def _link(
        self,
        source: int,
        target: int,
        laser_pose: NDArray[np.float64],
        base_pose: NDArray[np.float64],
        covariance: NDArray[np.float64],
    ) -> None:
        """LinkScans: an edge from node ``source`` to node ``target`` placed at ``laser_pose`` (its base
        at ``base_pose``). slam_toolbox's edge joins the two base poses; open_karto's (``graph_frame``
        "laser") joins the two laser poses, as its LinkInfo takes the scans' sensor poses."""
        if self.config.graph_frame == "laser":
            self.graph.link(source, target, laser_pose, covariance, origin=self._laser_pose(source))
        else:
            self.graph.link(source, target, base_pose, covariance)

    def _add_edges(self, index: int, covariance: NDArray[np.float64]) -> None:
        """AddEdges: link to the previous node, the running buffer and near chains; then the weighted mean."""
        c = self.config
        node = self.graph.nodes[index]
        means: list[NDArray[np.float64]] = []
        covariances: list[NDArray[np.float64]] = []
        if index > 0:
            laser_pose = self._laser_pose(index)
            self._link(index - 1, index, laser_pose, node.pose, covariance)
            means.append(laser_pose)
            covariances.append(covariance)
            self._link_chain(self.running, index, laser_pose, covariance)
        reference = self._references()
        for chain in find_near_chains(self.graph, index, reference, c.link_scan_maximum_distance):
            if len(chain) < c.loop_match_minimum_chain_size:
                continue
            result = self._match(self.sequential, self._laser_pose(index), index, chain, penalize=False)
            if result.response > c.link_match_minimum_response_fine - KT_TOLERANCE:
                means.append(result.pose)
                covariances.append(result.covariance)
                self._link_chain(chain, index, result.pose, result.covariance)
        if means:
            node.pose = self._base_pose(weighted_mean(means, covariances))

    def _add_running(self, index: int) -> None:
        c = self.config
        self.running.append(index)
        limit = c.scan_buffer_maximum_scan_distance**2 - KT_TOLERANCE
        while True:
            front, back = self._laser_pose(self.running[0]), self._laser_pose(self.running[-1])
            dx, dy = back[0] - front[0], back[1] - front[1]
            if len(self.running) > c.scan_buffer_size or dx * dx + dy * dy > limit:
                self.running.pop(0)
            else:
                break

    def _optimize(self) -> None:
        """CorrectPoses: optimize the whole graph from the solver's copy of the nodes and move every node."""
        edges = self.graph.edges
        started = time.perf_counter()
        solve = optimize_spa if self.config.optimizer == "spa" else optimize_pose_graph
        result = solve(
            np.array(self._solver_poses, dtype=np.float64).reshape(-1, 3),
            np.array([e.source for e in edges]),
            np.array([e.target for e in edges]),
            np.array([e.mean for e in edges]),
            np.array([information(e.covariance) for e in edges]),
        )
        self.optimizations.append((len(self.graph.nodes), len(edges), time.perf_counter() - started, result.iterations))
        if self.config.graph_frame == "laser":
            # open_karto's CorrectPoses hands each optimized pose to SetSensorPose: it becomes the laser pose
            self.graph.set_poses(np.array([self._base_pose(pose) for pose in result.poses]).reshape(-1, 3))
        else:
            self.graph.set_poses(result.poses)
        self._solver_poses = [pose.copy() for pose in result.poses]

    def _close_loops(self, index: int) -> None:
        """TryCloseLoop: try every candidate chain in turn; optimize after each accepted closure."""
        c = self.config
        node = self.graph.nodes[index]
        start = 0
        chain, start = find_loop_closure_chain(
            self.graph,
            index,
            self._references(),
            c.loop_search_maximum_distance,
            c.loop_match_minimum_chain_size,
            start,
        )
        while chain:
            laser_pose = self._laser_pose(index)
            coarse = self._match(self.loop_matcher, laser_pose, index, chain, penalize=False, refine=False)
            bound = c.loop_match_maximum_variance_coarse**2
            fine_response, accepted, jump = math.nan, False, 0.0
            if (
                coarse.response > c.loop_match_minimum_response_coarse
                and coarse.covariance[0, 0] < bound
                and coarse.covariance[1, 1] < bound
            ):
                fine = self._match(self.sequential, coarse.pose, index, chain, penalize=False)
                fine_response = fine.response
                if fine.response >= c.loop_match_minimum_response_fine:
                    accepted = True
                    jump = math.hypot(fine.pose[0] - laser_pose[0], fine.pose[1] - laser_pose[1])
                    node.pose = self._base_pose(fine.pose)
                    self._link_chain(chain, index, fine.pose, fine.covariance)
                    self._optimize()
                    self.loop_closures += 1
            self.loop_checks.append(
                LoopCheck(
                    index,
                    chain[0],
                    chain[-1],
                    float(coarse.response),
                    float(coarse.covariance[0, 0]),
                    float(coarse.covariance[1, 1]),
                    float(fine_response),
                    accepted,
                    jump,
                )
            )
            chain, start = find_loop_closure_chain(
                self.graph,
                index,
                self._references(),
                c.loop_search_maximum_distance,
                c.loop_match_minimum_chain_size,
                start,
            )

    def _add_node(
        self,
        frame_index: int,
        t: float,
        odometry: NDArray[np.float64],
        predicted: NDArray[np.float64],
        ranges: NDArray[np.float64],
    ) -> ScanNode:
        c = self.config
        started = time.perf_counter()
        node = self._scan_node(frame_index, t, odometry, predicted, ranges)
        covariance = np.eye(3)
        if c.use_scan_matching and self.graph.nodes:
            laser_pose = compose1(predicted, self.mount)
            result = self.sequential.match(
                laser_pose,
                *self._own_points(laser_pose, node),
                self._points(self.running),
                penalize=True,
                refine=True,
            )
            node.pose = self._base_pose(result.pose)
            covariance = result.covariance
        index = self.graph.add_node(node)
        # the solver's copy of the node (CeresSolver::AddNode, called by AddVertex before AddEdges)
        self._solver_poses.append(node.pose.copy())
        if c.use_scan_matching:
            self._add_edges(index, covariance)
            self._add_running(index)
            if c.do_loop_closing:
                self._close_loops(index)
        self.updates += 1
        self.timings.append((index, time.perf_counter() - started))
        if t - self._last_map_t >= c.map_update_interval:
            self._rebuild_map()
            self._last_map_t = t
        return node

    def _rebuild_map(self) -> None:
        nodes = self.graph.nodes
        self.map.update(compose(self.graph.poses(), self.mount), [n.ranges for n in nodes])

    # ------------------------------------------------------------------ protocol

    def process(self, frame: Reading) -> NDArray[np.float64]:
        """Take one frame; return the online base-pose estimate (map frame), float64 ``[3]``.

        Raises
        ------
        ConfigError
            The frame has no laser readings.
        """
        t = float(frame.t)
        ranges = np.asarray(frame.ranges, dtype=np.float64).reshape(-1)
        if ranges.shape[0] == 0:
            raise ConfigError(f"karto: the frame at t = {t:g} s has no laser readings; a scan is needed")
        odometry = np.asarray(frame.odometry, dtype=np.float64)
        nodes = self.graph.nodes
        if nodes:
            last = nodes[-1]
            predicted = compose1(last.pose, ominus1(last.odometry, odometry))
        else:
            start = self.config.initial_pose
            predicted = odometry.copy() if start is None else np.asarray(start, dtype=np.float64)
        if self._is_node(t, odometry):
            estimate = self._add_node(len(self._t), t, odometry, predicted, ranges).pose.copy()
        else:
            estimate = predicted
        self._t.append(t)
        self._odometry.append(odometry)
        self._anchor.append(len(self.graph.nodes) - 1)
        self._estimates.append(estimate)
        return estimate

    def occupancy(self) -> OccupancyGrid:
        """The published map, rebuilt from the nodes' poses at most every ``map_update_interval`` seconds."""
        return self.map.occupancy()

    def final_occupancy(self) -> OccupancyGrid:
        """The map rebuilt now from the nodes' current (final) poses."""
        self._rebuild_map()
        return self.map.occupancy()

    def trajectory(self) -> Trajectory:
        """The final estimate: the nodes at their optimized poses, every other frame carried there by
        odometry from the node nearest to it in time (the earlier one on a tie).

        That is how the Freiburg evaluator scores a graph's output, which holds poses at its nodes
        only: the pose nearest in time, carried to the timestamp by the odometry between the two.
        """
        t = np.array(self._t, dtype=np.float64)
        if not self._t:
            return Trajectory(t=t, poses=np.zeros((0, 3)))
        node_poses = self.graph.poses()
        node_t = np.array([n.t for n in self.graph.nodes], dtype=np.float64)
        node_odometry = np.array([n.odometry for n in self.graph.nodes], dtype=np.float64)
        before = np.array(self._anchor, dtype=np.intp)  # last node at or before each frame
        after = np.minimum(before + 1, len(node_t) - 1)
        nearest = np.where(node_t[after] - t < t - node_t[before], after, before)
        odometry = np.array(self._odometry, dtype=np.float64)
        poses = compose(node_poses[nearest], ominus(node_odometry[nearest], odometry))
        return Trajectory(t=t, poses=poses)

    def online_estimates(self) -> NDArray[np.float64]:
        """float64 ``[T, 3]``: what :meth:`process` returned for every frame."""
        return np.array(self._estimates, dtype=np.float64).reshape(-1, 3)
