"""Karto's correlation grid: smeared scan points, and the correlative search over (x, y, theta).

Kernels of :mod:`.scanmatch` (numba, ``cache=True``; sin and cos from the C library via ``math``).

Grid. A square ``uint8`` grid of ``roi`` x ``roi`` cells of ``resolution`` metres centred on the scan
being matched, plus a border of ``half + 1`` cells so the smearing kernel never runs off the array. Cell
``(gx, gy)`` (ROI coordinates, y up) covers the points that round to it: ``gx = round((x - ox) /
resolution)`` with Karto's rounding (halves away from zero), ``(ox, oy)`` the world position of ROI
cell (0, 0). Array index ``[gy + border, gx + border]``. A marked point sets its cell to 100 and every
cell within ``half`` cells to at least the kernel's ``round(100 exp(-d^2 / (2 sigma^2)))``.

Search. For every searched position (a regular lattice around the search centre) and heading (a regular
fan), the response is the sum of the grid values under the scan's points, each point's cell offset
rounded on its own (Karto's lookup tables), divided by ``100 *`` the scan's reading count (Karto's
GetResponse divides by the size of the scan's lookup array: one entry per reading, with a point or not); points that land outside the array add nothing (Karto checks
only the flat index, so such points may wrap onto another row there: see docs/karto.md).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials import stablemath

__all__ = [
    "OCCUPIED_VALUE",
    "MAX_VARIANCE",
    "karto_round",
    "smear_kernel",
    "find_valid_points",
    "add_points",
    "correlate",
]

#: Value of a cell holding a scan point (Karto's GridStates_Occupied).
OCCUPIED_VALUE = 100
#: Variance (m^2) Karto gives a match with no response.
MAX_VARIANCE = 500.0
_DISTANCE_PENALTY_GAIN = 0.2
_ANGLE_PENALTY_GAIN = 0.2
#: Karto's KT_TOLERANCE (Math.h): the margin of its DoubleEqual and of its distance and response tests
KT_TOLERANCE = 1e-6
#: FindValidPoints' least step (m^2) between checked points, math::Square(0.1) as Karto writes it: 0.1 * 0.1
#: is one ulp above the literal 0.01, so a step of exactly 0.1 m is not checked
_MIN_STEP_SQUARED = 0.1 * 0.1


@njit(cache=True, nogil=True)
def _round(value):  # pragma: no cover - compiled
    """Karto's math::Round: halves away from zero."""
    return math.floor(value + 0.5) if value >= 0.0 else math.ceil(value - 0.5)


def karto_round(value: float) -> int:
    """Round half away from zero (Karto's ``math::Round``), as an int."""
    return int(math.floor(value + 0.5) if value >= 0.0 else math.ceil(value - 0.5))


def smear_kernel(resolution: float, deviation: float) -> NDArray[np.uint8]:
    """Karto's smearing kernel: ``uint8 [K, K]``, ``K = 2 round(2 deviation / resolution) + 1``,
    cell value ``round(100 exp(-d^2 / (2 deviation^2)))`` at distance ``d`` (m) from the centre."""
    half = karto_round(2.0 * deviation / resolution)
    offsets = np.arange(-half, half + 1, dtype=np.float64) * resolution
    distance = stablemath.hypot(offsets[None, :], offsets[:, None])
    z = stablemath.exp(-0.5 * (distance / deviation) ** 2)
    return np.floor(z * OCCUPIED_VALUE + 0.5).astype(np.uint8)


