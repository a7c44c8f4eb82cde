"""Numba kernels of the particle maps: cell lookup, scan-matcher score and likelihood, hill climbing,
endpoint registration with copy-on-write tiles.

Map layout (see :mod:`slamtrials.slam.gmapping.tilemap`): a pool of tiles of ``TILE x TILE`` cells;
``count[k, i, j]`` endpoints in cell (row ``i`` from the bottom, column ``j``) of tile ``k``, and
``mean[k, i, j]`` their mean's offset (m, float32 x and y) from the cell's lower-left corner, so the
mean is ``(column * res + mean[..., 0], row * res + mean[..., 1])`` in the map frame; a cell without
endpoints holds :data:`EMPTY` as its offset, so the window search needs no branch per cell. A particle's
``directory[tile row, tile column]`` holds its tile ids (-1: no tile); directory cell (0, 0) is global
tile (``tile_row0``, ``tile_col0``). Global cell ``(c, r)`` covers ``[c res, (c + 1) res) x
[r res, (r + 1) res)``.

The score and likelihood follow spec/gmapping.md, section 3.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from slamtrials.slam.gmapping.window import NOTHING_D2, window_min_3x3

__all__ = [
    "TILE_SHIFT",
    "TILE",
    "score_pose",
    "score_3x3",
    "STOPPED",
    "likelihood_3x3",
    "score_scratch",
    "match_particles",
    "register_endpoints",
]

# 32-cell tiles: a 3 x 3 window crosses a tile border for 12 % of beams (23 % with 16-cell tiles),
# which takes the slower scalar path; the price is about twice the particle-map memory (bench/RESULTS.md)
TILE_SHIFT = 5
#: Cells per tile side.
TILE = 1 << TILE_SHIFT
_MASK = TILE - 1
#: Mean offset stored in cells that hold no endpoint: far enough that no distance to it can win.
EMPTY = np.float32(1.0e18)
#: Tile 0 of every pool is kept empty (never handed out, never written): cells without a tile read it.
EMPTY_TILE = 0
_FOUND_D2 = 1.0e30


@njit(cache=True, nogil=True, inline="always")
def _tile_or_empty(directory, rows, cols, drow, dcol):  # pragma: no cover - compiled
    """Tile id at directory-relative cell (dcol, drow); :data:`EMPTY_TILE` outside the directory or where
    the particle has no tile."""
    tr = drow >> TILE_SHIFT
    tc = dcol >> TILE_SHIFT
    if drow < 0 or dcol < 0 or tr >= rows or tc >= cols:
        return EMPTY_TILE
    tile = directory[np.uint64(tr), np.uint64(tc)]
    return tile if tile >= 0 else EMPTY_TILE


@njit(cache=True, nogil=True, inline="always")
def _window_min_across_tiles(directory, mean, rows, cols, drow, dcol, ox, oy, res):  # pragma: no cover - compiled
    """The default 3 x 3 window's smallest squared distance (or :data:`NOTHING_D2`) around directory-relative
    cell (``dcol``, ``drow``), endpoint offset (``ox``, ``oy``) in it, for windows that cross a tile
    border: one directory lookup per cell."""
    d2 = NOTHING_D2
    for dr in range(3):
        uy0 = oy - (dr - 1) * res
        row = drow + dr - 1
        for dc in range(3):
            col = dcol + dc - 1
            tile = _tile_or_empty(directory, rows, cols, row, col)
            k = np.uint64(tile * (2 * TILE * TILE) + (row & _MASK) * (2 * TILE) + (col & _MASK) * 2)
            ux = ox - (dc - 1) * res - mean[k]
            uy = uy0 - mean[k + np.uint64(1)]
            d2 = min(d2, ux * ux + uy * uy)
    return d2


#: Taylor coefficients 1/k! of exp, k = 0 .. 13.
_EXP_TAYLOR = tuple(1.0 / math.factorial(k) for k in range(14))
#: Largest argument a for which _exp_minus(a) uses the series (error below 1e-15 relative there).
_EXP_SERIES_MAX = 0.5


@njit(cache=True, nogil=True, inline="always")
def _exp_series_minus(a):  # pragma: no cover - compiled
    """The degree-13 Taylor series of exp(-a) by Estrin's scheme: exact to 1e-15 relative for 0 <= a <= 0.5
    (:data:`_EXP_SERIES_MAX`). Branch free, so that a loop of it vectorizes."""
    x = -a
    x2 = x * x
    x4 = x2 * x2
    c = _EXP_TAYLOR
    q0 = (c[0] + x * c[1]) + x2 * (c[2] + x * c[3])
    q1 = (c[4] + x * c[5]) + x2 * (c[6] + x * c[7])
    q2 = (c[8] + x * c[9]) + x2 * (c[10] + x * c[11])
    q3 = c[12] + x * c[13]
    return (q0 + x4 * q1) + (x4 * x4) * (q2 + x4 * q3)


@njit(cache=True, nogil=True, inline="always")
def _exp_minus(a):  # pragma: no cover - compiled
    """exp(-a) for a >= 0: the Taylor series for a <= 0.5 (where the score's arguments almost all are),
    else libm; about twice as fast as libm's exp, within a few ulp of it."""
    if a > _EXP_SERIES_MAX:
        return math.exp(-a)
    return _exp_series_minus(a)


@njit(cache=True, nogil=True)
def score_pose(
    directory,
    mean,
    tile_col0,
    tile_row0,
    res,
    x,
    y,
    theta,
    lx,
    ly,
    lfx,
    lfy,
    kernel,
    sigma,
    lsigma,
    free_test,
    with_likelihood,
):  # pragma: no cover - compiled
    """Score (and log-likelihood) of a scan from laser pose (x, y, theta) in one particle's map.

    Parameters
    ----------
    directory:
        int32 ``[TR, TC]`` the particle's tile directory.
    mean:
        float32 ``[K * TILE * TILE * 2]``: the pool's mean offsets, flattened (module docstring).
    lx, ly:
        float64 ``[K]``: the used beams' endpoints in the laser frame (m).
    lfx, lfy:
        The free points one diagonal cell back along each beam (read only with ``free_test``).

    Returns ``(score, log_likelihood)``; the likelihood is 0 unless ``with_likelihood``. Indexes are
    unsigned so that numba does no negative-index wrap-around per access. The hill climbing scores the
    default window with :func:`score_3x3` (same results, faster); this function gives the likelihood,
    the other windows and the free-cell test. Each beam's term ``exp(-d^2 / sigma)`` is computed as
    ``_exp_minus(d^2 * (1 / sigma))``: a quarter faster than libm's exp of a quotient, and within a few
    ulp of it.
    """
    inv_res = 1.0 / res
    inv_sigma = 1.0 / sigma
    c = math.cos(theta)
    s = math.sin(theta)
    score = 0.0
    likelihood = 0.0
    no_hit = -0.5 / lsigma
    rows, cols = directory.shape
    base_c = tile_col0 << TILE_SHIFT
    base_r = tile_row0 << TILE_SHIFT
    row_stride = 2 * TILE
    tile_stride = 2 * TILE * TILE
    for b in range(lx.shape[0]):
        ex = x + c * lx[b] - s * ly[b]
        ey = y + s * lx[b] + c * ly[b]
        gc = int(math.floor(ex * inv_res))
        gr = int(math.floor(ey * inv_res))
        ox = ex - gc * res
        oy = ey - gr * res
        dcol = gc - base_c
        drow = gr - base_r
        lc = dcol & _MASK
        lr = drow & _MASK
        best = NOTHING_D2
        if not free_test and kernel == 1:
            # the default window, with constant bounds so that the compiler unrolls it (2x faster);
            # cells without a tile read the empty tile, so there is no branch per cell
            if 1 <= lc < TILE - 1 and 1 <= lr < TILE - 1:  # the window lies in one tile
                tile = _tile_or_empty(directory, rows, cols, drow, dcol)
                first = tile * tile_stride + (lr - 1) * row_stride + (lc - 1) * 2
                for dr in range(3):
                    uy0 = oy - (dr - 1) * res
                    k = np.uint64(first + dr * row_stride)
                    for dc in range(3):
                        ux = ox - (dc - 1) * res - mean[k + np.uint64(2 * dc)]
                        uy = uy0 - mean[k + np.uint64(2 * dc + 1)]
                        best = min(best, ux * ux + uy * uy)
            else:
                best = _window_min_across_tiles(directory, mean, rows, cols, drow, dcol, ox, oy, res)
        elif not free_test and kernel <= lc < TILE - kernel and kernel <= lr < TILE - kernel:
            # the whole window lies in one tile: one directory lookup, no branch per cell
            tile = _tile_or_empty(directory, rows, cols, drow, dcol)
            first = tile * tile_stride + (lr - kernel) * row_stride + (lc - kernel) * 2
            for dr in range(-kernel, kernel + 1):
                uy0 = oy - dr * res
                k = np.uint64(first + (dr + kernel) * row_stride)
                for dc in range(-kernel, kernel + 1):
                    ux = ox - dc * res - mean[k]
                    uy = uy0 - mean[k + np.uint64(1)]
                    best = min(best, ux * ux + uy * uy)
                    k += np.uint64(2)
        else:
            fdcol = 0
            fdrow = 0
            if free_test:
                fdcol = int(math.floor((x + c * lfx[b] - s * lfy[b]) * inv_res)) - base_c
                fdrow = int(math.floor((y + s * lfx[b] + c * lfy[b]) * inv_res)) - base_r
            for dr in range(-kernel, kernel + 1):
                uy0 = oy - dr * res
                for dc in range(-kernel, kernel + 1):
                    tile = _tile_or_empty(directory, rows, cols, drow + dr, dcol + dc)
                    k = np.uint64(tile * tile_stride + ((drow + dr) & _MASK) * row_stride + ((dcol + dc) & _MASK) * 2)
                    mx = mean[k]
                    if mx >= EMPTY:
                        continue
                    if free_test:
                        free_tile = _tile_or_empty(directory, rows, cols, fdrow + dr, fdcol + dc)
                        f = np.uint64(
                            free_tile * tile_stride + ((fdrow + dr) & _MASK) * row_stride + ((fdcol + dc) & _MASK) * 2
                        )
                        if mean[f] < EMPTY:
                            continue
                    ux = ox - dc * res - mx
                    uy = uy0 - mean[k + np.uint64(1)]
                    best = min(best, ux * ux + uy * uy)
        if best < _FOUND_D2:
            score += _exp_minus(best * inv_sigma)
            if with_likelihood:
                likelihood -= best / lsigma
        elif with_likelihood:
            likelihood += no_hit
    return score, likelihood


@njit(cache=True, nogil=True)
def score_scratch(beams):
    """Work arrays of :func:`score_3x3` for scans of ``beams`` used beams: float64 ``[5, beams]`` (rows 0
    and 1 for the stages, rows 2 to 4 for window minima) and int64 ``[4, beams]``."""
    return np.empty((5, beams)), np.empty((4, beams), dtype=np.int64)


@njit(cache=True, nogil=True, inline="always")
def _window_minima_3x3(
    directory, mean, tile_col0, tile_row0, res, x, y, c, s, lx, ly, offset_x, offset_y, best, ints, lo, hi
):  # pragma: no cover - compiled
    """Stages 1 and 2 of :func:`score_3x3` for beams ``lo`` to ``hi - 1`` from laser pose (x, y) with
    heading cosine ``c`` and sine ``s``: each beam's smallest squared distance to a mean in its 3 x 3
    window goes to ``best`` (:data:`NOTHING_D2` if none), its endpoint's offset in its cell to
    ``offset_x`` and ``offset_y``; ``ints``: four int64 ``[B]`` work rows (a tuple: first window index,
    the beams whose window crosses a tile border, their columns and rows). The loops count with unsigned
    integers: from a signed start numba keeps its negative-index wrap-around in every access, which
    kept the compiler from vectorizing them (the score took a third longer)."""
    inv_res = 1.0 / res
    rows, cols = directory.shape
    base_c = tile_col0 << TILE_SHIFT
    base_r = tile_row0 << TILE_SHIFT
    row_stride = 2 * TILE
    tile_stride = 2 * TILE * TILE
    first, crossing, crossing_col, crossing_row = ints  # crossing: beams whose window crosses a tile border
    crossings = 0
    for b in range(np.uint64(lo), np.uint64(hi)):
        ex = x + c * lx[b] - s * ly[b]
        ey = y + s * lx[b] + c * ly[b]
        gc = int(math.floor(ex * inv_res))
        gr = int(math.floor(ey * inv_res))
        offset_x[b] = ex - gc * res
        offset_y[b] = ey - gr * res
        dcol = gc - base_c
        drow = gr - base_r
        lc = dcol & _MASK
        lr = drow & _MASK
        if 1 <= lc < TILE - 1 and 1 <= lr < TILE - 1:
            tile = _tile_or_empty(directory, rows, cols, drow, dcol)
            first[b] = tile * tile_stride + (lr - 1) * row_stride + (lc - 1) * 2
        else:
            first[b] = EMPTY_TILE * tile_stride
            crossing[crossings] = b
            crossing_col[crossings] = dcol
            crossing_row[crossings] = drow
            crossings += 1
    for b in range(np.uint64(lo), np.uint64(hi)):
        best[b] = window_min_3x3(mean, first[b], row_stride, offset_x[b], offset_y[b], res)
    for i in range(crossings):
        b = crossing[i]
        best[b] = _window_min_across_tiles(
            directory, mean, rows, cols, crossing_row[i], crossing_col[i], offset_x[b], offset_y[b], res
        )


#: Beams per block of :func:`score_3x3`: after each block it checks whether the score can still beat
#: its ``floor``.
_BLOCK = 64
#: More than the rounding error of any score sum and of the terms' own (at most a few thousand terms,
#: each at most 1 to within an ulp, every rounding below 1e-12), so that a bound with it added is an
#: upper bound of the computed score.
_BOUND_SLACK = 1.0e-6
#: What :func:`score_3x3` returns when it stopped early: below every score.
STOPPED = -1.0


@njit(cache=True, nogil=True, fastmath={"nnan", "ninf", "nsz"})
def score_3x3(
    directory,
    mean,
    tile_col0,
    tile_row0,
    res,
    x,
    y,
    theta,
    lx,
    ly,
    sigma,
    floats,
    ints,
    row=2,
    floor=-1.0,
    canonical=None,
):  # pragma: no cover - compiled
    """The score of :func:`score_pose` for its default window (``kernel`` 1, no free-cell test), bit for
    bit, in stages that keep each loop short: the hill climbing's hot spot. Blocks of :data:`_BLOCK`
    beams in beam order go through

    1. per beam: endpoint, offset in its cell and, when the 3 x 3 window lies in one tile, the window's
       first index in ``mean`` (else the beam goes on a list);
    2. per beam: the window minimum in vector code (:func:`~slamtrials.slam.gmapping.window.window_min_3x3`;
       listed beams read the empty tile here); then the listed beams again, one directory lookup per
       cell;
    3. the exp series of every beam (a loop the compiler vectorizes), then the sum in beam order, with
       libm's exp where the series does not apply.

    Early stop: every beam adds at most 1 (``exp`` of a number <= 0), so after a block the score can
    reach at most the sum so far plus the number of beams left. When that bound (plus
    :data:`_BOUND_SLACK` for rounding) is at most ``floor``, the score cannot exceed ``floor`` and the
    function returns :data:`STOPPED` at once (the hill climbing passes its current score: a candidate
    is taken only when it scores strictly more). The sum is the same sequence of additions either way,
    so a score that is returned is the same number bit for bit.

    Beams in another order: with ``canonical`` (int64 ``[B]``), ``lx`` and ``ly`` hold the scan's beams
    in another order, beam ``b`` of the scan at position ``canonical[b]``. The blocks and the early stop
    then go in the given order (:func:`match_particles` puts first the beams that are likely to add
    nothing, so that the bound falls fast), and the score returned is the sum in the scan's own order,
    the same number bit for bit as with the beams in that order.

    ``floats`` and ``ints`` come from :func:`score_scratch` (at least ``len(lx)`` columns); the window
    minima are left in ``floats[row]`` (in the given order; ``row`` 2, 3 or 4) for :func:`_likelihood_of`. The arithmetic per
    beam is the same as in :func:`score_pose`, and the fast-math flags allowed here (no NaN, no
    infinity, no signed zero; all values are finite) do not change any result.
    """
    inv_sigma = 1.0 / sigma
    n = lx.shape[0]
    best = floats[row]
    offset_x = floats[0]
    terms = offset_x  # a block's offsets are no longer needed once its minima are known
    offset_y = floats[1]
    work = (ints[0], ints[1], ints[2], ints[3])
    c = math.cos(theta)
    s = math.sin(theta)
    score = 0.0
    for lo in range(0, n, _BLOCK):
        hi = min(lo + _BLOCK, n)
        _window_minima_3x3(
            directory, mean, tile_col0, tile_row0, res, x, y, c, s, lx, ly, offset_x, offset_y, best, work, lo, hi
        )
        for b in range(np.uint64(lo), np.uint64(hi)):
            terms[b] = _exp_series_minus(best[b] * inv_sigma)
        for b in range(np.uint64(lo), np.uint64(hi)):
            d2 = best[b]
            term = 0.0
            if d2 < _FOUND_D2:
                a = d2 * inv_sigma
                term = terms[b] if a <= _EXP_SERIES_MAX else math.exp(-a)
            terms[b] = term
            score += term
        if hi < n and score + (n - hi) + _BOUND_SLACK <= floor:
            return STOPPED
    if canonical is None:
        return score
    in_order = 0.0  # the beams were given in another order: the sum in the scan's own order
    for b in range(n):
        in_order += terms[canonical[b]]
    return in_order


@njit(cache=True, nogil=True, fastmath={"nnan", "ninf", "nsz"})
def likelihood_3x3(
    directory, mean, tile_col0, tile_row0, res, x, y, theta, lx, ly, lsigma, floats, ints
):  # pragma: no cover - compiled
    """The log-likelihood of :func:`score_pose` for its default window (``kernel`` 1, no free-cell
    test), bit for bit: the window minima of :func:`score_3x3`, then the sum in beam order."""
    c = math.cos(theta)
    s = math.sin(theta)
    work = (ints[0], ints[1], ints[2], ints[3])
    _window_minima_3x3(
        directory,
        mean,
        tile_col0,
        tile_row0,
        res,
        x,
        y,
        c,
        s,
        lx,
        ly,
        floats[0],
        floats[1],
        floats[2],
        work,
        0,
        lx.shape[0],
    )
    return _likelihood_of(floats[2], lsigma, np.arange(lx.shape[0]))


@njit(cache=True, nogil=True, inline="always")
def _likelihood_of(best, lsigma, canonical):  # pragma: no cover - compiled
    """The log-likelihood from the beams' window minima ``best`` ``[B]``, summed in the scan's beam order
    (beam ``b`` at ``best[canonical[b]]``, as :func:`score_3x3` takes it)."""
    no_hit = -0.5 / lsigma
    likelihood = 0.0
    for b in range(best.shape[0]):
        d2 = best[canonical[b]]
        if d2 < _FOUND_D2:
            likelihood -= d2 / lsigma
        else:
            likelihood += no_hit
    return likelihood


@njit(cache=True, nogil=True, inline="always")
def _match_score(
    directory,
    mean,
    tile_col0,
    tile_row0,
    res,
    x,
    y,
    theta,
    lx,
    ly,
    lfx,
    lfy,
    kernel,
    sigma,
    lsigma,
    free_test,
    floats,
    ints,
    row,
    floor,
    canonical,
):  # pragma: no cover - compiled
    """The scan-matching score at one pose: :func:`score_3x3` for the default window (window minima left
    in ``floats[row]``; :data:`STOPPED` when the score cannot exceed ``floor``; the beams in the order
    ``canonical`` says), else :func:`score_pose` (the beams in the scan's order)."""
    if kernel == 1 and not free_test:
        return score_3x3(
            directory, mean, tile_col0, tile_row0, res, x, y, theta, lx, ly, sigma, floats, ints, row, floor, canonical
        )
    score, _ = score_pose(
        directory,
        mean,
        tile_col0,
        tile_row0,
        res,
        x,
        y,
        theta,
        lx,
        ly,
        lfx,
        lfy,
        kernel,
        sigma,
        lsigma,
        free_test,
        False,
    )
    return score


_OPPOSITE = (1, 0, 3, 2, 5, 4)
#: Poses a hill climb remembers (:func:`_hill_climb`); a climb scores about 70 (bench_gmapping's tour).
_SEEN_CAPACITY = 256


@njit(cache=True, nogil=True, inline="always")
def _seen_before(seen, count, x, y, theta):  # pragma: no cover - compiled
    """Whether pose (x, y, theta) is one of the first ``count`` rows of ``seen`` ``[S, 3]``."""
    for q in range(count):
        if seen[q, 0] == x and seen[q, 1] == y and seen[q, 2] == theta:
            return True
    return False


@njit(cache=True, nogil=True)
def _hill_climb(
    directory,
    mean,
    tile_col0,
    tile_row0,
    res,
    pose,
    lx,
    ly,
    lfx,
    lfy,
    kernel,
    sigma,
    lsigma,
    free_test,
    lstep,
    astep,
    iterations,
    floats,
    ints,
    seen,
    canonical,
):  # pragma: no cover - compiled
    """GMapping's hill climbing from ``pose`` (spec/gmapping.md, section 3); returns (x, y, theta, score,
    row): with the default window, ``floats[row]`` holds the window minima at the returned pose (for its
    likelihood, in the order of ``canonical``: see :func:`score_3x3`). ``floats``, ``ints``: work arrays
    from :func:`score_scratch`; ``seen``: float64 ``[S, 3]`` work array.

    Three savings over the original, none of which changes the result:

    - right after a move, the move straight back (same step) is not tried; it returns to the pose just
      left, whose score is lower than the current one, so it could not win;
    - a candidate pose equal to one scored earlier in this climb (the first ``S``; after moves along
      two axes, one step back along the first lands where the previous iteration already looked, about
      6 % of all candidates) is not scored again. Its score cannot exceed the current one: the current
      score never decreases and a pose is taken only when it scores strictly more, so an earlier pose
      scored at most what was current then;
    - a candidate is scored with the current score as floor (:func:`score_3x3`): it is given up as soon
      as its beams so far show it cannot score more, which it would need to be taken.
    """
    cx, cy, ct = pose[0], pose[1], pose[2]
    seen[0, 0], seen[0, 1], seen[0, 2] = cx, cy, ct
    n_seen = 1
    # rows of floats: the current pose's window minima, the best candidate's so far, the next candidate's
    at, kept, scratch = 2, 3, 4
    current = _match_score(
        directory,
        mean,
        tile_col0,
        tile_row0,
        res,
        cx,
        cy,
        ct,
        lx,
        ly,
        lfx,
        lfy,
        kernel,
        sigma,
        lsigma,
        free_test,
        floats,
        ints,
        at,
        STOPPED,
        canonical,
    )
    ld = lstep
    ad = astep
    refinement = 0
    best = -1.0
    came_by = -1  # the move that led to the current pose at the current step size, or -1
    for _ in range(100_000):  # a safety bound; the loop ends long before
        if best >= current:
            refinement += 1
            ld *= 0.5
            ad *= 0.5
            came_by = -1
        best = current
        bx, by, bt = cx, cy, ct
        accepted = -1
        for move in range(6):
            if came_by >= 0 and move == _OPPOSITE[came_by]:
                continue
            px, py, pt = cx, cy, ct
            if move == 0:
                px += ld
            elif move == 1:
                px -= ld
            elif move == 2:
                py -= ld
            elif move == 3:
                py += ld
            elif move == 4:
                pt += ad
            else:
                pt -= ad
            if _seen_before(seen, n_seen, px, py, pt):
                continue
            if n_seen < seen.shape[0]:
                seen[n_seen, 0], seen[n_seen, 1], seen[n_seen, 2] = px, py, pt
                n_seen += 1
            local = _match_score(
                directory,
                mean,
                tile_col0,
                tile_row0,
                res,
                px,
                py,
                pt,
                lx,
                ly,
                lfx,
                lfy,
                kernel,
                sigma,
                lsigma,
                free_test,
                floats,
                ints,
                scratch,
                current,
                canonical,
            )
            if local > current:
                current = local
                bx, by, bt = px, py, pt
                accepted = move
                kept, scratch = scratch, kept
        cx, cy, ct = bx, by, bt
        came_by = accepted
        if accepted >= 0:
            at, kept = kept, at
        if not (current > best or refinement < iterations):
            break
    return cx, cy, ct, best, at


@njit(cache=True, nogil=True)
def match_particles(
    directories,
    mean,
    tile_col0,
    tile_row0,
    res,
    poses,
    lx,
    ly,
    lfx,
    lfy,
    kernel,
    sigma,
    lsigma,
    free_test,
    lstep,
    astep,
    iterations,
    minimum_score,
):  # pragma: no cover - compiled
    """Scan-match every particle and weigh it (spec/gmapping.md, section 3).

    Parameters
    ----------
    directories:
        int32 ``[N, TR, TC]`` tile directories.
    mean:
        float32 ``[K * TILE * TILE * 2]`` the pool's mean offsets, flattened.
    poses:
        float64 ``[N, 3]`` laser poses after the motion model (map frame).

    Returns
    -------
    matched:
        float64 ``[N, 3]``: the matched pose where the score exceeds ``minimum_score``, else the input.
    scores:
        float64 ``[N]`` best match scores.
    likelihoods:
        float64 ``[N]`` log-likelihoods of the scan at the returned poses.
    """
    n = poses.shape[0]
    matched = poses.copy()
    scores = np.zeros(n)
    likelihoods = np.zeros(n)
    floats, ints = score_scratch(lx.shape[0])
    seen = np.empty((_SEEN_CAPACITY, 3))
    canonical = np.arange(lx.shape[0])
    given_x, given_y = lx, ly
    for p in range(n):
        directory = directories[p]
        x, y, t, best, row = _hill_climb(
            directory,
            mean,
            tile_col0,
            tile_row0,
            res,
            poses[p],
            given_x,
            given_y,
            lfx,
            lfy,
            kernel,
            sigma,
            lsigma,
            free_test,
            lstep,
            astep,
            iterations,
            floats,
            ints,
            seen,
            canonical,
        )
        scores[p] = best
        if best > minimum_score:
            matched[p, 0] = x
            matched[p, 1] = y
            matched[p, 2] = math.atan2(math.sin(t), math.cos(t))
        if p == 0 and kernel == 1 and not free_test:
            # the beams that fit worst where the first particle's climb ended (things not in the map, walls
            # not yet mapped) likely add little for every particle: the others score them first, so that
            # a candidate's bound falls fast (score_3x3); the scores stay the same numbers
            order = np.argsort(-floats[row], kind="mergesort")
            canonical = np.empty_like(order)
            canonical[order] = np.arange(order.shape[0])
            given_x, given_y = lx[order], ly[order]
            if best > minimum_score and matched[p, 2] == t:
                likelihoods[p] = _likelihood_of(floats[row], lsigma, np.arange(lx.shape[0]))
                continue
        if kernel == 1 and not free_test and best > minimum_score and matched[p, 2] == t:
            likelihoods[p] = _likelihood_of(floats[row], lsigma, canonical)  # the climb scored this very pose last
        elif kernel == 1 and not free_test:
            likelihoods[p] = likelihood_3x3(
                directory,
                mean,
                tile_col0,
                tile_row0,
                res,
                matched[p, 0],
                matched[p, 1],
                matched[p, 2],
                lx,
                ly,
                lsigma,
                floats,
                ints,
            )
        else:
            _, likelihoods[p] = score_pose(
                directory,
                mean,
                tile_col0,
                tile_row0,
                res,
                matched[p, 0],
                matched[p, 1],
                matched[p, 2],
                lx,
                ly,
                lfx,
                lfy,
                kernel,
                sigma,
                lsigma,
                free_test,
                True,
            )
    return matched, scores, likelihoods


@njit(cache=True, nogil=True)
def _copy_tile(count, mean, source, target):  # pragma: no cover - compiled
    """``count[target] = count[source]`` and ``mean[target] = mean[source]``, as loops: numba's
    array-to-array assignment carries the code of its shape-mismatch message, whose string functions
    took about 2 s of a first run's compile."""
    for i in range(count.shape[1]):
        for j in range(count.shape[2]):
            count[target, i, j] = count[source, i, j]
            for axis in range(mean.shape[3]):
                mean[target, i, j, axis] = mean[source, i, j, axis]


@njit(cache=True, nogil=True)
def register_endpoints(
    directories, count, mean, refs, free_stack, state, tile_col0, tile_row0, res, ex, ey, start
):  # pragma: no cover - compiled
    """Add each particle's scan endpoints to its map, copying shared tiles before writing (copy-on-write).

    Parameters
    ----------
    directories:
        int32 ``[N, TR, TC]``; must already cover every endpoint.
    count, mean:
        The pool (module docstring); updated.
    refs:
        int32 ``[K]`` number of directory entries pointing at each tile.
    free_stack, state:
        int32 ``[K]`` ids of released tiles and int64 ``[2]`` = (number of them on the stack, tiles ever
        allocated); both updated.
    ex, ey:
        float64 ``[N, B]`` endpoints (map frame, m) of particle ``p`` in row ``p``.
    start:
        First particle to do.

    Returns
    -------
    The index of the first particle NOT done: ``N`` when all are done, less when the pool ran short of
    tiles (grow it and call again from there).
    """
    n, beams = ex.shape
    capacity = count.shape[0]
    inv_res = 1.0 / res
    for p in range(start, n):
        if state[0] + (capacity - state[1]) < beams:
            return p
        directory = directories[p]
        for b in range(beams):
            gc = int(math.floor(ex[p, b] * inv_res))
            gr = int(math.floor(ey[p, b] * inv_res))
            lc = gc - (tile_col0 << TILE_SHIFT)
            lr = gr - (tile_row0 << TILE_SHIFT)
            tr = lr >> TILE_SHIFT
            tc = lc >> TILE_SHIFT
            tile = directory[tr, tc]
            if tile < 0 or refs[tile] > 1:
                if state[0] > 0:
                    state[0] -= 1
                    fresh = free_stack[state[0]]
                else:
                    fresh = state[1]
                    state[1] += 1
                if tile < 0:
                    count[fresh] = 0
                    mean[fresh] = EMPTY
                else:
                    _copy_tile(count, mean, tile, fresh)
                    refs[tile] -= 1
                refs[fresh] = 1
                directory[tr, tc] = fresh
                tile = fresh
            i = gr & _MASK
            j = gc & _MASK
            k = count[tile, i, j] + 1
            count[tile, i, j] = k
            ox = ex[p, b] - gc * res
            oy = ey[p, b] - gr * res
            if k == 1:
                mean[tile, i, j, 0] = ox
                mean[tile, i, j, 1] = oy
            else:  # running mean
                mean[tile, i, j, 0] += (ox - mean[tile, i, j, 0]) / k
                mean[tile, i, j, 1] += (oy - mean[tile, i, j, 1]) / k
    return n
