"""``slamtrials evaluate``: real datasets (estimate + relations files) and simulated run folders."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.geometry import compose, ominus
from slamtrials.io.relations import read_relations, write_relations
from slamtrials.io.runfolder import write_run
from slamtrials.io.tum import write_tum
from slamtrials.record import LaserGeometry, Relations, RunRecord, Trajectory

runner = CliRunner()
#: For the tests of what is scored, not of how relations are drawn: the paper's rule draws a few hundred
#: relations at most on these runs, the default (precise) rule 200,000 on a perfect estimate (0.3 s to
#: write); test_run_folder_is_scored_on_its_own_relation_set draws by the default rule.
FEW = ["--rule", "paper"]
REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared")) / "data" / "mit-csail"
LASER = LaserGeometry.from_dict(
    {"angle_min": -2.356, "angle_increment": 0.0087, "range_min": 0.0, "range_max": 30.0, "mount": [0.0, 0.0, 0.0]}
)


def _summary_rows(output: str) -> tuple[list[float], list[float]]:
    lines = output.splitlines()
    rows = [lines[i + 1] for i, line in enumerate(lines) if line == "Mean, Std, Min, Max, NumMeasures"]
    assert len(rows) == 2, output
    return [float(v) for v in rows[0].split(",")], [float(v) for v in rows[1].split(",")]


def _files(tmp_path, comment: bool = True):
    """Truth moves 1 m per second along x; the estimate (other frame) overshoots each relation by 0.1 m."""
    t = 1134864600.0 + np.arange(5.0)
    truth = np.column_stack([np.arange(5.0), np.zeros(5), np.zeros(5)])
    estimate = compose(np.array([3.0, -2.0, 1.0]), np.column_stack([np.arange(5.0) * 1.1, np.zeros(5), np.zeros(5)]))
    est = write_tum(tmp_path / "est.tum", Trajectory(t=t, poses=estimate))
    i, j = np.array([0, 1, 0]), np.array([1, 2, 2])
    rel = tmp_path / "rel.txt"
    write_relations(rel, Relations(t1=t[i], t2=t[j], delta=ominus(truth[i], truth[j])))
    if comment:
        rel.write_text("# t1 t2 x y z roll pitch yaw\n\n" + rel.read_text())
    return est, rel, t


def test_estimate_and_relations_files_known_answer(tmp_path):
    est, rel, _ = _files(tmp_path)
    result = runner.invoke(
        app, ["evaluate", "--estimate", str(est), "--relations", str(rel), "--errors", str(tmp_path / "e.npz")]
    )
    assert result.exit_code == 0, result.output
    trans, rot = _summary_rows(result.output)
    np.testing.assert_allclose(
        trans, [0.4 / 3, np.std([0.1, 0.1, 0.2], ddof=1), 0.1, 0.2, 3], rtol=1e-5
    )  # printed to 6 digits
    np.testing.assert_allclose(rot, [0, 0, 0, 0, 3], atol=1e-9)
    assert "Translational error (m, absolute)" in result.output and "Rotational error (rad, absolute)" in result.output
    with np.load(tmp_path / "e.npz") as npz:
        np.testing.assert_allclose(npz["translational"], [0.1, 0.1, 0.2], atol=1e-9)
        assert not npz["squared"] and len(npz["unmatched"]) == 0
    squared = runner.invoke(
        app, ["evaluate", "-e", str(est), "-r", str(rel), "--squared", "--errors", str(tmp_path / "e.txt")]
    )
    assert squared.exit_code == 0 and "(m^2, squared)" in squared.output
    assert _summary_rows(squared.output)[0][3] == pytest.approx(0.04)
    assert (tmp_path / "e.txt").read_text().startswith("# t1 t2 translational_error[m^2]")


def test_unmatched_relations_are_reported_with_their_lines(tmp_path):
    est, rel, t = _files(tmp_path)
    with rel.open("a") as handle:
        handle.write(f"{float(t[1]) + 0.5!r} {float(t[3])!r} 2.0 0.0 0.0 0.0 0.0 0.0\n")  # line 6: t1 between two poses
    result = runner.invoke(app, ["evaluate", "-e", str(est), "-r", str(rel)])
    assert result.exit_code == 0, result.output
    assert "matched 3 of 4 relations" in result.output and "unmatched: line 6" in result.output


def test_bad_input_names_the_file_and_line(tmp_path):
    est, rel, t = _files(tmp_path)
    outside = tmp_path / "outside.txt"
    outside.write_text(rel.read_text() + f"{float(t[0])!r} {float(t[-1]) + 5.0!r} 9.0 0.0 0.0 0.0 0.0 0.0\n")  # line 6
    result = runner.invoke(app, ["evaluate", "-e", str(est), "-r", str(outside)])
    assert result.exit_code == 2
    assert f"{outside}:6: relation 3: timestamp" in result.output and "outside the time span" in result.output
    assert runner.invoke(app, ["evaluate", "-e", str(est), "-r", str(outside), "--allow-outside"]).exit_code == 0

    garbage = tmp_path / "garbage.txt"
    garbage.write_text("1.0 2.0 0.0 0.0 0.0 0.0 0.0 0.0\n1.0 2.0 zero 0.0 0.0 0.0 0.0 0.0\n")
    result = runner.invoke(app, ["evaluate", "-e", str(est), "-r", str(garbage)])
    assert result.exit_code == 2 and f"{garbage}:2:" in result.output

    unordered = tmp_path / "unordered.tum"
    unordered.write_text("0.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n")
    result = runner.invoke(app, ["evaluate", "-e", str(unordered), "-r", str(rel)])
    assert result.exit_code == 2 and f"{unordered}:3:" in result.output

    empty = tmp_path / "empty.tum"
    empty.write_text("# nothing here\n")
    result = runner.invoke(app, ["evaluate", "-e", str(empty), "-r", str(rel)])
    assert result.exit_code == 2 and str(empty) in result.output

    result = runner.invoke(app, ["evaluate", "-e", str(est)])
    assert result.exit_code == 2 and "--relations" in result.output
    result = runner.invoke(app, ["evaluate", "-e", str(est), "-r", str(tmp_path / "missing.txt")])
    assert result.exit_code == 2 and "missing.txt" in result.output


def _run(tmp_path, n: int = 200) -> tuple[Path, RunRecord]:
    """A run folder: a wandering drive at 10 Hz and an odometry that drifts from it."""
    rng = np.random.default_rng(0)
    steps = np.column_stack([np.full(n - 1, 0.05), np.zeros(n - 1), rng.normal(0, 0.05, n - 1)])
    truth, odometry = np.zeros((n, 3)), np.zeros((n, 3))
    truth[0] = [2.0, 3.0, 0.5]
    for k in range(n - 1):
        truth[k + 1] = compose(truth[k], steps[k])
        odometry[k + 1] = compose(odometry[k], steps[k] * [1.01, 1.0, 1.02])
    record = RunRecord(
        t=np.arange(n) * 0.1,
        scans=np.zeros((n, 3), np.float32),
        odometry=odometry,
        truth=truth,
        stalled=np.zeros(n, bool),
        laser=LASER,
        metadata={"seed": 0},
    )
    return write_run(tmp_path / "run", record), record


def test_run_folder_samples_relations_and_writes_them(tmp_path):
    folder, record = _run(tmp_path)
    result = runner.invoke(
        app, ["evaluate", str(folder), "--seed", "3", "--rule", "paper", "--margin-t", "0.005", "--margin-r", "0.005"]
    )
    assert result.exit_code == 0, result.output
    assert "the run's odometry" in result.output and "sampling:  pilot 500 pairs" in result.output
    written = folder / "evaluations" / "odometry"  # a new folder in the run: never the run's own files
    relations = read_relations(written / "relations.txt")
    assert not (folder / "relations.txt").exists()
    trans, rot = _summary_rows(result.output)
    assert trans[4] == len(relations) == rot[4] and trans[0] > 0.0 and rot[0] > 0.0
    with np.load(written / "errors.npz") as npz:
        assert len(npz["translational"]) == len(relations)
        assert npz["translational"].mean() == pytest.approx(trans[0], rel=1e-5)
    first = (written / "relations.txt").read_text()
    again = runner.invoke(
        app, ["evaluate", str(folder), "--seed", "3", "--rule", "paper", "--margin-t", "0.005", "--margin-r", "0.005"]
    )
    assert (
        again.exit_code == 0 and (folder / "evaluations" / "odometry-2" / "relations.txt").read_text() == first
    )  # seeded
    chosen = runner.invoke(app, ["evaluate", str(folder), "--seed", "3", "--out", str(tmp_path / "mine")])
    assert chosen.exit_code == 0 and (tmp_path / "mine" / "relations.txt").is_file()
    taken = runner.invoke(app, ["evaluate", str(folder), "--seed", "3", "--out", str(tmp_path / "mine")])
    assert taken.exit_code == 2 and "already holds an evaluation" in taken.output


def test_run_folder_is_scored_on_its_own_relation_set(tmp_path):
    """A run with relations.npz (as a campaign or a trial writes it): every estimate is scored on that set."""
    from slamtrials.campaign.config import MetricSettings
    from slamtrials.campaign.score import score_run
    from slamtrials.campaign.task import write_scored_run

    folder, record = _run(tmp_path)
    record.estimate = record.truth + np.random.default_rng(2).normal(0.0, 0.01, record.truth.shape)
    score = score_run(record, 5, MetricSettings())
    write_scored_run(folder, record, score)
    result = runner.invoke(app, ["evaluate", str(folder)])
    assert result.exit_code == 0, result.output
    assert (
        f"the run's relation set {folder / 'relations.npz'}: {len(score.relation_set)} relations, seed 5"
        in result.output
    )
    trans, _ = _summary_rows(result.output)
    assert trans[4] == len(score.relation_set) and trans[0] == pytest.approx(score.eps_t, abs=1e-6)
    # another estimate of the same run: the same relations (paired), its own errors
    other = tmp_path / "other.tum"
    write_tum(other, Trajectory(t=record.t, poses=record.odometry))
    result = runner.invoke(app, ["evaluate", str(folder), "--estimate", str(other)])
    trans, _ = _summary_rows(result.output)
    assert trans[4] == len(score.relation_set) and trans[0] == pytest.approx(score.odometry.eps_t, abs=1e-6)
    # written: the errors on the run's own set, no text copy of its relations; again: the same folder
    assert not (folder / "evaluations" / "other" / "relations.txt").exists()
    with np.load(folder / "evaluations" / "other" / "errors.npz") as npz:
        assert len(npz["translational"]) == len(score.relation_set)
    again = runner.invoke(app, ["evaluate", str(folder), "--estimate", str(other)])
    assert again.exit_code == 0 and sorted(p.name for p in (folder / "evaluations").iterdir()) == ["estimate", "other"]
    # asking for a sampling draws afresh
    fresh = runner.invoke(app, ["evaluate", str(folder), "--seed", "6"])
    assert "sampling:  pilot 500 pairs" in fresh.output and "precise rule" in fresh.output
    bad = runner.invoke(app, ["evaluate", str(folder), "--margin-t", "0.01"])
    assert bad.exit_code == 2 and "margin_t is an absolute margin of the paper rule" in bad.output


def test_a_trajectory_of_another_run_is_refused_and_nothing_is_written(tmp_path):
    folder, record = _run(tmp_path)
    campaign_relations = b"the relations a campaign scored the run on"
    (folder / "relations.txt").write_bytes(campaign_relations)
    short = tmp_path / "other.tum"
    write_tum(short, Trajectory(t=record.t[: len(record) // 2], poses=record.truth[: len(record) // 2]))
    result = runner.invoke(app, ["evaluate", str(folder), "--estimate", str(short)])
    assert result.exit_code == 2 and "other.tum" in result.output and "not an estimate of this run" in result.output
    assert "spans 0.0 to" in result.output and len(result.output.strip().splitlines()) == 1
    assert not (folder / "evaluations").exists() and (folder / "relations.txt").read_bytes() == campaign_relations
    whole = tmp_path / "same.tum"
    write_tum(whole, Trajectory(t=record.t, poses=record.truth))
    done = runner.invoke(app, ["evaluate", str(folder), "--estimate", str(whole), *FEW])
    assert done.exit_code == 0 and (folder / "evaluations" / "same" / "relations.txt").is_file()
    assert (folder / "relations.txt").read_bytes() == campaign_relations


def test_run_folder_with_an_estimate_file(tmp_path):
    folder, record = _run(tmp_path)
    write_tum(folder / "estimate.tum", Trajectory(t=record.t, poses=record.truth))  # a perfect estimate
    result = runner.invoke(app, ["evaluate", str(folder), "--seed", "1", *FEW])
    assert result.exit_code == 0, result.output
    assert "estimate.tum (TUM" in result.output
    trans, rot = _summary_rows(result.output)
    assert trans[0] < 1e-9 and rot[0] < 1e-9


def test_run_folder_with_a_sparse_estimate_uses_the_odometry_between_its_poses(tmp_path):
    """A perfect estimate at every 3rd frame: the other ground-truth poses are reached from the nearest
    estimated pose through the run's odometry (1-2 % off over 0.1-0.2 s), so errors stay at millimetres;
    with the Freiburg 0.1 s tolerance the neighbouring frame's pose would be taken as is (5 cm off)."""
    folder, record = _run(tmp_path, n=199)  # every 3rd frame, the last one included
    write_tum(folder / "estimate.tum", Trajectory(t=record.t[::3], poses=record.truth[::3]))
    result = runner.invoke(app, ["evaluate", str(folder), "--seed", "1", *FEW])
    assert result.exit_code == 0, result.output
    trans, rot = _summary_rows(result.output)
    assert trans[0] < 0.005 and rot[0] < 0.005
    assert "0 through the odometry" not in result.output
    coarse = runner.invoke(app, ["evaluate", str(folder), "--seed", "1", "--tolerance", "0.1", *FEW])
    assert _summary_rows(coarse.output)[0][0] > 10 * trans[0]
    result = runner.invoke(
        app, ["evaluate", str(folder), "--relations", str(folder / "evaluations" / "estimate" / "relations.txt")]
    )
    assert result.exit_code == 2 and "drop --relations" in result.output