@njit(cache=True, nogil=True)
def find_valid_points(px, py, vx, vy):  # pragma: no cover - compiled
    """Karto's FindValidPoints: which of a scan's points (world frame, beam order, NaN where a beam has no
    point) face the viewpoint ``(vx, vy)``; returns bool ``[B]``.

    Walking the points in beam order, every step of more than 10 cm is checked for the side of the line
    from the viewpoint through the previous checked point it lies on; the points since the last
    check are kept when the step turns counter-clockwise as seen from the viewpoint.
    """
    n = px.shape[0]
    valid = np.zeros(n, dtype=np.bool_)
    trailing = 0
    first_time = True
    fx = 0.0
    fy = 0.0
    for i in range(n):
        x = px[i]
        y = py[i]
        if first_time and not math.isnan(x) and not math.isnan(y):
            fx = x
            fy = y
            first_time = False
        dx = fx - x
        dy = fy - y
        if dx * dx + dy * dy > _MIN_STEP_SQUARED:
            a = vy - fy
            b = fx - vx
            c = fy * vx - fx * vy
            side = x * a + y * b + c
            fx = x
            fy = y
            if side < 0.0:
                trailing = i
            else:
                for j in range(trailing, i):
                    valid[j] = True
                trailing = i
    return valid


@njit(cache=True, nogil=True)
def add_points(grid, border, roi, ox, oy, inv_res, px, py, valid, kernel, box):  # pragma: no cover - compiled
    """Mark the ``valid`` points ``(px, py)`` (world, m) in ``grid`` and smear each newly marked cell.

    ``box`` int64 ``[4]`` (row min, row max, col min, col max of the array cells written) is widened in
    place, so the caller can clear only what was written.
    """
    half = kernel.shape[0] // 2
    for k in range(px.shape[0]):
        if not valid[k]:
            continue
        x = px[k]
        y = py[k]
        if not (math.isfinite(x) and math.isfinite(y)):
            continue
        gx = _round((x - ox) * inv_res)
        gy = _round((y - oy) * inv_res)
        if gx < 0 or gx >= roi or gy < 0 or gy >= roi:
            continue
        r = int(gy) + border
        c = int(gx) + border
        if grid[r, c] == OCCUPIED_VALUE:
            continue
        grid[r, c] = OCCUPIED_VALUE
        for j in range(-half, half + 1):
            for i in range(-half, half + 1):
                value = kernel[j + half, i + half]
                if value > grid[r + j, c + i]:
                    grid[r + j, c + i] = value
        box[0] = min(box[0], r - half)
        box[1] = max(box[1], r + half)
        box[2] = min(box[2], c - half)
        box[3] = max(box[3], c + half)


@njit(cache=True, nogil=True)
def _lookup(lx, ly, heading0, angle_step, n_angles, ox, oy, inv_res):  # pragma: no cover - compiled
    """Cell offsets ``[A, P]`` (columns, rows) of the points at each searched heading.

    As Karto's GridIndexLookup::ComputeOffsets, the rotated point is moved by the grid's origin and
    back before it is rounded (WorldToGrid of offset + origin), which can round a point lying on a
    cell's edge the other way."""
    n = lx.shape[0]
    dcol = np.empty((n_angles, n), dtype=np.int64)
    drow = np.empty((n_angles, n), dtype=np.int64)
    for a in range(n_angles):
        angle = heading0 + a * angle_step
        c = math.cos(angle)
        s = math.sin(angle)
        for p in range(n):
            dcol[a, p] = int(_round(((c * lx[p] - s * ly[p]) + ox - ox) * inv_res))
            drow[a, p] = int(_round(((s * lx[p] + c * ly[p]) + oy - oy) * inv_res))
    return dcol, drow


