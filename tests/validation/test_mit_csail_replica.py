"""Validation on real data: MIT CSAIL replicated with the paper's profile, and another log's relations refused.

Skipped when the shared data set is absent.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.io.relations import read_relations
from slamtrials.sim.profiles import BUNDLED_PROFILES
from slamtrials.slamrun import load_recording
from slamtrials.validation import ValidationSettings, validate

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared")) / "data"
LOG = DATA / "mit-csail" / "mit-csail.clf"
RELATIONS = DATA / "mit-csail" / "mit-csail.relations"
OTHER = DATA / "fr079" / "fr079.relations"

pytestmark = pytest.mark.skipif(
    not (LOG.is_file() and RELATIONS.is_file() and OTHER.is_file()), reason=f"no MIT CSAIL / fr079 data in {DATA}"
)


def test_another_logs_relations_are_one_line_and_nothing_runs(tmp_path):
    out = tmp_path / "v.json"
    result = CliRunner().invoke(app, ["validate", str(LOG), "--relations", str(OTHER), "--json", str(out)])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "fr079.relations does not belong to" in lines[0] and "mit-csail.clf" in lines[0]
    assert not out.exists()


@pytest.mark.slow
def test_mit_csail_paper_replica_is_far_easier_than_the_real_log():
    """The issue's measurement: the Stage-like replica gives a fraction of the real error (0.048 m)."""
    record = load_recording(LOG)
    relations = read_relations(RELATIONS)
    result = validate(record, relations, BUNDLED_PROFILES["paper"], ValidationSettings(runs=1))
    assert result.blocked == 0 and result.relations_replica == result.real_slam.relations == len(relations)
    assert 0.04 < result.real_slam.translational < 0.06
    replica = result.replicas[0]
    assert replica.slam.relations == len(relations)
    assert replica.slam.translational < 0.5 * result.real_slam.translational
    assert replica.odometry.translational < 0.5 * result.real_odometry.translational
