"""Where a short reading's thing stands along its beam (``short_position_power``).

Real short readings stand farther along the beam than a uniform draw puts them: on the shared logs
fewer than 1 % lie in the tenth of the beam nearest the sensor, and their gaps before the wall grow with
the wall's range (docs/realism.md, "Assumptions"). The model: the thing's position as a fraction ``v``
of the beam from ``min_range`` to the wall has density ``(a + 1) v^a`` on [0, 1], ``a =
short_position_power``; 0 (the default) is uniform. ``v`` is drawn from the one uniform ``u`` the draw
order gives a short reading's distance, by the inverse CDF ``v = u^(1 / (a + 1))``; with ``a = 0`` it is
``u`` itself, so the uniform draw is the same bit for bit. The distance is ``min_range + v (r -
min_range)``.
"""

from __future__ import annotations

import math

from numba import njit

__all__ = ["short_distance"]


@njit(cache=True, fastmath=False, nogil=True)
def short_distance(u: float, r: float, min_range: float, power: float) -> float:  # pragma: no cover
    """The distance (m) of a short reading on a beam whose wall is at ``r`` (m), for a uniform ``u`` in [0, 1)
    and the position power ``power`` (>= 0)."""
    span = max(r - min_range, 0.0)
    v = u if power == 0.0 else math.pow(u, 1.0 / (power + 1.0))
    return min_range + v * span
