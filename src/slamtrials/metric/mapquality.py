"""How well a SLAM map draws the floor plan: :class:`MapQuality`, computed by :func:`map_quality`.

The final SLAM map (map frame) is placed on the floor plan (world frame) by the run's alignment of its
estimate to its truth (:func:`slamtrials.metric.rigidfit.align_estimate`: ``world_from_map``), each cell
taken at its centre and looked up in the nearest cell of the other grid. A map cell is occupied when its
value is at least 50, free when it is 0 to 49, unknown when negative (a trinary map holds 100, 0 and -1);
unknown cells count as neither. Distances are between cell centres (m); a tolerance of ``k`` cells is
``k`` times the SLAM map's resolution. The reachable space is the free space of the floor plan connected
to the robot's start, and its walls are the floor plan's wall (or obstacle) cells that share a side with
it: the surfaces the laser can see from there (:meth:`FloorPlan.wall_faces`; the inside of a thick wall,
and the mass of occupied cells a floor plan has around a building, are not walls anyone could map). The
figures (:data:`DEFINITIONS` says each in one line):

* ``occupied_precision_k``: share of the map's occupied cells within ``k`` cells of a wall;
* ``occupied_recall_k``: share of the walls within ``k`` cells of an occupied map cell;
* ``free_iou``: area mapped free that lies on reachable space, over the area mapped free or reachable;
* ``ghost_free_m2``: area (m^2) mapped free farther than one cell (:data:`GHOST_TOLERANCE_CELLS`) from the
  reachable space: free space where the building has walls, is outside, or is closed off from the start.

Distances come from exact Euclidean distance transforms (``scipy.ndimage.distance_transform_edt``, integer
arithmetic and one square root); the only floating-point steps are the cells' placement (stablemath's
sine and cosine) and a few divisions, so the figures are the same bits on every machine.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from slamtrials.geometry import as_poses, inverse, transform_points
from slamtrials.metric.raster import Raster
from slamtrials.record import OccupancyGrid

__all__ = [
    "FloorPlan",
    "MapQuality",
    "map_quality",
    "MAP_QUALITY_KEY",
    "MAP_QUALITY_FORMAT",
    "MAP_QUALITY_FIGURES",
    "DEFINITIONS",
    "TOLERANCES_CELLS",
    "GHOST_TOLERANCE_CELLS",
]

#: run.json key (and metadata key of a record) of a run's map quality.
MAP_QUALITY_KEY = "map_quality"
#: Format tag of the ``map_quality`` object.
MAP_QUALITY_FORMAT = "slamtrials-mapquality/1"
#: The tolerances (SLAM map cells) of the occupied-cell precision and recall.
TOLERANCES_CELLS = (1, 2)
#: How far (SLAM map cells) from the reachable space a free map cell may lie before it counts as ghost:
#: one cell absorbs where the edge of the free space falls between two cells.
GHOST_TOLERANCE_CELLS = 1
#: The figures of a :class:`MapQuality` that campaigns keep per run and average per world.
MAP_QUALITY_FIGURES = (
    "occupied_precision_1",
    "occupied_recall_1",
    "occupied_precision_2",
    "occupied_recall_2",
    "free_iou",
    "ghost_free_m2",
)
#: One line per figure: what it measures (the report and the docs print these).
DEFINITIONS = {
    "occupied_precision_1": "share of the map's occupied cells within 1 cell of a wall of the floor plan (a wall "
    "cell that shares a side with the reachable space)",
    "occupied_recall_1": "share of those wall cells of the floor plan within 1 cell of an occupied map cell",
    "occupied_precision_2": "the same share of occupied cells, within 2 cells",
    "occupied_recall_2": "the same share of wall cells, within 2 cells",
    "free_iou": "area mapped free on reachable space over the area mapped free or reachable (intersection over union)",
    "ghost_free_m2": "area (m^2) mapped free more than 1 cell from the reachable space (inside walls, outside the "
    "building, or closed off from the start)",
}

_OCCUPIED_FROM = 50  # cell values >= this are occupied, 0..49 free, negative unknown


@dataclass(frozen=True, eq=False)
class FloorPlan:
    """The truth a SLAM map is scored against: the floor plan's walls and its reachable space.

    Attributes
    ----------
    walls:
        bool ``[H, W]``: True where the floor plan has a wall or obstacle (row 0 the top row).
    reachable:
        bool ``[H, W]``: the free cells connected to the robot's start.
    resolution:
        Cell size (m).
    origin:
        float64 ``[3]``: world-frame pose (x m, y m, theta rad) of the lower-left corner of the grid.
    """

    walls: NDArray[np.bool_]
    reachable: NDArray[np.bool_]
    resolution: float
    origin: NDArray[np.float64]

    def __post_init__(self) -> None:
        walls, reachable = np.asarray(self.walls, dtype=bool), np.asarray(self.reachable, dtype=bool)
        if walls.ndim != 2 or walls.shape != reachable.shape:
            raise ValueError(f"walls {walls.shape} and reachable {reachable.shape} must be the same [H, W]")
        if (walls & reachable).any():
            raise ValueError("a reachable cell cannot be a wall")
        object.__setattr__(self, "walls", walls)
        object.__setattr__(self, "reachable", reachable)
        object.__setattr__(self, "resolution", float(self.resolution))

    def wall_faces(self) -> NDArray[np.bool_]:
        """bool ``[H, W]``: the wall cells that share a side with a reachable cell, the walls the robot can see."""
        cross = ndimage.generate_binary_structure(2, 1)
        return self.walls & ndimage.binary_dilation(self.reachable, structure=cross)

    @property
    def raster(self) -> Raster:
        """Where the plan's cells lie in the world frame."""
        return Raster.of(self.walls.shape, self.resolution, self.origin)


