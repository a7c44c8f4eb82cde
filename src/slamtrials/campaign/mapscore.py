"""A run's map scored against its floor plan: :func:`score_map` and :func:`add_map_quality`.

The composition of :mod:`slamtrials.metric.mapquality` with a world: the floor plan's walls and the free
space connected to the run's true start (:meth:`slamtrials.worlds.World.reachable_free`), and the run's
final SLAM map placed on it by the least-squares rigid fit of its estimate to its truth
(:func:`slamtrials.metric.rigidfit.align_estimate`). Trials (``slamtrials trial`` and campaign runs) and
replays store the result in run.json under ``map_quality``
(:data:`~slamtrials.metric.mapquality.MAP_QUALITY_KEY`); a run without a map or an estimate has none.
"""

from __future__ import annotations

from numpy.typing import ArrayLike

from slamtrials.metric.mapquality import MAP_QUALITY_KEY, FloorPlan, MapQuality, map_quality
from slamtrials.metric.rigidfit import align_estimate
from slamtrials.record import RunRecord
from slamtrials.worlds import World

__all__ = ["floor_plan", "score_map", "add_map_quality"]


def floor_plan(world: World, start: ArrayLike | None = None) -> FloorPlan:
    """The truth a map is scored against: ``world``'s walls and the free cells 4-connected to ``start``
    (a world-frame pose ``[3]`` or position; default the world's start pose)."""
    return FloorPlan(world.occupied, world.reachable_free(start), world.resolution, world.origin)


def score_map(record: RunRecord, world: World) -> MapQuality | None:
    """The quality of ``record``'s final map (map frame) against ``world``'s floor plan, or None when the
    record has no map or no estimate; the reachable space is taken from the run's first true pose."""
    if record.map is None or record.estimate is None or len(record) == 0:
        return None
    alignment = align_estimate(record.estimate, record.truth)
    plan = floor_plan(world, record.truth[0])
    return map_quality(record.map, plan, alignment.world_from_map, alignment_rms_m=alignment.rms_m)


def add_map_quality(record: RunRecord, world: World) -> MapQuality | None:
    """Score ``record``'s map (:func:`score_map`) and store the result in its metadata under ``map_quality``
    (replacing any earlier one, e.g. a replay's source run's); return it."""
    quality = score_map(record, world)
    record.metadata.pop(MAP_QUALITY_KEY, None)
    if quality is not None:
        record.metadata[MAP_QUALITY_KEY] = quality.to_dict()
    return quality