@njit(cache=True, nogil=True)
def _response(grid, row, col, dcol, drow, a, norm):  # pragma: no cover - compiled
    height, width_step = grid.shape
    size = height * width_step
    total = 0
    for p in range(dcol.shape[1]):
        flat = (row + drow[a, p]) * width_step + col + dcol[a, p]
        if 0 <= flat < size:
            total += grid[flat // width_step, flat % width_step]
    return total / norm


@njit(cache=True, nogil=True)
def _totals(grid, rows, cols, dcol, drow):  # pragma: no cover - compiled
    """int32 ``[A, Y, X]``: the sum of the grid values under the points at heading ``a`` from the position
    in array row ``rows[y]`` and column ``cols[x]``, each point read at its flat index (Karto's lookup:
    module docstring).

    The same sums as :func:`_response` at every position, accumulated point by point over the whole
    lattice of positions instead (integer sums, at most 100 per point: the order does not change them).
    For one heading and point the cells read are a small window of the grid: a strided view when the
    rows and columns are evenly spaced (they nearly always are) and the window neither leaves the array
    nor runs past a row's end; else cell by cell.
    """
    height, width_step = grid.shape
    size = height * width_step
    n_angles, n_points = dcol.shape
    n_y = rows.shape[0]
    n_x = cols.shape[0]
    totals = np.zeros((n_angles, n_y, n_x), dtype=np.int32)
    even = _evenly_spaced(rows) and _evenly_spaced(cols)
    row_stride = rows[1] - rows[0] if n_y > 1 else 1
    col_stride = cols[1] - cols[0] if n_x > 1 else 1
    for a in range(n_angles):
        for p in range(n_points):
            dr = drow[a, p]
            dc = dcol[a, p]
            if even:
                first = (rows[0] + dr) * width_step + cols[0] + dc
                top = first // width_step
                left = first - top * width_step
                if top >= 0 and top + row_stride * (n_y - 1) < height and left + col_stride * (n_x - 1) < width_step:
                    window = grid[
                        top : top + row_stride * n_y : row_stride, left : left + col_stride * n_x : col_stride
                    ]
                    out2 = totals[a]
                    for iy in range(n_y):
                        for ix in range(n_x):
                            out2[iy, ix] += window[iy, ix]
                    continue
            for iy in range(n_y):
                base = (rows[iy] + dr) * width_step + dc
                out = totals[a, iy]
                for ix in range(n_x):
                    flat = base + cols[ix]
                    if 0 <= flat < size:
                        out[ix] += grid[flat // width_step, flat % width_step]
    return totals


@njit(cache=True, nogil=True)
def _evenly_spaced(cols):  # pragma: no cover - compiled
    """Whether ``cols`` is ``cols[0] + k stride``, ``stride > 0`` (rounding may, rarely, make one step
    longer)."""
    stride = cols[1] - cols[0] if cols.shape[0] > 1 else 1
    if stride <= 0:
        return False
    for k in range(cols.shape[0]):
        if cols[k] != cols[0] + stride * k:
            return False
    return True


@njit(cache=True, nogil=True)
def _nonzero_rows(grid):  # pragma: no cover - compiled
    """The grid's nonzero cells row by row: ``starts`` int64 ``[H + 1]`` (row ``r``'s cells are
    ``starts[r]:starts[r + 1]``), their columns (increasing within a row) and values."""
    height, width = grid.shape
    starts = np.zeros(height + 1, dtype=np.int64)
    count = 0
    for r in range(height):
        for c in range(width):
            if grid[r, c] != 0:
                count += 1
        starts[r + 1] = count
    nonzero_cols = np.empty(count, dtype=np.int64)
    values = np.empty(count, dtype=np.int32)
    k = 0
    for r in range(height):
        for c in range(width):
            if grid[r, c] != 0:
                nonzero_cols[k] = c
                values[k] = grid[r, c]
                k += 1
    return starts, nonzero_cols, values


@njit(cache=True, nogil=True)
def _totals_sparse(starts, nonzero_cols, values, width_step, rows, cols, dcol, drow):  # pragma: no cover - compiled
    """:func:`_totals` from the grid's nonzero cells (:func:`_nonzero_rows`), for evenly spaced ``cols``:
    a point adds to the positions whose cell is one of the nonzero cells it reads (zeros add nothing).
    The cells one point reads from one row of positions are consecutive flat indexes, so they lie on one
    or more consecutive array rows; each piece is walked over its row's nonzero cells instead of cell by
    cell."""
    height = starts.shape[0] - 1
    n_angles, n_points = dcol.shape
    n_y = rows.shape[0]
    n_x = cols.shape[0]
    totals = np.zeros((n_angles, n_y, n_x), dtype=np.int32)
    stride = cols[1] - cols[0] if n_x > 1 else 1
    for a in range(n_angles):
        for p in range(n_points):
            dr = drow[a, p]
            dc = dcol[a, p]
            for iy in range(n_y):
                out = totals[a, iy]
                row_first = (rows[iy] + dr) * width_step + cols[0] + dc  # flat index read from position 0
                start = 0
                while start < n_x:
                    flat = row_first + start * stride
                    r = flat // width_step
                    first = flat - r * width_step
                    # positions start .. stop - 1 read array row r, columns first, first + stride, ...
                    stop = min(n_x, start + (width_step - 1 - first) // stride + 1)
                    last = first + (stop - 1 - start) * stride
                    if 0 <= r < height:
                        lo = starts[r]
                        hi = starts[r + 1]
                        if lo < hi and nonzero_cols[lo] <= last and nonzero_cols[hi - 1] >= first:
                            k = lo + np.searchsorted(nonzero_cols[lo:hi], first)
                            while k < hi and nonzero_cols[k] <= last:
                                offset = nonzero_cols[k] - first
                                if offset % stride == 0:
                                    out[start + offset // stride] += values[k]
                                k += 1
                    start = stop
    return totals


@njit(cache=True, nogil=True)
def correlate(
    grid,
    border,
    ox,
    oy,
    resolution,
    lx,
    ly,
    n_points,
    cx,
    cy,
    ctheta,
    search_offset,
    search_step,
    angle_offset,
    angle_step,
    penalize,
    distance_variance,
    minimum_distance_penalty,
    angle_variance,
    minimum_angle_penalty,
    fine,
    mean,
    covariance,
):  # pragma: no cover - compiled
    """Karto's CorrelateScan: search around ``(cx, cy, ctheta)``; return the best response (<= 1).

    ``lx, ly``: the scan's points in the laser frame (m), only beams that have one; ``n_points`` the
    response's denominator (the scan's reading count, at least 1). Positions ``c + k search_step`` for ``|k search_step| <= search_offset`` in x and y, headings
    ``ctheta + k angle_step`` within ``angle_offset``. ``penalize`` multiplies nonzero responses by the
    distance and angle penalties (variances in m^2 and rad^2). ``mean`` float64 ``[3]`` receives the
    average of the poses with the best response (headings averaged through cos and sin). ``covariance``
    float64 ``[3, 3]``: on the coarse pass (``fine`` False) it is reset and receives the positional
    covariance of the response surface (Karto's ComputePositionalCovariance); on the fine pass only its
    heading variance is set (ComputeAngularCovariance).
    """
    inv_res = 1.0 / resolution
    n_x = int(_round(search_offset * 2.0 / search_step)) + 1
    n_angles = int(_round(angle_offset * 2.0 / angle_step)) + 1
    heading0 = ctheta - angle_offset
    dcol, drow = _lookup(lx, ly, heading0, angle_step, n_angles, ox, oy, inv_res)
    norm = float(n_points) * OCCUPIED_VALUE
    rows = np.empty(n_x, dtype=np.int64)
    cols = np.empty(n_x, dtype=np.int64)
    for k in range(n_x):
        offset = -search_offset + k * search_step
        rows[k] = int(_round((cy + offset - oy) * inv_res)) + border
        cols[k] = int(_round((cx + offset - ox) * inv_res)) + border
    height, width = grid.shape
    if height * width * 4 < n_angles * lx.shape[0] * n_x * n_x and _evenly_spaced(cols):
        # a large search on a small grid (the loop matcher): walk only the nonzero cells of each row
        starts, nonzero_cols, values = _nonzero_rows(grid)
        totals = _totals_sparse(starts, nonzero_cols, values, width, rows, cols, dcol, drow)
    else:
        totals = _totals(grid, rows, cols, dcol, drow)
    responses = np.empty((n_x, n_x, n_angles))
    for iy in range(n_x):
        y = -search_offset + iy * search_step
        for ix in range(n_x):
            x = -search_offset + ix * search_step
            for a in range(n_angles):
                response = totals[a, iy, ix] / norm
                if penalize and abs(response) >= KT_TOLERANCE:
                    distance_penalty = 1.0 - _DISTANCE_PENALTY_GAIN * (x * x + y * y) / distance_variance
                    distance_penalty = max(distance_penalty, minimum_distance_penalty)
                    da = -angle_offset + a * angle_step
                    angle_penalty = 1.0 - _ANGLE_PENALTY_GAIN * da * da / angle_variance
                    angle_penalty = max(angle_penalty, minimum_angle_penalty)
                    response *= distance_penalty * angle_penalty
                responses[iy, ix, a] = response
    best = -1.0
    for iy in range(n_x):
        for ix in range(n_x):
            for a in range(n_angles):
                best = max(best, responses[iy, ix, a])
    sum_x = 0.0
    sum_y = 0.0
    sum_c = 0.0
    sum_s = 0.0
    count = 0
    for iy in range(n_x):
        for ix in range(n_x):
            for a in range(n_angles):
                if abs(responses[iy, ix, a] - best) < KT_TOLERANCE:
                    sum_x += cx + (-search_offset + ix * search_step)
                    sum_y += cy + (-search_offset + iy * search_step)
                    heading = heading0 + a * angle_step
                    sum_c += math.cos(heading)
                    sum_s += math.sin(heading)
                    count += 1
    mean[0] = sum_x / count
    mean[1] = sum_y / count
    mean[2] = math.atan2(sum_s / count, sum_c / count)
    if not fine:
        _positional_covariance(
            responses, best, mean[0] - cx, mean[1] - cy, search_offset, search_step, angle_step, covariance
        )
    else:
        row = int(_round((mean[1] - oy) * inv_res)) + border
        col = int(_round((mean[0] - ox) * inv_res)) + border
        best_angle = mean[2]
        while best_angle - ctheta < -math.pi:
            best_angle += 2.0 * math.pi
        while best_angle - ctheta > math.pi:
            best_angle -= 2.0 * math.pi
        total = 0.0
        accumulated = 0.0
        for a in range(n_angles):
            response = _response(grid, row, col, dcol, drow, a, norm)
            if response >= best - 0.1:
                angle = heading0 + a * angle_step
                total += response
                accumulated += (angle - best_angle) ** 2 * response
        if total > KT_TOLERANCE:
            if accumulated < KT_TOLERANCE:
                accumulated = angle_step * angle_step
            accumulated /= total
        else:
            accumulated = 1000.0 * angle_step * angle_step
        covariance[2, 2] = accumulated
    return min(best, 1.0)


@njit(cache=True, nogil=True)
def _positional_covariance(
    responses, best, dx, dy, search_offset, search_step, angle_step, covariance
):  # pragma: no cover - compiled
    """Karto's ComputePositionalCovariance over the best response of each searched position."""
    for i in range(3):
        for j in range(3):
            covariance[i, j] = 1.0 if i == j else 0.0
    if best < KT_TOLERANCE:
        covariance[0, 0] = MAX_VARIANCE
        covariance[1, 1] = MAX_VARIANCE
        covariance[2, 2] = 4.0 * angle_step * angle_step
        return
    n_x = responses.shape[0]
    total = 0.0
    xx = 0.0
    xy = 0.0
    yy = 0.0
    for iy in range(n_x):
        y = -search_offset + iy * search_step
        for ix in range(n_x):
            x = -search_offset + ix * search_step
            response = responses[iy, ix, 0]
            for a in range(1, responses.shape[2]):
                response = max(response, responses[iy, ix, a])
            if response >= best - 0.1:
                total += response
                xx += (x - dx) ** 2 * response
                xy += (x - dx) * (y - dy) * response
                yy += (y - dy) ** 2 * response
    if total > KT_TOLERANCE:
        minimum = 0.1 * search_step * search_step
        multiplier = 1.0 / best
        covariance[0, 0] = max(xx / total, minimum) * multiplier
        covariance[0, 1] = xy / total * multiplier
        covariance[1, 0] = xy / total * multiplier
        covariance[1, 1] = max(yy / total, minimum) * multiplier
        covariance[2, 2] = 4.0 * angle_step * angle_step
    if abs(covariance[0, 0]) < KT_TOLERANCE:
        covariance[0, 0] = MAX_VARIANCE
    if abs(covariance[1, 1]) < KT_TOLERANCE:
        covariance[1, 1] = MAX_VARIANCE
