"""Behaviour taken from slam_toolbox's and Karto's source that the accuracy on real logs depends on: the
scan gate before a node, which readings the matcher and the barycentre see, the response's denominator,
and where the final estimate puts frames between nodes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.geometry import compose1, ominus1
from slamtrials.record import Frame
from slamtrials.slam import make_algorithm
from slamtrials.slam.karto.scanmatch import MatcherSettings, ScanMatcher, points_in_map

SETTINGS = MatcherSettings(
    coarse_search_angle_offset=0.349,
    coarse_angle_resolution=0.0349,
    fine_search_angle_offset=0.00349,
    distance_variance=0.25,
    angle_variance=1.0,
    minimum_distance_penalty=0.5,
    minimum_angle_penalty=0.9,
    use_response_expansion=True,
)


def _frames(synthetic, odometry, times):
    angles = synthetic.laser.beam_angles(361)
    ranges = synthetic.raycast(np.array([-6.0, -6.0, 0.0]), angles, synthetic.segments, synthetic.laser.range_max)
    poses = [np.array(o, dtype=np.float64) for o in odometry]
    return [Frame(t=t, ranges=ranges, odometry=o, truth=o) for t, o in zip(times, poses)]


def _nodes(synthetic, odometry, times, **overrides):
    karto = make_algorithm("karto", synthetic.laser, overrides={"use_scan_matching": False, **overrides})
    for frame in _frames(synthetic, odometry, times):
        karto.process(frame)
    return [n.frame for n in karto.graph.nodes]


def test_the_scan_gate_is_slam_toolboxs_and_karto_keeps_its_own_node_rule(synthetic):
    # shouldProcessScan: the first scan passes, scans 2-4 never do; then at least 0.5 s and a base travel
    # of sqrt(0.8) * 0.5 = 0.447 m since the last scan it let through (node or not), no heading test.
    # Then Karto's HasMovedEnough with its own time interval (3600 s: slam_toolbox never passes its
    # minimum_time_interval to the mapper): 0.5 m of laser travel or a 0.5 rad turn since the last node
    odometry = [
        (0.0, 0.0, 0.0),
        (1.0, 0.0, 0.0),  # 2nd scan: far enough, but too early in the count
        (2.0, 0.0, 0.0),
        (3.0, 0.0, 0.0),
        (3.0, 0.0, 0.0),  # 5th: 3 m from the first scan -> through the gate, and a node
        (3.0, 0.0, 1.5),  # turned 1.5 rad in place: the gate has no heading test
        (3.46, 0.0, 1.5),  # 0.46 m (>= 0.447) through the gate; turned since the last node -> node
        (3.9, 0.0, 1.5),  # 0.44 m: not through the gate
        (3.92, 0.0, 1.5),  # 0.46 m: through the gate, but 0.46 m < 0.5 m from the last node: no node
        (4.0, 0.0, 1.5),  # 0.54 m from the last node, but 0.08 m from the gate's last scan: refused
        (4.4, 0.0, 1.5),  # 0.48 m from the gate's last scan, 0.94 m from the last node -> node
        (4.9, 0.0, 1.5),  # 0.5 m, but 0.3 s after the gate's last scan
    ]
    times = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 7.2, 7.9, 8.5, 8.8]
    assert _nodes(synthetic, odometry, times) == [0, 4, 6, 10]


def test_without_the_gate_karto_makes_a_node_on_a_turn_or_after_its_time_interval(synthetic):
    # Karto's HasMovedEnough alone (slam_karto): time interval, or heading, or laser travel
    odometry = [(0.0, 0.0, 0.0), (0.1, 0.0, 0.0), (0.1, 0.0, 0.6), (0.1, 0.0, 0.6), (0.1, 0.0, 0.6)]
    times = [0.0, 1.0, 2.0, 3.0, 13.0]
    nodes = _nodes(synthetic, odometry, times, scan_throttle=False, minimum_time_interval=10.0)
    assert nodes == [0, 2, 4]


def test_the_matcher_sees_every_reading_and_the_barycentre_only_those_within_the_range_threshold(synthetic):
    # Karto's matcher takes a scan's unfiltered point readings (GetPointReadings() with its default
    # wantFiltered = false, in FindValidPoints and GridIndexLookup::ComputeOffsets); only the barycentre
    # is taken over the readings within the range threshold (m_PointReadings)
    karto = make_algorithm("karto", synthetic.laser, overrides={"max_laser_range": 3.0})
    frame = _frames(synthetic, [(0.0, 0.0, 0.0)], [0.0])[0]
    karto.process(frame)
    node = karto.graph.nodes[0]
    ranges = np.asarray(frame.ranges, dtype=np.float64)
    x, y, barycentre = karto._world_points(0)  # map-frame points at the node's laser pose (here the origin)
    far = (ranges > 3.0) & (ranges < synthetic.laser.range_max)
    assert far.any() and (ranges <= 3.0).any()
    np.testing.assert_array_equal(~np.isnan(x), ranges < synthetic.laser.range_max)
    near = ranges <= 3.0
    np.testing.assert_array_equal(node.within, near)
    assert np.hypot(*barycentre) <= 3.0
    np.testing.assert_allclose(barycentre, [x[near].mean(), y[near].mean()], atol=1e-12)


def test_the_response_is_divided_by_the_readings_not_the_points(synthetic):
    # GetResponse divides by the size of the scan's lookup array, which holds one entry per unfiltered
    # point reading, those without a point (INVALID_SCAN) included: a scan matched against itself scores
    # about the share of its readings that have a point
    laser = synthetic.laser
    angles = laser.beam_angles(361)
    pose = np.array([-6.0, -1.0, math.pi / 2])
    ranges = synthetic.raycast(pose, angles, synthetic.segments, laser.range_max).astype(np.float64)
    assert np.all(ranges < laser.range_max)
    lx, ly = ranges * np.cos(angles), ranges * np.sin(angles)
    matcher = ScanMatcher(0.5, 0.01, 0.1, laser.range_max, SETTINGS)
    whole = matcher.match(pose, lx, ly, [points_in_map(pose, lx, ly)]).response
    ranges[::2] = np.nan  # 181 of the 361 readings without a point
    lx, ly = ranges * np.cos(angles), ranges * np.sin(angles)
    half = matcher.match(pose, lx, ly, [points_in_map(pose, lx, ly)]).response
    assert whole > 0.9
    assert abs(half - whole * 180 / 361) < 0.05


def test_frames_between_nodes_are_placed_from_the_nearest_node(square_loop):
    karto = make_algorithm("karto", square_loop.laser, overrides={"use_scan_matching": False})
    for frame in square_loop.frames:
        karto.process(frame)
    nodes = karto.graph.nodes
    assert len(nodes) > 3
    # move every node off its odometry chain, as an optimization would
    poses = karto.graph.poses()
    poses[:, 0] += 0.3 * np.arange(len(nodes))
    poses[:, 2] += 0.01 * np.arange(len(nodes))
    karto.graph.set_poses(poses)
    trajectory = karto.trajectory()
    node_t = np.array([n.t for n in nodes])
    placed_from_next = 0
    for k, frame in enumerate(square_loop.frames):
        gaps = np.abs(node_t - frame.t)
        nearest = int(np.flatnonzero(gaps == gaps.min())[0])  # the earlier one on a tie
        node = nodes[nearest]
        expected = compose1(node.pose, ominus1(node.odometry, np.asarray(frame.odometry, dtype=np.float64)))
        np.testing.assert_allclose(trajectory.poses[k], expected, atol=1e-9)
        placed_from_next += node.t > frame.t
    assert placed_from_next > 0


@pytest.mark.slow  # karto over the whole loop, recording every optimization
def test_the_optimizer_starts_from_its_own_copy_of_the_nodes(square_loop, monkeypatch):
    # slam_toolbox's CeresSolver keeps each node's pose from AddNode (called by AddVertex, right after
    # sequential matching) and overwrites it only with its own results: a pose set on the scan later
    # (AddEdges' weighted mean, a loop closure's match) is not its starting point
    import slamtrials.slam.karto.algorithm as karto_algorithm
    from slamtrials.slam.karto.graph import PoseGraph

    added: list[np.ndarray] = []
    add_node = PoseGraph.add_node

    def recording_add_node(self, node):
        added.append(node.pose.copy())
        return add_node(self, node)

    calls = []
    optimize = karto_algorithm.optimize_pose_graph

    def recording_optimize(poses, *args, **kwargs):
        result = optimize(poses, *args, **kwargs)
        calls.append((poses.copy(), karto.graph.poses(), len(added), result.poses.copy()))
        return result

    monkeypatch.setattr(PoseGraph, "add_node", recording_add_node)
    monkeypatch.setattr(karto_algorithm, "optimize_pose_graph", recording_optimize)
    karto = make_algorithm("karto", square_loop.laser)
    for frame in square_loop.frames:
        karto.process(frame)
    assert calls
    previous = None
    moved_since = False
    for start, current, count, result in calls:
        expected = np.array(added[:count])
        if previous is not None:
            expected[: len(previous)] = previous
        np.testing.assert_array_equal(start, expected)
        moved_since |= not np.array_equal(start, current)
        previous = result
    assert moved_since  # some node's pose had been set after it was added


def test_karto_compares_distances_with_its_tolerance_of_1e_6(synthetic):
    # HasMovedEnough: squared travel >= minimum^2 - KT_TOLERANCE (1e-6 in Karto's Math.h): a laser that
    # moved 0.2 m less 2e-7 m makes a node in the slam_karto setting (0.04 - 8e-8 >= 0.04 - 1e-6)
    odometry = [(0.0, 0.0, 0.0), (0.2 - 2e-7, 0.0, 0.0), (0.2 - 2e-7 + 0.19, 0.0, 0.0)]
    times = [0.0, 1.0, 2.0]
    nodes = _nodes(
        synthetic, odometry, times, scan_throttle=False, minimum_travel_distance=0.2, minimum_time_interval=3600.0
    )
    assert nodes == [0, 1]
