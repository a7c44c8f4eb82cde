"""Readings at depth edges (``edge_chance``, ``edge_reach``): a beam next to a nearer surface reads it.

Why. Real short readings crowd at the depth edges of the map (door frames, pillar sides, corridor
openings): on both shared logs about 10 % of the beams have a neighbour within two beams whose wall is
more than :data:`EDGE_MIN_STEP` nearer, and 13 to 15 % of those read that nearer wall (to 0.1 m), where a
beam elsewhere almost never reads a neighbour's wall (``bench/studies/short_edges.py``; docs/realism.md,
"Assumptions"). A laser's spot is wider than the angle between its beams, and the reference that finds
the edges is itself a little off; either way the reading lies on real geometry, not at a random place.

What. A beam whose nearest neighbour within ``edge_reach`` (rad) to either side (the beams ``1 ..
floor(edge_reach / increment)`` places away) has a true range more than :data:`EDGE_MIN_STEP` metres
shorter than its own reads, with probability ``edge_chance``, that neighbour's range in place of its own:
its true range becomes the nearer one, and the other error models (noise, dropout, short readings) apply
to it as to any beam. A beam with no wall within the maximum range counts its range as the maximum. A
flat wall met at a grazing angle makes neighbouring ranges differ by more than the step too (beyond
about 74 degrees of incidence at 10 m with 0.5 degree between beams); such beams count as far sides of an
edge in the simulator and in the calibration alike (a spot spread along the wall returns first from its
nearest part).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["EDGE_MIN_STEP", "reach_in_beams", "nearest_neighbour_range", "edge_ranges"]

#: Least depth step (m) between a beam's wall and a neighbour's that makes the beam's a far side of an edge.
EDGE_MIN_STEP = 0.3


def reach_in_beams(reach: float, increment: float) -> int:
    """How many beams to either side ``reach`` (rad) covers at ``increment`` (rad) between beams."""
    if reach <= 0.0 or increment <= 0.0:
        return 0
    return int(math.floor(reach / increment + 1e-9))


def nearest_neighbour_range(ranges: NDArray[np.float64], beams: int) -> NDArray[np.float64]:
    """float64 ``[B]``: the shortest of ``ranges`` ``[B]`` (m) among the beams 1 to ``beams`` places to either
    side of each beam (not the beam itself); ``inf`` where there is none."""
    r = np.asarray(ranges, dtype=np.float64)
    nearest = np.full(r.shape, np.inf)
    for step in range(1, min(beams, r.shape[0] - 1) + 1):
        nearest[step:] = np.minimum(nearest[step:], r[:-step])
        nearest[:-step] = np.minimum(nearest[:-step], r[step:])
    return nearest


def edge_ranges(
    ranges: NDArray[np.float64], nearer: NDArray[np.float64], uniforms: NDArray[np.float64], chance: float
) -> NDArray[np.float64]:
    """float64 ``[B]``: the ranges (m) the beams read before their other errors, for true ``ranges`` ``[B]``,
    each beam's nearest neighbouring range ``nearer`` ``[B]`` (:func:`nearest_neighbour_range`) and one
    uniform in [0, 1) per beam: the neighbour's range where it is more than :data:`EDGE_MIN_STEP` nearer and
    the uniform is below ``chance``, the beam's own elsewhere."""
    reads_edge = (nearer < ranges - EDGE_MIN_STEP) & (uniforms < chance)
    return np.where(reads_edge, nearer, ranges)
