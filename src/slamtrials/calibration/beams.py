"""The laser's beams against the reference: each beam's reading beside the range cast in the reference map.

For every used frame the laser pose is the reference pose composed with the laser's mount; each beam is
cast twice with :func:`slamtrials.sim.raycast.cast_scan`, once against the reference map's walls only
and once against walls and unknown cells. A beam is kept when both casts stop at the same place before
the laser's maximum range: it hit a wall of the map after crossing only cells the map knows to be free.
Its incidence on the wall is that of the cell side it enters (:func:`incidence_cosines`), as the
simulator's dropout model has it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.calibration.reference import Reference
from slamtrials.geometry import compose1
from slamtrials.record import RunRecord
from slamtrials.sim.laser_errors import incidence_cosines
from slamtrials.sim.raycast import RaycastMap, cast_scan
from slamtrials.worlds.world import world_to_map

__all__ = ["BeamSample", "beam_sample"]


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
            frames_used=self.frames_used,
            frame_step=self.frame_step,
            beams_cast=self.beams_cast,
        )


def beam_sample(
    record: RunRecord, reference: Reference, max_beams: int, frames: NDArray[np.int64] | None = None
) -> BeamSample:
    """Cast the beams of every ``step``-th of ``frames`` (default all; ``step`` keeps the beams cast at
    most ``max_beams``)."""
    walls, known = reference.worlds()
    walls_map, known_map = RaycastMap.for_world(walls), RaycastMap.for_world(known)
    laser = record.laser
    beams = record.scans.shape[1]
    angles = np.ascontiguousarray(laser.beam_angles(beams))
    chosen = np.arange(len(record)) if frames is None else np.asarray(frames, dtype=np.int64)
    step = max(1, math.ceil(chosen.size * beams / max_beams))
    mount = laser.mount
    limit = float(laser.range_max)
    res = walls.resolution
    frame_ids: list[NDArray[np.int64]] = []
    beam_ids: list[NDArray[np.int64]] = []
    casts: list[NDArray[np.float64]] = []
    readings: list[NDArray[np.float64]] = []
    incidences: list[NDArray[np.float64]] = []
    used = 0
    for k in chosen[::step].tolist():
        used += 1
        pose = compose1(reference.poses[k], mount)
        uv = world_to_map(walls, pose[:2])
        theta = float(pose[2] - walls.origin[2])
        to_wall = cast_scan(walls_map.dist, uv, theta, angles, limit, res)
        to_known = cast_scan(known_map.dist, uv, theta, angles, limit, res)
        keep = (to_wall == to_known) & (to_wall > 0.0) & (to_wall < np.float32(limit))
        if not keep.any():
            continue
        index = np.flatnonzero(keep)
        cells = to_wall.astype(np.float64) / res
        cosines = incidence_cosines((float(uv[0]), float(uv[1])), theta, angles, cells)
        frame_ids.append(np.full(index.size, k, dtype=np.int64))
        beam_ids.append(index.astype(np.int64))
        casts.append(to_wall[index].astype(np.float64))
        readings.append(record.scans[k, index].astype(np.float64))
        incidences.append(cosines[index])
    if not frame_ids:
        empty = np.zeros(0)
        none = np.zeros(0, np.int64)
        return BeamSample(none, none, empty, empty, empty, np.zeros(0, bool), used, step, used * beams)
    reading = np.concatenate(readings)
    return BeamSample(
        frame=np.concatenate(frame_ids),
        beam=np.concatenate(beam_ids),
        cast=np.concatenate(casts),
        reading=reading,
        incidence=np.concatenate(incidences),
        no_return=reading >= limit,
        frames_used=used,
        frame_step=step,
        beams_cast=used * beams,
    )