@pytest.mark.skipif(not (DATA / "mit-csail.clf").is_file(), reason=f"no MIT CSAIL data in {DATA}")
def test_mit_csail_raw_odometry():
    """Both pose triples of this log are the raw odometry (see tests/metric/test_mit_csail.py):
    observed 1.68146 m and 0.0885188 rad mean error over all 1,172 relations."""
    result = runner.invoke(
        app,
        [
            "evaluate",
            "-e",
            str(DATA / "mit-csail.clf"),
            "-r",
            str(DATA / "mit-csail.relations"),
            "--odometry",
            str(DATA / "mit-csail.clf"),
        ],
    )
    assert result.exit_code == 0, result.output
    trans, rot = _summary_rows(result.output)
    assert trans[4] == rot[4] == 1172
    assert trans[0] > 5 * 0.049 and 0.01 < rot[0] < 1.0


def test_run_folder_with_an_estimate_that_covers_nothing(tmp_path):
    folder, record = _run(tmp_path)
    write_tum(folder / "estimate.tum", Trajectory(t=record.t + 1000.0, poses=record.truth))
    result = runner.invoke(app, ["evaluate", str(folder)])
    assert result.exit_code == 2
    assert f"{folder / 'estimate.tum'}: its poses span 1000.0 to" in result.output
    assert "not an estimate of this run" in result.output


