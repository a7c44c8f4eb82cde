"""The fit of the short-reading chance by the wall's range: the rise read back, a constant rate kept
constant, the cut's seen share and the false alarms taken into account."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.calibration.shortchance import ShortChance, fit_short_chance
from slamtrials.sim.shortrate import short_chances


def _beams(truth: ShortChance, n: int, seed: int, seen_floor: float = 0.9, false_alarm: float = 0.0):
    """Walls at 0.3 to 25 m, whether each beam read short, and each beam's seen share."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(0.3, 25.0, n)
    seen = seen_floor + (1.0 - seen_floor) * rng.random(n)
    short = rng.random(n) < false_alarm + (1.0 - false_alarm) * seen * truth.at(r)
    return r, short, seen


def test_a_rising_chance_is_read_back():
    truth = ShortChance(0.35, 4.5, 1.5)
    r, short, seen = _beams(truth, 300_000, seed=1, false_alarm=0.00135)
    fitted = fit_short_chance(r, short, seen, 0.00135)
    assert fitted.rate == pytest.approx(0.35, abs=0.01)
    assert fitted.scale == pytest.approx(4.5, rel=0.06)
    assert fitted.shape == pytest.approx(1.5, rel=0.08)
    # the simulator's chance for the fitted values is the fit's own
    walls = np.array([0.5, 2.0, 8.0])
    assert np.allclose(fitted.at(walls), short_chances(walls, fitted.rate, fitted.scale, fitted.shape))


def test_a_constant_chance_stays_constant_and_the_seen_share_is_undone():
    r, short, seen = _beams(ShortChance(0.1, 0.0, 1.0), 200_000, seed=2, seen_floor=0.5)
    fitted = fit_short_chance(r, short, seen, 0.0)
    assert fitted.scale == 0.0 and fitted.shape == 1.0
    # half the short readings or more of some beams fall inside the cut: the raw share is well below 0.1
    assert np.mean(short) < 0.08 and fitted.rate == pytest.approx(0.1, abs=0.004)


def test_too_few_short_readings_give_the_constant_rate():
    fitted = fit_short_chance(np.linspace(1.0, 9.0, 50), np.zeros(50, dtype=bool), np.ones(50), 0.0)
    assert fitted == ShortChance(0.0, 0.0, 1.0)
