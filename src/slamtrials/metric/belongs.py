"""Whether an estimated trajectory belongs to a run: its turns are the run's odometry's turns.

An estimate of another run of the same length covers the same time span, so times alone cannot tell it
apart. Its turns can: a SLAM estimate corrects the odometry by a few per cent of each turn (and by a
jump now and then), while another run's robot turns at other times. The check cuts the common time span
into windows of ``window`` seconds, takes the heading change of both trajectories over each, keeps the
windows where either turns by at least ``min_turn``, and calls a window contradicting when the two
changes differ by more than ``share`` of the larger. An estimate contradicts the odometry when more
than half of at least ``min_windows`` such windows contradict it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.record import Trajectory

__all__ = ["TurnAgreement", "turn_agreement"]


@dataclass(frozen=True)
class TurnAgreement:
    """How an estimate's turns agree with the odometry's.

    Attributes
    ----------
    turning_windows:
        Windows in which the estimate or the odometry turned by at least ``min_turn``.
    contradicting_windows:
        Those whose two heading changes differ by more than the allowed share of the larger.
    decided:
        Enough turning windows to judge (at least ``min_windows``).
    """

    turning_windows: int
    contradicting_windows: int
    decided: bool

    @property
    def contradicting_share(self) -> float:
        """Share of turning windows that contradict (0 when there are none)."""
        return self.contradicting_windows / self.turning_windows if self.turning_windows else 0.0

    @property
    def belongs(self) -> bool:
        """False only when enough turning windows were seen and more than half contradict."""
        return not (self.decided and self.contradicting_share > 0.5)


def _heading_at(trajectory: Trajectory, times: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unwrapped heading (rad) interpolated linearly at ``times`` (s), which lie in the trajectory's span."""
    order = np.argsort(trajectory.t, kind="stable")
    t = np.asarray(trajectory.t, dtype=np.float64)[order]
    theta = np.unwrap(np.asarray(trajectory.poses, dtype=np.float64)[order, 2])
    return np.interp(times, t, theta)


def turn_agreement(
    estimate: Trajectory,
    odometry: Trajectory,
    *,
    window: float = 2.0,
    min_turn: float = 0.35,
    share: float = 0.5,
    min_windows: int = 10,
) -> TurnAgreement:
    """Compare the heading changes of ``estimate`` and ``odometry`` over windows of ``window`` seconds.

    Parameters
    ----------
    estimate, odometry:
        Trajectories in any frames (headings in rad; only heading changes are compared, so a constant
        offset between the frames does not matter).
    window:
        Window length (s).
    min_turn:
        Heading change (rad) from which a window counts as turning (0.35 rad: 20 deg).
    share:
        Largest allowed difference of the two changes, as a share of the larger.
    min_windows:
        Fewest turning windows needed to judge.
    """
    if len(estimate.t) < 2 or len(odometry.t) < 2:
        return TurnAgreement(0, 0, False)
    start = max(float(np.min(estimate.t)), float(np.min(odometry.t)))
    end = min(float(np.max(estimate.t)), float(np.max(odometry.t)))
    if end - start < 2.0 * window:
        return TurnAgreement(0, 0, False)
    edges = start + window * np.arange(int((end - start) // window) + 1, dtype=np.float64)
    turn_estimate = np.diff(_heading_at(estimate, edges))
    turn_odometry = np.diff(_heading_at(odometry, edges))
    larger = np.maximum(np.abs(turn_estimate), np.abs(turn_odometry))
    turning = larger >= min_turn
    contradicting = turning & (np.abs(turn_estimate - turn_odometry) > share * larger)
    n_turning = int(np.count_nonzero(turning))
    return TurnAgreement(n_turning, int(np.count_nonzero(contradicting)), n_turning >= min_windows)
