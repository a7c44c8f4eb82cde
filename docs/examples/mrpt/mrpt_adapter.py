#!/usr/bin/env python3
"""Helpers that let MRPT's icp-slam run offline over a CARMEN log (used by icp_slam.sh).

  mrpt_adapter.py stamp LOG RAWLOG
      Give each observation of RAWLOG (written by `carmen2rawlog -i LOG`) the timestamp of its
      laser line in LOG. MRPT 2.5's carmen2rawlog stamps every observation with the same time
      (the moment of the conversion), and icp-slam's pose predictor then ignores the odometry.
      carmen2rawlog writes one odometry and one laser-scan observation per laser line
      (FLASER, RLASER, ROBOTLASER*), in file order, each holding that shared timestamp once
      (uint64, 100-ns ticks since 1601). They are replaced, in order, by the lines' times.

  mrpt_adapter.py tum LOG PATH OUT
      Convert icp-slam's log_estimated_path.txt (PATH; one `step x y yaw` line per rawlog
      observation, no time) to a TUM trajectory OUT: step 2k+1 (right after laser line k was
      matched) gets laser line k's timestamp, written exactly as in LOG.

Only the standard library is used. Errors end with a message on stderr and exit status 1.
"""

import gzip
import math
import struct
import sys
from collections import Counter
from decimal import Decimal

LASER_KINDS = ("ROBOTLASER", "FLASER", "RLASER")  # the lines carmen2rawlog turns into scans
EPOCH_1601 = 11644473600  # seconds from 1601-01-01 to 1970-01-01 (MRPT's clock epoch)


def fail(msg):
    sys.exit(f"mrpt_adapter: {msg}")


def laser_times(log):
    """The ipc_timestamp (as written) of every laser line of a CARMEN log, in order."""
    times = []
    with open(log) as f:
        for n, line in enumerate(f, 1):
            tok = line.split()
            if tok and tok[0].upper().startswith(LASER_KINDS):
                # every CARMEN message ends with: ipc_timestamp ipc_hostname logger_timestamp
                try:
                    Decimal(tok[-3])
                except Exception:
                    fail(f"{log}:{n}: no timestamp at the end of the {tok[0]} line")
                times.append(tok[-3])
    if not times:
        fail(f"{log}: no laser lines ({', '.join(LASER_KINDS)})")
    return times


def stamp(log, rawlog):
    times = laser_times(log)
    with open(rawlog, "rb") as f:
        data = f.read()
    zipped = data[:2] == b"\x1f\x8b"
    if zipped:
        data = gzip.decompress(data)
    # The shared timestamp: the 8-byte value near "now" that occurs once per observation.
    lo, hi = (EPOCH_1601 + 10**9) * 10**7, (EPOCH_1601 + 10**10) * 10**7  # 2001 .. 2286
    counts = Counter()
    for shift in range(8):  # every byte offset
        end = shift + (len(data) - shift) // 8 * 8
        counts.update(v for (v,) in struct.iter_unpack("<Q", data[shift:end]) if lo < v < hi)
    if not counts:
        fail(f"{rawlog}: no timestamp found")
    shared, n = counts.most_common(1)[0]
    if n != 2 * len(times):
        fail(
            f"{rawlog}: {n} observations carry the conversion time, expected 2 per laser line "
            f"of {log} ({2 * len(times)}); carmen2rawlog's output format changed?"
        )
    old = struct.pack("<Q", shared)
    parts = data.split(old)
    assert len(parts) == n + 1
    out = [parts[0]]
    for k, part in enumerate(parts[1:]):
        ticks = int((Decimal(times[k // 2]) + EPOCH_1601) * 10_000_000)
        if ticks <= 0:
            fail(f"{log}: timestamp {times[k // 2]} before 1601")
        out += [struct.pack("<Q", ticks), part]
    data = b"".join(out)
    with open(rawlog, "wb") as f:
        f.write(gzip.compress(data, 1) if zipped else data)


def tum(log, path, out):
    times = laser_times(log)
    rows = []
    with open(path) as f:
        for line in f:
            tok = line.split()
            if tok and not tok[0].startswith("%"):
                rows.append(tok)
    if len(rows) != 2 * len(times):
        fail(
            f"{path}: {len(rows)} steps, expected 2 per laser line of {log} ({2 * len(times)}): icp-slam stopped early?"
        )
    with open(out, "w") as f:
        for k, t in enumerate(times):
            step, x, y, yaw = rows[2 * k + 1][:4]
            if int(step) != 2 * k + 1:
                fail(f"{path}: step {step} where {2 * k + 1} was expected")
            x, y, yaw = float(x), float(y), float(yaw)
            if not all(map(math.isfinite, (x, y, yaw))):
                fail(f"{path}: step {step} is not finite")
            f.write(f"{t} {x:.6f} {y:.6f} 0 0 0 {math.sin(yaw / 2):.9f} {math.cos(yaw / 2):.9f}\n")


if __name__ == "__main__":
    cmd, args = (sys.argv[1], sys.argv[2:]) if len(sys.argv) > 1 else ("", [])
    if cmd == "stamp" and len(args) == 2:
        stamp(*args)
    elif cmd == "tum" and len(args) == 3:
        tum(*args)
    else:
        sys.exit(__doc__)
