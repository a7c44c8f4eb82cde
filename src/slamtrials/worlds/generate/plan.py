"""The metric floor plan the generator lays out before rasterising: rectangles of rooms and circulation.

Plan coordinates are metres with x to the right and y up; they are also the world coordinates of the
generated :class:`~slamtrials.worlds.World` (its origin is placed so that they coincide). Rectangles
are given by the *centre lines* of their walls: a wall is drawn on each boundary between two
rectangles of different rooms, centred on it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Rect", "RoomSpec", "Plan", "split_length"]


@dataclass(frozen=True)
class Rect:
    """Axis-aligned rectangle ``[x0, x1] x [y0, y1]`` in plan metres."""

    x0: float
    y0: float
    x1: float
    y1: float

    @property
    def width(self) -> float:
        """Extent along x (m)."""
        return self.x1 - self.x0

    @property
    def height(self) -> float:
        """Extent along y (m)."""
        return self.y1 - self.y0

    @property
    def area(self) -> float:
        """Area (m^2)."""
        return max(0.0, self.width) * max(0.0, self.height)

    def shifted(self, dx: float, dy: float) -> Rect:
        """The rectangle moved by (dx, dy) metres."""
        return Rect(self.x0 + dx, self.y0 + dy, self.x1 + dx, self.y1 + dy)


@dataclass(frozen=True)
class RoomSpec:
    """A room to paint: its rectangle, what it is used for and the style that furnishes it.

    ``use`` is one of ``"room"`` (ordinary room of a strip), ``"big"`` (a double-width room),
    ``"small"`` (storage, toilet), ``"hall"`` (a large core room), ``"end"`` (a room across the end
    of a wing) or ``"shaft"`` (a solid core: lifts, ducts; painted as wall).
    """

    rect: Rect
    use: str
    style: str


@dataclass
class Plan:
    """Everything the rasteriser needs: rooms (painted first) and circulation (painted over them).

    Attributes
    ----------
    rooms:
        Rooms in painting order; a later room overwrites an earlier one where they overlap.
    corridors:
        Corridor rectangles, with the axis they run along (``"x"`` or ``"y"``) and the style of their
        wing (for lockers, notice boards, ...).
    lobbies:
        Open circulation areas (entrance halls, junctions), painted like corridors; they get pillars.
    recesses:
        Alcoves in corridor walls, painted like corridors.
    shape:
        Name of the building shape (``bar``, ``racetrack``, ``L``, ``U``, ``H``, ``comb``, ...).
    """

    rooms: list[RoomSpec] = field(default_factory=list)
    corridors: list[tuple[Rect, str, str]] = field(default_factory=list)
    lobbies: list[tuple[Rect, str]] = field(default_factory=list)
    recesses: list[Rect] = field(default_factory=list)
    shape: str = "bar"

    def bounds(self) -> Rect:
        """The bounding rectangle of every room and circulation area."""
        rects = [r.rect for r in self.rooms] + [c[0] for c in self.corridors] + [lob[0] for lob in self.lobbies]
        return Rect(
            min(r.x0 for r in rects), min(r.y0 for r in rects), max(r.x1 for r in rects), max(r.y1 for r in rects)
        )

    def shifted(self, dx: float, dy: float) -> Plan:
        """The plan moved by (dx, dy) metres."""
        return Plan(
            rooms=[RoomSpec(r.rect.shifted(dx, dy), r.use, r.style) for r in self.rooms],
            corridors=[(c.shifted(dx, dy), axis, style) for c, axis, style in self.corridors],
            lobbies=[(lob.shifted(dx, dy), style) for lob, style in self.lobbies],
            recesses=[r.shifted(dx, dy) for r in self.recesses],
            shape=self.shape,
        )

    def extend(self, other: Plan) -> None:
        """Append another plan's rooms and circulation to this one."""
        self.rooms.extend(other.rooms)
        self.corridors.extend(other.corridors)
        self.lobbies.extend(other.lobbies)
        self.recesses.extend(other.recesses)


def split_length(length: float, lo: float, hi: float, rng: np.random.Generator) -> list[float]:
    """Cut ``length`` metres into pieces of ``lo`` to ``hi`` metres (random widths summing to ``length``).

    A length shorter than ``lo`` gives one piece. The last pieces are evened out so that none is
    shorter than ``lo`` when that is possible.
    """
    if length <= hi:
        return [length]
    pieces: list[float] = []
    remaining = length
    while remaining > hi:
        piece = float(rng.uniform(lo, hi))
        if remaining - piece < lo:
            piece = remaining - lo if remaining - lo >= lo else remaining / 2.0
        pieces.append(piece)
        remaining -= piece
    pieces.append(remaining)
    return pieces
