"""Which earlier scans a new scan is matched against, besides the running buffer (Karto's MapperGraph).

Both searches work on node indices (the order scans were added) and on every node's reference
position (``[N, 2]``, map frame: the barycentre of its points, or its laser position).

* :func:`find_near_chains` (LinkNearChains): chains of consecutive nodes near the new one, around
  every node the graph already links to it within ``link_scan_maximum_distance``; a chain that
  reaches the new node itself is the recent path and is dropped.
* :func:`find_loop_closure_chain` (FindPossibleLoopClosure): the next run of consecutive nodes within
  ``loop_search_maximum_distance`` of the new node that holds no node the graph links to it (within
  that distance), at least ``loop_match_minimum_chain_size`` long.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from slamtrials.slam.karto.correlation import KT_TOLERANCE
from slamtrials.slam.karto.graph import PoseGraph

__all__ = ["find_near_chains", "find_loop_closure_chain"]


def _squared_distance(reference: NDArray[np.float64], a: int, b: int) -> float:
    dx = reference[a, 0] - reference[b, 0]
    dy = reference[a, 1] - reference[b, 1]
    return float(dx * dx + dy * dy)


def find_near_chains(
    graph: PoseGraph, new: int, reference: NDArray[np.float64], max_distance: float
) -> list[list[int]]:
    """Chains of consecutive nodes within ``max_distance`` (m) of node ``new`` (see the module)."""
    limit = max_distance * max_distance + KT_TOLERANCE
    chains: list[list[int]] = []
    processed: set[int] = set()
    count = len(graph.nodes)
    for near in graph.near_linked(new, reference, max_distance):
        if near == new or near in processed:
            continue
        processed.add(near)
        valid = True
        before: list[int] = []
        for candidate in range(near - 1, -1, -1):
            if candidate == new:
                valid = False
            if _squared_distance(reference, new, candidate) < limit:
                before.append(candidate)
                processed.add(candidate)
            else:
                break
        after: list[int] = []
        for candidate in range(near + 1, count):
            if candidate == new:
                valid = False
            if _squared_distance(reference, new, candidate) < limit:
                after.append(candidate)
                processed.add(candidate)
            else:
                break
        if valid:
            chains.append(before[::-1] + [near] + after)
    return chains


def find_loop_closure_chain(
    graph: PoseGraph, new: int, reference: NDArray[np.float64], max_distance: float, minimum_size: int, start: int
) -> tuple[list[int], int]:
    """The next loop-closure candidate chain for node ``new``, scanning nodes from index ``start``.

    Returns the chain (empty when there is none left) and the index to continue from.
    """
    limit = max_distance * max_distance + KT_TOLERANCE
    linked = set(graph.near_linked(new, reference, max_distance))
    chain: list[int] = []
    count = len(graph.nodes)
    index = start
    while index < count:
        if _squared_distance(reference, index, new) < limit:
            if index in linked:
                chain = []
            else:
                chain.append(index)
        else:
            if len(chain) >= minimum_size:
                return chain, index
            chain = []
        index += 1
    return chain, index
