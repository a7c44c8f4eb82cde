"""Split-half validation: the log is cut at the middle of its time span, each half keeps its own relations,
the first half is calibrated and the second validated; bad splits are one line."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from slamtrials.errors import ConfigError
from slamtrials.record import LaserGeometry, Relations, RunRecord
from slamtrials.validation.split import record_frames, relations_within, split_log

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared")) / "data"
LOG = DATA / "mit-csail" / "mit-csail.clf"
RELATIONS = DATA / "mit-csail" / "mit-csail.relations"


def _record(n: int = 101) -> RunRecord:
    t = np.linspace(10.0, 20.0, n)  # cut at 15 s
    return RunRecord(
        t=t,
        scans=np.ones((n, 4), dtype=np.float32),
        odometry=np.column_stack([t, np.zeros(n), np.zeros(n)]),
        truth=np.zeros((n, 3)),
        stalled=np.zeros(n, dtype=bool),
        laser=LaserGeometry(angle_min=-0.1, angle_increment=0.1, range_min=0.0, range_max=10.0),
    )


def _relations(t1, t2) -> Relations:
    t1, t2 = np.asarray(t1, float), np.asarray(t2, float)
    return Relations(t1=t1, t2=t2, delta=np.column_stack([t2 - t1, np.zeros_like(t1), np.zeros_like(t1)]))


def test_a_log_is_cut_at_the_middle_of_its_time_span_and_relations_across_the_cut_are_dropped():
    record = _record()
    early = np.linspace(10.0, 14.0, 30)
    late = np.linspace(15.5, 19.5, 25)
    across = (np.array([14.0, 12.0]), np.array([16.0, 18.0]))
    relations = _relations(
        np.concatenate([early, late, across[0]]), np.concatenate([early + 0.5, late + 0.3, across[1]])
    )
    halves = split_log(record, relations)
    assert halves.split_t == pytest.approx(15.0)
    assert halves.first.t[-1] <= 15.0 < halves.second.t[0]
    assert len(halves.first) + len(halves.second) == len(record)
    assert len(halves.first_relations) == 30 and len(halves.second_relations) == 25
    np.testing.assert_array_equal(halves.second_relations.t1, late)
    np.testing.assert_array_equal(halves.second.odometry[:, 0], halves.second.t)


def test_a_half_with_too_few_relations_is_one_line_naming_both_counts():
    relations = _relations(np.linspace(10.0, 14.0, 30), np.linspace(10.5, 14.5, 30))
    with pytest.raises(ConfigError) as info:
        split_log(_record(), relations, log="run.clf")
    message = str(info.value)
    assert "\n" not in message and "run.clf" in message
    assert "first half holds 30 relations and the second 0" in message


def test_record_frames_and_relations_within_keep_what_they_are_asked_to():
    record = _record(11)
    keep = record.t >= 15.0
    part = record_frames(record, keep)
    np.testing.assert_array_equal(part.t, record.t[keep])
    assert part.scans.shape == (keep.sum(), 4) and part.laser == record.laser
    inside = relations_within(_relations([11.0, 14.0, 16.0], [12.0, 17.0, 16.5]), 10.0, 15.0)
    assert inside.t1.tolist() == [11.0]


@pytest.mark.slow
@pytest.mark.skipif(not (LOG.is_file() and RELATIONS.is_file()), reason=f"no MIT CSAIL data in {DATA}")
def test_mit_csail_split_half_calibrates_the_first_half_and_validates_the_second():
    from slamtrials.calibration import CalibrationSettings
    from slamtrials.io.relations import read_relations
    from slamtrials.slamrun import load_recording
    from slamtrials.validation import ValidationSettings
    from slamtrials.validation.split import split_validate

    record = load_recording(LOG)
    relations = read_relations(RELATIONS)
    result = split_validate(
        record, relations, ValidationSettings(runs=1), CalibrationSettings(bootstrap=10), log="mit-csail.clf"
    )
    halves = result.halves
    assert result.validation.relations_total == len(halves.second_relations)
    assert result.profile.laser["short_rate"] > 0.05 and result.profile.odometry["noise_linear_per_m"] > 0.0
    real = result.validation.real("slam").translational
    simulated = result.validation.simulated("slam", "translational").mean
    assert 0.0 < real < 0.2 and 0.0 < simulated < 0.2


@pytest.mark.skipif(not (LOG.is_file() and RELATIONS.is_file()), reason=f"no MIT CSAIL data in {DATA}")
def test_cli_split_with_a_half_without_relations_or_with_a_profile_is_one_line_and_nothing_runs(tmp_path):
    from typer.testing import CliRunner

    from slamtrials.cli.main import app

    lines = RELATIONS.read_text().splitlines()
    early = tmp_path / "early.relations"
    early.write_text("\n".join(lines[:40]) + "\n")  # the relations file is in time order: all in the first half
    out = tmp_path / "v.json"
    runner = CliRunner()
    result = runner.invoke(app, ["validate", str(LOG), "-r", str(early), "--split", "--json", str(out)])
    assert result.exit_code == 2, result.output
    message = result.output.strip().splitlines()
    assert len(message) == 1 and "the second 0" in message[0] and "mit-csail.clf" in message[0]
    result = runner.invoke(app, ["validate", str(LOG), "-r", str(RELATIONS), "--split", "--profile", "paper"])
    assert result.exit_code == 2 and "leave out --profile" in result.output
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.skipif(not (LOG.is_file() and RELATIONS.is_file()), reason=f"no MIT CSAIL data in {DATA}")
def test_mit_csail_split_half_with_a_program_fits_the_first_half_against_the_programs_estimate(tmp_path):
    import shlex
    import sys

    from typer.testing import CliRunner

    from slamtrials.cli.main import app

    # a real program: slamtrials' own GMapping run as a separate process on the exported CARMEN log
    slam = f"{shlex.quote(sys.executable)} -m slamtrials slam -i {{input}} --algorithm gmapping --out {{workdir}}/run"
    command = f"{slam} && cp {{workdir}}/run/trajectory.tum {{output}}"
    out = tmp_path / "split.json"
    result = CliRunner().invoke(
        app,
        [
            "validate",
            str(LOG),
            "-r",
            str(RELATIONS),
            "--split",
            "--runs",
            "1",
            "--program",
            command,
            "--json",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "first half" in result.output and "second half" in result.output
    text = " ".join(result.output.split())  # rich wraps long lines
    assert "reference: program:slamtrials estimate (seed 0) and the map drawn from it" in text
    import json

    doc = json.loads(out.read_text())
    assert doc["program"]["command"] == command and doc["profile"]["name"].endswith("first-half")
