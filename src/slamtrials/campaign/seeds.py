"""Seed streams of a campaign: one independent, reproducible seed per (world, run index).

``run_seed(root, world, index)`` is the first 63 bits of the state of
``numpy.random.SeedSequence(root, spawn_key=(crc32(world), index))``. The trial uses it as its seed
(simulator and SLAM streams are spawned from it, see :func:`slamtrials.trial.run_trial`), and the
relation sampling of the run uses ``numpy.random.default_rng(seed)``, exactly as
``slamtrials evaluate RUN --seed SEED`` does. A run is therefore reproduced from its world, the root seed
and its index alone, on any worker and in any order.
"""

from __future__ import annotations

import zlib

import numpy as np

__all__ = ["run_seed", "world_key_hash"]


def world_key_hash(world: str) -> int:
    """CRC-32 of the world's campaign name (UTF-8), a stable 32-bit spawn key."""
    return zlib.crc32(world.encode("utf-8")) & 0xFFFFFFFF


def run_seed(root: int, world: str, index: int) -> int:
    """The seed of run ``index`` (0-based) of ``world`` in a campaign with root seed ``root``.

    Returns
    -------
    int
        A non-negative integer below ``2**63`` (fits SQLite's signed 64-bit integers).
    """
    if root < 0 or index < 0:
        raise ValueError(f"root seed and run index must be non-negative, got {root} and {index}")
    sequence = np.random.SeedSequence(int(root), spawn_key=(world_key_hash(world), int(index)))
    return int(sequence.generate_state(1, np.uint64)[0] >> np.uint64(1))