def test_pose_indices_map_to_file_lines(tmp_path):
    """The readers refuse bad trajectories themselves; this is the backstop for errors the metric finds."""
    from slamtrials.errors import FormatError, MetricError
    from slamtrials.evaluation import PoseTriple, _read_trajectory, _with_lines

    tum = tmp_path / "est.tum"
    tum.write_text("# header\n0.0 0 0 0 0 0 0 1\n\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n")
    source = _read_trajectory(tum, PoseTriple.first, "estimate")
    mapped = _with_lines(MetricError("pose 2 is bad", what="estimate", index=2), {"estimate": source}, None)
    assert isinstance(mapped, FormatError) and (mapped.path, mapped.line) == (tum, 5)
    clf = tmp_path / "log.clf"
    clf.write_text(
        "PARAM robot_front_laser_max 30.0 0 h 0\n"
        "FLASER 2 1.0 1.0 0 0 0 0 0 0 10.0 h 0\n"
        "ODOM 0 0 0 0 0 0 10.05 h 0\n"
        "FLASER 2 1.0 1.0 0 0 0 0 0 0 10.1 h 0\n"
    )
    source = _read_trajectory(clf, PoseTriple.second, "estimate")
    mapped = _with_lines(MetricError("pose 1 is bad", what="estimate", index=1), {"estimate": source}, None)
    assert (mapped.path, mapped.line) == (clf, 4)
    source = _read_trajectory(clf, PoseTriple.second, "odometry")  # odometry: the ODOM lines, as the Freiburg program
    mapped = _with_lines(MetricError("pose 0 is bad", what="odometry", index=0), {"odometry": source}, None)
    assert (mapped.path, mapped.line) == (clf, 3) and "1 ODOM lines" in source.label
    robot = "ROBOTLASER1 0 -0.5 1.0 1.0 30 0.01 0 2 1 1 0 0 0 0 0 0 0 0 0 0 0 0 {t} h 0\n"
    mixed = tmp_path / "mixed.clf"  # the front laser in both formats: the ROBOTLASER1 lines are the poses
    mixed.write_text(clf.read_text().replace("FLASER 2 1.0 1.0 0 0 0 0 0 0 10.1 h 0\n", "") + robot.format(t=10.0))
    mixed.write_text(mixed.read_text() + "FLASER 2 1.0 1.0 0 0 0 0 0 0 10.1 h 0\n" + robot.format(t=10.1))
    source = _read_trajectory(mixed, PoseTriple.first, "estimate")
    mapped = _with_lines(MetricError("pose 1 is bad", what="estimate", index=1), {"estimate": source}, None)
    assert (mapped.path, mapped.line) == (mixed, 6) and "2 ROBOTLASER1 lines" in source.label
    unknown = MetricError("no index")
    assert _with_lines(unknown, {}, None) is unknown


