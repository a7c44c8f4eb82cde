"""A path replayed in the simulator (sim/pathreplay.py): the odometry noise follows the motion, not the stamps.

Issue 32, item 2. The noise is a random walk per metre driven and per radian turned
(:mod:`slamtrials.sim.odometry`), so the error accumulated over a path must be the same whether its
frames come every 0.1 s, at jittered gaps, or at the stamps of a log whose lines were out of order
(duplicated stamps, gaps of a microsecond across a normal step, bursts of sub-millisecond steps).

The statistical test: for each stamp pattern, ``N`` seeds replay the path; over the seeds, the variance of
the summed arc-length error and of the summed heading error is compared with the model's prediction
``a^2 D + b^2 R`` and ``c^2 R + d^2 D`` (``D`` metres driven, ``R`` radians turned, the same for every
pattern). The sample variance of ``N`` normal errors over its expectation is ``chi^2_N / N``, of std
``sqrt(2 / N)``; the test allows 4.5 of those. The model before issue 32 (std ``k L`` per step, rescaled by
``sqrt(0.1 s / gap)`` in the replay) gives about a thousand times the regular pattern's variance on the third
pattern (checked against that code, commit 603ee2e, with these patterns), and fails.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.errors import SimulationError
from slamtrials.geometry import ominus
from slamtrials.sim import SimConfig
from slamtrials.sim.config import ErrorProfile
from slamtrials.sim.pathreplay import simulate_path
from slamtrials.worlds import World

SEEDS = 200
SPEED = 0.4  # m/s
DURATION = 30.0  # s: 12 m, and about 6.8 rad of turning


def _world() -> World:
    occ = np.ones((60, 60), bool)
    occ[5:55, 5:55] = False
    return World(occ, 0.05, name="box", start=np.array([1.5, 1.5, 0.0]))


def _path(t: np.ndarray) -> np.ndarray:
    """The true path at times ``t`` ``[T]``: constant speed, turn rate ``0.35 sin(0.4 t)`` (rad/s),
    integrated in closed form (the heading) and numerically fine (the position), ``[T, 3]``."""
    fine = np.linspace(0.0, DURATION, 400_001)
    heading = 0.35 / 0.4 * (1.0 - np.cos(0.4 * fine))
    dx = np.concatenate(([0.0], np.cumsum(0.5 * (np.cos(heading[1:]) + np.cos(heading[:-1])) * SPEED * np.diff(fine))))
    dy = np.concatenate(([0.0], np.cumsum(0.5 * (np.sin(heading[1:]) + np.sin(heading[:-1])) * SPEED * np.diff(fine))))
    return np.column_stack(
        [1.5 + np.interp(t, fine, dx), 1.5 + np.interp(t, fine, dy), 0.35 / 0.4 * (1.0 - np.cos(0.4 * t))]
    )


def _regular() -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, DURATION + 1e-9, 0.1)
    return t, _path(t)


def _jittered() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(11)
    t = np.concatenate(([0.0], np.cumsum(rng.uniform(0.02, 0.3, 400))))
    t = t[t <= DURATION]
    return t, _path(t)


def _log_stamps() -> tuple[np.ndarray, np.ndarray]:
    """The path at regular 0.1 s instants, but stamped as a log whose lines were out of order and then
    sorted: a third of the gaps shrunk to 1 to 100 microseconds across a normal step, duplicated frames
    (the same pose again 1 microsecond later: a step of no motion), and every tenth step cut into 25
    sub-millisecond steps (0.4 ms apart)."""
    rng = np.random.default_rng(12)
    instants = np.arange(0.0, DURATION + 1e-9, 0.1)
    times, poses_at = [0.0], [0.0]
    stamp = 0.0
    for k in range(1, instants.size):
        if k % 10 == 0:  # a burst of sub-millisecond steps along the path
            for j in range(1, 25):
                stamp += 0.0004
                times.append(stamp)
                poses_at.append(instants[k - 1] + 0.1 * j / 25)
            stamp += 0.0004
        elif rng.random() < 1.0 / 3.0:
            stamp += float(rng.uniform(1e-6, 1e-4))
        else:
            stamp += 0.1
        times.append(stamp)
        poses_at.append(instants[k])
        if rng.random() < 0.1:  # a duplicated frame
            stamp += 1e-6
            times.append(stamp)
            poses_at.append(instants[k])
    return np.array(times), _path(np.array(poses_at))


PATTERNS = {"regular 0.1 s": _regular, "jittered": _jittered, "log stamps": _log_stamps}


def _arcs(poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed arc length ``[T - 1]`` (m) and heading change (rad) of each step, read as the model does."""
    d = ominus(poses[:-1], poses[1:])
    half = 0.5 * d[:, 2]
    sinc = np.where(np.abs(half) < 1e-8, 1.0, np.sin(half) / np.where(half == 0.0, 1.0, half))
    return (d[:, 0] * np.cos(half) + d[:, 1] * np.sin(half)) / sinc, d[:, 2]


