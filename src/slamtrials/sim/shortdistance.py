"""Where a short reading's thing stands along its beam (``short_wall_share``, ``short_wall_gap``).

Real short readings crowd towards the walls: on the shared logs fewer than 1 % lie in the tenth of the
beam nearest the sensor and a third in the tenth nearest the wall (furniture, people and doors stand in
rooms near their walls, and the map's own errors sit at the walls; docs/realism.md, "Assumptions"). The
model: with probability ``short_wall_share`` the thing stands a gap ``g`` before the wall, exponential
with mean ``short_wall_gap`` (m) and cut to the beam's length ``L = r - min_range``; otherwise it stands
anywhere on the beam, uniformly (all of them with share 0, the default). Both take the one uniform ``u``
the draw order gives a short reading's distance: ``u < share`` picks the wall with ``v = u / share`` and
``g = -gap ln(1 - v (1 - exp(-L / gap)))`` (the cut exponential's inverse CDF), else ``v = (u - share) /
(1 - share)`` and the distance ``min_range + v L`` (with share 0: ``v = u``, the uniform draw bit for bit).
"""

from __future__ import annotations

import math

from numba import njit

__all__ = ["short_distance"]


@njit(cache=True, fastmath=False, nogil=True)
def short_distance(u: float, r: float, min_range: float, share: float, gap: float) -> float:  # pragma: no cover
    """The distance (m) of a short reading on a beam whose wall is at ``r`` (m), for a uniform ``u`` in [0, 1)."""
    span = max(r - min_range, 0.0)
    if u < share and gap > 0.0:
        v = u / share
        return max(r - (-gap * math.log(1.0 - v * (1.0 - math.exp(-span / gap)))), min_range)
    return min_range + (u - share) / (1.0 - share) * span
