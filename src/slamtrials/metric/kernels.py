"""Numba kernels of the metric's hot paths: nearest-timestamp lookup and relative poses of many pairs.

A million relations against a hundred thousand poses must evaluate in well under a second on one core;
``numpy.searchsorted`` with unsorted keys and the temporaries of the array SE(2) functions take about
that long on their own, so these loops do the same work in one pass each.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["EPS", "nearest_indices", "relative_poses"]

#: Relative slack of the inclusive tolerance test: one unit in the last place of a timestamp is at most
#: ``|t| * EPS``.
EPS = float(np.finfo(np.float64).eps)


@numba.njit(cache=True)
def _nearest_kernel(times, t, tolerance, index, gap, within):  # pragma: no cover - compiled
    n = len(times)
    first = times[0]
    span = times[n - 1] - first
    buckets = n
    # starts[b] = first pose index with time >= the lower edge of bucket b (sorted keys: one merge pass)
    starts = np.empty(buckets + 1, dtype=np.int64)
    i = 0
    for b in range(buckets):
        edge = first + span * b / buckets
        while i < n and times[i] < edge:
            i += 1
        starts[b] = i
    starts[buckets] = n
    for k in range(len(t)):
        q = t[k]
        if span > 0.0:
            f = (q - first) / span * buckets
            if f < 0.0:
                b = 0
            elif f >= buckets:
                b = buckets - 1
            else:
                b = int(f)
        else:
            b = 0
        lo = starts[b]
        hi = starts[b + 1]
        # first index with times[index] >= q, searched in [lo, hi], then corrected for rounding at the edges
        while lo < hi:
            mid = (lo + hi) // 2
            if times[mid] < q:
                lo = mid + 1
            else:
                hi = mid
        right = lo
        while right > 0 and times[right - 1] >= q:
            right -= 1
        while right < n and times[right] < q:
            right += 1
        if right >= n:
            right = n - 1
        left = right - 1 if right > 0 else 0
        gap_left = abs(q - times[left])
        gap_right = abs(times[right] - q)
        if gap_left <= gap_right:
            index[k] = left
            gap[k] = gap_left
        else:
            index[k] = right
            gap[k] = gap_right
        within[k] = gap[k] <= tolerance + abs(q) * 2.220446049250313e-16


def nearest_indices(
    times: NDArray[np.float64], t: NDArray[np.float64], tolerance: float
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]:
    """Nearest element of sorted ``times`` for each ``t`` (the earlier one on a tie), its gap, and ``gap <= tolerance``.

    Parameters
    ----------
    times:
        float64 ``[N]`` strictly increasing timestamps (s), ``N >= 1``.
    t:
        float64 ``[M]`` query timestamps (s), any order.
    tolerance:
        Largest accepted gap (s), inclusive up to one unit in the last place of the query.

    Returns
    -------
    index, gap, within:
        int64 ``[M]`` nearest indices, float64 ``[M]`` absolute gaps (s), bool ``[M]`` accepted.
    """
    times = np.ascontiguousarray(times, dtype=np.float64)
    t = np.ascontiguousarray(t, dtype=np.float64)
    index = np.empty(len(t), dtype=np.int64)
    gap = np.empty(len(t), dtype=np.float64)
    within = np.empty(len(t), dtype=np.bool_)
    _nearest_kernel(times, t, float(tolerance), index, gap, within)
    return index, gap, within


@numba.njit(cache=True)
def _relative_kernel(a, ia, b, ib, out):  # pragma: no cover - compiled
    two_pi = 2.0 * math.pi
    for k in range(len(ia)):
        i = ia[k]
        j = ib[k]
        c = math.cos(a[i, 2])
        s = math.sin(a[i, 2])
        dx = b[j, 0] - a[i, 0]
        dy = b[j, 1] - a[i, 1]
        out[k, 0] = c * dx + s * dy
        out[k, 1] = -s * dx + c * dy
        out[k, 2] = ((b[j, 2] - a[i, 2]) + math.pi) % two_pi - math.pi


def relative_poses(
    a: NDArray[np.float64], ia: NDArray[np.int64], b: NDArray[np.float64], ib: NDArray[np.int64]
) -> NDArray[np.float64]:
    """``ominus(a[ia], b[ib])`` without the gathered copies: pose ``b[ib[k]]`` seen from pose ``a[ia[k]]``.

    Parameters
    ----------
    a, b:
        float64 ``[Na, 3]``, ``[Nb, 3]`` poses (m, m, rad) in one frame.
    ia, ib:
        int64 ``[K]`` row indices into ``a`` and ``b``.

    Returns
    -------
    NDArray[np.float64]
        ``[K, 3]`` relative poses, theta wrapped into [-pi, pi); equal to
        :func:`slamtrials.geometry.ominus` up to rounding (computed as :func:`~slamtrials.geometry.ominus1`).
    """
    out = np.empty((len(ia), 3), dtype=np.float64)
    _relative_kernel(
        np.ascontiguousarray(a, dtype=np.float64),
        np.ascontiguousarray(ia, dtype=np.int64),
        np.ascontiguousarray(b, dtype=np.float64),
        np.ascontiguousarray(ib, dtype=np.int64),
        out,
    )
    return out
