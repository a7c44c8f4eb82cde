"""Fixtures shared across test folders: synthetic drives for tests that compare an estimate's turns with
a run's odometry."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from slamtrials.geometry import compose


def _drive(seed: int, seconds: float = 300.0, dt: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Times and poses of a robot at 0.4 m/s that picks a new turn rate in [-0.6, 0.6] rad/s every 3 s."""
    rng = np.random.default_rng(seed)
    n = int(seconds / dt)
    rates = np.repeat(rng.uniform(-0.6, 0.6, n // 30 + 1), 30)[: n - 1]
    poses = np.zeros((n, 3))
    for k in range(n - 1):
        poses[k + 1] = compose(poses[k], [0.4 * dt, 0.0, rates[k] * dt])
    return np.arange(n) * dt, poses


def _odometry_of(poses: np.ndarray, seed: int, turn_scale: float = 1.06) -> np.ndarray:
    """Odometry that drifts from ``poses``: 6 % over-counted turns and noise on every step."""
    rng = np.random.default_rng(seed)
    out = np.zeros_like(poses)
    out[0] = [5.0, -2.0, 1.0]  # its own frame
    for k in range(len(poses) - 1):
        dx, dy, dth = poses[k + 1] - poses[k]
        c, s = np.cos(poses[k, 2]), np.sin(poses[k, 2])
        step = np.array([c * dx + s * dy, -s * dx + c * dy, np.arctan2(np.sin(dth), np.cos(dth))])
        step = step * [1.0, 1.0, turn_scale] + rng.normal(0.0, [0.002, 0.002, 0.004])
        out[k + 1] = compose(out[k], step)
    return out


@pytest.fixture
def drive() -> Callable[..., tuple[np.ndarray, np.ndarray]]:
    """``drive(seed, seconds=300, dt=0.1)``: times (s) and poses ``[T, 3]`` of a turning robot."""
    return _drive


@pytest.fixture
def odometry_of() -> Callable[..., np.ndarray]:
    """``odometry_of(poses, seed, turn_scale=1.06)``: a drifting odometry of ``poses`` in its own frame."""
    return _odometry_of
