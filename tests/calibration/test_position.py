"""The fit of where short readings stand along the beam (``short_position_power``): the maximum-likelihood
power of the truncated density ``(a + 1) v^a``, only past the floor."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.calibration.laser import POSITION_POWER_BOUNDS, position_power


def _draw(power: float, n: int, seed: int, range_min: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Readings [n] (m) drawn with the simulator's inverse CDF on walls 1 to 12 m away, and the walls."""
    rng = np.random.default_rng(seed)
    wall = rng.uniform(1.0, 12.0, n)
    v = rng.random(n) ** (1.0 / (power + 1.0))
    return range_min + v * (wall - range_min), wall


@pytest.mark.parametrize("power", [0.0, 0.7, 1.5, 4.0])
def test_the_power_is_read_back_from_the_readings_past_the_floor(power):
    reading, wall = _draw(power, 40_000, seed=3)
    cut = np.full(reading.size, 0.12)
    fitted = position_power(reading, wall, cut, 0.1, floor=0.5, min_short=100)
    # the MLE's standard error is (a + 1) / sqrt(n) for the n readings past the floor (23,000 to 36,000)
    n = np.count_nonzero(wall - reading >= 0.5)
    assert fitted == pytest.approx(power, abs=3.0 * (power + 1.0) / np.sqrt(n))


def test_readings_near_the_wall_do_not_move_the_fit():
    reading, wall = _draw(1.0, 40_000, seed=4)
    clutter = wall[:10_000] - np.random.default_rng(5).uniform(0.12, 0.5, 10_000)  # within the floor
    together = position_power(
        np.concatenate([reading, clutter]), np.concatenate([wall, wall[:10_000]]), np.full(50_000, 0.12), 0.1, 0.5, 100
    )
    without_floor = position_power(
        np.concatenate([reading, clutter]), np.concatenate([wall, wall[:10_000]]), np.full(50_000, 0.12), 0.1, 0.0, 100
    )
    assert together == pytest.approx(1.0, abs=0.05)
    assert without_floor > 1.3  # the same readings without the floor follow the clutter


def test_too_few_readings_give_uniform_and_the_bounds_hold():
    reading, wall = _draw(2.0, 50, seed=6)
    assert position_power(reading, wall, np.full(50, 0.1), 0.1, 0.5, 100) == 0.0
    # every reading at the floor: the fit would go beyond any power, and stops at the bound
    wall = np.linspace(2.0, 10.0, 200)
    assert position_power(wall - 0.5, wall, np.full(200, 0.1), 0.0, 0.5, 100) == POSITION_POWER_BOUNDS[1]
