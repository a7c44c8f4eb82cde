"""The reference a log is calibrated against: a path (one pose per frame) and a map.

On a real log the reference is a SLAM algorithm's best estimate (its final trajectory and map,
:func:`slam_reference`); on a simulated recording it can be the ground truth and the true world
(:meth:`Reference.from_world`), which is how the calibration is tested.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import CalibrationError
from slamtrials.record import OCCUPIED, UNKNOWN, OccupancyGrid, RunRecord
from slamtrials.slam.offline import run_over_recording
from slamtrials.worlds.world import World

__all__ = ["Reference", "slam_reference", "check_calibratable"]


@dataclass(frozen=True, eq=False)
class Reference:
    """A reference path and map.

    Attributes
    ----------
    poses:
        float64 ``[T, 3]`` robot base poses (map frame), one per frame of the recording.
    occupied:
        bool ``[H, W]`` wall cells (row 0 at the top, as :class:`~slamtrials.worlds.World`).
    unknown:
        bool ``[H, W]`` cells whose state the map does not know; a beam whose path enters one is not used.
    resolution:
        Cell size (m).
    origin:
        float64 ``[3]`` map pose of the grid's lower-left corner.
    source:
        What the reference is (e.g. ``"gmapping final estimate, seed 0"``).
    """

    poses: NDArray[np.float64]
    occupied: NDArray[np.bool_]
    unknown: NDArray[np.bool_]
    resolution: float
    origin: NDArray[np.float64]
    source: str

    @classmethod
    def from_grid(cls, poses: NDArray[np.float64], grid: OccupancyGrid, source: str) -> Reference:
        """A SLAM map (100 occupied, 0 free, -1 unknown) and path."""
        return cls(
            poses=np.asarray(poses, dtype=np.float64),
            occupied=grid.grid == OCCUPIED,
            unknown=grid.grid == UNKNOWN,
            resolution=float(grid.resolution),
            origin=np.asarray(grid.origin, dtype=np.float64),
            source=source,
        )

    @classmethod
    def from_world(cls, poses: NDArray[np.float64], world: World, source: str) -> Reference:
        """A known world (nothing unknown) and path, e.g. a simulation's truth."""
        return cls(
            poses=np.asarray(poses, dtype=np.float64),
            occupied=np.asarray(world.occupied, dtype=bool),
            unknown=np.zeros(world.occupied.shape, dtype=bool),
            resolution=float(world.resolution),
            origin=np.asarray(world.origin, dtype=np.float64),
            source=source,
        )

    def worlds(self) -> tuple[World, World]:
        """Two worlds on a grid padded by one unknown cell: walls only, and walls or unknown.

        A beam cast in both that stops at the same place crossed only known free cells before its wall.
        """
        occupied = np.pad(self.occupied, 1, constant_values=False)
        blocked = occupied | np.pad(self.unknown, 1, constant_values=True)
        origin = self.origin.copy()
        c, s = math.cos(origin[2]), math.sin(origin[2])
        origin[0] -= self.resolution * (c - s)  # one cell left and one down, in the grid's own frame
        origin[1] -= self.resolution * (s + c)
        free = np.flatnonzero(~blocked)
        if free.size == 0:
            raise CalibrationError("the reference map has no free cell")
        row, col = divmod(int(free[0]), blocked.shape[1])
        h = blocked.shape[0]
        u, v = (col + 0.5) * self.resolution, (h - row - 0.5) * self.resolution
        start = np.array([origin[0] + c * u - s * v, origin[1] + s * u + c * v, origin[2]])
        return (
            World(occupied=occupied, resolution=self.resolution, origin=origin, name="reference", start=start),
            World(occupied=blocked, resolution=self.resolution, origin=origin, name="reference-known", start=start),
        )


def check_calibratable(
    record: RunRecord,
    *,
    min_frames: int,
    min_distance: float,
    min_rotation: float,
    min_gap: float = 0.01,
    max_tiny_share: float = 0.5,
) -> None:
    """Raise :class:`CalibrationError` (one line, saying which) when ``record`` is too short, too irregular
    or has no odometry.

    Too irregular: frame times that are not finite or do not increase (lines out of order), or more than
    ``max_tiny_share`` of the frame gaps shorter than ``min_gap`` seconds (duplicated stamps): such a log's
    frames do not sample its motion in time, and its relations would not find their frames.
    """
    n = len(record)
    if n < min_frames:
        raise CalibrationError(f"the log is too short: {n} laser frames; calibration needs at least {min_frames}")
    t = np.asarray(record.t, dtype=np.float64)
    if not np.all(np.isfinite(t)):
        raise CalibrationError("the log is too irregular: some frame times are not finite")
    gaps = np.diff(t)
    back = np.flatnonzero(gaps < 0.0)
    if back.size:
        raise CalibrationError(
            f"the log is too irregular: its frame times go back {back.size} times (first at frame {int(back[0]) + 1}, "
            f"t = {t[back[0] + 1]:.3f} s); sort its lines by time"
        )
    tiny = int(np.count_nonzero(gaps < min_gap))
    if gaps.size and tiny > max_tiny_share * gaps.size:
        raise CalibrationError(
            f"the log is too irregular: {tiny} of its {gaps.size} frame gaps are shorter than {min_gap:g} s "
            f"(duplicated stamps); calibration allows at most {100 * max_tiny_share:g} %"
        )
    odo = record.odometry
    if not np.all(np.isfinite(odo)):
        raise CalibrationError("the log's odometry holds non-finite poses (no odometry to calibrate from)")
    step = np.diff(odo, axis=0)
    moved = float(np.sum(np.sqrt(step[:, 0] ** 2 + step[:, 1] ** 2)))
    turned = float(np.sum(np.abs((step[:, 2] + np.pi) % (2.0 * np.pi) - np.pi)))
    if moved == 0.0 and turned == 0.0:
        raise CalibrationError("the log has no odometry: its odometry pose never changes")
    if moved < min_distance:
        raise CalibrationError(
            f"the log is too short: its odometry travels {moved:.2f} m; calibration needs at least {min_distance:g} m"
        )
    if turned < min_rotation:
        raise CalibrationError(
            f"the log is too short: its odometry turns {turned:.2f} rad in all; calibration needs at least "
            f"{min_rotation:g} rad"
        )


def slam_reference(
    record: RunRecord,
    algorithm: str,
    *,
    preset: str | None = None,
    overrides: dict[str, Any] | None = None,
    seed: int = 0,
    on_frame: Callable[[int, int], None] | None = None,
) -> Reference:
    """Run ``algorithm`` over ``record``; its final trajectory and map are the reference."""
    run = run_over_recording(record, algorithm, preset=preset, overrides=overrides, seed=seed, on_frame=on_frame)
    poses = run.estimate_per_frame(record)
    settings = ", ".join(f"{k}={v}" for k, v in sorted((overrides or {}).items()))
    source = f"{algorithm} final estimate and map (seed {seed}{', preset ' + preset if preset else ''}"
    source += f", {settings})" if settings else ")"
    return Reference.from_grid(poses, run.occupancy, source)
