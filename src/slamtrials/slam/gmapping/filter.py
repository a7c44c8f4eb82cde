"""``gmapping``: a Rao-Blackwellized particle filter that behaves like the GMapping code (spec/gmapping.md).

Per reading (:meth:`GMapping.process`):

1. every particle moves by its own sample of the motion model (:mod:`.motion`);
2. the odometry travel and turn since the last processed reading are accumulated; the reading is
   processed when it is the first, or they reach ``linearUpdate`` / ``angularUpdate``, or more than
   ``temporalUpdate`` seconds passed (when that is >= 0);
3. processing (not the first reading): hill-climbing scan matching of every particle in its own map,
   log-likelihood added to its accumulated log weight, weights normalised with the ``ogain * N``
   divisor, systematic resampling when Neff < ``resampleThreshold * N`` (log weights then restart at
   0), and the scan's endpoints registered into every particle's map (:mod:`.tilemap`, copy-on-write
   tiles). The first reading is only registered.
4. when a processed reading comes more than ``map_update_interval`` seconds after the last map update,
   the published map is rebuilt from the best particle's path and the stored scans, with free-space
   ray tracing (:mod:`.published`).

Frames. As in slam_gmapping the filter tracks the LASER's pose: the odometry it uses is the laser's
(odometry composed with the laser mount) and the base pose is read back through the mount. The map
frame starts on the first reading's odometry pose, or ``initial_pose``.

Which particle is "best". As in the code: the one with the largest sum of all log-likelihoods along its
ancestry (GMapping's ``weightSum``, which resampling does not reset), not the largest log weight since the
last resampling.

Beams. A beam is used by the filter when ``range_min < r < range_max`` (a return), ``r <= maxUrange`` and
``r <= maxRange``; NaN, zero and no-return readings (``r >= range_max`` or ``+inf``, REP 117) are not. The
published map uses every return up to ``maxRange`` (cut at ``maxUrange``, marking free space only up to
the cut) and skips the rest, no-returns included (:mod:`slamtrials.slam.gridmap`). As in slam_gmapping,
``maxRange`` defaults to the laser's ``range_max - 0.01``, so a reading at the sensor's maximum (how Stage
and many drivers report no return) is skipped too.

Free-cell test. The original's likelihood is meant to skip a window cell whose "free" cell in front of
the endpoint holds endpoints, but its free cell lands off the map, so the test never rejects anything.
By default slamtrials does the same (no test, ``free_cell_test = False``); ``free_cell_test = True``
does the test as intended, with the free point one diagonal cell (``sqrt(2) * delta``) back along the beam.

Estimates. :meth:`GMapping.process` returns the online estimate, the current best particle's pose.
:meth:`GMapping.trajectory` returns the final best particle's path (one pose per processed reading, the
way GMapping's results are evaluated), with every other reading placed by odometry from the processed
reading nearest to it in time, as the spec's evaluation carries relation timestamps to the nearest
processed scan.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.geometry import compose, compose1, inverse, ominus, wrap_angle1
from slamtrials.record import LaserGeometry, Reading, Trajectory
from slamtrials.slam.base import OccupancyGrid, register_algorithm
from slamtrials.slam.gmapping.config import PRESETS, GMappingConfig, default_max_range
from slamtrials.slam.gmapping.kernels import match_particles
from slamtrials.slam.gmapping.lineage import Lineage
from slamtrials.slam.gmapping.motion import sample_motion
from slamtrials.slam.gmapping.published import PublishedMap
from slamtrials.slam.gmapping.tilemap import TileMaps
from slamtrials.slam.gmapping.weights import effective_sample_size, normalized_weights, systematic_resample

__all__ = ["GMapping"]


@register_algorithm
class GMapping:
    """GMapping as its code behaves (registry name ``gmapping``; see the module docstring).

    Parameters
    ----------
    config:
        Validated :class:`~slamtrials.slam.gmapping.config.GMappingConfig`.
    laser:
        The laser's geometry (:class:`~slamtrials.record.LaserGeometry`).

    Attributes
    ----------
    updates:
        Processed readings since :meth:`reset` (the first reading counts).
    resamplings:
        Resampling steps since :meth:`reset`.
    neff:
        Neff after the latest processed reading.
    """

    name: ClassVar[str] = "gmapping"
    Config: ClassVar[type[GMappingConfig]] = GMappingConfig
    PRESETS: ClassVar[dict[str, dict[str, Any]]] = PRESETS

    def __init__(self, config: GMappingConfig, laser: LaserGeometry):
        self.config = config
        self.laser = laser
        self.mount = np.asarray(laser.mount, dtype=np.float64)
        self.range_min = laser.range_min
        self.range_max = laser.range_max
        self.max_urange = self.range_max if config.maxUrange is None else float(config.maxUrange)
        self.max_range = (
            default_max_range(self.range_min, self.range_max) if config.maxRange is None else float(config.maxRange)
        )
        self.reset(np.random.default_rng(0))

    # ------------------------------------------------------------------ state

    def reset(self, rng: np.random.Generator) -> None:
        """Forget every reading; motion noise and resampling draws then come from ``rng``."""
        c = self.config
        self.rng = rng
        self.updates = 0
        self.resamplings = 0
        self.neff = float(c.particles)
        self.maps = TileMaps(c.particles, c.delta)
        self.poses = np.zeros((c.particles, 3))
        self.log_weights = np.zeros(c.particles)
        self.weight_sums = np.zeros(c.particles)
        self.lineage = Lineage()
        self.published = PublishedMap(
            c.delta, self.laser, max_urange=min(self.max_urange, self.range_max), occ_thresh=c.occ_thresh
        )
        self._scans: list[NDArray[np.float32]] = []  # scans of processed readings, maxRange applied
        self._t: list[float] = []
        self._odometry: list[NDArray[np.float64]] = []  # base odometry of every reading
        self._processed: list[int] = []  # reading index of every processed reading
        self._estimates: list[NDArray[np.float64]] = []
        self._last_laser_odometry: NDArray[np.float64] | None = None
        self._moved = 0.0
        self._turned = 0.0
        self._last_update_t = -math.inf
        self._last_map_t = -math.inf
        self._angles: NDArray[np.float64] | None = None

    @property
    def best_particle(self) -> int:
        """Index of the particle with the largest accumulated log-likelihood (GMapping's weightSum)."""
        return int(np.argmax(self.weight_sums))

    # ------------------------------------------------------------------ per reading

    def _used_beams(self, ranges: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """Laser-frame endpoints of the beams the filter uses.

        Returns ``(lx, ly, mx, my, lfx, lfy)``: ``lx, ly`` every usable return (registered into the
        maps), ``mx, my`` those of them the matcher and likelihood use (every ``lskip + 1``-th beam, as
        the original counts), ``lfx, lfy`` the free points of the latter, one diagonal cell back.
        """
        c = self.config
        angles = self._angles
        assert angles is not None
        usable = (
            ~np.isnan(ranges)
            & (ranges > self.range_min)
            & (ranges < self.range_max)
            & (ranges <= self.max_urange)
            & (ranges <= self.max_range)
        )
        matched = usable & (np.arange(ranges.shape[0]) % (c.lskip + 1) == c.lskip)
        r, a = ranges[usable], angles[usable]
        cos_a, sin_a = stablemath.cos(a), stablemath.sin(a)
        lx, ly = r * cos_a, r * sin_a
        keep = matched[usable]
        back = (r - math.sqrt(2.0) * c.delta)[keep]
        return lx, ly, lx[keep], ly[keep], back * cos_a[keep], back * sin_a[keep]

    def _register(self, lx: NDArray[np.float64], ly: NDArray[np.float64]) -> None:
        """Add the scan seen from every particle's pose to its map."""
        x, y, t = self.poses[:, 0:1], self.poses[:, 1:2], self.poses[:, 2:3]
        cos_t, sin_t = stablemath.cos(t), stablemath.sin(t)
        self.maps.register(x + cos_t * lx - sin_t * ly, y + sin_t * lx + cos_t * ly)

    def _due(self, t: float, laser_odometry: NDArray[np.float64]) -> bool:
        c = self.config
        if self._last_laser_odometry is None:
            return True
        dx, dy, dth = laser_odometry - self._last_laser_odometry
        self._moved += math.hypot(dx, dy)
        self._turned += abs(wrap_angle1(dth))
        if self._moved >= c.linearUpdate or self._turned >= c.angularUpdate:
            return True
        return c.temporalUpdate >= 0 and t - self._last_update_t > c.temporalUpdate

    def _update(
        self, lx: NDArray[np.float64], ly: NDArray[np.float64], lfx: NDArray[np.float64], lfy: NDArray[np.float64]
    ) -> None:
        """Scan matching, weighing and (maybe) resampling of every particle (spec sections 3 and 4)."""
        c = self.config
        m = self.maps
        matched, _, likelihoods = match_particles(
            m.directories,
            m.mean.reshape(-1),
            m.tile_col0,
            m.tile_row0,
            c.delta,
            self.poses,
            lx,
            ly,
            lfx,
            lfy,
            c.kernelSize,
            c.sigma,
            c.lsigma,
            c.free_cell_test,
            c.lstep,
            c.astep,
            c.iterations,
            c.minimumScore,
        )
        self.poses = matched
        self.log_weights += likelihoods
        self.weight_sums += likelihoods
        weights = normalized_weights(self.log_weights, c.ogain)
        self.neff = effective_sample_size(weights)
        self.lineage.add(self.poses)
        if self.neff < c.resampleThreshold * c.particles:
            indexes = systematic_resample(weights, float(self.rng.random()))
            self.poses = self.poses[indexes]
            self.weight_sums = self.weight_sums[indexes]
            self.log_weights = np.zeros(c.particles)
            self.maps.resample(indexes)
            self.lineage.resampled(indexes)
            self.resamplings += 1

    def process(self, frame: Reading) -> NDArray[np.float64]:
        """Take one reading; return the best particle's base pose (map frame), float64 ``[3]``."""
        c = self.config
        t = float(frame.t)
        ranges = np.asarray(frame.ranges, dtype=np.float64)
        odometry = np.asarray(frame.odometry, dtype=np.float64)
        laser_odometry = compose1(odometry, self.mount)
        if self._angles is None or self._angles.shape[0] != ranges.shape[0]:
            self._angles = self.laser.beam_angles(ranges.shape[0])
        previous = self._last_laser_odometry
        first = previous is None
        if previous is None:
            start = laser_odometry if c.initial_pose is None else compose1(np.asarray(c.initial_pose), self.mount)
            self.poses[:] = start
        else:
            self.poses = sample_motion(self.poses, previous, laser_odometry, c.srr, c.srt, c.str, c.stt, self.rng)
        due = self._due(t, laser_odometry)
        self._last_laser_odometry = laser_odometry
        if due:
            lx, ly, mx, my, lfx, lfy = self._used_beams(ranges)
            if first:
                self.lineage.add(self.poses)
            else:
                self._update(mx, my, lfx, lfy)
            self._register(lx, ly)
            self._scans.append(np.where(ranges > self.max_range, np.nan, ranges).astype(np.float32))
            self._processed.append(len(self._t))
            self.updates += 1
            self._moved = self._turned = 0.0
            self._last_update_t = t
            if t - self._last_map_t > c.map_update_interval:
                self.published.rebuild(self.lineage.path(self.best_particle), self._scans)
                self._last_map_t = t
        estimate = compose1(self.poses[self.best_particle], inverse(self.mount))
        self._t.append(t)
        self._odometry.append(odometry)
        self._estimates.append(estimate)
        return estimate

    # ------------------------------------------------------------------ results

    def occupancy(self) -> OccupancyGrid:
        """The published map: rebuilt on a processed reading more than ``map_update_interval`` seconds
        after the last rebuild, as slam_gmapping publishes it (so up to that long out of date)."""
        return self.published.occupancy()

    def trajectory(self) -> Trajectory:
        """The final best particle's path; every reading is placed by odometry from the processed reading
        nearest to it in time (before or after it; the earlier one on a tie)."""
        t = np.array(self._t, dtype=np.float64)
        if not self._processed:
            return Trajectory(t=t, poses=np.zeros((0, 3)))
        odometry = np.array(self._odometry, dtype=np.float64)
        processed = np.array(self._processed, dtype=np.intp)
        path = compose(self.lineage.path(self.best_particle), inverse(self.mount))
        before = np.searchsorted(processed, np.arange(t.shape[0]), side="right") - 1
        after = np.minimum(before + 1, processed.shape[0] - 1)
        anchor = np.where(t[processed[after]] - t < t - t[processed[before]], after, before)
        poses = compose(path[anchor], ominus(odometry[processed[anchor]], odometry))
        return Trajectory(t=t, poses=poses)

    def online_estimates(self) -> NDArray[np.float64]:
        """float64 ``[T, 3]``: what :meth:`process` returned for every reading."""
        return np.array(self._estimates, dtype=np.float64).reshape(-1, 3)
