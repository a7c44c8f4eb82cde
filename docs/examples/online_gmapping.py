"""slamtrials' own GMapping as an online program: the reference client of ``slamtrials-online/1``.

    slam: {algorithm: program, params: {command: "python3 docs/examples/online_gmapping.py paper"}}

It rebuilds the random stream slamtrials gave it (``rng_state``), so a trial with it is the trial with
the built-in ``gmapping`` (same preset) bit for bit; it sends its map whenever GMapping publishes a new
one (every ``map_update_interval`` seconds, as slam_gmapping does). The argument is the GMapping preset
(default: none).
"""

import json
import os
import sys
import time

import numpy as np

from slamtrials.external.protocol import decode_ranges, encode_map
from slamtrials.record import LaserGeometry, Reading
from slamtrials.slam import get_algorithm, resolve_config


def main(preset: str | None) -> None:
    spent = 0.0  # seconds inside GMapping, written to $ONLINE_GMAPPING_SECONDS at the end if set (benchmarks)
    slam = None
    sent = None  # the map object last sent: GMapping publishes a new one every map_update_interval seconds
    for line in sys.stdin:
        message = json.loads(line)
        kind = message["type"]
        if kind == "start":
            laser = message["laser"]
            geometry = LaserGeometry(
                angle_min=laser["angle_min"],
                angle_increment=laser["angle_increment"],
                range_min=laser["range_min"],
                range_max=laser["range_max"],
                mount=tuple(laser["mount"]),
            )
            cls = get_algorithm("gmapping")
            slam = cls(resolve_config(cls, preset=preset), geometry)
            rng = np.random.Generator(np.random.PCG64())
            rng.bit_generator.state = message["rng_state"]
            slam.reset(rng)
            continue
        if kind == "frame":
            ranges = decode_ranges(message["ranges"])
            reading = Reading(t=message["t"], ranges=ranges, odometry=np.array(message["odometry"], dtype=np.float64))
            started = time.perf_counter()
            pose = slam.process(reading)
            spent += time.perf_counter() - started
            reply = {"pose": [float(v) for v in pose], "updates": int(slam.updates)}
            grid = slam.occupancy()
            if grid is not sent and grid.grid.size:
                reply["map"] = encode_map(grid)
                sent = grid
        elif kind == "end":
            trajectory = slam.trajectory()
            rows = np.column_stack([trajectory.t, trajectory.poses])
            reply = {"trajectory": rows.tolist(), "map": encode_map(slam.occupancy())}
        else:
            raise SystemExit(f"unknown message {kind!r}")
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()
        if kind == "end":
            if os.environ.get("ONLINE_GMAPPING_SECONDS"):
                with open(os.environ["ONLINE_GMAPPING_SECONDS"], "w") as out:
                    out.write(f"{spent!r}\n")
            return


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
