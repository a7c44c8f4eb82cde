"""Where real short readings stand: how many of them are next to a depth edge of the reference map.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/short_edges.py LOG [KEY=VALUE ...] [--every 5]
[--jump 0.3] [--short 0.3]``.

GMapping (its defaults plus the ``KEY=VALUE`` overrides, seed 0) runs over the log; its final path and
map are the reference, as for ``slamtrials calibrate``. Every ``--every``-th frame is cast in the
reference map from its reference pose (the calibration's caster: only beams that hit a mapped wall
through known free space count). A beam is *at an edge* when the cast range of a beam up to two places
to either side differs from its own by more than ``--jump`` metres (a depth discontinuity: a door
frame, a pillar's side, a corridor opening); it reads *short* when its reading is more than ``--short``
metres below its cast range. Printed: the share of beams at an edge, the share of short readings at an
edge, and the ratio of the two (1: short readings stand anywhere, as the simulator's model draws them).
Then, for the beams on the *far* side of an edge (a beam up to two places away has a cast range more
than ``--jump`` shorter), the share that reads the nearer surface (within ``--near`` metres of the
nearest neighbouring cast range): an estimate of how often a beam next to a nearer surface reads it.
"""

from __future__ import annotations

import argparse
import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402


def at_edges(cast: np.ndarray, jump: float, reach: int = 2) -> np.ndarray:
    """bool ``[B]``: beams whose cast range differs by more than ``jump`` from a beam within ``reach``."""
    edge = np.zeros(cast.shape, dtype=bool)
    for step in range(1, reach + 1):
        differs = np.abs(cast[step:] - cast[:-step]) > jump
        edge[step:] |= differs
        edge[:-step] |= differs
    return edge


def nearest_neighbour_cast(cast: np.ndarray, reach: int = 2) -> np.ndarray:
    """float64 ``[B]``: the shortest cast range among the beams up to ``reach`` places to either side."""
    nearest = np.full(cast.shape, np.inf)
    for step in range(1, reach + 1):
        nearest[step:] = np.minimum(nearest[step:], cast[:-step])
        nearest[:-step] = np.minimum(nearest[:-step], cast[step:])
    return nearest


def main() -> None:
    from slamtrials.calibration import slam_reference
    from slamtrials.calibration.beams import FrameCaster
    from slamtrials.cli.slam import parse_settings
    from slamtrials.slamrun import load_recording

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("settings", nargs="*", help="GMapping parameter overrides KEY=VALUE")
    parser.add_argument("--every", type=int, default=5, help="cast every N-th frame")
    parser.add_argument("--jump", type=float, default=0.3, help="depth step (m) that makes an edge")
    parser.add_argument("--short", type=float, default=0.3, help="shortfall (m) that makes a short reading")
    parser.add_argument("--near", type=float, default=0.1, help="how close (m) a reading must be to the nearer side")
    args = parser.parse_args()

    record = load_recording(args.log)
    reference = slam_reference(record, "gmapping", overrides=parse_settings(args.settings) or None, seed=0)
    caster = FrameCaster(record, reference)
    beams = shorts = edge_beams = edge_shorts = far_side = reads_near = 0
    for k in range(0, len(record), args.every):
        frame = caster.cast(k)
        reading = record.scans[k].astype(np.float64)
        cast = frame.ranges.astype(np.float64)
        usable = frame.kept & (reading < record.laser.range_max)
        short = usable & (reading - cast < -args.short)
        edge = at_edges(cast, args.jump)
        beams += int(usable.sum())
        shorts += int(short.sum())
        edge_beams += int((usable & edge).sum())
        edge_shorts += int((short & edge).sum())
        nearer = nearest_neighbour_cast(cast)
        far = usable & (nearer < cast - args.jump)
        far_side += int(far.sum())
        reads_near += int((far & (np.abs(reading - nearer) <= args.near)).sum())
    edge_share = edge_beams / max(beams, 1)
    edge_share_short = edge_shorts / max(shorts, 1)
    print(
        f"{args.log}: {beams} beams hit a mapped wall (every {args.every}th frame); "
        f"{shorts / max(beams, 1):.3f} read more than {args.short} m short; "
        f"at an edge (> {args.jump} m within 2 beams): {edge_share:.3f} of all beams, "
        f"{edge_share_short:.3f} of the short readings ({edge_share_short / max(edge_share, 1e-12):.1f} times)"
    )
    print(
        f"far side of an edge: {far_side} beams ({far_side / max(beams, 1):.3f}); "
        f"{reads_near / max(far_side, 1):.3f} of them read the nearer side (within {args.near} m)"
    )


if __name__ == "__main__":
    main()