@pytest.mark.parametrize(
    "coefficients",
    [
        {"noise_linear_per_m": 0.03, "noise_angular_per_m": 0.02},  # growth per metre
        pytest.param(
            {"noise_linear_per_rad": 0.04, "noise_angular_per_rad": 0.05}, marks=pytest.mark.slow
        ),  # growth per radian
    ],
    ids=["per-metre", "per-radian"],
)
@pytest.mark.slow
def test_error_growth_per_metre_and_per_radian_does_not_depend_on_the_stamps(coefficients):
    profile = ErrorProfile(
        name="odometry-noise",
        odometry={**coefficients, "bias_linear_range": (0.0, 0.0), "bias_angular_range": (0.0, 0.0)},
    )
    config = SimConfig.from_dict({"profile": profile, "laser": {"fov": 0.1, "angular_resolution": 0.1}})
    values = {k: coefficients.get(k, 0.0) for k in ODOMETRY_NOISE}
    world = _world()
    allowed = 4.5 * math.sqrt(2.0 / SEEDS)
    for name, make in PATTERNS.items():
        t, path = make()
        assert np.all(np.diff(t) > 0.0)
        true_l, true_phi = _arcs(path)
        distance, turned = float(np.sum(np.abs(true_l))), float(np.sum(np.abs(true_phi)))
        assert distance == pytest.approx(SPEED * DURATION, rel=0.01) and turned == pytest.approx(6.8, rel=0.05)
        errors = np.empty((SEEDS, 2))
        for seed in range(SEEDS):
            odo_l, odo_phi = _arcs(simulate_path(world, t, path, config, seed).odometry)
            errors[seed] = np.sum(odo_l) - np.sum(true_l), np.sum(odo_phi) - np.sum(true_phi)
        var_l = values["noise_linear_per_m"] ** 2 * distance + values["noise_linear_per_rad"] ** 2 * turned
        var_phi = values["noise_angular_per_rad"] ** 2 * turned + values["noise_angular_per_m"] ** 2 * distance
        ratio_l = float(np.mean(errors[:, 0] ** 2)) / var_l
        ratio_phi = float(np.mean(errors[:, 1] ** 2)) / var_phi
        assert abs(ratio_l - 1.0) < allowed, f"{name}: arc-length error variance {ratio_l:.3f} x the model's"
        assert abs(ratio_phi - 1.0) < allowed, f"{name}: heading error variance {ratio_phi:.3f} x the model's"


ODOMETRY_NOISE = ("noise_linear_per_m", "noise_linear_per_rad", "noise_angular_per_rad", "noise_angular_per_m")


@pytest.mark.slow
def test_slips_along_a_path_do_not_depend_on_the_stamps():
    """Slips are a Poisson process in distance: the slips' summed heading error has variance
    ``slip_per_m D slip_angular_std^2`` on every stamp pattern."""
    profile = ErrorProfile(
        name="slips",
        odometry={
            "slip_per_m": 0.5,
            "slip_angular_std": 0.05,
            "bias_linear_range": (0.0, 0.0),
            "bias_angular_range": (0.0, 0.0),
        },
    )
    config = SimConfig.from_dict({"profile": profile, "laser": {"fov": 0.1, "angular_resolution": 0.1}})
    world = _world()
    for name, make in PATTERNS.items():
        t, path = make()
        true_l, true_phi = _arcs(path)
        errors = np.array(
            [
                np.sum(_arcs(simulate_path(world, t, path, config, seed).odometry)[1]) - np.sum(true_phi)
                for seed in range(SEEDS)
            ]
        )
        expected = 0.5 * float(np.sum(np.abs(true_l))) * 0.05**2
        # a compound Poisson sum is not normal: its variance estimate has std sqrt((3 / (lambda D) + 2) / N) of it
        allowed = 4.5 * math.sqrt((3.0 / (0.5 * SPEED * DURATION) + 2.0) / SEEDS)
        assert abs(float(np.mean(errors**2)) / expected - 1.0) < allowed, name


def test_simulate_path_refuses_times_that_do_not_increase():
    t, path = _regular()
    t[5] = t[4]
    with pytest.raises(SimulationError, match="strictly increasing"):
        simulate_path(_world(), t, path, None, 0)


def test_simulate_path_defaults_to_the_default_profile():
    t, path = _regular()
    by_default = simulate_path(_world(), t, path, None, 4)
    realistic = simulate_path(_world(), t, path, SimConfig(), 4)
    paper = simulate_path(_world(), t, path, SimConfig.paper(), 4)
    assert np.array_equal(by_default.scans, realistic.scans)
    assert np.array_equal(by_default.odometry, realistic.odometry)
    assert not np.array_equal(by_default.odometry, paper.odometry)
