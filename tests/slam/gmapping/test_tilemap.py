"""Copy-on-write particle maps (:class:`TileMaps`) against a naive dense reference.

The reference keeps, per particle, a dict ``cell -> list of endpoints`` and replays every registration
along the particle's ancestry (resampling copies the parent's dict). After any sequence of
registrations and resamplings (random, from hypothesis):

* every particle's map holds exactly the reference's cells, with the same counts and means (float32);
* ``refs[k]`` equals the number of directory entries pointing at tile ``k``, and no directory points at
  a tile beyond those allocated;
* this holds whatever the starting pool size (``initial_tiles=1`` forces the pool to grow mid-scan)
  and when endpoints far away force the directories to grow.

Directed tests check that a write by one of two particles sharing a tile copies the tile and leaves
the other's view (and the shared tile's content) unchanged, and that ``cell_mean`` reads a cell back.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from slamtrials.slam.gmapping.kernels import EMPTY, EMPTY_TILE, TILE
from slamtrials.slam.gmapping.tilemap import TileMaps

RES = 0.05
INV = 1.0 / RES  # the kernels locate a point's cell as floor(x * (1 / res))


def cell_key(x: float, y: float) -> tuple[int, int]:
    return math.floor(x * INV), math.floor(y * INV)


def dense(maps: TileMaps, p: int) -> dict[tuple[int, int], tuple[int, float, float]]:
    """Every non-empty cell of particle ``p``'s map read straight from the pool: (col, row) -> (n, x, y)."""
    out = {}
    for tr, tc in zip(*np.nonzero(maps.directories[p] >= 0)):
        tile = int(maps.directories[p, tr, tc])
        for i, j in zip(*np.nonzero(maps.count[tile])):
            gc = (maps.tile_col0 + int(tc)) * TILE + int(j)
            gr = (maps.tile_row0 + int(tr)) * TILE + int(i)
            out[(gc, gr)] = (
                int(maps.count[tile, i, j]),
                gc * RES + float(maps.mean[tile, i, j, 0]),
                gr * RES + float(maps.mean[tile, i, j, 1]),
            )
    return out


def reference_cells(points: list[tuple[float, float]]) -> dict[tuple[int, int], tuple[int, float, float]]:
    cells: dict = {}
    for x, y in points:
        cells.setdefault(cell_key(x, y), []).append((x, y))
    return {k: (len(v), sum(p[0] for p in v) / len(v), sum(p[1] for p in v) / len(v)) for k, v in cells.items()}


def check_against_reference(maps: TileMaps, reference: list[list[tuple[float, float]]]) -> None:
    for p, points in enumerate(reference):
        got, want = dense(maps, p), reference_cells(points)
        assert got.keys() == want.keys(), f"particle {p}: cells differ"
        for key, (n, x, y) in want.items():
            gn, gx, gy = got[key]
            assert gn == n
            assert abs(gx - x) <= 2e-6 and abs(gy - y) <= 2e-6, f"particle {p}, cell {key}: mean differs"
    held = maps.directories[maps.directories >= 0]
    allocated = int(maps.state[1])
    assert held.size == 0 or held.max() < allocated
    np.testing.assert_array_equal(maps.refs[:allocated], np.bincount(held, minlength=allocated)[:allocated])
    assert not np.any(maps.refs[allocated:])


def _register(maps: TileMaps, reference: list, points: np.ndarray) -> None:
    """Register ``points`` [N, B, 2] into the maps and the reference."""
    maps.register(points[:, :, 0], points[:, :, 1])
    for p in range(points.shape[0]):
        reference[p].extend((float(x), float(y)) for x, y in points[p])


coordinate = st.floats(min_value=-3.0, max_value=3.0, allow_nan=False, allow_infinity=False)


@st.composite
def scenarios(draw):
    n = draw(st.integers(min_value=1, max_value=5))
    beams = draw(st.integers(min_value=1, max_value=12))
    initial_tiles = draw(st.sampled_from([1, 2, 1024]))
    ops = []
    for _ in range(draw(st.integers(min_value=1, max_value=8))):
        if draw(st.booleans()):
            far = draw(st.sampled_from([0.0, 0.0, 0.0, 25.0, -40.0]))  # sometimes far away: the directories grow
            pts = draw(st.lists(coordinate, min_size=2 * n * beams, max_size=2 * n * beams))
            ops.append(("register", np.array(pts, dtype=np.float64).reshape(n, beams, 2) + far))
        else:
            ops.append(("resample", np.array(draw(st.lists(st.integers(0, n - 1), min_size=n, max_size=n)))))
    return n, initial_tiles, ops


@settings(max_examples=150, deadline=None)
@given(scenarios())
def test_random_registrations_and_resamplings_match_the_dense_reference(scenario):
    n, initial_tiles, ops = scenario
    maps = TileMaps(n, RES, initial_tiles=initial_tiles)
    reference: list[list[tuple[float, float]]] = [[] for _ in range(n)]
    for kind, arg in ops:
        if kind == "register":
            _register(maps, reference, arg)
        else:
            maps.resample(arg)
            reference = [list(reference[int(i)]) for i in arg]
        check_against_reference(maps, reference)


