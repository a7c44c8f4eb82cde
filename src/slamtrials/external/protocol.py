"""The messages of ``slamtrials-online/1``, the protocol between slamtrials and an online SLAM program.

One JSON object per line on the program's stdin (from slamtrials) and stdout (from the program); the
program's stderr is its own (slamtrials keeps its last lines for error messages). Floats are written
with Python's shortest round-trip form, so values cross the pipe bit for bit.

slamtrials sends:

``{"type": "start", "protocol": "slamtrials-online/1", "laser": {...}, "seed": S, "rng_state": {...}}``
    once, first. ``laser``: ``beams``, ``angle_min``, ``angle_increment`` (rad), ``range_min``,
    ``range_max`` (m) and ``mount`` (``[x, y, theta]`` of the laser on the base). ``seed``: a 32-bit
    seed for the program's random draws; ``rng_state``: the same stream as numpy's ``PCG64`` state, for
    a program in Python that wants slamtrials' own stream. No reply.
``{"type": "frame", "index": k, "t": T, "odometry": [x, y, theta], "ranges": R}``
    for every frame (``t`` s, odometry in its own frame, m and rad). ``R`` is the base64 of the
    ``beams`` ranges (m) as little-endian float32, beam 0 first; a beam with no return is ``+inf``
    (JSON numbers would cost more than the SLAM step of most frames). Reply: one line ``{"pose": [x, y, theta]}``, the robot base's pose estimate in the map
    frame, optionally with ``"updates": n`` (the updates done so far) and ``"map": {...}``.
``{"type": "end"}``
    after the last frame. Reply: one line, ``{}`` or ``{"trajectory": [[t, x, y, theta], ...],
    "map": {...}}``, the final estimate of every frame (default: the poses it replied) and map; then the
    program exits with status 0.

A ``map`` is ``{"resolution": r, "width": W, "height": H, "origin": [x, y, theta], "data": D}``, as a
ROS ``nav_msgs/OccupancyGrid``: ``D`` is the base64 of the ``W * H`` int8 cells, row by row from the
BOTTOM row (smallest y), 100 occupied, 0 free, -1 unknown; ``origin`` is the pose of the lower-left
corner of the lower-left cell. Send one whenever the map changed: the explorer plans on the latest map
sent. A program that never sends one gets a map drawn from its poses and the scans.
"""

from __future__ import annotations

import base64
import json
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import ProgramError
from slamtrials.record import LaserGeometry, OccupancyGrid, Reading

__all__ = [
    "PROTOCOL",
    "start_message",
    "frame_message",
    "END_MESSAGE",
    "parse_reply",
    "parse_pose",
    "parse_map",
    "parse_trajectory",
    "encode_map",
    "decode_ranges",
]

PROTOCOL = "slamtrials-online/1"
END_MESSAGE = b'{"type": "end"}\n'


def start_message(laser: LaserGeometry, beams: int, seed: int, rng_state: dict[str, Any]) -> bytes:
    """The ``start`` line."""
    doc = {
        "type": "start",
        "protocol": PROTOCOL,
        "laser": {
            "beams": int(beams),
            "angle_min": float(laser.angle_min),
            "angle_increment": float(laser.angle_increment),
            "range_min": float(laser.range_min),
            "range_max": float(laser.range_max),
            "mount": [float(v) for v in laser.mount],
        },
        "seed": int(seed),
        "rng_state": rng_state,
    }
    return (json.dumps(doc) + "\n").encode()


def frame_message(index: int, reading: Reading) -> bytes:
    """The ``frame`` line of ``reading`` (ranges as base64 little-endian float32)."""
    ranges = base64.b64encode(np.ascontiguousarray(reading.ranges, dtype="<f4").tobytes()).decode("ascii")
    doc = {
        "type": "frame",
        "index": int(index),
        "t": float(reading.t),
        "odometry": [float(v) for v in reading.odometry],
        "ranges": ranges,
    }
    return (json.dumps(doc) + "\n").encode()


def decode_ranges(text: str) -> NDArray[np.float32]:
    """The ranges of a ``frame`` message (for clients written in Python): float32 ``[B]``, m."""
    return np.frombuffer(base64.b64decode(text), dtype="<f4").astype(np.float32)


