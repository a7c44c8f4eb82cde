"""Particle weights and low-variance resampling (spec/gmapping.md, section 4).

* ``normalized_weights`` is the softmax of ``l / (ogain * N)`` (compared with scipy's softmax, which
  computes it another way), so the ``ogain * N`` divisor flattens the weights;
* ``effective_sample_size`` is ``1 / sum w^2`` (N for uniform weights, 1 for a single particle);
* ``systematic_resample`` draws particle ``i`` floor(N w_i) or ceil(N w_i) times, returns sorted
  indexes, is the identity for uniform weights and never draws a zero-weight particle (for offsets
  ``u`` not exactly 0, where pointers sit on interval boundaries and rounding decides).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import softmax

from slamtrials.slam.gmapping.weights import effective_sample_size, normalized_weights, systematic_resample


@pytest.mark.parametrize("ogain", [1.0, 3.0, 10.0])
def test_normalized_weights_use_the_ogain_times_n_divisor(ogain):
    rng = np.random.default_rng(int(ogain))
    logs = rng.normal(-200.0, 40.0, size=30)
    w = normalized_weights(logs, ogain)
    np.testing.assert_allclose(w, softmax(logs / (ogain * 30)), rtol=1e-12)
    assert w.sum() == pytest.approx(1.0, abs=1e-12)
    # dividing by ogain*N (not ogain alone) makes the weights flatter: higher Neff
    assert effective_sample_size(w) > effective_sample_size(softmax(logs / ogain))
    # shifting all log weights changes nothing (only differences matter)
    np.testing.assert_allclose(normalized_weights(logs + 1.0e4, ogain), w, rtol=1e-12)


def test_normalized_weights_survive_huge_log_weight_ranges():
    """Log weights far below the best give tiny but finite weights, never NaN."""
    logs = np.array([0.0, -1.0e6, -1.0e9, -5.0])
    w = normalized_weights(logs, 3.0)
    assert np.all(np.isfinite(w)) and w[0] > w[3] > w[1] >= w[2] >= 0.0
    assert w.sum() == pytest.approx(1.0)


def test_effective_sample_size_formula():
    rng = np.random.default_rng(0)
    w = rng.random(17)
    w /= w.sum()
    assert effective_sample_size(w) == pytest.approx(1.0 / float(np.sum(w * w)), rel=1e-12)
    assert effective_sample_size(np.full(40, 1.0 / 40)) == pytest.approx(40.0)
    one = np.zeros(10)
    one[3] = 1.0
    assert effective_sample_size(one) == pytest.approx(1.0)


@settings(max_examples=300, deadline=None)
@given(
    raw=st.lists(st.floats(min_value=0.0, max_value=1.0, allow_nan=False), min_size=1, max_size=60),
    u=st.floats(min_value=1e-6, max_value=0.999999),
)
def test_systematic_resample_counts_are_floor_or_ceil(raw, u):
    w = np.array(raw, dtype=np.float64)
    if w.sum() <= 0.0:
        w = np.ones_like(w)
    w /= w.sum()
    n = w.shape[0]
    indexes = systematic_resample(w, u)
    assert indexes.shape == (n,)
    assert np.all(np.diff(indexes) >= 0)
    assert np.all((indexes >= 0) & (indexes < n))
    counts = np.bincount(indexes, minlength=n)
    expected = n * w
    # floor / ceil, with slack for the rounding of the cumulative sum at exact boundaries
    assert np.all(counts >= np.floor(expected - 1e-9)) and np.all(counts <= np.ceil(expected + 1e-9))
    assert not np.any(counts[w == 0.0])


@settings(max_examples=100, deadline=None)
@given(n=st.integers(min_value=1, max_value=200), u=st.floats(min_value=1e-6, max_value=0.999))
def test_uniform_weights_resample_to_the_identity(n, u):
    """(``u`` exactly 0 is left out: pointers then sit exactly on cumulative boundaries, and the rounding
    of ``cumsum`` decides; e.g. N = 5 draws particle 2 twice and 3 never. ``rng.random()`` gives 0 with
    probability 2^-53.)"""
    np.testing.assert_array_equal(systematic_resample(np.full(n, 1.0 / n), u), np.arange(n))


def test_systematic_resample_matches_pointer_definition():
    """Pointer k = (u + k) / N picks the particle whose cumulative interval [c_{i-1}, c_i) holds it."""
    w = np.array([0.1, 0.0, 0.45, 0.05, 0.4])
    u = 0.3
    got = systematic_resample(w, u)
    cumulative = np.cumsum(w)
    expected = [int(np.argmax(cumulative > (u + k) / len(w))) for k in range(len(w))]
    np.testing.assert_array_equal(got, expected)
    assert math.isclose(sum(w), 1.0)