def test_the_estimate_of_another_run_of_the_same_length_is_refused(tmp_path, drive, odometry_of):
    """Same times, other turns: the time-span check cannot see it, the turn check does (exit 2, nothing
    written); the run's own estimate passes."""
    t, truth = drive(1, seconds=100.0)
    record = RunRecord(
        t=t,
        scans=np.zeros((len(t), 3), np.float32),
        odometry=odometry_of(truth, 2),
        truth=truth,
        stalled=np.zeros(len(t), bool),
        laser=LASER,
        metadata={"seed": 0},
    )
    folder = write_run(tmp_path / "run", record)
    _, other_truth = drive(5, seconds=100.0)
    foreign = tmp_path / "run001.tum"
    write_tum(foreign, Trajectory(t=t, poses=other_truth))
    result = runner.invoke(app, ["evaluate", str(folder), "--estimate", str(foreign)])
    assert result.exit_code == 2, result.output
    assert len(result.output.strip().splitlines()) == 1
    assert (
        "run001.tum" in result.output
        and "contradict" in result.output
        and "not an estimate of this run" in result.output
    )
    assert not (folder / "evaluations").exists()
    own = tmp_path / "run000.tum"
    write_tum(own, Trajectory(t=t, poses=truth))
    assert runner.invoke(app, ["evaluate", str(folder), "--estimate", str(own), *FEW]).exit_code == 0


def test_an_estimate_in_another_time_base_is_mapped_by_time_offset(tmp_path):
    """A program run by hand on an exported bag writes times from 1 s on: refused with the offset named,
    and scored once --time-offset takes it away."""
    folder, record = _run(tmp_path)
    shifted = tmp_path / "bag_time.tum"
    write_tum(shifted, Trajectory(t=record.t + 1.0, poses=record.truth))
    refused = runner.invoke(app, ["evaluate", str(folder), "--estimate", str(shifted), "--seed", "1"])
    assert refused.exit_code == 2 and "--time-offset 1" in refused.output
    done = runner.invoke(
        app, ["evaluate", str(folder), "--estimate", str(shifted), "--seed", "1", "--time-offset", "1", *FEW]
    )
    assert done.exit_code == 0, done.output
    assert "times minus 1 s" in done.output and _summary_rows(done.output)[0][0] < 1e-9
