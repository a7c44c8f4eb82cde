"""Where and why GMapping goes wrong on a real log: the error along the chain of local relations.

Run: ``SLAMTRIALS_SHARED=<shared> NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/fr079_diagnose.py [--log fr079]
[--seeds 0 1 2] [--set key=value ...] [--repair]``.

The Freiburg relations of a log are of two kinds: local ones between consecutive reference scans (fr079:
987 of them, under 7 s apart, chained end to start over the whole log but for one 1 s gap) and long ones
that close loops. A run's error on each local relation is the error it made over those few seconds, so
the signed rotational error along the chain, summed, is the run's heading drift against the reference
over time, and a jump in it is one place where the run went wrong. It first prints what the log's ODOM
lines say about reversing (fr079: the logged pose advances forward while the velocity is negative). For
each seed it then prints the summed heading drift of the run and of the raw odometry every 50 s, the
local relations with the largest rotational error, and per filter update what the scan matcher did there
(how many particles' matches were taken and the best score), so one can tell whether all seeds fail at
one place (one event) or drift everywhere, and whether the matcher or the motion model is to blame.
Nothing is written.
"""

from __future__ import annotations

import argparse
import math
import os
import sys

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/, for bench_real_logs

import numpy as np  # noqa: E402

import slamtrials.slam.gmapping.filter as gmapping_filter  # noqa: E402
from bench_real_logs import datasets, shared_data  # noqa: E402
from fr079_study import repaired_odometry  # noqa: E402
from slamtrials.cli.slam import parse_settings  # noqa: E402
from slamtrials.io.carmen_read import read_carmen  # noqa: E402
from slamtrials.io.relations import read_relations  # noqa: E402
from slamtrials.metric.matching import match_relations  # noqa: E402
from slamtrials.record import Relations, Trajectory  # noqa: E402
from slamtrials.slam.offline import run_over_recording  # noqa: E402
from slamtrials.slamrun import load_recording  # noqa: E402

#: Relations shorter than this (s) are the local chain; longer ones close loops.
LOCAL = 10.0


class MatchLog:
    """Wraps GMapping's ``match_particles`` (and ``process``, for the time) and keeps, per update, the
    reading time, every particle's match score and how many particles took their matched pose."""

    def __init__(self) -> None:
        self.original = gmapping_filter.match_particles
        self.original_process = gmapping_filter.GMapping.process
        self.t = math.nan
        self.times: list[float] = []
        self.scores: list[np.ndarray] = []
        self.accepted: list[int] = []

    def __call__(self, *args):  # the numba kernel's positional signature; minimumScore is the last
        matched, scores, likelihoods = self.original(*args)
        self.times.append(self.t)
        self.scores.append(scores.copy())
        self.accepted.append(int(np.sum(scores > args[-1])))
        return matched, scores, likelihoods

    def install(self) -> None:
        log = self

        def process(slam, frame):
            log.t = float(frame.t)
            return log.original_process(slam, frame)

        gmapping_filter.match_particles = self
        gmapping_filter.GMapping.process = process  # type: ignore[method-assign]

    def uninstall(self) -> None:
        gmapping_filter.match_particles = self.original
        gmapping_filter.GMapping.process = self.original_process  # type: ignore[method-assign]

    def near(self, t1: float, t2: float) -> str:
        """The matcher's updates between t1 and t2: per update, particles that took the match and the best score."""
        times = np.array(self.times)
        inside = np.flatnonzero((times >= t1 - 0.5) & (times <= t2 + 0.5))
        return ", ".join(f"{self.accepted[i]}/{self.scores[i].max():.0f}" for i in inside) or "no update"


def signed_errors(estimate: Trajectory, relations: Relations) -> tuple[np.ndarray, np.ndarray]:
    """Per relation: translational error (m) and signed rotational error (rad, estimate minus truth)."""
    match = match_relations(estimate, relations)
    d = match.delta - relations.delta
    rot = (d[:, 2] + math.pi) % (2.0 * math.pi) - math.pi
    return np.hypot(d[:, 0], d[:, 1]), rot


