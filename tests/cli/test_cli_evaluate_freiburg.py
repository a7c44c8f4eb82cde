"""``slamtrials evaluate`` on the Freiburg metricEvaluator's own input files: pose-only test logs
(``FLASER 0 x y th x y th ts host ts``), compressed logs, and relations of another log."""

from __future__ import annotations

import bz2
import gzip
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.io.carmen import read_carmen
from slamtrials.io.relations import read_relations

runner = CliRunner()
REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared")) / "data" / "mit-csail"
FR079 = DATA.parent / "fr079" / "fr079.clf.bz2"
HEADER = "Mean, Std, Min, Max, NumMeasures"


def _rows(output: str) -> tuple[str, str]:
    lines = output.splitlines()
    rows = [lines[i + 1] for i, line in enumerate(lines) if line == HEADER]
    assert len(rows) == 2, output
    return rows[0], rows[1]


def _test_log(path: Path, t, poses, second=None) -> Path:
    """A trajectory as SLAM programs write it for the Freiburg evaluator: FLASER lines without readings."""
    second = poses if second is None else second
    with path.open("w") as handle:
        for stamp, p, q in zip(t, poses, second):
            handle.write(
                "FLASER 0 {:.6f} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f} nohost {:.6f}\n".format(
                    *p, *q, stamp, stamp - t[0]
                )
            )
    return path


def _by_hand(t, poses, relations_path: Path, tolerance: float = 0.1) -> tuple[str, str]:
    """The Freiburg program's numbers, computed here from its definition: the pose nearest in time to each
    relation timestamp (all within 0.1 s here), the relative pose from t1 to t2, the difference to the relation's (translation: length of the
    difference of the two translations; rotation: |wrapped angle difference|), then its %f row: mean, sample
    standard deviation as it computes it (sqrt((n S2 - S1^2) / (n (n - 1)))), min, max, count."""
    t, poses = np.asarray(t, dtype=float), np.asarray(poses, dtype=float)

    def at(stamp: float) -> np.ndarray:
        k = int(np.argmin(np.abs(t - stamp)))
        assert abs(t[k] - stamp) <= tolerance  # np.argmin: the first in the file on a tie, as the program scans
        return poses[k]

    trans, rot = [], []
    for line in relations_path.read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        t1, t2, x, y, _, _, _, yaw = (float(v) for v in line.split())
        a, b = at(t1), at(t2)
        c, s = math.cos(a[2]), math.sin(a[2])
        dx, dy = c * (b[0] - a[0]) + s * (b[1] - a[1]), -s * (b[0] - a[0]) + c * (b[1] - a[1])
        dtheta = math.remainder(b[2] - a[2] - yaw, 2 * math.pi)
        trans.append(math.hypot(dx - x, dy - y))
        rot.append(abs(dtheta))

    def row(e: list[float]) -> str:
        n, s1, s2 = len(e), sum(e), sum(v * v for v in e)
        std = math.sqrt(max(n * s2 - s1 * s1, 0.0) / (n * (n - 1)))
        return f"{s1 / n:f}, {std:f}, {min(e):f}, {max(e):f}, {n}"

    return row(trans), row(rot)


def _synthetic(tmp_path: Path):
    rng = np.random.default_rng(7)
    t = 1134864600.0 + 0.2 * np.arange(40)
    steps = np.column_stack(
        [0.1 + 0.02 * rng.standard_normal(40), 0.01 * rng.standard_normal(40), 0.05 * rng.standard_normal(40)]
    )
    poses = np.cumsum(steps, axis=0)
    poses = np.round(poses, 6)  # what the %.6f test log holds
    relations = tmp_path / "test.relations"
    with relations.open("w") as handle:
        for i, j in [(0, 1), (3, 9), (10, 30), (5, 6), (12, 39), (20, 21), (0, 39)]:
            truth = poses[j] - poses[i] + 0.03 * rng.standard_normal(3)  # any numbers serve as relations
            handle.write(
                f"{t[i]:.5f} {t[j]:.5f} {truth[0]:.5f} {truth[1]:.5f} 0.00000 0.00000 0.00000 {truth[2]:.5f}\n"
            )
    return t, poses, relations