@dataclass(frozen=True)
class MapQuality:
    """How well one SLAM map draws the floor plan (module docstring; :data:`DEFINITIONS`).

    Every share is in [0, 1] and None where undefined (no occupied map cell, no wall, nothing mapped free
    and nothing reachable). A wall is a wall cell of the floor plan that shares a side with the reachable
    space (:meth:`FloorPlan.wall_faces`); a cell is the SLAM map's.

    Attributes
    ----------
    occupied_precision_1, occupied_precision_2:
        Share of the map's occupied cells within 1 (2) cells of a wall.
    occupied_recall_1, occupied_recall_2:
        Share of the walls within 1 (2) cells of an occupied map cell.
    free_iou:
        Area mapped free on reachable space over the area mapped free or reachable.
    ghost_free_m2:
        Area (m^2) mapped free farther than 1 cell from the reachable space.
    cell_m:
        The SLAM map's resolution (m): one cell of the tolerances.
    alignment_rms_m:
        RMS distance (m) between the estimated positions placed on the truth and the true ones: how well
        one rigid motion places the map (a bent map or a large error leaves it large); None if unknown.
    """

    occupied_precision_1: float | None
    occupied_recall_1: float | None
    occupied_precision_2: float | None
    occupied_recall_2: float | None
    free_iou: float | None
    ghost_free_m2: float
    cell_m: float
    alignment_rms_m: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON form stored in run.json under :data:`MAP_QUALITY_KEY` (``format`` first)."""
        return {"format": MAP_QUALITY_FORMAT, **asdict(self)}

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> MapQuality:
        """Read the JSON form; a missing or non-numeric figure reads as None (``ghost_free_m2``, ``cell_m``: NaN)."""
        values: dict[str, Any] = {}
        for item in fields(cls):
            value = _figure(doc.get(item.name))
            values[item.name] = math.nan if value is None and item.name in ("ghost_free_m2", "cell_m") else value
        return cls(**values)

    @classmethod
    def of(cls, metadata: Mapping[str, Any]) -> MapQuality | None:
        """The map quality stored in a record's metadata (or a run.json document); None for a run without one
        (a run of an earlier version, or one without a map)."""
        doc = metadata.get(MAP_QUALITY_KEY)
        return cls.from_dict(doc) if isinstance(doc, Mapping) else None

    def figures(self) -> dict[str, float | None]:
        """The :data:`MAP_QUALITY_FIGURES` by name (None where undefined)."""
        return {name: _figure(getattr(self, name)) for name in MAP_QUALITY_FIGURES}


def _figure(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def _share(hits: NDArray[np.bool_]) -> float | None:
    return float(np.count_nonzero(hits)) / hits.size if hits.size else None


def _distance_m(mask: NDArray[np.bool_], raster: Raster, pad: int) -> tuple[NDArray[np.float64], Raster]:
    """Distance (m) from every cell of ``mask`` padded by ``pad`` cells to the nearest set cell (inf for none)."""
    padded = np.pad(mask, pad, constant_values=False)
    if not padded.any():
        return np.full(padded.shape, math.inf), raster.padded(pad)
    return ndimage.distance_transform_edt(~padded) * raster.resolution, raster.padded(pad)


def map_quality(
    slam_map: OccupancyGrid,
    plan: FloorPlan,
    world_from_map: ArrayLike,
    *,
    alignment_rms_m: float | None = None,
) -> MapQuality:
    """Score ``slam_map`` against ``plan`` (module docstring).

    Parameters
    ----------
    slam_map:
        The SLAM map (map frame): int8 ``[h, w]`` cells, resolution and origin.
    plan:
        The floor plan and its reachable space (world frame).
    world_from_map:
        ``[3]`` (x m, y m, theta rad): the pose of the map frame in the world frame, e.g.
        :attr:`slamtrials.metric.rigidfit.EstimateAlignment.world_from_map`.
    alignment_rms_m:
        Stored as :attr:`MapQuality.alignment_rms_m`.
    """
    pose = as_poses(world_from_map).reshape(3)
    grid = np.asarray(slam_map.grid)
    cell = float(slam_map.resolution)
    map_raster = Raster.of(grid.shape, cell, slam_map.origin)
    plan_raster = plan.raster
    tolerances = tuple(k * cell for k in TOLERANCES_CELLS)
    slack = 1e-9 * cell  # a distance of exactly k cells is within k cells
    occupied = grid >= _OCCUPIED_FROM
    free = (grid >= 0) & ~occupied

    walls = plan.wall_faces()

    # precision: occupied map cells, placed on the plan, near a wall
    plan_pad = int(math.ceil(max(tolerances) / plan.resolution)) + 2
    to_wall, wall_raster = _distance_m(walls, plan_raster, plan_pad)
    placed = transform_points(pose, map_raster.centres(*np.nonzero(occupied)))
    wall_gap = wall_raster.sample(to_wall, placed, math.inf)
    precision = [_share(wall_gap <= tol + slack) for tol in tolerances]

    # recall: the plan's walls, placed on the map, near an occupied map cell
    map_pad = max(TOLERANCES_CELLS) + 2
    to_occupied, occupied_raster = _distance_m(occupied, map_raster, map_pad)
    seen_from_map = transform_points(inverse(pose), plan_raster.centres(*np.nonzero(walls)))
    map_gap = occupied_raster.sample(to_occupied, seen_from_map, math.inf)
    recall = [_share(map_gap <= tol + slack) for tol in tolerances]

    # free space: free map cells, placed on the plan, on (or near) the reachable space
    free_centres = transform_points(pose, map_raster.centres(*np.nonzero(free)))
    on_reachable = plan_raster.sample(plan.reachable, free_centres, False)
    ghost_pad = int(math.ceil(GHOST_TOLERANCE_CELLS * cell / plan.resolution)) + 2
    to_reachable, reachable_raster = _distance_m(plan.reachable, plan_raster, ghost_pad)
    ghost = reachable_raster.sample(to_reachable, free_centres, math.inf) > GHOST_TOLERANCE_CELLS * cell + slack
    cell_area = cell * cell
    both = float(np.count_nonzero(on_reachable)) * cell_area
    union = (
        float(free_centres.shape[0]) * cell_area + float(np.count_nonzero(plan.reachable)) * plan.resolution**2 - both
    )
    return MapQuality(
        occupied_precision_1=precision[0],
        occupied_recall_1=recall[0],
        occupied_precision_2=precision[1],
        occupied_recall_2=recall[1],
        free_iou=both / union if union > 0 else None,
        ghost_free_m2=float(np.count_nonzero(ghost)) * cell_area,
        cell_m=cell,
        alignment_rms_m=_figure(alignment_rms_m),
    )
