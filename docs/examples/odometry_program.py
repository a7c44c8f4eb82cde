"""The smallest SLAM program: it reports the odometry as its estimate.

A template for wrapping your own program. slamtrials runs it as

    python docs/examples/odometry_program.py {input} {output}

where {input} is the run as a CARMEN log (ODOM lines: ``ODOM x y theta tv rv accel timestamp host
logger_timestamp``; ROBOTLASER1 lines with the scans) and {output} is where the estimated trajectory
goes, as TUM lines ``t x y z qx qy qz qw`` at the log's own timestamps.
"""

import math
import sys


def main(source: str, target: str) -> None:
    with open(source, encoding="utf-8") as log, open(target, "w", encoding="utf-8") as out:
        for line in log:
            words = line.split()
            if not words or words[0] != "ODOM":
                continue
            x, y, theta = (float(v) for v in words[1:4])
            t = float(words[7])
            out.write(f"{t:.6f} {x:.6f} {y:.6f} 0 0 0 {math.sin(theta / 2):.9f} {math.cos(theta / 2):.9f}\n")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