def test_pose_only_test_log_prints_the_freiburg_numbers_digit_by_digit(tmp_path):
    t, poses, relations = _synthetic(tmp_path)
    log = _test_log(tmp_path / "test.log", t, poses)
    result = runner.invoke(app, ["evaluate", "--estimate", str(log), "--relations", str(relations)])
    assert result.exit_code == 0, result.output
    assert _rows(result.output) == _by_hand(t, poses, relations)
    assert "matched 7 of 7 relations" in result.output and "second pose triple" in result.output


def test_pose_only_log_is_read_as_the_freiburg_program_does_second_triple(tmp_path, caplog):
    """The metricEvaluator reads a FLASER line's second triple; a pose-only log is evaluated that way by default."""
    t, poses, relations = _synthetic(tmp_path)
    wrong = poses + np.array([0.3, -0.2, 0.1]) * np.arange(len(poses))[:, None]
    log = _test_log(tmp_path / "test.log", t, wrong, second=poses)
    result = runner.invoke(app, ["evaluate", "-e", str(log), "-r", str(relations)])
    assert result.exit_code == 0, result.output
    assert _rows(result.output) == _by_hand(t, poses, relations)
    assert any("pose triples differ on 39 of 40" in r.getMessage() for r in caplog.records)
    first = runner.invoke(app, ["evaluate", "-e", str(log), "-r", str(relations), "--estimate-pose", "first"])
    assert first.exit_code == 0 and _rows(first.output) == _by_hand(t, wrong, relations)


def test_compressed_test_log(tmp_path):
    t, poses, relations = _synthetic(tmp_path)
    log = _test_log(tmp_path / "test.log", t, poses)
    packed = tmp_path / "test.log.bz2"
    packed.write_bytes(bz2.compress(log.read_bytes()))
    result = runner.invoke(app, ["evaluate", "-e", str(packed), "-r", str(relations)])
    assert result.exit_code == 0, result.output
    assert _rows(result.output) == _by_hand(t, poses, relations)