def test_dense_clustered_scans_with_a_one_tile_pool():
    """Many endpoints, several per cell, across resamplings, starting from a one-tile pool: the pool
    grows (keeping every tile's content) and the maps still equal the reference."""
    rng = np.random.default_rng(0)
    n = 6
    maps = TileMaps(n, RES, initial_tiles=1)
    reference: list[list[tuple[float, float]]] = [[] for _ in range(n)]
    for _ in range(6):
        base = rng.uniform(-4, 4, size=(1, 150, 2))
        points = base + rng.normal(0, 0.02, size=(n, 150, 2))  # nearby but different per particle
        _register(maps, reference, points)
        check_against_reference(maps, reference)
        indexes = np.sort(rng.integers(0, n, size=n))
        maps.resample(indexes)
        reference = [list(reference[int(i)]) for i in indexes]
        check_against_reference(maps, reference)
    assert maps.count.shape[0] > 1  # the pool grew
    assert maps.tiles_in_use < n * len(dense(maps, 0))  # sharing: far fewer tiles than cells x particles


def test_a_write_to_a_shared_tile_copies_it_and_leaves_the_other_sharer_alone():
    maps = TileMaps(2, RES, initial_tiles=4)
    near = np.array([[[0.12, 0.31], [0.33, 0.08]], [[0.12, 0.31], [0.33, 0.08]]])
    maps.register(near[:, :, 0], near[:, :, 1])
    maps.resample(np.array([1, 1]))  # both particles now hold particle 1's tile
    shared = int(maps.directories[0, -maps.tile_row0, -maps.tile_col0])
    assert shared >= 0 and maps.directories[1, -maps.tile_row0, -maps.tile_col0] == shared
    assert maps.refs[shared] == 2
    before_count, before_mean = maps.count[shared].copy(), maps.mean[shared].copy()
    # particle 0 writes into the shared tile; particle 1 writes far away (another tile)
    writes = np.array([[[0.14, 0.33]], [[5.01, 5.02]]])
    maps.register(writes[:, :, 0], writes[:, :, 1])
    tile0 = int(maps.directories[0, -maps.tile_row0, -maps.tile_col0])
    assert tile0 != shared and int(maps.directories[1, -maps.tile_row0, -maps.tile_col0]) == shared
    assert maps.refs[shared] == 1 and maps.refs[tile0] == 1
    np.testing.assert_array_equal(maps.count[shared], before_count)
    np.testing.assert_array_equal(maps.mean[shared], before_mean)
    assert maps.cell_mean(0, (0.125, 0.325))[0] == 2  # (0.12, 0.31) and (0.14, 0.33) share cell (2, 6)
    assert maps.cell_mean(1, (0.125, 0.325))[0] == 1
    n, mean = maps.cell_mean(0, (0.125, 0.325))
    np.testing.assert_allclose(mean, [0.13, 0.32], atol=1e-6)
    assert maps.cell_mean(0, (5.01, 5.02))[0] == 0 and maps.cell_mean(1, (5.01, 5.02))[0] == 1


def test_resampling_releases_unheld_tiles_for_reuse():
    """A tile nobody holds after resampling goes on the free stack and is reused (cleared) before the
    pool hands out new ones."""
    maps = TileMaps(2, RES, initial_tiles=8)
    pts = np.array([[[0.1, 0.1]], [[2.0, 2.0]]])  # each particle gets its own tile
    maps.register(pts[:, :, 0], pts[:, :, 1])
    reserved = EMPTY_TILE + 1  # tiles the pool keeps for itself
    allocated = int(maps.state[1])
    assert allocated == reserved + 2
    maps.resample(np.array([0, 0]))
    assert maps.tiles_in_use == 1 and int(maps.state[0]) == 1
    far = np.array([[[-3.0, -3.0]], [[-3.0, -3.0]]])
    maps.register(far[:, :, 0], far[:, :, 1])
    assert int(maps.state[1]) == reserved + 3  # one reused from the free stack, one new
    # the reused tile was cleared: only the new endpoint is in it
    assert maps.cell_mean(0, (-3.0, -3.0))[0] == 1 and maps.cell_mean(1, (-3.0, -3.0))[0] == 1
    assert maps.cell_mean(0, (2.0, 2.0))[0] == 0 and maps.cell_mean(1, (2.0, 2.0))[0] == 0
    reference = [[(0.1, 0.1), (-3.0, -3.0)], [(0.1, 0.1), (-3.0, -3.0)]]
    check_against_reference(maps, reference)


def test_cell_mean_reads_back_an_endpoint_registered_on_a_cell_border():
    """An endpoint at x = 0.15 goes into cell column 3 (the kernels: floor(0.15 * 20.0) = 3);
    ``cell_mean`` must look there too, not in column 2 (floor(0.15 / 0.05) = floor(2.9999999999999996))."""
    maps = TileMaps(1, RES)
    maps.register(np.array([[0.15]]), np.array([[0.02]]))
    assert maps.cell_mean(0, (0.15, 0.02))[0] == 1


def test_the_empty_tile_is_never_handed_out_or_written():
    """Score windows read tile ``EMPTY_TILE`` where a particle has no tile: registrations and
    resamplings (which release unheld tiles) must never give it out or write into it."""
    rng = np.random.default_rng(5)
    maps = TileMaps(3, RES, initial_tiles=4)
    for _ in range(6):
        pts = rng.uniform(-4.0, 4.0, size=(3, 40, 2))
        maps.register(pts[:, :, 0], pts[:, :, 1])
        maps.resample(rng.integers(0, 3, size=3))
        assert not (maps.directories == EMPTY_TILE).any()
        assert (maps.count[EMPTY_TILE] == 0).all() and (maps.mean[EMPTY_TILE] == EMPTY).all()
        assert EMPTY_TILE not in maps.free_stack[: int(maps.state[0])]
