"""SLAM repeated on a dataset: seeds 0..N-1, each run scored on the dataset's relations, the spread reported."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.errors import ConfigError
from slamtrials.io.carmen import carmen_from_run, write_carmen
from slamtrials.io.relations import write_relations
from slamtrials.metric import relations_between
from slamtrials.record import Relations, Trajectory
from slamtrials.repeat import RepeatSettings, check_relations_fit, repeat_slam, write_repeat_outputs
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.slam.offline import run_over_recording
from slamtrials.worlds import load_world

pytestmark = pytest.mark.slow

SETTINGS = {"particles": 8}


@pytest.fixture(scope="module")
def dataset():
    """A short simulated drive through office_small_01 and relations drawn from its ground truth."""
    world = load_world("office_small_01")
    x, y = world.start[:2]
    record = simulate_waypoints(world, [(x + 1.5, y), (x + 1.5, y + 1.0), (x, y + 1.0)], SimConfig.paper(), seed=3)
    truth = Trajectory(t=record.t, poses=record.truth)
    i = np.arange(0, len(record) - 10, 5)
    return record, relations_between(truth, i, i + 10)


def test_each_seed_is_a_separate_run_scored_on_the_relations(dataset, tmp_path):
    record, relations = dataset
    settings = RepeatSettings(algorithm="gmapping", overrides=SETTINGS, runs=3, confidence=0.9)
    result = repeat_slam(record, relations, settings, workers=1)
    assert [r.seed for r in result.runs] == [0, 1, 2]
    # seed 1 of the repeated experiment is exactly the single run with seed 1
    single = run_over_recording(record, "gmapping", overrides=SETTINGS, seed=1)
    from slamtrials.metric import evaluate_relations

    errors = evaluate_relations(single.trajectory, relations, tolerance=0.1)
    assert result.runs[1].eps_t == float(np.mean(errors.translational))
    assert result.runs[1].relations == len(relations)
    eps = np.array([r.eps_t for r in result.runs])
    assert result.stats_t.n == 3 and result.stats_t.mean == pytest.approx(eps.mean())
    assert result.stats_t.std_sample == pytest.approx(eps.std(ddof=1))
    assert result.stats_t.ci_low < result.stats_t.mean < result.stats_t.ci_high
    assert result.diverged.threshold == pytest.approx(5 * np.median(eps))
    assert result.best.eps_t == eps.min() and result.worst.eps_t == eps.max()
    written = write_repeat_outputs(result, tmp_path / "out")
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["runs"] == 3 and summary["translational_m"]["mean"] == pytest.approx(eps.mean())
    lines = (tmp_path / "out" / "runs.csv").read_text().splitlines()
    assert (
        lines[0].startswith("seed,eps_t") and len(lines) == 4 and float(lines[2].split(",")[1]) == result.runs[1].eps_t
    )
    assert {p.name for p in written} >= {"errors.png", "best_map.png", "worst_map.yaml"}
    with pytest.raises(ConfigError, match="already holds"):
        write_repeat_outputs(result, tmp_path / "out")


def test_relations_of_another_recording_are_refused(dataset):
    record, relations = dataset
    foreign = Relations(t1=relations.t1 + 1000.0, t2=relations.t2 + 1000.0, delta=relations.delta)
    with pytest.raises(ConfigError, match="do not belong together"):
        check_relations_fit(record, foreign, 0.1)
    with pytest.raises(ConfigError, match="do not belong together"):
        repeat_slam(record, foreign, RepeatSettings(algorithm="odometry", runs=2), workers=1)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"runs": 1}, "at least 2"),
        ({"runs": "many"}, "at least 2"),
        ({"confidence": 1.5}, "confidence"),
        ({"initial": 1}, "initial"),
    ],
)
def test_bad_settings_are_refused(options, match):
    with pytest.raises(ConfigError, match=match):
        RepeatSettings(algorithm="gmapping", **options)


def test_the_cli_repeats_on_a_carmen_log_and_refuses_bad_options(dataset, tmp_path):
    record, relations = dataset
    log = write_carmen(tmp_path / "drive.clf", carmen_from_run(record))
    rel = write_relations(tmp_path / "drive.relations", relations)
    runner = CliRunner()
    base = ["slam", "--algorithm", "odometry", "--input", str(log), "--out", str(tmp_path / "rep")]
    done = runner.invoke(app, [*base, "--relations", str(rel), "--runs", "2", "--workers", "1"])
    assert done.exit_code == 0, done.output
    assert "translational: mean" in done.output and "diverged: 0 of 2 runs" in done.output
    for extra, expected in (
        (["--runs", "2"], "go together"),
        (["--relations", str(rel), "--runs", "1"], "at least 2"),
        (["--relations", str(rel), "--runs", "x"], "'auto'"),
    ):
        bad = runner.invoke(
            app, ["slam", "--algorithm", "odometry", "--input", str(log), "--out", str(tmp_path / "b"), *extra]
        )
        assert bad.exit_code == 2 and expected in bad.output and "Traceback" not in bad.output, bad.output
    assert not (tmp_path / "b").exists()
