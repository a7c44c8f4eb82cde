"""The particles' family tree (:class:`Lineage`): a particle's path follows its parents across resamplings.

Poses are labelled so that a pose tells where it was recorded: at update ``u`` particle ``j`` is at
``(u, j, 0)``. A path read back then spells out the ancestry, which is worked out by hand for a small
case and by a brute-force replay for random ones.
"""

from __future__ import annotations

import numpy as np

from slamtrials.slam.gmapping.lineage import Lineage


def labelled(u: int, n: int) -> np.ndarray:
    return np.column_stack([np.full(n, float(u)), np.arange(n, dtype=float), np.zeros(n)])


def test_paths_follow_parents_across_resamplings_by_hand():
    """Three particles, four updates.

    update 0: rows 0 1 2
    resample [2, 2, 0]   -> current particles descend from rows 2, 2, 0 of update 0
    update 1: rows 0 1 2 (parents 2 2 0)
    resample [1, 0, 0]   -> current descend from rows 1, 0, 0 of update 1
    resample [2, 2, 1]   -> two resamplings before the next update fold into one: rows 0, 0, 0 of update 1
    update 2: rows 0 1 2 (parents 0 0 0)
    update 3: rows 0 1 2 (no resampling: parents 0 1 2)
    """
    lineage = Lineage()
    lineage.add(labelled(0, 3))
    lineage.resampled(np.array([2, 2, 0]))
    lineage.add(labelled(1, 3))
    lineage.resampled(np.array([1, 0, 0]))
    lineage.resampled(np.array([2, 2, 1]))
    lineage.add(labelled(2, 3))
    lineage.add(labelled(3, 3))
    assert len(lineage) == 4
    # particle 0 of update 3 <- row 0 of update 2 <- row 0 of update 1 <- row 2 of update 0
    np.testing.assert_array_equal(lineage.path(0)[:, :2], [[0, 2], [1, 0], [2, 0], [3, 0]])
    np.testing.assert_array_equal(lineage.path(1)[:, :2], [[0, 2], [1, 0], [2, 1], [3, 1]])
    np.testing.assert_array_equal(lineage.path(2)[:, :2], [[0, 2], [1, 0], [2, 2], [3, 2]])
    # a resampling after the last update changes whose path a current particle reads
    lineage.resampled(np.array([2, 2, 2]))
    for p in range(3):
        np.testing.assert_array_equal(lineage.path(p)[:, :2], [[0, 2], [1, 0], [2, 2], [3, 2]])


def test_paths_equal_a_brute_force_replay():
    """Random resamplings between random numbers of updates: every particle's path equals the path
    obtained by carrying whole path copies along (what a naive filter would store)."""
    rng = np.random.default_rng(4)
    n = 7
    lineage = Lineage()
    carried: list[list[tuple[int, int]]] = [[] for _ in range(n)]
    for u in range(25):
        lineage.add(labelled(u, n))
        carried = [path + [(u, j)] for j, path in enumerate(carried)]
        for _ in range(int(rng.integers(0, 3))):
            indexes = np.sort(rng.integers(0, n, size=n))
            lineage.resampled(indexes)
            carried = [list(carried[int(i)]) for i in indexes]
        for p in range(n):
            np.testing.assert_array_equal(lineage.path(p)[:, :2], carried[p])
    # the paths did merge into common ancestors (the test exercised the parent links)
    assert len({tuple(map(tuple, lineage.path(p)[:5, :2])) for p in range(n)}) < n
