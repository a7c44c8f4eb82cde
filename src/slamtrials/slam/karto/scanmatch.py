"""Karto's correlative scan matcher (ScanMatcher::MatchScan): a coarse search over x, y and heading,
then a fine angular pass, with the covariance read off the response surface.

One :class:`ScanMatcher` is built per search space (the sequential matcher and the loop-closure
matcher). :meth:`ScanMatcher.match` rasterises the base scans (only their points that face the new
scan, Karto's FindValidPoints) into the smeared correlation grid centred on the new scan's laser pose,
searches it (:func:`~.correlation.correlate`) and returns the best laser pose, the response in [0, 1] and
the covariance (m^2, rad^2, map frame).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.slam.karto.correlation import (
    KT_TOLERANCE,
    MAX_VARIANCE,
    add_points,
    correlate,
    find_valid_points,
    karto_round,
    smear_kernel,
)

__all__ = ["MatchResult", "MatcherSettings", "ScanMatcher", "local_points", "points_in_map", "scan_points"]


@dataclass(frozen=True)
class MatchResult:
    """Outcome of one match.

    Attributes
    ----------
    response:
        Best (penalised) response, in [0, 1].
    pose:
        float64 ``[3]`` best laser pose (x, y, theta), map frame.
    covariance:
        float64 ``[3, 3]`` its covariance (m^2, rad^2), map frame.
    """

    response: float
    pose: NDArray[np.float64]
    covariance: NDArray[np.float64]


@dataclass(frozen=True)
class MatcherSettings:
    """The search settings every matcher of a mapper shares (Karto's mapper parameters; variances in m^2
    and rad^2, already squared)."""

    coarse_search_angle_offset: float
    coarse_angle_resolution: float
    fine_search_angle_offset: float
    distance_variance: float
    angle_variance: float
    minimum_distance_penalty: float
    minimum_angle_penalty: float
    use_response_expansion: bool


def points_in_map(
    laser_pose: NDArray[np.float64], lx: NDArray[np.float64], ly: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Laser-frame points ``[B]`` (NaN where a beam has none) seen from ``laser_pose`` ``[3]``: map-frame x, y."""
    c, s = math.cos(float(laser_pose[2])), math.sin(float(laser_pose[2]))
    return laser_pose[0] + c * lx - s * ly, laser_pose[1] + s * lx + c * ly


@njit(cache=True, nogil=True)
def scan_points(laser_pose, readings, angle_min, angle_increment):  # pragma: no cover - compiled
    """Karto's point readings of a scan taken at ``laser_pose`` (LocalizedRangeScan::Update), with its
    arithmetic: beam ``i`` at heading ``(theta + angle_min) + i angle_increment``, the point at
    ``x + r cos(heading)``, ``y + r sin(heading)``.

    ``laser_pose`` float64 ``[3]`` (map frame), ``readings`` float64 ``[B]`` ranges (m), NaN where a
    beam has no point. Returns map-frame ``x, y`` float64 ``[B]``, NaN where a beam has none.
    """
    n = readings.shape[0]
    x = np.empty(n)
    y = np.empty(n)
    for i in range(n):
        heading = (laser_pose[2] + angle_min) + i * angle_increment
        x[i] = laser_pose[0] + readings[i] * math.cos(heading)
        y[i] = laser_pose[1] + readings[i] * math.sin(heading)
    return x, y


@njit(cache=True, nogil=True)
def barycentre(x, y, within):  # pragma: no cover - compiled
    """Karto's barycentre: the sequential sum of the map-frame points flagged in ``within`` (bool
    ``[B]``), divided by their count; float64 ``[2]``, NaN when none is."""
    sx = 0.0
    sy = 0.0
    count = 0
    for i in range(x.shape[0]):
        if within[i]:
            sx += x[i]
            sy += y[i]
            count += 1
    out = np.full(2, np.nan)
    if count:
        out[0] = sx / count
        out[1] = sy / count
    return out


@njit(cache=True, nogil=True)
def local_points(laser_pose, x, y):  # pragma: no cover - compiled
    """Map-frame points ``[B]`` brought back into the frame of ``laser_pose`` as Karto's
    GridIndexLookup does it (Transform::InverseTransformPose): ``(c dx + s dy, -s dx + c dy)``."""
    c = math.cos(laser_pose[2])
    s = math.sin(laser_pose[2])
    n = x.shape[0]
    lx = np.empty(n)
    ly = np.empty(n)
    for i in range(n):
        dx = x[i] - laser_pose[0]
        dy = y[i] - laser_pose[1]
        lx[i] = c * dx + s * dy
        ly[i] = -s * dx + c * dy
    return lx, ly


