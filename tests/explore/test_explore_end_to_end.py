"""End to end: the explorer drives the real simulator on a "perfect SLAM" map (built from true poses)
until no reachable frontier is left, and maps at least 90 % of the reachable free area."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

from slamtrials.worlds import load_world
from slamtrials.worlds.generate import generate_world


def _load_harness():
    """The harness module next to this file (pytest runs with --import-mode=importlib)."""
    name = "explore_harness"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, Path(__file__).with_name(f"{name}.py"))
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


harness = _load_harness()
coverage, run = harness.coverage, harness.run

pytestmark = pytest.mark.slow


@pytest.mark.parametrize(
    "make",
    [lambda: load_world("office_small_01"), lambda: generate_world("house", 90, seed=7)],
    ids=["office_small_01", "generated_house"],
)
def test_explores_a_small_building(make):
    world = make()
    result = run(world, max_time=900.0)
    assert result.reason in ("no_frontiers", "map_converged"), result.line()
    assert result.sim_time < 900.0
    assert result.coverage >= 0.90, result.line()
    assert result.collisions <= 5, result.line()
    assert result.stats["backing_outs"] >= 1, result.stats  # rooms are left by backing out, not turning round


def test_runs_are_reproducible():
    world = load_world("house_small_01")
    a = run(world, max_time=40.0)
    b = run(world, max_time=40.0)
    assert a.sim_time == b.sim_time and a.stats["replans"] == b.stats["replans"]
    assert np.array_equal(a.occupancy.grid, b.occupancy.grid)
    assert a.coverage == b.coverage == coverage(world, b.occupancy)[0]
