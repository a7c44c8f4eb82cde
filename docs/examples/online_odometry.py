"""The smallest online SLAM program: it answers every frame with the odometry (standard library only).

slamtrials runs it as the algorithm ``program``:

    slam: {algorithm: program, params: {command: "python3 docs/examples/online_odometry.py"}}

and talks to it over stdin/stdout, one JSON object per line (protocol ``slamtrials-online/1``). It sends no
map, so slamtrials draws one from its poses and the scans. Replace the pose with your algorithm's.
"""

import base64
import json
import struct
import sys


def estimate(t: float, odometry: list, ranges: tuple) -> list:
    """Your SLAM step: the robot base's pose [x, y, theta] in the map frame. This one trusts the odometry."""
    return odometry


def main() -> None:
    for line in sys.stdin:
        message = json.loads(line)
        kind = message["type"]
        if kind == "start":
            beams = message["laser"]["beams"]  # and the beam geometry, the laser's mount, a seed
            continue
        if kind == "frame":
            ranges = struct.unpack(f"<{beams}f", base64.b64decode(message["ranges"]))  # metres, inf: no return
            reply = {"pose": estimate(message["t"], message["odometry"], ranges)}
        elif kind == "end":
            reply = {}  # or {"trajectory": [[t, x, y, theta], ...], "map": {...}}
        else:
            raise SystemExit(f"unknown message {kind!r}")
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()  # slamtrials waits for every reply
        if kind == "end":
            return


if __name__ == "__main__":
    main()