def reversals(t: np.ndarray, pose: np.ndarray, tv: np.ndarray, gap: float = 2.0) -> list[str]:
    """What the log's ODOM lines say about driving backwards: lines with ``tv < 0``, the distance the pose
    moved during them, whether the pose then advanced forward or backward along its heading (steps with
    ``tv < -0.1 m/s``), and the bursts (lines less than ``gap`` s apart) longer than 0.5 m."""
    step = np.diff(pose[:, :2], axis=0)
    heading = pose[:-1, 2]
    along = step[:, 0] * np.cos(heading) + step[:, 1] * np.sin(heading)
    moved = np.hypot(step[:, 0], step[:, 1])
    back = tv[1:] < 0.0
    fast = tv[1:] < -0.1
    lines = [
        f"ODOM lines with tv < 0: {int(np.sum(tv < 0.0))} of {len(tv)}; the pose moved {moved[back].sum():.1f} m "
        f"during them ({moved.sum():.0f} m in all); of the {int(fast.sum())} steps with tv < -0.1 m/s the pose "
        f"advanced forward along its heading in {int(np.sum(fast & (along > 0.0)))}, backward in "
        f"{int(np.sum(fast & (along < 0.0)))}"
    ]
    index = np.flatnonzero(back) + 1
    for burst in np.split(index, np.flatnonzero(np.diff(t[index]) > gap) + 1) if len(index) else []:
        distance = float(moved[burst - 1].sum())
        if distance > 0.5:
            lines.append(
                f"  {t[burst[0]]:.1f}-{t[burst[-1]]:.1f} s: {distance:.2f} m backwards logged as forward "
                f"(odometry off by {2.0 * distance:.1f} m)"
            )
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", default="fr079")
    parser.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2])
    parser.add_argument("--set", dest="settings", action="append", default=[])
    parser.add_argument("--top", type=int, default=8, help="local relations with the largest error shown per seed")
    parser.add_argument("--repair", action="store_true", help="re-sign the odometry where it reverses (fr079_study.py)")
    args = parser.parse_args()
    found = datasets(shared_data(), [args.log])
    if not found:
        print(f"no dataset {args.log!r} with relations under {shared_data()}", file=sys.stderr)
        return 2
    _, log, relations_path = found[0]
    record = load_recording(log)
    odom = read_carmen(log, ranges=False).odom
    if len(odom):
        print("\n".join(reversals(odom.t, odom.pose, odom.tv)))
    if args.repair:
        record = repaired_odometry(record, odom.t, odom.tv)
    relations = read_relations(relations_path)
    local = np.flatnonzero(np.abs(relations.t2 - relations.t1) < LOCAL)
    local = local[np.argsort(relations.t1[local], kind="stable")]
    odometry = Trajectory(t=record.t, poses=record.odometry)
    _, odo_rot = signed_errors(odometry, relations)
    overrides = parse_settings(args.settings)
    repaired = " (odometry re-signed where it reverses)" if args.repair else ""
    print(f"# {args.log}: {len(local)} local relations (< {LOCAL:g} s), settings {overrides or 'defaults'}{repaired}")
    marks = np.arange(record.t[0] + 50.0, record.t[-1] + 50.0, 50.0)

    def drift(rot: np.ndarray) -> list[str]:
        summed = np.cumsum(np.nan_to_num(rot[local]))
        at = np.searchsorted(relations.t2[local], marks, side="right") - 1
        return [f"{math.degrees(summed[i]):+.0f}" if i >= 0 else "0" for i in at]

    print("heading drift against the local chain (deg), every 50 s from", f"{record.t[0]:.0f} s:")
    print(f"  odometry: {' '.join(drift(odo_rot))}")
    for seed in args.seeds:
        log_matches = MatchLog()
        log_matches.install()
        try:
            run = run_over_recording(record, "gmapping", overrides=overrides, seed=seed)
        finally:
            log_matches.uninstall()
        trans, rot = signed_errors(run.trajectory, relations)
        print(f"  seed {seed}: {' '.join(drift(rot))}   (mean eps_t {np.nanmean(trans):.3f} m)")
        worst = local[np.argsort(-np.abs(np.nan_to_num(rot[local])), kind="stable")[: args.top]]
        for k in sorted(worst, key=lambda k: relations.t1[k]):
            print(
                f"    {relations.t1[k]:8.1f}-{relations.t2[k]:8.1f} s: rot err {math.degrees(rot[k]):+6.1f} deg "
                f"(odometry {math.degrees(odo_rot[k]):+6.1f}), trans err {trans[k]:.2f} m, "
                f"true turn {math.degrees(relations.delta[k, 2]):+6.1f} deg; updates (taken/best score): "
                f"{log_matches.near(relations.t1[k], relations.t2[k])}"
            )
        accepted = np.array(log_matches.accepted)
        best = np.array([s.max() for s in log_matches.scores])
        particles = len(log_matches.scores[0]) if log_matches.scores else 0
        print(
            f"    matches taken: {accepted.sum()} of {accepted.size * particles} particle-updates; "
            f"updates where none was taken: {int(np.sum(accepted == 0))}; best score median {np.median(best):.0f}, "
            f"min {best.min():.0f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
