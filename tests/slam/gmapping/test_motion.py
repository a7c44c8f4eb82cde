"""GMapping's motion model (spec/gmapping.md, section 2).

With 200,000 particles at random headings, the noisy increments (recovered with ``ominus`` from each
particle's start pose) have the odometry increment as mean and the spec's standard deviations

    sx  = srr |dx| + str |dth| + 0.3 srr |dy|
    sy  = srr |dy| + str |dth| + 0.3 srr |dx|
    sth = stt |dth| + srt sqrt(dx^2 + dy^2)

(``str``: translation noise from rotation; ``srt``: rotation noise from translation), the three noises
uncorrelated. The parameters are chosen so that swapping srt and str would change every sigma a lot.
A zero increment moves nothing; the same seed gives the same samples.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.geometry import compose, ominus, ominus1, wrap_angle
from slamtrials.slam.gmapping.motion import motion_sigmas, sample_motion

SRR, SRT, STR, STT = 0.1, 0.4, 0.05, 0.2
N = 200_000


def spec_sigmas(dx: float, dy: float, dth: float) -> np.ndarray:
    """The spec's formulas, written out."""
    dx, dy, dth = abs(dx), abs(dy), abs(dth)
    return np.array(
        [
            SRR * dx + STR * dth + 0.3 * SRR * dy,
            SRR * dy + STR * dth + 0.3 * SRR * dx,
            STT * dth + SRT * math.sqrt(dx * dx + dy * dy),
        ]
    )


def _start_poses(rng: np.random.Generator) -> np.ndarray:
    return np.column_stack([rng.uniform(-5, 5, N), rng.uniform(-5, 5, N), rng.uniform(-np.pi, np.pi, N)])


@pytest.mark.parametrize("increment", [(0.5, -0.2, 0.3), (0.0, 0.0, -0.4), (0.8, 0.0, 0.0), (-0.3, 0.1, 0.05)])
def test_noisy_increments_have_the_spec_mean_and_sigmas(increment):
    """Mean within 5 standard errors, std within 1.5 % of the formula, correlations below 0.01."""
    rng = np.random.default_rng(7)
    starts = _start_poses(rng)
    odo_old = np.array([1.0, 2.0, 0.7])
    odo_new = compose(odo_old, np.array(increment))
    moved = sample_motion(starts, odo_old, odo_new, SRR, SRT, STR, STT, np.random.default_rng(11))
    noisy = ominus(starts, moved)
    expected_sigma = spec_sigmas(*increment)
    assert np.allclose(motion_sigmas(np.array(increment), SRR, SRT, STR, STT), expected_sigma, rtol=1e-9, atol=1e-15)
    for k in range(3):
        values = noisy[:, k] if k < 2 else wrap_angle(noisy[:, 2] - increment[2]) + increment[2]
        assert abs(values.mean() - increment[k]) < 5 * expected_sigma[k] / math.sqrt(N)
        assert values.std() == pytest.approx(expected_sigma[k], rel=0.015)
    noise = noisy - np.array(increment)
    noise[:, 2] = wrap_angle(noise[:, 2])
    corr = np.corrcoef(noise.T)
    assert np.all(np.abs(corr[np.triu_indices(3, 1)]) < 0.01)


def test_srt_and_str_are_not_swapped():
    """Pure rotation gives translation noise str*|dth| (not srt*|dth|); pure translation gives rotation
    noise srt*|d| (not str*|d|)."""
    turn = motion_sigmas(np.array([0.0, 0.0, 1.0]), SRR, SRT, STR, STT)
    assert turn[0] == pytest.approx(STR) and turn[1] == pytest.approx(STR) and turn[2] == pytest.approx(STT)
    drive = motion_sigmas(np.array([1.0, 0.0, 0.0]), SRR, SRT, STR, STT)
    assert drive[2] == pytest.approx(SRT)
    assert drive[0] == pytest.approx(SRR) and drive[1] == pytest.approx(0.3 * SRR)


def test_zero_increment_moves_nothing():
    """Standing still: every pose comes back unchanged (x, y bit for bit, theta up to wrapping)."""
    rng = np.random.default_rng(3)
    starts = _start_poses(rng)[:1000]
    odo = np.array([0.3, -1.2, 2.5])
    moved = sample_motion(starts, odo, odo.copy(), SRR, SRT, STR, STT, np.random.default_rng(5))
    np.testing.assert_array_equal(moved[:, :2], starts[:, :2])
    np.testing.assert_allclose(wrap_angle(moved[:, 2] - starts[:, 2]), 0.0, atol=1e-15)


def test_same_seed_same_samples_and_stream_independent_of_motion():
    """Equal seeds give bitwise equal samples; a different seed different ones. The generator advances
    by the same draws whether or not the robot moved (so later draws do not depend on standing still)."""
    starts = _start_poses(np.random.default_rng(1))[:500]
    old, new = np.array([0.0, 0.0, 0.0]), np.array([0.4, 0.1, 0.2])
    a = sample_motion(starts, old, new, SRR, SRT, STR, STT, np.random.default_rng(42))
    b = sample_motion(starts, old, new, SRR, SRT, STR, STT, np.random.default_rng(42))
    c = sample_motion(starts, old, new, SRR, SRT, STR, STT, np.random.default_rng(43))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    moving, still = np.random.default_rng(9), np.random.default_rng(9)
    sample_motion(starts, old, new, SRR, SRT, STR, STT, moving)
    sample_motion(starts, old, old.copy(), SRR, SRT, STR, STT, still)
    assert moving.random() == still.random()


def test_samples_are_the_array_composition_bit_for_bit():
    """The compiled per-particle loop gives exactly ``compose(start, wrap(increment + noise))`` of the
    geometry module, with the noise drawn as ``standard_normal((N, 3)) * sigmas`` from the same seed
    (including headings at +-pi and a turn that crosses it)."""
    starts = _start_poses(np.random.default_rng(2))[:2000]
    starts[:4, 2] = [math.pi, -math.pi, 0.0, math.pi / 2]
    old, new = np.array([1.0, -2.0, 3.0]), np.array([1.3, -1.7, -2.9])
    moved = sample_motion(starts, old, new, SRR, SRT, STR, STT, np.random.default_rng(8))
    increment = ominus1(old, new)
    sigmas = motion_sigmas(increment, SRR, SRT, STR, STT)
    noisy = increment + np.random.default_rng(8).standard_normal((len(starts), 3)) * sigmas
    noisy[:, 2] = wrap_angle(noisy[:, 2])
    np.testing.assert_array_equal(moved, compose(starts, noisy))
