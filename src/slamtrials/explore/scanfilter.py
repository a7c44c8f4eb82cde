"""Isolated laser returns: dropped before the explorer's reactive checks (a speckle filter).

A real laser reports things that are not in the map (people, glass, clutter, spurious returns from
edges), and the ``realistic`` profile models them as *short readings*: a beam returns at a random
range between the sensor and the true one. Such a reading is a single beam whose endpoint lies far
from its neighbours' endpoints. A real obstacle close enough to matter to the robot (within the few
metres it needs to stop or turn) spans several beams: at 2 m a 0.5 degree beam spacing puts adjacent
endpoints 1.7 cm apart. The path follower and the recovery react to every scan point, so a single
phantom point in front of the robot stops it (office_small_01 with ``realistic``, seed 1: the robot
was blocked in 67 % of its steps and reached no goal in 1,080 s).

:func:`confirmed_ranges` keeps a return only when another return among the ``window`` beams on either
side ends within ``distance`` of it (the "distance" speckle filter of ROS's laser_filters does the
same). Beams it drops become NaN (no information), which the follower and the recovery skip. Only
returns within ``reach`` are examined: the reactive checks need what is near, and far away the
returns of one surface lie farther apart than ``distance``. With a noise-free laser every return
within reach on a surface at least two beams wide, not seen at a grazing angle, is kept.

Close to a wall the short readings of adjacent beams often land close together (a beam whose true
range is 0.5 m puts its short reading within 0.5 m of the laser), so pairs of phantoms confirm each
other. The simulator's short readings are drawn anew for every scan, while what the robot must stop
for stays where it is: :class:`ScanMemory` also asks a return to lie within ``distance`` of a
confirmed return of the previous scan (both placed in the map frame by the pose the explorer drove
by), which removes the pairs. A real robot's costmap does the same when it clears obstacles that the
next scan's beams pass through.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from slamtrials import stablemath
from slamtrials.explore.follower import _beam_directions
from slamtrials.record import LaserGeometry

__all__ = ["ScanMemory", "confirmed_ranges", "inside_footprint"]

#: Largest angle (rad) a point moves across the scan between two consecutive scans besides the turn:
#: parallax of a point 0.25 m away while the robot moves 0.07 m (0.7 m/s for 0.1 s) across it.
_PARALLAX = math.radians(25.0)


@njit(cache=True, nogil=True)
def _confirmed(ranges, cos_k, range_min, range_max, distance, reach):  # pragma: no cover - compiled
    """float64 [B]: ``ranges`` with returns that no return within ``len(cos_k)`` beams confirms set to NaN.

    ``cos_k[k - 1]`` is the cosine of ``k`` beam spacings; endpoints ``i`` and ``j = i + k`` are
    ``sqrt(r_i^2 + r_j^2 - 2 r_i r_j cos_k)`` apart (law of cosines, no sqrt needed).
    """
    count = ranges.shape[0]
    window = cos_k.shape[0]
    d2 = distance * distance
    out = ranges.copy()
    for i in range(count):
        ri = ranges[i]
        if not (ri > range_min and ri < range_max) or ri > reach:  # not a return (NaN too), or too far to matter
            continue
        confirmed = False
        for k in range(1, window + 1):
            for j in (i - k, i + k):
                if j < 0 or j >= count:
                    continue
                rj = ranges[j]
                if not (rj > range_min and rj < range_max):
                    continue
                if ri * ri + rj * rj - 2.0 * ri * rj * cos_k[k - 1] <= d2:
                    confirmed = True
                    break
            if confirmed:
                break
        if not confirmed:
            out[i] = np.nan
    return out


def inside_footprint(ranges: ArrayLike, laser: LaserGeometry, radius: float) -> NDArray[np.float64]:
    """float64 ``[B]``: the scan (m) with every return that ends inside the robot's disc (``radius`` m
    around the base's origin) replaced by NaN: nothing can be there but the robot itself (the footprint
    filter of ROS's laser_filters). Short readings land there often, since all beams start there."""
    r = np.array(ranges, dtype=np.float64)
    if radius <= 0.0 or r.shape[0] == 0:
        return r
    cos, sin = _beam_directions(r.shape[0], laser)
    finite = np.isfinite(r)  # a no-return (+inf) ends nowhere
    reach = np.where(finite, r, 0.0)
    px = laser.mount[0] + reach * cos
    py = laser.mount[1] + reach * sin
    r[finite & (px * px + py * py < radius * radius)] = np.nan
    return r


