"""Is a real log's laser stamped late against its odometry? The lag that best fits the benchmark relations.

Run: ``.venv/bin/python bench/studies/laser_latency.py LOG RELATIONS [--max-span 2] [--lags -0.3 0.3 0.01]``.

A relation gives the true motion of the laser between the scans stamped ``t1`` and ``t2``. The log's
odometry, read at the same stamps, should move the same way, up to its own error. If the scans were taken
a little before (or after) their stamps relative to the odometry, the odometry read at ``t1 + L`` and
``t2 + L`` fits better for some lag ``L``. For every lag on the grid this prints the root mean square of
the heading error (relation against odometry, wrapped) and the mean translation error, over the
relations spanning at most ``--max-span`` seconds (short ones: the odometry's own drift stays small).
The odometry between frames is interpolated linearly in x, y and the unwrapped heading. The heading is
the telling column: on some logs the relations' translations were refined from the odometry itself
(docs/karto.md, "Why MIT CSAIL stays at 0.046 m"), so their translation error says little.
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np


def lag_errors(
    t: np.ndarray, odometry: np.ndarray, t1: np.ndarray, t2: np.ndarray, delta: np.ndarray, lags: np.ndarray
) -> np.ndarray:
    """``[L, 3]`` per lag: (lag s, heading rms rad, mean translation error m) of the odometry read at the
    relations' stamps shifted by the lag. ``t`` ``[T]`` frame stamps (s), ``odometry`` ``[T, 3]``; ``t1``,
    ``t2`` ``[R]`` and ``delta`` ``[R, 3]`` the relations (motion of scan 2 in scan 1's frame)."""
    heading = np.unwrap(odometry[:, 2])
    rows = []
    for lag in lags:
        x1, y1, a1 = (np.interp(t1 + lag, t, v) for v in (odometry[:, 0], odometry[:, 1], heading))
        x2, y2, a2 = (np.interp(t2 + lag, t, v) for v in (odometry[:, 0], odometry[:, 1], heading))
        turn = (a2 - a1 - delta[:, 2] + np.pi) % (2.0 * np.pi) - np.pi
        c, s = np.cos(a1), np.sin(a1)
        dx, dy = x2 - x1, y2 - y1
        along, across = c * dx + s * dy, -s * dx + c * dy
        shift = np.hypot(along - delta[:, 0], across - delta[:, 1])
        rows.append((float(lag), float(np.sqrt(np.mean(turn**2))), float(np.mean(shift))))
    return np.array(rows)


def main() -> None:
    from slamtrials.io.relations import read_relations
    from slamtrials.slamrun import load_recording

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", help="a real log (CARMEN, optionally .bz2/.gz, or a bag)")
    parser.add_argument("relations", help="the log's benchmark relations")
    parser.add_argument("--max-span", type=float, default=2.0, help="longest relation used (s)")
    parser.add_argument(
        "--lags", type=float, nargs=3, default=(-0.3, 0.3, 0.01), metavar=("FIRST", "LAST", "STEP"), help="lags (s)"
    )
    args = parser.parse_args()

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a log's own warnings (fr079's reversals) are not this study's
        record = load_recording(args.log)
    relations = read_relations(args.relations)
    short = (relations.t2 - relations.t1) <= args.max_span
    first, last, step = args.lags
    lags = np.round(np.arange(first, last + 0.5 * step, step), 9)
    table = lag_errors(
        record.t, record.odometry, relations.t1[short], relations.t2[short], relations.delta[short], lags
    )
    at_zero = table[np.argmin(np.abs(table[:, 0]))]
    best = table[np.argmin(table[:, 1])]
    print(f"{args.log}: {int(short.sum())} relations of at most {args.max_span:g} s")
    print(
        f"heading rms at lag 0: {at_zero[1]:.4f} rad; least at lag {best[0]:+.2f} s: {best[1]:.4f} rad "
        f"(mean translation error {at_zero[2]:.4f} m at lag 0, {best[2]:.4f} m there)"
    )
    print("| lag (s) | heading rms (rad) | mean translation error (m) |")
    print("|---:|---:|---:|")
    for lag, turn, shift in table:
        print(f"| {lag:+.2f} | {turn:.4f} | {shift:.4f} |")


if __name__ == "__main__":
    main()
