"""Where a short reading's thing stands along its beam (``short_rate``, ``short_wall_gap``).

With ``short_wall_gap`` 0 (the default) the thing is anywhere between the sensor's ``min_range`` and the
wall, uniformly. Real short readings are not: on the shared logs fewer than 1 % lie in the tenth of the
beam nearest the sensor and a third in the tenth nearest the wall (furniture, people and doors stand in
rooms near their walls, and the map's own errors sit at the walls; docs/realism.md, "Calibration"). With
``short_wall_gap`` ``> 0`` the thing stands a gap ``g`` before the wall, ``g`` exponential with that mean
(m), cut to the beam's length ``r - min_range``. Both take the one uniform ``u`` the draw order gives a
short reading's distance (inverse CDF of the cut exponential: ``g = -gap ln(1 - u (1 - exp(-L / gap)))``).
"""

from __future__ import annotations

import math

from numba import njit

__all__ = ["short_distance"]


@njit(cache=True, fastmath=False, nogil=True)
def short_distance(u: float, r: float, min_range: float, gap: float) -> float:  # pragma: no cover - compiled
    """The distance (m) of a short reading on a beam whose wall is at ``r`` (m), for a uniform ``u`` in [0, 1)."""
    span = max(r - min_range, 0.0)
    if gap <= 0.0:
        return min_range + u * span
    return max(r - (-gap * math.log(1.0 - u * (1.0 - math.exp(-span / gap)))), min_range)
