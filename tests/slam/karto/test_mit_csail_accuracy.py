"""Karto's accuracy on real data: the whole MIT CSAIL log against its Freiburg benchmark relations.

karto with slam_toolbox's defaults over all 1,988 scans of ``mit-csail.clf``; the outputs are written as
``slamtrials slam`` writes them and ``trajectory.clf`` is evaluated as ``slamtrials evaluate -e
trajectory.clf -r mit-csail.relations`` does. It gives 0.0460 m mean translational error (535 nodes, as
slam_toolbox makes; slam_toolbox itself 0.0462 m; 29 Nov 2026); the bounds are those plus a little. With the
``slam_karto`` preset (open_karto's own defaults: a node every 0.2 m or 0.174 rad) it gives 0.0373 m and
0.0194 rad. The
issue's target, 0.035 m, is NOT met, and docs/karto.md ("Accuracy on real data") shows why: most of
what is left is the log's odometry between nodes. Skipped when the data set is absent."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from slamtrials.evaluation import PoseTriple, evaluate_files
from slamtrials.slamrun import load_recording, run_slam, write_slam_outputs

REPO = Path(__file__).resolve().parents[3]
DATA = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared")) / "data" / "mit-csail"
LOG = DATA / "mit-csail.clf"
RELATIONS = DATA / "mit-csail.relations"

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not (LOG.is_file() and RELATIONS.is_file()), reason=f"no MIT CSAIL data in {DATA}"),
]


def _within_five_percent_of_the_cpp(eps_t: float, program: str) -> None:
    """The C++ original's trajectory on the same log (../shared/data/karto-cpp), scored the same way."""
    reference = DATA.parent / "karto-cpp" / "mit-csail" / f"{program}.final_nearest.tum"
    if reference.is_file():
        cpp = evaluate_files(reference, RELATIONS).translational.mean
        assert abs(eps_t / cpp - 1.0) <= 0.05, (eps_t, cpp)


def test_karto_defaults_on_mit_csail(tmp_path):
    record = load_recording(LOG)
    result = run_slam(record, "karto", seed=0, source=str(LOG))
    assert result.config.minimum_travel_distance == 0.5
    assert 500 <= result.updates <= 700  # slam_toolbox's gate: 0.5 s and 0.447 m of odometry between nodes
    write_slam_outputs(result, tmp_path)
    evaluation = evaluate_files(tmp_path / "trajectory.clf", RELATIONS)
    assert evaluation.translational.n == 1172 and len(evaluation.errors.unmatched) == 0
    assert evaluation.translational.mean <= 0.0465
    assert evaluation.rotational.mean <= 0.0495
    _within_five_percent_of_the_cpp(evaluation.translational.mean, "slam_toolbox")
    odometry = evaluate_files(tmp_path / "trajectory.clf", RELATIONS, estimate_pose=PoseTriple.second)
    assert odometry.translational.mean > 10 * evaluation.translational.mean


def test_karto_slam_karto_preset_on_mit_csail(tmp_path):
    record = load_recording(LOG)
    result = run_slam(record, "karto", preset="slam_karto", seed=0, source=str(LOG))
    assert result.config.minimum_travel_distance == 0.2
    write_slam_outputs(result, tmp_path)
    evaluation = evaluate_files(tmp_path / "trajectory.clf", RELATIONS)
    assert evaluation.translational.n == 1172
    assert evaluation.translational.mean <= 0.0375
    _within_five_percent_of_the_cpp(evaluation.translational.mean, "slam_karto")
    assert evaluation.rotational.mean <= 0.021