def confirmed_ranges(
    ranges: ArrayLike, laser: LaserGeometry, window: int, distance: float, reach: float = math.inf
) -> NDArray[np.float64]:
    """float64 ``[B]``: the scan (m) with every isolated return replaced by NaN (module docstring).

    Parameters
    ----------
    ranges:
        ``[B]`` ranges (m) of one scan, beam ``b`` at ``laser.angle_min + b * laser.angle_increment``.
    laser:
        The laser's geometry (beam spacing and the valid range interval).
    window:
        Beams on either side searched for a confirming return; 0 returns the scan unchanged.
    distance:
        Largest distance (m) between two endpoints that confirm each other.
    reach:
        Returns farther than this (m) are kept as they are (they still confirm nearer ones).
    """
    r = np.ascontiguousarray(ranges, dtype=np.float64)
    if window <= 0 or r.shape[0] == 0:
        return r
    spacing = abs(float(laser.angle_increment)) * np.arange(1, window + 1, dtype=np.float64)
    return _confirmed(
        r, stablemath.cos(spacing), float(laser.range_min), float(laser.range_max), float(distance), float(reach)
    )


@njit(cache=True, nogil=True)
def _persistent(
    ranges, ex, ey, prev_x, prev_y, prev_index, shift, window, travel, increment, distance, reach
):  # pragma: no cover - compiled
    """``ranges`` with returns that no previous return (sorted by beam index) confirms set to NaN.

    Return ``b`` ends at map point (ex[b], ey[b]) (NaN where it is not a return); a previous return
    with beam index in ``[b + shift - w, b + shift + w]`` within ``distance`` confirms it, where ``w``
    covers the parallax of a point at that range after the robot moved ``travel`` m (at most ``window``).
    """
    out = ranges.copy()
    d2 = distance * distance
    count = prev_index.shape[0]
    for b in range(ranges.shape[0]):
        if not (ex[b] == ex[b]) or ranges[b] > reach:  # NaN: not a return; or too far to matter
            continue
        w = min(window, int((travel + distance) / (ranges[b] * increment)) + 2)
        lo = b + shift - w
        hi = b + shift + w
        k = np.searchsorted(prev_index, lo)
        found = False
        while k < count and prev_index[k] <= hi:
            dx = prev_x[k] - ex[b]
            dy = prev_y[k] - ey[b]
            if dx * dx + dy * dy <= d2:
                found = True
                break
            k += 1
        if not found:
            out[b] = np.nan
    return out


class ScanMemory:
    """Confirmation of returns by the previous scans (module docstring).

    Parameters
    ----------
    distance:
        Largest distance (m) between a return and a previous scan's return that confirms it.
    reach:
        Returns farther than this (m) are kept as they are.
    scans:
        Consecutive scans a return must be seen in: 1 keeps every return, 2 asks for a confirming
        return in the previous scan, 3 in each of the previous two, and so on.
    step:
        Farthest the robot moves from one scan to the next (m): bounds the parallax searched for.
    """

    def __init__(self, distance: float, reach: float = math.inf, scans: int = 2, step: float = 0.07):
        self.step = float(step)
        self.distance = float(distance)
        self.reach = float(reach)
        self.scans = int(scans)
        self.reset()

    def reset(self) -> None:
        """Forget the previous scans."""
        self._prev: list[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64], float]] = []

    def persistent(self, ranges: ArrayLike, pose: ArrayLike, laser: LaserGeometry) -> NDArray[np.float64]:
        """float64 ``[B]``: the returns of ``ranges`` (one scan, isolated returns already NaN) that a
        return of each of the previous ``scans - 1`` scans passed here confirms; the others NaN. Until
        that many scans were seen, the returns are checked against those there are.

        ``pose`` is float64 ``[3]`` the robot base's pose (map frame) the scan was taken from.
        """
        r = np.ascontiguousarray(ranges, dtype=np.float64)
        x, y, th = (float(v) for v in np.asarray(pose, dtype=np.float64)[:3])
        cos, sin = _beam_directions(r.shape[0], laser)  # base frame, cached
        valid = (r > laser.range_min) & (r < laser.range_max)
        ct, st = math.cos(th), math.sin(th)
        rv = np.where(valid, r, np.nan)
        bx, by = laser.mount[0] + rv * cos, laser.mount[1] + rv * sin
        ex = x + ct * bx - st * by
        ey = y + st * bx + ct * by
        out = r
        increment = abs(float(laser.angle_increment))
        if increment > 0.0:
            for age, (px, py, pidx, pth) in enumerate(reversed(self._prev), start=1):
                turn = math.remainder(th - pth, 2.0 * math.pi)
                shift = round(math.copysign(1.0, laser.angle_increment) * turn / increment)
                window = math.ceil(age * _PARALLAX / increment)
                out = _persistent(
                    out,
                    ex,
                    ey,
                    px,
                    py,
                    pidx,
                    int(shift),
                    int(window),
                    age * self.step,
                    increment,
                    self.distance,
                    self.reach,
                )
        if self.scans > 1:
            index = np.flatnonzero(valid).astype(np.int64)
            self._prev.append((ex[index].copy(), ey[index].copy(), index, th))
            del self._prev[: -(self.scans - 1)]
        return out
