"""Where short readings' things stand along the beam: density ``(a + 1) v^a`` of the beam fraction ``v``
(``short_position_power``; 0: uniform)."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.sim.config import LaserConfig
from slamtrials.sim.raycast import LaserModel
from slamtrials.sim.shortdistance import short_distance

from .test_raycast import room_world

POSE = np.array([10.0, 10.0, 0.4])


def _fractions(config: LaserConfig, scans: int = 40) -> np.ndarray:
    """Where the short readings stand, as a fraction of their wall's range, over ``scans`` scans."""
    laser = LaserModel(room_world(size_m=20.0), config)
    rng = np.random.default_rng(4)
    out = []
    for k in range(scans):
        pose = POSE + np.array([0.0, 0.0, 0.07 * k])
        true = laser.true_ranges(pose).astype(float)
        reading = laser.scan(pose, rng, t=0.1 * k).astype(float)
        short = reading < true - 1e-4
        out.append(reading[short] / true[short])
    return np.concatenate(out)


@pytest.mark.parametrize(
    "shape",
    [{}, {"short_run_beams": 4.0}, {"short_run_beams": 4.0, "short_lifetime": 5.0, "short_fleeting_share": 0.5}],
    ids=["independent", "runs", "runs that stay"],
)
def test_things_stand_farther_out_with_the_power(shape):
    power = _fractions(LaserConfig(short_rate=0.2, short_position_power=2.0, **shape))
    uniform = _fractions(LaserConfig(short_rate=0.2, **shape))
    assert power.size > 500 and uniform.size > 500
    # density (a + 1) v^a: mean (a + 1) / (a + 2), 3/4 for a = 2 (a run's later beams read its first beam's
    # distance against walls about as far, so the fractions stay close to the drawn ones); 1/2 uniform
    assert np.mean(power) == pytest.approx(0.75, abs=0.05)
    assert np.mean(uniform) == pytest.approx(0.5, abs=0.06)
    # a = 2: P(v < 0.3) = 0.3^3 = 2.7 %; uniform 30 % (things that stay are read again by beams whose walls
    # are farther or nearer than the one they were drawn on, which spreads the fractions a little)
    assert np.mean(power < 0.3) < 0.1 < 0.2 < np.mean(uniform < 0.3)


def test_the_inverse_cdf_and_power_zero_keeps_the_uniform_draw():
    u = np.linspace(0.0, 0.999, 50)
    for r in (0.3, 2.0, 15.0):
        far = np.array([short_distance(x, r, 0.1, 1.0) for x in u])
        assert np.all((far >= 0.1) & (far <= r)) and np.all(np.diff(far) >= 0.0)
        assert np.allclose(far, 0.1 + np.sqrt(u) * (r - 0.1), rtol=0, atol=1e-12)
        assert [short_distance(x, r, 0.1, 0.0) for x in u] == [0.1 + x * (r - 0.1) for x in u]
    draws = np.random.default_rng(2).random(20_000)
    v = np.array([short_distance(x, 21.0, 1.0, 3.0) for x in draws]) - 1.0
    v /= 20.0
    assert np.mean(v < 0.5) == pytest.approx(0.5**4, abs=0.01)  # CDF v^(a + 1)
    assert not LaserConfig(short_position_power=1.0).has_errors
