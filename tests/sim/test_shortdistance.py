"""Where short readings' things stand: anywhere on the beam, or a gap before the wall (``short_wall_share``,
``short_wall_gap``)."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.sim.config import LaserConfig
from slamtrials.sim.raycast import LaserModel
from slamtrials.sim.shortdistance import short_distance

from .test_raycast import room_world

POSE = np.array([10.0, 10.0, 0.4])


def _gaps(config: LaserConfig, scans: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Gaps before the wall (m) of the short readings, and their walls' ranges (m), over ``scans`` scans."""
    laser = LaserModel(room_world(size_m=20.0), config)
    rng = np.random.default_rng(4)
    gaps, walls = [], []
    for k in range(scans):
        pose = POSE + np.array([0.0, 0.0, 0.07 * k])
        true = laser.true_ranges(pose).astype(float)
        reading = laser.scan(pose, rng, t=0.1 * k).astype(float)
        short = reading < true - 1e-4
        gaps.append(true[short] - reading[short])
        walls.append(true[short])
    return np.concatenate(gaps), np.concatenate(walls)


@pytest.mark.parametrize(
    "shape",
    [{}, {"short_run_beams": 4.0}, {"short_run_beams": 4.0, "short_lifetime": 5.0, "short_fleeting_share": 0.5}],
    ids=["independent", "runs", "runs that stay"],
)
def test_things_stand_an_exponential_gap_before_the_wall(shape):
    gaps, walls = _gaps(LaserConfig(short_rate=0.2, short_wall_share=0.99, short_wall_gap=0.6, **shape))
    assert gaps.size > 500
    # the walls are 7 to 14 m away, so the cut at the sensor does not matter: an exponential's mean and
    # median (a run reads its first beam's distance; its other beams' walls are about as far; 1 % are
    # anywhere on the beam)
    assert np.mean(gaps) == pytest.approx(0.99 * 0.6 + 0.01 * 0.5 * np.mean(walls), rel=0.2)
    assert np.median(gaps) == pytest.approx(0.6 * np.log(2.0), rel=0.25)
    uniform, walls_u = _gaps(LaserConfig(short_rate=0.2, **shape))
    # without the gap a thing is anywhere on the beam: on average half the wall's range before it
    assert np.mean(uniform / walls_u) == pytest.approx(0.5, abs=0.06)


def test_the_gap_is_cut_to_the_beam_and_share_zero_keeps_the_uniform_draw():
    u = np.linspace(0.0, 0.999, 50)
    for r in (0.3, 2.0, 15.0):
        near = np.array([short_distance(x, r, 0.1, 0.999, 2.0) for x in u])
        assert np.all((near >= 0.1) & (near <= r)) and np.all(np.diff(near) <= 0.0)  # nearer the sensor as u grows
        assert [short_distance(x, r, 0.1, 0.0, 2.0) for x in u] == [0.1 + x * (r - 0.1) for x in u]
    # a share of them at the wall, the rest uniform: u below the share picks the wall
    draws = np.random.default_rng(2).random(20_000)
    d = np.array([short_distance(x, 20.0, 0.0, 0.4, 0.5) for x in draws])
    assert np.mean(20.0 - d < 2.0) == pytest.approx(0.4 * (1 - np.exp(-4.0)) + 0.6 * 0.1, abs=0.015)
    assert not LaserConfig(short_wall_share=0.5, short_wall_gap=1.0).has_errors