def test_a_compressed_test_log_cut_short_warns_once_per_oddity(tmp_path, caplog):
    t, poses, relations = _synthetic(tmp_path)
    log = _test_log(tmp_path / "test.log", t, poses)
    packed = tmp_path / "test.log.gz"
    data = gzip.compress(log.read_bytes() * 50)  # the trajectory 50 times over: only the first copy is in time order
    packed.write_bytes(data[: len(data) // 2])
    result = runner.invoke(app, ["evaluate", "-e", str(packed), "-r", str(relations)])
    assert result.exit_code == 0, result.output
    assert _rows(result.output) == _by_hand(t, poses, relations)
    messages = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert sum("ends early" in m for m in messages) == 1, messages
    assert (
        sum("cut short" in m for m in messages) == 1
        and sum("repeat an earlier line's timestamp" in m for m in messages) == 1
    )


def test_changing_beam_counts_are_evaluated_from_the_poses(tmp_path):
    """A ROBOTLASER1 log whose scans are on no common grid is still a trajectory."""
    t, poses, relations = _synthetic(tmp_path)
    log = tmp_path / "robot.clf"
    with log.open("w") as handle:
        for k, (stamp, p) in enumerate(zip(t, poses)):
            n, res = (3, 0.5) if k % 2 else (5, 0.25)
            handle.write(
                f"ROBOTLASER1 0 -0.5 {res * (n - 1)} {res} 30 0.01 0 {n} {' '.join(['2.0'] * n)} 0 "
                f"%.6f %.6f %.6f %.6f %.6f %.6f 0 0 0 0 0 %.6f h 0\n" % (*p, *p, stamp)
            )
    with pytest.raises(Exception, match="angular grid"):
        read_carmen(log)
    result = runner.invoke(app, ["evaluate", "-e", str(log), "-r", str(relations)])
    assert result.exit_code == 0, result.output
    assert _rows(result.output) == _by_hand(t, poses, relations)


def test_relations_of_another_log_are_one_line_and_exit_2(tmp_path):
    t, poses, relations = _synthetic(tmp_path)
    relative = _test_log(tmp_path / "relative.log", t - 1134864000.0, poses)  # the same run on another clock
    used = {0, 1, 3, 5, 6, 9, 10, 12, 20, 21, 30, 39}  # scans the relations refer to
    other = [k for k in range(len(t)) if k not in used]  # 0.2 s or more from them
    sparse = _test_log(tmp_path / "sparse.log", t[other], poses[other])
    for log in (relative, sparse):
        result = runner.invoke(app, ["evaluate", "-e", str(log), "-r", str(relations)])
        assert result.exit_code == 2
        assert result.output.count("\n") == 1, result.output
        assert (
            f"{relations}: no relation timestamp (7 relations in [" in result.output
            and "not of this log" in result.output
        )
        assert f"within 0.1 s of a pose: {log} has" in result.output and "Traceback" not in result.output


def test_infinite_tolerance_is_the_programs_nearest_pose_whatever_the_gap(tmp_path):
    """Without -o the metricEvaluator takes the nearest pose however far; ``--tolerance inf`` does the same."""
    t, poses, relations = _synthetic(tmp_path)
    sparse = np.arange(0, len(t), 3)
    log = _test_log(tmp_path / "sparse.log", t[sparse], poses[sparse])
    result = runner.invoke(app, ["evaluate", "-e", str(log), "-r", str(relations), "--tolerance", "inf"])
    assert result.exit_code == 0, result.output
    assert _rows(result.output) == _by_hand(t[sparse], poses[sparse], relations, tolerance=math.inf)
    assert "matched 7 of 7 relations" in result.output


@pytest.mark.slow  # real data: the whole fr079 log
@pytest.mark.skipif(
    not (DATA / "mit-csail.relations").is_file() or not FR079.is_file(), reason="shared data not present"
)
def test_relations_of_another_real_log_are_refused(tmp_path):
    result = runner.invoke(app, ["evaluate", "-e", str(FR079), "-r", str(DATA / "mit-csail.relations")])
    assert result.exit_code == 2 and result.output.count("\n") == 1, result.output
    assert "no relation timestamp (1172 relations in [" in result.output and "not of this log" in result.output
    assert not (tmp_path / "anything").exists()


@pytest.mark.skipif(not (DATA / "mit-csail.relations").is_file(), reason="shared data not present")
def test_mit_csail_odometry_as_a_test_log_matches_the_original_program(tmp_path):
    """The log's own odometry written as a Freiburg test log. The expected rows are what the metricEvaluator
    printed for these files (-w "{1,1,1,0,0,0}" and "{0,0,0,1,1,1}", -e), built from its source."""
    laser = read_carmen(DATA / "mit-csail.clf", ranges=False).laser
    log = _test_log(tmp_path / "mit-odometry.log", laser.t, laser.odometry)
    relations = DATA / "mit-csail.relations"
    result = runner.invoke(app, ["evaluate", "-e", str(log), "-r", str(relations)])
    assert result.exit_code == 0, result.output
    rows = _rows(result.output)
    assert rows == ("1.681461, 5.294470, 0.000000, 22.972185, 1172", "0.088519, 0.143895, 0.000000, 1.041741, 1172")
    assert rows == _by_hand(np.round(laser.t, 6), np.round(laser.odometry, 6), relations)
    assert len(read_relations(relations)) == 1172


@pytest.mark.slow  # a new Python process (about 2.5 s of imports)
def test_the_cli_shows_each_tolerated_oddity_once(tmp_path):
    t, poses, relations = _synthetic(tmp_path)
    log = _test_log(tmp_path / "test.log", t, poses)
    lines = log.read_text().splitlines(keepends=True)
    lines[5] = f"FLASER 0 nan 0 0 nan 0 0 {t[5] + 0.01:.6f} nohost 1\n"  # an extra line, with a nan pose
    lines[8], lines[9] = lines[9], lines[8]
    log.write_text("".join(lines) + lines[-1][:25])  # a last line cut short
    code = "import sys; from slamtrials.cli.main import main; sys.argv[0] = 'slamtrials'; main()"
    done = subprocess.run(
        [sys.executable, "-c", code, "evaluate", "-e", str(log), "-r", str(relations)],
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "PYTHONPATH": str(REPO / "src")},
    )
    assert done.returncode == 0, done.stderr
    warnings = [line for line in done.stderr.splitlines() if line.startswith("WARNING")]
    assert len(warnings) == 3, done.stderr
    assert any("1 FLASER lines with a non-finite pose" in w for w in warnings)
    assert any("1 FLASER lines with a timestamp earlier" in w for w in warnings)
    assert any("last line is cut short" in w for w in warnings)
