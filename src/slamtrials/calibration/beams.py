"""The laser's beams against the reference: each beam's reading beside the range cast in the reference map.

For every used frame the laser pose is the reference pose composed with the laser's mount; each beam is
cast twice with :func:`slamtrials.sim.raycast.cast_scan`, once against the reference map's walls only
and once against walls and unknown cells. A beam is kept when both casts stop at the same place before
the laser's maximum range: it hit a wall of the map after crossing only cells the map knows to be free.
Its incidence on the wall is that of the cell side it enters (:func:`incidence_cosines`), as the
simulator's dropout model has it. Beside each kept beam goes the nearest wall range cast for its
neighbours within the edge reach (any beam of the scan, kept or not), for the fit of the edge model
(:mod:`slamtrials.sim.edges`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.calibration.reference import Reference
from slamtrials.geometry import compose1
from slamtrials.record import RunRecord
from slamtrials.sim.edges import nearest_neighbour_range, reach_in_beams
from slamtrials.sim.laser_errors import incidence_cosines
from slamtrials.sim.raycast import RaycastMap, cast_scan
from slamtrials.worlds.world import world_to_map

__all__ = ["BeamSample", "beam_sample", "FrameCast", "FrameCaster"]


@dataclass(frozen=True, eq=False)
class BeamSample:
    """The kept beams, in frame order.

    Attributes
    ----------
    frame:
        int64 ``[N]`` index of each beam's frame in the recording.
    beam:
        int64 ``[N]`` index of the beam in its scan (neighbours differ by 1).
    cast:
        float64 ``[N]`` range (m) cast in the reference map (a wall within the laser's range).
    reading:
        float64 ``[N]`` the recorded reading (m).
    incidence:
        float64 ``[N]`` ``|cos|`` of the angle between the beam and the normal of the wall cell side.
    no_return:
        bool ``[N]`` the reading is the laser's "nothing" (``>= range_max``).
    nearer:
        float64 ``[N]`` the shortest range (m) cast for the beam's neighbours up to the edge reach to either
        side (``inf`` with a reach of no beam).
    frames_used:
        How many frames were cast (every ``frame_step``-th one).
    frame_step:
        The thinning step of the frames.
    beams_cast:
        All beams cast, kept or not.
    """

    frame: NDArray[np.int64]
    beam: NDArray[np.int64]
    cast: NDArray[np.float64]
    reading: NDArray[np.float64]
    incidence: NDArray[np.float64]
    no_return: NDArray[np.bool_]
    nearer: NDArray[np.float64]
    frames_used: int
    frame_step: int
    beams_cast: int

    def take(self, index: NDArray[np.int64]) -> BeamSample:
        """The beams at ``index`` (a bootstrap resample)."""
        return BeamSample(
            frame=self.frame[index],
            beam=self.beam[index],
            cast=self.cast[index],
            reading=self.reading[index],
            incidence=self.incidence[index],
            no_return=self.no_return[index],
            nearer=self.nearer[index],
            frames_used=self.frames_used,
            frame_step=self.frame_step,
            beams_cast=self.beams_cast,
        )

    def with_cast(self, cast: NDArray[np.float64]) -> BeamSample:
        """The same beams with other walls ``cast`` ``[N]`` (m): those the beams are taken to have read."""
        return BeamSample(
            frame=self.frame,
            beam=self.beam,
            cast=np.asarray(cast, dtype=np.float64),
            reading=self.reading,
            incidence=self.incidence,
            no_return=self.no_return,
            nearer=self.nearer,
            frames_used=self.frames_used,
            frame_step=self.frame_step,
            beams_cast=self.beams_cast,
        )


@dataclass(frozen=True, eq=False)
class FrameCast:
    """One frame's beams cast in the reference map.

    Attributes
    ----------
    laser_pose:
        float64 ``[3]`` the laser's pose (map frame: m, m, rad).
    ranges:
        float32 ``[B]`` range (m) to the first wall of the map, ``range_max`` where none is within it.
    kept:
        bool ``[B]`` the beam hit a wall within the laser's range through known free space only.
    nearer:
        float64 ``[B]`` the shortest of ``ranges`` among each beam's neighbours within the edge reach.
    incidence:
        float64 ``[B]`` ``|cos|`` of the angle between the beam and the normal of the wall cell side.
    """

    laser_pose: NDArray[np.float64]
    ranges: NDArray[np.float32]
    kept: NDArray[np.bool_]
    incidence: NDArray[np.float64]
    nearer: NDArray[np.float64]


class FrameCaster:
    """Casts the frames of ``record`` from the reference poses in the reference map (module docstring);
    ``edge_reach`` (rad) is how far to either side a beam's neighbours are looked at for ``nearer``."""

    def __init__(self, record: RunRecord, reference: Reference, edge_reach: float = 0.0) -> None:
        self._walls, known = reference.worlds()
        self._walls_map, self._known_map = RaycastMap.for_world(self._walls), RaycastMap.for_world(known)
        self._poses = reference.poses
        self._mount = record.laser.mount
        self._limit = float(record.laser.range_max)
        self.angles: NDArray[np.float64] = np.ascontiguousarray(record.laser.beam_angles(record.scans.shape[1]))
        self.reach_beams = reach_in_beams(edge_reach, float(record.laser.angle_increment))

    def cast(self, k: int) -> FrameCast:
        """Frame ``k``'s beams."""
        walls, res = self._walls, self._walls.resolution
        pose = compose1(self._poses[k], self._mount)
        uv = world_to_map(walls, pose[:2])
        theta = float(pose[2] - walls.origin[2])
        to_wall = cast_scan(self._walls_map.dist, uv, theta, self.angles, self._limit, res)
        to_known = cast_scan(self._known_map.dist, uv, theta, self.angles, self._limit, res)
        kept = (to_wall == to_known) & (to_wall > 0.0) & (to_wall < np.float32(self._limit))
        cells = to_wall.astype(np.float64) / res
        incidence = incidence_cosines((float(uv[0]), float(uv[1])), theta, self.angles, cells)
        nearer = nearest_neighbour_range(to_wall.astype(np.float64), self.reach_beams)
        return FrameCast(laser_pose=pose, ranges=to_wall, kept=kept, incidence=incidence, nearer=nearer)


def beam_sample(
    record: RunRecord,
    reference: Reference,
    max_beams: int,
    frames: NDArray[np.int64] | None = None,
    edge_reach: float = 0.0,
) -> BeamSample:
    """Cast the beams of every ``step``-th of ``frames`` (default all; ``step`` keeps the beams cast at
    most ``max_beams``); ``edge_reach`` (rad) as for :class:`FrameCaster`."""
    caster = FrameCaster(record, reference, edge_reach)
    beams = record.scans.shape[1]
    chosen = np.arange(len(record)) if frames is None else np.asarray(frames, dtype=np.int64)
    step = max(1, math.ceil(chosen.size * beams / max_beams))
    frame_ids: list[NDArray[np.int64]] = []
    beam_ids: list[NDArray[np.int64]] = []
    casts: list[NDArray[np.float64]] = []
    readings: list[NDArray[np.float64]] = []
    incidences: list[NDArray[np.float64]] = []
    nearers: list[NDArray[np.float64]] = []
    used = 0
    for k in chosen[::step].tolist():
        used += 1
        cast = caster.cast(k)
        if not cast.kept.any():
            continue
        index = np.flatnonzero(cast.kept)
        frame_ids.append(np.full(index.size, k, dtype=np.int64))
        beam_ids.append(index.astype(np.int64))
        casts.append(cast.ranges[index].astype(np.float64))
        readings.append(record.scans[k, index].astype(np.float64))
        incidences.append(cast.incidence[index])
        nearers.append(cast.nearer[index])
    limit = float(record.laser.range_max)
    if not frame_ids:
        empty = np.zeros(0)
        none = np.zeros(0, np.int64)
        return BeamSample(none, none, empty, empty, empty, np.zeros(0, bool), empty, used, step, used * beams)
    reading = np.concatenate(readings)
    return BeamSample(
        frame=np.concatenate(frame_ids),
        beam=np.concatenate(beam_ids),
        cast=np.concatenate(casts),
        reading=reading,
        incidence=np.concatenate(incidences),
        no_return=reading >= limit,
        nearer=np.concatenate(nearers),
        frames_used=used,
        frame_step=step,
        beams_cast=used * beams,
    )
