"""How a run's seed becomes its random streams: one convention for every place that runs SLAM.

A trial's seed ``s`` is split by ``numpy.random.SeedSequence(s).spawn(2)`` into the simulator's stream
(first child: odometry bias, laser noise) and the SLAM algorithm's stream (second child: motion noise,
resampling). Running the same algorithm over the trial's recording with seed ``s`` (``slamtrials slam
--seed s``, a campaign replay) uses the same second child, so it reproduces the trial's estimate bit
for bit: the algorithm sees the same frames and draws the same numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from slamtrials.errors import ConfigError

__all__ = ["RunStreams", "run_streams", "slam_rng", "check_seed"]


@dataclass(frozen=True, eq=False)
class RunStreams:
    """The two independent seed sequences of one run."""

    simulator: np.random.SeedSequence
    slam: np.random.SeedSequence


def check_seed(seed: object, what: str = "seed") -> int:
    """``seed`` as an int; :class:`ConfigError` (``"<what> must be ..."``) unless it is a non-negative integer."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ConfigError(f"{what} must be a non-negative integer, got {seed!r}")
    return int(seed)


def run_streams(seed: int) -> RunStreams:
    """The simulator's and the SLAM algorithm's seed sequences of the run with seed ``seed``."""
    sequence = np.random.SeedSequence(check_seed(seed))
    simulator, slam = sequence.spawn(2)
    return RunStreams(simulator=simulator, slam=slam)


def slam_rng(seed: int) -> np.random.Generator:
    """The generator a SLAM algorithm is reset with in the run with seed ``seed``."""
    return np.random.default_rng(run_streams(seed).slam)
