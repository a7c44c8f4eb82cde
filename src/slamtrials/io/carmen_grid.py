"""Putting laser lines whose beam count or geometry changes onto one angular grid, for ``[N, B]`` scans.

A run record holds scans as one ``[T, B]`` array with one geometry, so lines with different beam counts
can only be stacked when their beams fall on one common grid of angles: the same angular increment,
first beams that differ by whole increments. Each line is then placed at its offset on the widest grid
that covers them all, and the cells it does not cover are filled with no-return readings (the common
maximum range). Lines with a shorter maximum range have their no-return readings raised to the common
one (a reading of the line's own maximum means no return there, and must still mean so). Lines on
another grid cannot be stacked without resampling, which slamtrials does not do: FormatError at the
first such line; so are lines whose common grid would be more than twice as wide as the widest line
(beams shifted that far apart are not one laser). Lines without readings (pose-only) fit any grid and become all no-return.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import FormatError

__all__ = ["CommonGrid", "common_grid"]

#: Largest difference (rad) between two increments taken as the same, and largest fraction of an
#: increment between a line's first beam and the grid: geometry is read from 6-decimal text.
_INCREMENT_TOL = 1e-9
_OFFSET_TOL = 1e-6


@dataclass(frozen=True, eq=False)
class CommonGrid:
    """Scans stacked on one grid.

    Attributes
    ----------
    ranges:
        float32 ``[N, B]`` readings (m); ``B`` = 0 when no line has readings.
    angle_min, angle_increment, range_max:
        The common geometry (rad, rad, m).
    padded:
        Indices of the lines that had fewer than ``B`` readings (filled with ``range_max``).
    raised:
        Indices of the lines whose maximum range was below ``range_max``.
    """

    ranges: NDArray[np.float32]
    angle_min: float
    angle_increment: float
    range_max: float
    padded: NDArray[np.int64]
    raised: NDArray[np.int64]


def _same_everywhere(geometry: NDArray[np.float64], counts: NDArray[np.int64]) -> bool:
    return bool((counts == counts[0]).all() and (geometry == geometry[0]).all())


def common_grid(
    path: Path, kind: str, numbers: list[int], ranges: list[NDArray[np.float64]], geometry: NDArray[np.float64]
) -> CommonGrid:
    """Stack the readings of ``N`` lines on their common angular grid (see the module docstring).

    Parameters
    ----------
    path, kind, numbers:
        The file, the line type and each line's 1-based number (for messages).
    ranges:
        ``N`` float64 arrays of readings (m), of any lengths.
    geometry:
        float64 ``[N, 3]``: each line's angle of the first beam, angular increment (rad) and maximum
        range (m).

    Raises
    ------
    FormatError
        At the first line whose beams are not on the grid of the first line with readings.
    """
    n = len(ranges)
    counts = np.array([len(r) for r in ranges], dtype=np.int64)
    none = np.zeros(0, dtype=np.int64)
    if _same_everywhere(geometry, counts):
        stacked = np.stack(ranges) if counts[0] else np.zeros((n, 0))
        return CommonGrid(
            stacked.astype(np.float32), float(geometry[0, 0]), float(geometry[0, 1]), float(geometry[0, 2]), none, none
        )
    range_max = float(geometry[:, 2].max())
    with_readings = np.flatnonzero(counts > 0)
    if with_readings.size == 0:
        return CommonGrid(
            np.zeros((n, 0), np.float32),
            float(geometry[0, 0]),
            float(geometry[0, 1]),
            range_max,
            none,
            np.flatnonzero(geometry[:, 2] < range_max),
        )
    ref = int(with_readings[0])
    start0, increment = float(geometry[ref, 0]), float(geometry[ref, 1])
    offsets = np.zeros(n, dtype=np.int64)
    widest = int(counts.max())
    for i in with_readings.tolist():
        start, inc = float(geometry[i, 0]), float(geometry[i, 1])
        same_increment = counts[i] == 1 or abs(inc - increment) <= _INCREMENT_TOL * max(1.0, abs(increment))
        steps = (start - start0) / increment if increment != 0 else (0.0 if start == start0 else np.inf)
        near = abs(steps) <= widest + 1  # finite and small enough to round; shifts beyond the widest line refused
        on_grid = same_increment and near and abs(steps - round(steps)) <= _OFFSET_TOL and abs(round(steps)) <= widest
        if not on_grid:
            raise FormatError(
                path,
                f"{kind} has {counts[i]} readings from {start!r} rad every {inc!r} rad, not on the angular "
                f"grid of line {numbers[ref]} ({counts[ref]} from {start0!r} every {increment!r}): slamtrials "
                "stacks scans on one grid (slamtrials evaluate reads only the poses of such a log)",
                line=numbers[i],
            )
        offsets[i] = round(steps)
    low = int(offsets[with_readings].min())
    high = int((offsets + counts - 1)[with_readings].max())
    beams = high - low + 1
    if beams > 2 * widest:
        i = int(with_readings[np.argmax((offsets != offsets[ref])[with_readings])])
        raise FormatError(
            path,
            f"{kind} lines on one angular grid would span {beams} beams, more than twice the widest "
            f"line ({widest}): not one laser (slamtrials evaluate reads only the poses of such a log)",
            line=numbers[i],
        )
    out = np.full((n, beams), range_max, dtype=np.float64)
    for i in with_readings.tolist():
        row = ranges[i]
        if geometry[i, 2] < range_max:
            row = np.where(row >= geometry[i, 2], range_max, row)
        out[i, offsets[i] - low : offsets[i] - low + counts[i]] = row
    padded = np.flatnonzero(counts < beams)
    raised = np.flatnonzero(geometry[:, 2] < range_max)
    return CommonGrid(out.astype(np.float32), start0 + low * increment, increment, range_max, padded, raised)
