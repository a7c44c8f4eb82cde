"""The fit of how long what reads short stays (``short_lifetime``, ``short_fleeting_share``) reads back the
values a simulated tour was made with, against the truth as reference."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.calibration import CalibrationSettings, Reference
from slamtrials.calibration.beams import beam_sample
from slamtrials.calibration.laser import fit_laser
from slamtrials.calibration.lifetime import fit_lifetime
from slamtrials.sim.config import LaserConfig, SimConfig
from slamtrials.sim.tour import tour_waypoints
from slamtrials.sim.waypoints import simulate_waypoints
from slamtrials.worlds import load_world

LASER = {"range_noise_std": 0.02, "range_noise_per_m": 0.01, "short_rate": 0.08, "short_run_beams": 3.0}
SETTINGS = CalibrationSettings(bootstrap=30)


def _fit(lifetime: float, fleeting: float):
    world = load_world("office_small_01")
    laser = LaserConfig(**LASER, short_lifetime=lifetime, short_fleeting_share=fleeting)
    record = simulate_waypoints(
        world, tour_waypoints(world, num_goals=6), SimConfig(profile="paper", laser=laser), seed=5, max_time=600
    )
    reference = Reference.from_world(record.truth, world, "simulation truth")
    fit = fit_laser(beam_sample(record, reference, SETTINGS.max_beams), SETTINGS, record.laser.range_min)
    assert fit is not None
    return fit_lifetime(record, reference, fit, SETTINGS, seed=1)


@pytest.mark.slow
def test_the_lifetime_and_the_fleeting_share_are_read_back_within_their_stated_uncertainty():
    fit = _fit(4.0, 0.5)
    assert fit is not None and fit.short_readings > 5000
    assert abs(fit.lifetime - 4.0) <= 2.0 * fit.stderr and 0.0 < fit.stderr < 3.0, fit.lifetime
    assert abs(fit.fleeting - 0.5) <= 2.0 * fit.fleeting_stderr and 0.0 < fit.fleeting_stderr < 0.3, fit.fleeting
    assert not fit.at_bound
    # the fitted curve is the log's: what was simulated is what the replay of the fitted values gives
    assert np.max(np.abs(fit.fitted - fit.real)) < 0.03
    # the curves fall with the lag, and longer lifetimes hold on longer
    assert np.all(np.diff(fit.real) < 0.0)
    assert fit.model[0, -1, -1] > fit.model[0, 1, -1]


@pytest.mark.slow
def test_short_readings_drawn_anew_for_every_scan_fit_no_lifetime():
    fit = _fit(0.0, 0.0)
    assert fit is not None
    assert fit.lifetime < 0.25
    assert fit.real[0] < 0.4  # the chance that another short reading lands within the radius


def test_settings_refuse_grids_that_are_not_increasing():
    with pytest.raises(ValueError, match="increasing"):
        CalibrationSettings(lifetime_grid=(1.0, 0.5))
    with pytest.raises(ValueError, match="shares"):
        CalibrationSettings(fleeting_grid=(0.0, 1.0))