class ScanMatcher:
    """A correlation grid and search space of one size (Karto's ScanMatcher::Create).

    Parameters
    ----------
    search_dimension:
        Side (m) of the square of positions searched.
    resolution:
        Grid cell (m); the coarse search steps two cells, the fine pass one.
    smear_deviation:
        Standard deviation (m) of the smearing kernel.
    range_threshold:
        Longest reading (m) the grid must hold around the searched positions.
    settings:
        Angular search and penalties.
    """

    def __init__(
        self,
        search_dimension: float,
        resolution: float,
        smear_deviation: float,
        range_threshold: float,
        settings: MatcherSettings,
    ):
        self.resolution = float(resolution)
        self.settings = settings
        self.search_side = karto_round(search_dimension / resolution) + 1
        self.roi = self.search_side + 2 * int(math.ceil(range_threshold / resolution))
        self.kernel = smear_kernel(resolution, smear_deviation)
        self.border = self.kernel.shape[0] // 2 + 1
        size = self.roi + 2 * self.border
        # Karto's Grid stores its rows with a stride rounded up to a multiple of 8 (AlignValue): the
        # padding stays zero, and a point read beyond a row's end lands there or on the next row
        self.grid = np.zeros((size, -(-size // 8) * 8), dtype=np.uint8)
        self._box = np.array([size, -1, size, -1], dtype=np.int64)  # written cells: rows, columns

    def _clear(self) -> None:
        r0, r1, c0, c1 = (int(v) for v in self._box)
        if r1 >= r0:
            self.grid[r0 : r1 + 1, c0 : c1 + 1] = 0
        size = self.grid.shape[0]
        self._box[:] = (size, -1, size, -1)

    def match(
        self,
        laser_pose: NDArray[np.float64],
        lx: NDArray[np.float64],
        ly: NDArray[np.float64],
        base: Sequence[tuple[NDArray[np.float64], NDArray[np.float64]]],
        *,
        penalize: bool = True,
        refine: bool = True,
    ) -> MatchResult:
        """Match a scan taken at ``laser_pose`` (map frame, the search centre) against ``base`` scans.

        Parameters
        ----------
        laser_pose:
            float64 ``[3]`` the scan's laser pose guess.
        lx, ly:
            float64 ``[B]`` its points in the laser frame, NaN where a beam has none.
        base:
            Map-frame points ``(x [B_i], y [B_i])`` of each base scan, beam order, NaN where none.
        penalize:
            Penalise poses far from the search centre (sequential matching does, loop closing does not).
        refine:
            Do the fine angular pass (the covariance's heading variance then comes from it).
        """
        s = self.settings
        n_beams = lx.shape[0]
        pose = np.asarray(laser_pose, dtype=np.float64)
        mean = pose.copy()
        covariance = np.zeros((3, 3))
        if n_beams == 0:
            covariance[0, 0] = covariance[1, 1] = MAX_VARIANCE
            covariance[2, 2] = 4.0 * s.coarse_angle_resolution**2
            return MatchResult(0.0, mean, covariance)
        res = self.resolution
        ox = pose[0] - 0.5 * (self.roi - 1) * res
        oy = pose[1] - 0.5 * (self.roi - 1) * res
        self._clear()
        inv_res = 1.0 / res
        for px, py in base:
            valid = find_valid_points(px, py, float(pose[0]), float(pose[1]))
            add_points(self.grid, self.border, self.roi, ox, oy, inv_res, px, py, valid, self.kernel, self._box)
        has_point = ~np.isnan(lx)
        mx, my = lx[has_point], ly[has_point]
        # GetResponse divides by the size of the scan's lookup array, one entry per unfiltered point reading:
        # every reading, those without a point (INVALID_SCAN) included
        n_readings = max(int(n_beams), 1)
        coarse_offset = 0.5 * (self.search_side - 1) * res
        coarse_step = 2.0 * res
        args = (s.distance_variance, s.minimum_distance_penalty, s.angle_variance, s.minimum_angle_penalty)
        best = correlate(
            self.grid,
            self.border,
            ox,
            oy,
            res,
            mx,
            my,
            n_readings,
            pose[0],
            pose[1],
            pose[2],
            coarse_offset,
            coarse_step,
            s.coarse_search_angle_offset,
            s.coarse_angle_resolution,
            penalize,
            *args,
            False,
            mean,
            covariance,
        )
        if s.use_response_expansion and abs(best) < KT_TOLERANCE:
            angle_offset = s.coarse_search_angle_offset
            for _ in range(3):
                angle_offset += math.radians(20.0)
                best = correlate(
                    self.grid,
                    self.border,
                    ox,
                    oy,
                    res,
                    mx,
                    my,
                    n_readings,
                    pose[0],
                    pose[1],
                    pose[2],
                    coarse_offset,
                    coarse_step,
                    angle_offset,
                    s.coarse_angle_resolution,
                    penalize,
                    *args,
                    False,
                    mean,
                    covariance,
                )
                if abs(best) >= KT_TOLERANCE:
                    break
        if refine:
            center = mean.copy()
            best = correlate(
                self.grid,
                self.border,
                ox,
                oy,
                res,
                mx,
                my,
                n_readings,
                center[0],
                center[1],
                center[2],
                res,
                res,
                0.5 * s.coarse_angle_resolution,
                s.fine_search_angle_offset,
                penalize,
                *args,
                True,
                mean,
                covariance,
            )
        return MatchResult(float(best), mean, covariance)
