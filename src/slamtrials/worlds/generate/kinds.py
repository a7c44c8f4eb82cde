"""The table of building kinds and of the room styles they are made of.

A *style* fixes the dimensions of one wing's rooms, corridors and doors (office, school, lab, house).
A *kind* is what a user asks for: it names the styles its wings draw from, the building shapes it may
take and the range of areas it can be generated at. All lengths are in metres; widths of corridors and
rooms are *clear* widths between wall faces.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

from slamtrials.errors import ConfigError

__all__ = ["Style", "KindSpec", "STYLES", "KINDS", "BUILDING_KINDS", "validate_request"]


@dataclass(frozen=True)
class Style:
    """Dimensions and habits of one wing's rooms (all lengths in metres, clear of walls).

    Attributes
    ----------
    name:
        Style name; furniture recipes are chosen by it.
    corridor:
        (min, max) clear corridor width.
    depth:
        (min, max) depth of a room strip, from the corridor wall to the outer wall.
    room_width:
        (min, max) width of a room along the corridor.
    big_room_prob:
        Probability that a room is two to three times as wide (open-plan office, double lab, ...).
    small_room_prob:
        Probability that a room is a small one (storage, toilet, shaft), 1.8 to 3 m wide.
    door:
        (min, max) door width of ordinary rooms; halls and big rooms get double doors.
    hall_prob:
        Probability that a core section between two corridors is one hall instead of two strips.
    lobby_prob:
        Probability of an entrance lobby on the wing's corridor.
    connect_prob:
        Probability of an extra door between two neighbouring rooms.
    recess_prob:
        Probability, per room boundary along a corridor, of an alcove in the corridor wall.
    """

    name: str
    corridor: tuple[float, float]
    depth: tuple[float, float]
    room_width: tuple[float, float]
    big_room_prob: float
    small_room_prob: float
    door: tuple[float, float]
    hall_prob: float
    lobby_prob: float
    connect_prob: float
    recess_prob: float


STYLES: dict[str, Style] = {
    "office": Style(
        "office",
        corridor=(1.8, 2.4),
        depth=(4.0, 5.8),
        room_width=(2.8, 5.0),
        big_room_prob=0.15,
        small_room_prob=0.12,
        door=(0.9, 1.1),
        hall_prob=0.5,
        lobby_prob=0.7,
        connect_prob=0.12,
        recess_prob=0.15,
    ),
    "school": Style(
        "school",
        corridor=(2.4, 3.0),
        depth=(6.5, 8.5),
        room_width=(6.5, 9.0),
        big_room_prob=0.1,
        small_room_prob=0.25,
        door=(1.0, 1.3),
        hall_prob=0.7,
        lobby_prob=0.8,
        connect_prob=0.05,
        recess_prob=0.2,
    ),
    "lab": Style(
        "lab",
        corridor=(2.0, 2.6),
        depth=(5.5, 7.5),
        room_width=(4.0, 7.5),
        big_room_prob=0.25,
        small_room_prob=0.15,
        door=(1.0, 1.4),
        hall_prob=0.5,
        lobby_prob=0.5,
        connect_prob=0.2,
        recess_prob=0.15,
    ),
    "house": Style(
        "house",
        corridor=(1.2, 1.5),
        depth=(3.0, 4.5),
        room_width=(2.6, 4.5),
        big_room_prob=0.2,
        small_room_prob=0.2,
        door=(0.9, 1.0),
        hall_prob=0.0,
        lobby_prob=0.0,
        connect_prob=0.1,
        recess_prob=0.0,
    ),
}


@dataclass(frozen=True)
class KindSpec:
    """One building kind that :func:`slamtrials.worlds.generate.generate_world` can make.

    Attributes
    ----------
    name:
        The kind's name.
    description:
        One line for help texts and the catalog.
    styles:
        Styles the wings draw from (one style per wing).
    area_range:
        (min, max) requested free area in m^2.
    free_fraction:
        Expected free area / gross footprint, the first guess of the footprint to lay out.
    """

    name: str
    description: str
    styles: tuple[str, ...]
    area_range: tuple[float, float]
    free_fraction: float


KINDS: dict[str, KindSpec] = {
    "office": KindSpec(
        "office",
        "offices and meeting rooms off corridors, open-plan areas with cubicles",
        ("office",),
        (80.0, 12000.0),
        0.84,
    ),
    "school": KindSpec(
        "school",
        "long wide corridors with lockers, large classrooms, gym or library halls",
        ("school",),
        (150.0, 12000.0),
        0.86,
    ),
    "lab": KindSpec(
        "lab", "laboratories full of benches, tables and cabinets, workshop halls", ("lab",), (80.0, 12000.0), 0.79
    ),
    "multiwing": KindSpec(
        "multiwing",
        "several wings (L, T, U, H, comb shapes) joined by corridors, mixed use",
        ("office", "school", "lab"),
        (1000.0, 15000.0),
        0.85,
    ),
    "house": KindSpec(
        "house", "a small house or flat: hallway, bedrooms, living room, kitchen", ("house",), (50.0, 400.0), 0.79
    ),
}

#: Names of the building kinds, in a stable order.
BUILDING_KINDS: tuple[str, ...] = tuple(KINDS)


def validate_request(kind: str, area: float, seed: object, resolution: float) -> KindSpec:
    """Check the arguments of a generation request and return the kind's spec.

    Raises
    ------
    ConfigError
        Unknown kind, area outside the kind's range, seed not a non-negative int, or a resolution
        outside [0.01, 0.2] m/px. The message names the option and the allowed values.
    """
    if kind not in KINDS:
        raise ConfigError(f"kind: unknown building kind {kind!r}; expected one of {', '.join(BUILDING_KINDS)}")
    spec = KINDS[kind]
    lo, hi = spec.area_range
    try:
        area_ok = lo <= float(area) <= hi
    except (TypeError, ValueError):
        area_ok = False
    if not area_ok:
        raise ConfigError(f"area: {area!r} m^2 is outside the range of kind {kind!r}: {lo:g} to {hi:g} m^2")
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise ConfigError(f"seed: expected a non-negative integer, got {seed!r}")
    try:
        res_ok = 0.01 <= float(resolution) <= 0.2
    except (TypeError, ValueError):
        res_ok = False
    if not res_ok:
        raise ConfigError(f"resolution: {resolution!r} m/px is outside the allowed range 0.01 to 0.2 m/px")
    return spec
