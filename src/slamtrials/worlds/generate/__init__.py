"""Procedural floor plans of buildings: offices, schools, labs, multi-wing buildings and houses.

:func:`generate_world` lays out wings of rooms along corridors (see :mod:`.skeleton` and
:mod:`.layout`), rasterises them with walls about 0.2 m thick, cuts doors at least 0.9 m wide so that
every room can be reached, furnishes rooms and corridors with items that keep every passage at least
1 m wide (:mod:`.placement`), and fills any free pocket that is not connected to the rest, so the
result has exactly one 4-connected free region.

**Area.** ``area`` is the requested *free* area in m^2: the area of the free cells of the generated
grid (:attr:`World.free_area`), i.e. floor space not covered by walls, solid cores or furniture. The
gross footprint (``metadata["footprint_m2"]``) is 15-30 % larger, most for labs. The generator tunes
the footprint until the free area is within 5 % of the request where the building's proportions
allow it (small buildings come in whole rooms: within 15 %; always within 25 %).

**Reproducibility.** All randomness comes from ``numpy.random.default_rng(seed)``; the same
arguments give a bit-identical grid (for a given numpy version).
"""

from __future__ import annotations

import logging
import math

from slamtrials.worlds.generate.build import Built, build_grid
from slamtrials.worlds.generate.kinds import BUILDING_KINDS, KINDS, validate_request
from slamtrials.worlds.world import World

__all__ = ["generate_world", "BUILDING_KINDS", "KINDS", "GENERATOR_VERSION"]

_log = logging.getLogger(__name__)

#: Bumped whenever a change to the generator changes its output for the same arguments.
#: 2: the start pose's ties broken by a fixed rule, not by numpy's sort (the same start on every CPU).
GENERATOR_VERSION = 2

#: Accept a pass whose free area is within this fraction of the request.
_TOLERANCE = 0.05
_MAX_PASSES = 4


def generate_world(kind: str, area: float, *, seed: int, resolution: float = 0.05, name: str | None = None) -> World:
    """Generate a building floor plan.

    Parameters
    ----------
    kind:
        One of :data:`BUILDING_KINDS`: ``office``, ``school``, ``lab``, ``multiwing``, ``house``.
    area:
        Requested free floor area (m^2); see the module docstring. Each kind has a range
        (``KINDS[kind].area_range``), e.g. 80 to 12,000 m^2 for offices.
    seed:
        Non-negative integer seed; the same arguments give the same grid bit for bit.
    resolution:
        Cell size (m/px), 0.01 to 0.2.
    name:
        World name; default ``"<kind>_<area>_s<seed>"``.

    Returns
    -------
    World
        Occupancy grid with row 0 at the top, origin such that the building's lower-left corner is
        near (0, 0) m, the start pose in a corridor near the building's centre (heading along it,
        at least 0.6 m from any obstacle), and metadata: ``generator``, ``generator_version``,
        ``kind``, ``shape``, ``seed``, ``area_requested_m2``, ``free_area_m2``, ``footprint_m2``,
        ``rooms``, ``doors`` (``[x, y, width, wall_axis]`` per door, metres; wall_axis 0 = the wall
        runs along x, 1 = along y), ``corridors`` (``[x0, y0, x1, y1]`` centre line of every corridor
        piece, metres).

    Raises
    ------
    ConfigError
        Unknown kind, area out of the kind's range, bad seed or resolution.
    """
    spec = validate_request(kind, area, seed, resolution)
    area, seed, resolution = float(area), int(seed), float(resolution)
    shape_area = area / spec.free_fraction
    gross = shape_area
    best: Built | None = None
    for _ in range(_MAX_PASSES if area > 2000 else 2 * _MAX_PASSES):
        built = build_grid(spec, shape_area, gross, seed, resolution)
        ratio = built.free_area / area
        _log.debug(
            "%s %g m^2 seed %d: footprint %.0f m^2 -> free %.0f m^2 (%.3f of the request)",
            kind,
            area,
            seed,
            gross,
            built.free_area,
            ratio,
        )
        if best is None or abs(math.log(ratio)) < abs(math.log(best.free_area / area)):
            best = built
        if abs(ratio - 1.0) <= _TOLERANCE:
            break
        gross /= ratio
    assert best is not None
    metadata = {
        "generator": "slamtrials.worlds.generate",
        "generator_version": GENERATOR_VERSION,
        "kind": kind,
        "shape": best.shape,
        "seed": seed,
        "area_requested_m2": area,
        "free_area_m2": round(best.free_area, 2),
        "footprint_m2": round(best.footprint, 2),
        "rooms": best.rooms,
        "doors": best.doors,
        "corridors": best.corridors,
    }
    return World(best.occupied, resolution, best.grid.origin, name or f"{kind}_{area:g}_s{seed}", best.start, metadata)
