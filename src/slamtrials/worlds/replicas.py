"""Replicas of the paper's own validation settings (Section IV, Tables II and III), drawn from rectangles.

The paper validates its simulator against two real data sets: the L-shaped industrial hall of its
reference [26] (10 x 12 m, one run in the empty hall, one furnished; Table II) and the 9 x 9 m AIRLab
laboratory of the Politecnico di Milano (Table III, Fig. 7). Neither floor plan is published: the paper
gives only the sizes, the words "L-shaped", "empty" and "furnished", and the small map pictures of Fig. 7.
**The layouts below are guesses** from that text: the outer bounds are the paper's, the shape of the L
(which corner is cut away, and how much), the furniture and the start poses are ours.

A replica is a union of free floor rectangles with solid obstacle rectangles on top (shelves, machines,
desks and cabinets drawn as solid blocks, as a Stage world draws them), in plan metres with the floor's
lower-left corner at (0, 0). Everything else, including a 0.5 m margin around the floor, is occupied, so
the building's outer walls are the edge of the free space. The grid is 0.05 m per cell, as every bundled
world. :func:`build_replica` draws one; :mod:`slamtrials.worlds.catalog_build` writes them into the
bundled catalog, and the test suite redraws them bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from slamtrials.errors import WorldError
from slamtrials.worlds.generate.plan import Rect
from slamtrials.worlds.generate.raster import Grid
from slamtrials.worlds.world import World

__all__ = ["ReplicaSpec", "REPLICAS", "REPLICA_VERSION", "replica_names", "build_replica"]

#: Version of the drawings; bump it when a layout changes (and rebuild the catalog).
REPLICA_VERSION = 1
#: Occupied margin (m) around the floor's bounding box.
_MARGIN = 0.5

_HALL_GUESS = (
    "layout guessed from the paper's text: the outer bounds are the paper's; the shape of the L, the furniture "
    "and the start pose are guesses (the real floor plan is not published)"
)
_LAB_GUESS = (
    "layout guessed from the paper's text and Fig. 7: the size is the paper's; the furniture and the start pose "
    "are guesses (the real floor plan is not published)"
)


@dataclass(frozen=True)
class ReplicaSpec:
    """One replica: its floor, its obstacles and its start pose, in plan metres.

    Attributes
    ----------
    name:
        Catalog name.
    shape:
        ``L`` or ``square`` (the catalog's ``shape`` column).
    floor:
        Free rectangles; their union is the floor inside the outer walls.
    obstacles:
        Solid rectangles drawn over the floor (furniture, machines, shelves).
    start:
        Start pose (x, y, theta) in m, m, rad: free, with room for the robot, near the middle as the paper's.
    description:
        One line for ``slamtrials worlds list`` and the catalog.
    source:
        Where the setting comes from in the paper, and what the paper reports about it.
    layout:
        What of the drawing is the paper's and what is guessed.
    """

    name: str
    shape: str
    floor: tuple[Rect, ...]
    obstacles: tuple[Rect, ...]
    start: tuple[float, float, float]
    description: str
    source: str
    layout: str

    @property
    def bounds(self) -> Rect:
        """Bounding box of the floor (m)."""
        return Rect(
            min(r.x0 for r in self.floor),
            min(r.y0 for r in self.floor),
            max(r.x1 for r in self.floor),
            max(r.y1 for r in self.floor),
        )


# The hall: 10 m along x, 12 m along y. The L is a 10 x 6 m bay along the bottom and a 5 m wide leg up
# the left side; the top-right 5 x 6 m is outside the hall (a guess: the paper says only "L-shaped").
_HALL_FLOOR = (Rect(0.0, 0.0, 10.0, 6.0), Rect(0.0, 0.0, 5.0, 12.0))
# Furnished: pallet shelving along two walls, two machines, a workbench and a stack of crates, leaving
# aisles of at least 1.5 m (a guess at "furnished"; the data set's photos are not in the paper).
_HALL_FURNITURE = (
    Rect(0.0, 7.0, 0.8, 11.2),  # shelving along the left wall of the leg
    Rect(5.8, 0.0, 10.0, 0.8),  # shelving along the bottom wall of the bay, into the corner
    Rect(6.4, 2.4, 8.0, 3.6),  # machine in the bay
    Rect(8.6, 4.6, 10.0, 6.0),  # machine in the bay's top-right corner
    Rect(2.6, 8.8, 3.4, 10.6),  # workbench in the leg
    Rect(1.0, 3.8, 2.0, 4.8),  # crates
)
# The lab: a 9 x 9 m room with desks and cabinets along the walls and a table in the middle (a guess from
# Fig. 7's small maps: a closed room, cluttered edges, an open centre where the robots run).
_LAB_FLOOR = (Rect(0.0, 0.0, 9.0, 9.0),)
_LAB_FURNITURE = (
    Rect(0.0, 0.0, 3.0, 0.8),  # desks along the bottom wall
    Rect(4.0, 0.0, 7.0, 0.8),
    Rect(0.0, 2.0, 0.8, 5.0),  # desks along the left wall
    Rect(8.2, 1.5, 9.0, 4.5),  # cabinets along the right wall
    Rect(0.0, 8.4, 4.0, 9.0),  # cabinets along the top wall
    Rect(6.0, 8.2, 9.0, 9.0),  # desks along the top wall
    Rect(3.0, 3.8, 5.5, 5.0),  # the middle table
    Rect(6.6, 6.0, 7.6, 7.0),  # a robot crate
)

_HALL_SOURCE = (
    "paper Section IV, Table II: the L-shaped 10 x 12 m industrial hall of the paper's reference [26] "
    "(motion-capture ground truth); laser inferred by the paper: 80 deg, 1 deg, 30 m, 10 Hz; odometry error "
    "up to 0.01 m/m and 2 deg/rad"
)
_LAB_SOURCE = (
    "paper Section IV, Table III, Fig. 7: the 9 x 9 m AIRLab of the Politecnico di Milano (OptiTrack ground "
    "truth), robot Robocom with a SICK LMS100: 270 deg, 0.25 deg, 20 m, 50 Hz; odometry error up to "
    "0.01 m/m and 4 deg/rad"
)

#: The bundled replicas, in catalog order.
REPLICAS: tuple[ReplicaSpec, ...] = (
    ReplicaSpec(
        name="paper_hall_empty",
        shape="L",
        floor=_HALL_FLOOR,
        obstacles=(),
        start=(2.5, 3.0, 0.0),
        description="replica of the paper's Table II empty L-shaped industrial hall, 10 x 12 m (layout guessed)",
        source=_HALL_SOURCE,
        layout=_HALL_GUESS,
    ),
    ReplicaSpec(
        name="paper_hall_furnished",
        shape="L",
        floor=_HALL_FLOOR,
        obstacles=_HALL_FURNITURE,
        start=(2.5, 3.0, 0.0),
        description="replica of the paper's Table II furnished L-shaped industrial hall, 10 x 12 m (layout guessed)",
        source=_HALL_SOURCE,
        layout=_HALL_GUESS,
    ),
    ReplicaSpec(
        name="paper_lab",
        shape="square",
        floor=_LAB_FLOOR,
        obstacles=_LAB_FURNITURE,
        start=(4.25, 6.3, 0.0),
        description="replica of the paper's Table III laboratory (AIRLab), 9 x 9 m with desks (layout guessed)",
        source=_LAB_SOURCE,
        layout=_LAB_GUESS,
    ),
)


def replica_names() -> list[str]:
    """Names of the replicas, in catalog order."""
    return [spec.name for spec in REPLICAS]


def _spec(name: str) -> ReplicaSpec:
    for spec in REPLICAS:
        if spec.name == name:
            return spec
    raise WorldError(f"no replica named {name!r}; replicas: {', '.join(replica_names())}")


def build_replica(name: str, resolution: float = 0.05) -> World:
    """Draw the replica ``name`` as a :class:`World` (origin at ``(-0.5, -0.5, 0)``, plan metres = world metres).

    Raises
    ------
    WorldError
        Unknown name.
    """
    spec = _spec(name)
    box = spec.bounds
    cols = int(math.ceil((box.x1 + 2 * _MARGIN) / resolution))
    rows = int(math.ceil((box.y1 + 2 * _MARGIN) / resolution))
    grid = Grid(rows, cols, resolution, _MARGIN)
    occupied = np.ones((rows, cols), dtype=bool)
    for rect in spec.floor:
        occupied[grid.slices(rect)] = False
    floor_area = float(np.count_nonzero(~occupied)) * resolution**2
    for rect in spec.obstacles:
        occupied[grid.slices(rect)] = True
    metadata = {
        "generator": "slamtrials.worlds.replicas",
        "replica_version": REPLICA_VERSION,
        "kind": "replica",
        "shape": spec.shape,
        "floor_area_m2": round(floor_area, 2),
        "floor": [_rect_list(r) for r in spec.floor],
        "obstacles": [_rect_list(r) for r in spec.obstacles],
        "source": spec.source,
        "layout": spec.layout,
    }
    return World(
        occupied=occupied,
        resolution=resolution,
        origin=grid.origin,
        name=spec.name,
        start=np.array(spec.start, dtype=np.float64),
        metadata=metadata,
    )


def _rect_list(rect: Rect) -> list[float]:
    return [rect.x0, rect.y0, rect.x1, rect.y1]
