"""The bundled ``mit-csail`` profile is what ``slamtrials calibrate`` fits to the shared MIT CSAIL log.

GMapping with its defaults, seed 0, over the whole log (about a minute), then the calibration with the
CLI's settings, the odometry against the log's benchmark relations (``calibrate --relations``, issue 32);
every bundled value must be the fitted one to its four significant digits, and the log's
residual figures must be those of issue 21 (a robust sigma near 7.6 cm, a quarter of the beams off by
more than 0.2 m, a few per cent without return where the map has a wall). Skipped without the data.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from slamtrials.calibration import CalibrationSettings, calibrate, slam_reference
from slamtrials.io.relations import read_relations
from slamtrials.sim.profiles import BUNDLED_PROFILES
from slamtrials.slamrun import load_recording

REPO = Path(__file__).resolve().parents[2]
LOG = Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared")) / "data" / "mit-csail" / "mit-csail.clf"
RELATIONS = LOG.with_suffix(".relations")

pytestmark = [pytest.mark.slow, pytest.mark.skipif(not LOG.is_file(), reason=f"no MIT CSAIL log at {LOG}")]


def test_the_bundled_mit_csail_profile_is_the_calibration_of_the_shared_log():
    record = load_recording(LOG)
    reference = slam_reference(record, "gmapping", seed=0)
    relations = read_relations(RELATIONS)
    fitted = calibrate(
        record,
        reference,
        CalibrationSettings(bootstrap=10),
        seed=0,
        relations=relations,
        relations_source=RELATIONS.name,
    )
    assert fitted.odometry.source == "relations" and fitted.odometry.relations.used == 1043
    bundled = BUNDLED_PROFILES["mit-csail"]
    profile = fitted.profile("mit-csail", "")
    for name, value in bundled.laser.items():
        assert profile.laser[name] == pytest.approx(value, rel=1e-3, abs=1e-9), name
    for name, value in bundled.odometry.items():
        assert profile.odometry[name] == pytest.approx(value, rel=1e-3, abs=1e-9), name
    laser = fitted.laser
    assert 0.06 < laser.robust_sigma < 0.09
    assert 0.2 < laser.off_share < 0.3
    assert 0.02 < laser.no_return_share < 0.05
