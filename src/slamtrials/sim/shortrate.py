"""How likely a beam is to read short, by the range of its wall (``short_range_scale``, ``short_range_shape``).

Real logs read short far more often on long beams: on both shared logs the share grows from 2 to 4 %
of the beams whose wall is 0.5 to 1 m away to 30 to 40 % beyond 8 m, and levels off there
(docs/realism.md, "Assumptions"). The model: a beam whose true range is ``r`` reads short with
probability

    p(r) = short_rate (1 - exp(-(r / s)^k)),   s = short_range_scale, k = short_range_shape,

a Weibull-shaped rise to ``short_rate`` over a few metres. ``s = 0`` (the default) is the constant
``short_rate`` of every beam. A beam without a wall (nothing within ``max_range``) takes ``r =
max_range``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath

__all__ = ["short_chances"]


def short_chances(ranges: NDArray[np.float64], short_rate: float, scale: float, shape: float) -> NDArray[np.float64]:
    """float64 ``[B]``: each beam's probability of reading short, for true ranges ``[B]`` (m)."""
    if scale <= 0.0:
        return np.full(ranges.shape, short_rate)
    rise = stablemath.power(np.maximum(ranges, 0.0) / scale, shape)
    return short_rate * (1.0 - stablemath.exp(-rise))
