"""GoalSearch: window searches agree with whole-map searches; blacklist, reached goals, hysteresis."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from slamtrials.explore import ExploreConfig, RobotLimits
from slamtrials.explore.costmap import influence_distance
from slamtrials.explore.goalsearch import GoalSearch

RES = 0.05


def building(frontier_cols):
    """A known 20 x 10 m hall (walls around, a few pillars) with unknown gaps in its top wall at the
    given columns (each 1 m wide), i.e. frontiers there."""
    grid = np.zeros((200, 400), dtype=np.int8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 100
    for c in range(40, 400, 60):
        grid[90:110, c : c + 8] = 100
    grid[0, :] = 100
    for c in frontier_cols:
        grid[0:3, c : c + 20] = -1
    return SimpleNamespace(grid=grid, resolution=RES, origin=np.zeros(3))


def windows(occ, pose, cfg):
    search = GoalSearch(cfg)
    whole = search.known_box(occ, occ.grid)
    rows = occ.grid.shape[0]
    row, col = rows - 1 - int(pose[1] / RES), int(pose[0] / RES)
    half = math.ceil(cfg.local_radius / RES)
    rim = math.ceil(influence_distance(cfg, RobotLimits(), RES) / RES) + 1
    local = (row - half - rim, row + half + rim + 1, col - half - rim, col + half + rim + 1)
    inner = (rim, local[1] - local[0] - rim, rim, local[3] - local[2] - rim)
    return search, whole, local, inner


def test_a_goal_settled_inside_the_window_is_the_global_one():
    cfg = ExploreConfig(local_radius=4.0)
    occ = building([60, 300])
    pose = np.array([4.0, 8.0, 0.0])  # near the first gap (x = 3..4 m, y = 10 m)
    search, whole, local, inner = windows(occ, pose, cfg)
    out_local, found_local = search.search(pose, occ, occ.grid, local, inner, visited=[], blacklist=[], current=None)
    out_whole, found_whole = search.search(pose, occ, occ.grid, whole, None, visited=[], blacklist=[], current=None)
    assert out_local == out_whole == "goal"
    assert np.allclose(found_local.goal, found_whole.goal)
    assert np.allclose(found_local.path, found_whole.path)


def test_a_far_goal_needs_the_whole_map():
    cfg = ExploreConfig(local_radius=4.0)
    occ = building([300])
    pose = np.array([4.0, 6.0, 0.0])
    search, whole, local, inner = windows(occ, pose, cfg)
    assert search.search(pose, occ, occ.grid, local, inner, visited=[], blacklist=[], current=None) == ("edge", None)
    outcome, found = search.search(pose, occ, occ.grid, whole, None, visited=[], blacklist=[], current=None)
    assert outcome == "goal" and 15.0 < found.goal[0] < 16.0


def test_reached_and_failed_goals_are_skipped():
    cfg = ExploreConfig()
    occ = building([60, 300])
    pose = np.array([4.0, 6.0, 0.0])
    search = GoalSearch(cfg)
    whole = search.known_box(occ, occ.grid)
    _, first = search.search(pose, occ, occ.grid, whole, None, visited=[], blacklist=[], current=None)
    assert 3.0 < first.goal[0] < 4.0
    gap = [np.array([3.5, 9.8])]
    for kind in ("visited", "blacklist"):
        lists = {"visited": [], "blacklist": []}
        lists[kind] = gap
        _, other = search.search(pose, occ, occ.grid, whole, None, current=None, **lists)
        assert 15.0 < other.goal[0] < 16.0
    search_all = search.search(
        pose, occ, occ.grid, whole, None, visited=[gap[0], np.array([15.5, 9.8])], blacklist=[], current=None
    )
    assert search_all == ("none", None)
    assert search.reachable_share > 0.9


def test_the_current_goal_is_kept_unless_clearly_worse():
    cfg = ExploreConfig(goal_hysteresis=0.5, turn_penalty=0.0)
    occ = building([60, 220])
    pose = np.array([7.5, 6.0, 0.0])  # gap 1 at x = 3..4 m, gap 2 at x = 11..12 m: gap 1 is closer
    search = GoalSearch(cfg)
    whole = search.known_box(occ, occ.grid)
    _, free_choice = search.search(pose, occ, occ.grid, whole, None, visited=[], blacklist=[], current=None)
    assert free_choice.goal[0] < 5.0
    _, kept = search.search(pose, occ, occ.grid, whole, None, visited=[], blacklist=[], current=np.array([11.5, 9.8]))
    assert kept.kept and kept.goal[0] > 10.0


@pytest.mark.parametrize(
    ("x", "heading", "expect_east"),
    [
        (7.5, 0.0, True),  # gaps 4.0 and 4.0 m away (gap 1 a little closer): facing east, the east one
        (7.5, math.pi, False),  # facing west: the west one, which is also the closest
        (5.5, 0.0, False),  # 2 m against 6 m: not worth the 3 m that turning round counts for
    ],
)
def test_a_goal_ahead_wins_when_turning_round_costs_more_than_it_saves(x, heading, expect_east):
    occ = building([60, 220])  # gaps at x = 3..4 m and 11..12 m in the top wall
    search = GoalSearch(ExploreConfig(turn_penalty=1.0))
    whole = search.known_box(occ, occ.grid)
    _, found = search.search(
        np.array([x, 6.0, heading]), occ, occ.grid, whole, None, visited=[], blacklist=[], current=None
    )
    assert (found.goal[0] > 10.0) == expect_east
    # without the penalty the closest gap wins whatever the heading
    plain = GoalSearch(ExploreConfig(turn_penalty=0.0))
    _, closest = plain.search(
        np.array([x, 6.0, heading]), occ, occ.grid, whole, None, visited=[], blacklist=[], current=None
    )
    assert closest.goal[0] < 5.0
