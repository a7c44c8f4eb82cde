"""Where karto's sequential matcher errs in heading: per-node errors against a reference path (issue 23).

Run: ``SLAMTRIALS_SHARED=<shared> NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/karto_heading.py --log fr079
--reference GMAPPING_RUN/trajectory.tum [--set key=value ...] [--isolated] [--relations]``.

The reference is a path that is locally right, e.g. GMapping's with ``linearUpdate 0.1`` (fr079: 0.045 m on
the benchmark relations; ``slamtrials slam --algorithm gmapping --set linearUpdate=0.1``), one pose per
reading of the log. Two measurements:

- *chained* (default): karto runs over the log as configured (add ``--set do_loop_closing=false`` for the
  open-loop path); for every node after the first, the motion from the previous node in karto's online
  estimate (the node's pose when it was added) is compared with the reference's motion between the same
  two readings. A matcher without bias gives heading errors of mean 0; their sum is the open-loop drift.
- *isolated* (``--isolated``): the same nodes, but each one is matched by karto's sequential matcher
  against its running buffer placed at the *reference* poses, from the reference's previous node carried
  by the odometry: the error of one match, without the drift of the ones before.

Prints the signed mean, the mean absolute value and the RMS of the per-node heading error (rad), the
mean per-node translational error (m), and with ``--relations`` the run's errors on the log's relations.
Nothing is written but ``--dump``.
"""

from __future__ import annotations

import argparse
import os
import sys

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/, for bench_real_logs

import numpy as np  # noqa: E402

from bench_real_logs import datasets, shared_data  # noqa: E402
from slamtrials.cli.slam import parse_settings  # noqa: E402
from slamtrials.geometry import compose1, ominus1, wrap_angle1  # noqa: E402
from slamtrials.io.relations import read_relations  # noqa: E402
from slamtrials.io.tum import read_tum  # noqa: E402
from slamtrials.metric.relerrors import evaluate_relations  # noqa: E402
from slamtrials.record import Frame  # noqa: E402
from slamtrials.slam import resolve_config  # noqa: E402
from slamtrials.slam.karto.algorithm import Karto  # noqa: E402
from slamtrials.slam.karto.scanmatch import local_points, scan_points  # noqa: E402
from slamtrials.slamrun import load_recording  # noqa: E402


def summarize(name: str, heading: np.ndarray, translation: np.ndarray) -> None:
    print(
        f"{name}: {heading.size} node steps; heading error (rad) mean {np.mean(heading):+.5f}, "
        f"mean abs {np.mean(np.abs(heading)):.5f}, RMS {np.sqrt(np.mean(heading**2)):.5f}, "
        f"sum {np.sum(heading):+.3f}; translation error mean {np.mean(translation):.4f} m"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", default="fr079", help="dataset name under <shared>/data")
    parser.add_argument("--reference", required=True, help="reference path (TUM, one pose per reading)")
    parser.add_argument("--set", dest="settings", action="append", default=[], help="karto parameter key=value")
    parser.add_argument("--isolated", action="store_true", help="also match each node against reference-placed buffers")
    parser.add_argument("--relations", action="store_true", help="also score the run on the log's relations")
    parser.add_argument("--dump", help="write the per-node errors to this .npz")
    args = parser.parse_args()
    found = datasets(shared_data(), [args.log])
    if not found:
        print(f"no {args.log} with relations under {shared_data()}; set SLAMTRIALS_SHARED", file=sys.stderr)
        return 2
    _, log, relations_path = found[0]
    record = load_recording(log)
    reference = read_tum(args.reference)
    if len(reference.t) != len(record.t) or np.max(np.abs(reference.t - record.t)) > 1e-3:
        print(f"{args.reference}: not one pose per reading of {log}", file=sys.stderr)
        return 2
    ref = reference.poses
    config = resolve_config(Karto, overrides=parse_settings(args.settings))
    slam = Karto(config, record.laser)
    slam.reset(np.random.default_rng(0))
    online = np.empty((len(record.t), 3))
    for k in range(len(record.t)):
        frame = Frame(
            t=float(record.t[k]),
            ranges=record.scans[k],
            odometry=record.odometry[k],
            truth=record.truth[k],
            stalled=bool(record.stalled[k]),
        )
        online[k] = slam.process(frame)
    frames = np.array([n.frame for n in slam.graph.nodes])
    heading, translation = [], []
    for a, b in zip(frames[:-1], frames[1:]):
        mine, theirs = ominus1(online[a], online[b]), ominus1(ref[a], ref[b])
        heading.append(wrap_angle1(mine[2] - theirs[2]))
        translation.append(float(np.hypot(mine[0] - theirs[0], mine[1] - theirs[1])))
    print(f"{log}: {len(frames)} nodes, {slam.loop_closures} loop closures; settings {args.settings or 'defaults'}")
    summarize("chained", np.array(heading), np.array(translation))
    dump = {"frames": frames, "chained_heading": np.array(heading), "chained_translation": np.array(translation)}
    if args.isolated:
        heading, translation = [], []
        nodes = slam.graph.nodes
        for i in range(1, len(nodes)):
            buffer: list[int] = []
            for j in range(i - 1, max(i - 1 - config.scan_buffer_size, -1), -1):
                first = compose1(ref[nodes[j].frame], slam.mount)
                last = compose1(ref[nodes[i - 1].frame], slam.mount)
                if np.hypot(first[0] - last[0], first[1] - last[1]) ** 2 > config.scan_buffer_maximum_scan_distance**2:
                    break
                buffer.insert(0, j)
            base = []
            for j in buffer:
                at = compose1(ref[nodes[j].frame], slam.mount)
                base.append(scan_points(at, nodes[j].readings, slam.laser.angle_min, slam.laser.angle_increment))
            a, b = nodes[i - 1].frame, nodes[i].frame
            guess = compose1(ref[a], ominus1(record.odometry[a], record.odometry[b]))
            laser_guess = compose1(guess, slam.mount)
            own = scan_points(laser_guess, nodes[i].readings, slam.laser.angle_min, slam.laser.angle_increment)
            result = slam.sequential.match(
                laser_guess, *local_points(laser_guess, *own), base, penalize=True, refine=True
            )
            error = ominus1(compose1(ref[b], slam.mount), result.pose)
            heading.append(wrap_angle1(error[2]))
            translation.append(float(np.hypot(error[0], error[1])))
        summarize("isolated", np.array(heading), np.array(translation))
        dump.update(isolated_heading=np.array(heading), isolated_translation=np.array(translation))
    if args.relations:
        errors = evaluate_relations(slam.trajectory(), read_relations(relations_path), allow_outside=True)
        print(f"relations: eps_t {np.mean(errors.translational):.4f} m, eps_r {np.mean(errors.rotational):.4f} rad")
    if args.dump:
        turn = [wrap_angle1(ref[b][2] - ref[a][2]) for a, b in zip(frames[:-1], frames[1:])]
        np.savez(args.dump, reference_turn=np.array(turn), **dump)
    return 0


if __name__ == "__main__":
    sys.exit(main())