def parse_reply(line: bytes, what: str) -> dict[str, Any]:
    """A reply line as a mapping; ``what`` names the message it answers (for the error)."""
    try:
        doc = json.loads(line)
    except ValueError:
        shown = line[:80].decode("utf-8", errors="replace")
        raise ProgramError(f"protocol: the reply to {what} is not a JSON line: {shown!r}") from None
    if not isinstance(doc, dict):
        raise ProgramError(f"protocol: the reply to {what} must be a JSON object, got {type(doc).__name__}")
    return doc


def parse_pose(doc: dict[str, Any], what: str) -> NDArray[np.float64]:
    """The reply's ``pose``: three finite numbers."""
    pose = doc.get("pose")
    try:
        values = np.array(pose, dtype=np.float64)
    except (TypeError, ValueError):
        values = np.empty(0)
    if values.shape != (3,) or not np.isfinite(values).all():
        raise ProgramError(f'protocol: the reply to {what} needs "pose": [x, y, theta] (finite), got {pose!r}'[:200])
    return values


def parse_map(doc: Any, what: str) -> OccupancyGrid:
    """A ``map`` object as an :class:`~slamtrials.record.OccupancyGrid` (row 0 at the top)."""
    try:
        resolution = float(doc["resolution"])
        width, height = int(doc["width"]), int(doc["height"])
        origin = np.array(doc["origin"], dtype=np.float64)
        data = base64.b64decode(doc["data"], validate=True)
    except (KeyError, TypeError, ValueError):
        raise ProgramError(
            f"protocol: the map in the reply to {what} needs resolution, width, height, origin [x, y, theta] "
            "and data (base64 of width * height int8 cells)"
        ) from None
    if not (resolution > 0 and math.isfinite(resolution)) or width <= 0 or height <= 0:
        raise ProgramError(
            f"protocol: the map in the reply to {what} has resolution {resolution}, size {width} x {height}"
        )
    if origin.shape != (3,) or not np.isfinite(origin).all():
        raise ProgramError(f"protocol: the map in the reply to {what} needs origin [x, y, theta]")
    if len(data) != width * height:
        raise ProgramError(
            f"protocol: the map in the reply to {what} holds {len(data)} cells for {width} x {height} = {width * height}"
        )
    cells = np.frombuffer(data, dtype=np.int8).reshape(height, width)
    if not (
        (cells == 0) | (cells == 100) | (cells == -1)
    ).all():  # probabilities, as ROS allows: map_saver's thresholds
        cells = np.where(cells >= 65, 100, np.where((cells >= 0) & (cells <= 25), 0, -1)).astype(np.int8)
    return OccupancyGrid(grid=np.ascontiguousarray(cells[::-1]), resolution=resolution, origin=origin)


def encode_map(grid: OccupancyGrid) -> dict[str, Any]:
    """The ``map`` object of ``grid`` (for clients written in Python)."""
    cells = np.ascontiguousarray(np.asarray(grid.grid, dtype=np.int8)[::-1])
    return {
        "resolution": float(grid.resolution),
        "width": int(cells.shape[1]),
        "height": int(cells.shape[0]),
        "origin": [float(v) for v in grid.origin],
        "data": base64.b64encode(cells.tobytes()).decode("ascii"),
    }


def parse_trajectory(doc: Any, times: NDArray[np.float64]) -> NDArray[np.float64]:
    """The ``trajectory`` of the end reply: ``[[t, x, y, theta], ...]``, one row per frame at its time."""
    try:
        rows = np.array(doc, dtype=np.float64)
    except (TypeError, ValueError):
        rows = np.empty((0, 0))
    if rows.ndim != 2 or rows.shape != (len(times), 4) or not np.isfinite(rows).all():
        raise ProgramError(
            f"protocol: the end reply's trajectory must hold {len(times)} rows [t, x, y, theta] (one per frame), "
            f"got shape {rows.shape}"
        )
    if not np.array_equal(rows[:, 0], times):
        k = int(np.argmax(rows[:, 0] != times))
        raise ProgramError(
            f"protocol: the end reply's trajectory row {k} has t = {float(rows[k, 0])!r}, frame {k} is at {float(times[k])!r}"
        )
    return np.ascontiguousarray(rows[:, 1:])
