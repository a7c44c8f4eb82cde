"""The Section III-C loop: hand-computed run counts, the cap, and agreement with replay_run_count."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.campaign import RunSettings, run_seed
from slamtrials.campaign.loop import next_step
from slamtrials.metric import replay_run_count

Z2 = 2.5758293035489004**2  # two-sided normal quantile of 99 %, squared


#: The paper's rule: 10 runs first, normal quantile at 99 % (the default quantile is Student t).
PAPER = RunSettings(distribution="normal")


def alternating(n: int, mean: float = 0.3, half: float = 0.05) -> dict[int, tuple[float, float]]:
    """eps_t = mean +- half alternately (known sample variance), eps_r constant 0.01."""
    return {i: (mean + (half if i % 2 == 0 else -half), 0.01) for i in range(n)}


def test_first_batch_is_the_initial_runs():
    step = next_step({}, PAPER)
    assert step.target == 10 and step.missing == tuple(range(10)) and not step.finished and step.decision is None
    step = next_step({0: (0.1, 0.1), 3: (0.2, 0.1)}, PAPER)
    assert step.missing == (1, 2, 4, 5, 6, 7, 8, 9)


def test_hand_computed_run_counts():
    # 10 runs at 0.3 +- 0.05: s^2 = 10 * 0.0025 / 9, N_t = ceil(z^2 s^2 / 0.02^2) = ceil(46.08) = 47
    s2 = 10 * 0.0025 / 9
    assert math.ceil(Z2 * s2 / 0.0004) == 47
    step = next_step(alternating(10), PAPER)
    assert step.target == 47 and step.missing == tuple(range(10, 47)) and step.decision.needed == 47
    # with 47 runs (24 high, 23 low) s^2 = (47 * 0.0025 - 47 * (0.05 / 47)^2) / 46 -> N = ceil(42.35) = 43 <= 47: stop
    s2 = (47 * 0.0025 - 47 * (0.05 / 47) ** 2) / 46
    assert math.ceil(Z2 * s2 / 0.0004) == 43
    step = next_step(alternating(47), PAPER)
    assert step.finished and not step.capped and step.target == 47 and step.decision.needed == 43
    assert [d.done for d in step.history] == [10, 47]
    # results beyond the target do not change the decisions
    assert next_step(alternating(80), PAPER) == step


def test_enough_after_the_first_batch_when_the_spread_is_small():
    step = next_step(alternating(10, half=0.005), PAPER)
    assert step.finished and step.target == 10 and step.decision.needed == 10  # N_t = 1 but at least initial


def test_the_cap_stops_a_world_and_is_reported():
    settings = RunSettings(initial=10, max_runs=20)
    step = next_step(alternating(10), settings)
    assert step.target == 20 and not step.finished  # the rule wanted 47, the cap allows 20
    step = next_step(alternating(20), settings)
    assert step.finished and step.capped and step.target == 20


def test_rotational_errors_count_too():
    results = {i: (0.3, 0.05 + (0.04 if i % 2 else -0.04)) for i in range(10)}
    step = next_step(results, PAPER)
    assert step.decision.needed_t <= 10 < step.decision.needed_r == step.target


@pytest.mark.parametrize("seed", range(6))
def test_agrees_with_replay_run_count(seed):
    rng = np.random.default_rng(seed)
    n = 400
    eps_t = 0.3 + rng.normal(0, 0.05 + 0.02 * seed, n)
    eps_r = 0.05 + rng.normal(0, 0.01 * (seed + 1), n)
    settings = RunSettings(initial=5 + seed, max_runs=300)
    results = {i: (float(t), float(r)) for i, (t, r) in enumerate(zip(eps_t, eps_r, strict=True))}
    step = next_step(results, settings)
    expected = replay_run_count(
        eps_t,
        eps_r,
        margin_t=0.02,
        margin_r=0.02,
        confidence=0.99,
        min_runs=settings.initial,
        max_runs=settings.max_runs,
    )
    assert step.finished and expected is not None
    assert step.target == expected.done and step.capped == expected.capped


def test_seeds_are_reproducible_and_distinct():
    assert run_seed(0, "office", 3) == run_seed(0, "office", 3)
    seeds = {run_seed(root, world, i) for root in (0, 1) for world in ("a", "b") for i in range(50)}
    assert len(seeds) == 200
    assert all(0 <= s < 2**63 for s in seeds)
    with pytest.raises(ValueError):
        run_seed(-1, "a", 0)
