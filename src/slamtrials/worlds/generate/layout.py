"""One wing of a building: bands of rooms and corridors along its length, partitioned into rooms.

A wing is a rectangle with a local frame: ``u`` along its length, ``v`` across it. Across, it is a
stack of *bands*: ``rooms`` (a strip of rooms along a corridor), ``corridor``, and ``core`` (the
deep band between two corridors: two strips of rooms back to back, or halls). At either end there
may be an *end block* of rooms across the whole width, where the corridors stop.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from slamtrials.worlds.generate.kinds import Style
from slamtrials.worlds.generate.plan import Plan, Rect, RoomSpec, split_length

__all__ = ["WALL", "Band", "Wing", "wing_plan", "room_widths"]

#: Nominal wall thickness (m): plan rectangles meet at wall centre lines, so a clear width ``w``
#: takes ``w + WALL`` of plan.
WALL = 0.2


@dataclass(frozen=True)
class Band:
    """A band across a wing: ``kind`` is ``rooms``, ``corridor`` or ``core``; ``depth`` in plan metres."""

    kind: str
    depth: float


@dataclass(frozen=True)
class Wing:
    """A rectangular wing placed in the plan.

    Attributes
    ----------
    x0, y0:
        Plan position (m) of the wing's lower-left corner.
    horizontal:
        True if the wing's length runs along x (u = x), False if along y (u = y, v = x).
    length:
        Extent along u (m).
    bands:
        Bands across the wing, from v = 0 up.
    end_depth:
        Depth (m) of the end blocks at u = 0 and u = length; 0 lets the corridors run to the wall.
    cross:
        u positions (m) of the centres of cross corridors joining the first and the last corridor.
    style:
        The style of the wing's rooms.
    lobby:
        Whether to open an entrance lobby on the wing's first corridor.
    """

    x0: float
    y0: float
    horizontal: bool
    length: float
    bands: tuple[Band, ...]
    end_depth: tuple[float, float]
    cross: tuple[float, ...]
    style: Style
    lobby: bool = False

    @property
    def width(self) -> float:
        """Extent across the wing (m)."""
        return sum(b.depth for b in self.bands)

    def band_range(self, index: int) -> tuple[float, float]:
        """(v0, v1) of band ``index``."""
        v0 = sum(b.depth for b in self.bands[:index])
        return v0, v0 + self.bands[index].depth

    def corridor_indices(self) -> list[int]:
        """Indices of the corridor bands."""
        return [i for i, b in enumerate(self.bands) if b.kind == "corridor"]

    def rect(self, u0: float, v0: float, u1: float, v1: float) -> Rect:
        """The plan rectangle of the local rectangle ``[u0, u1] x [v0, v1]``."""
        if self.horizontal:
            return Rect(self.x0 + u0, self.y0 + v0, self.x0 + u1, self.y0 + v1)
        return Rect(self.x0 + v0, self.y0 + u0, self.x0 + v1, self.y0 + u1)

    @property
    def bounds(self) -> Rect:
        """The wing's plan rectangle."""
        return self.rect(0.0, 0.0, self.length, self.width)

    @property
    def axis(self) -> str:
        """Plan axis of the wing's length: ``"x"`` or ``"y"``."""
        return "x" if self.horizontal else "y"


def room_widths(length: float, style: Style, rng: np.random.Generator) -> list[tuple[float, str]]:
    """Cut a strip of ``length`` plan metres into rooms: (plan width, use) pairs summing to ``length``.

    Uses are ``room``, ``big`` (2-3 ordinary widths) and ``small`` (1.8-3 m clear).
    """
    lo, hi = style.room_width
    pieces: list[tuple[float, str]] = []
    remaining = length
    while remaining > hi + WALL:
        draw = rng.random()
        if draw < style.small_room_prob:
            piece, use = float(rng.uniform(1.8, 3.0)) + WALL, "small"
        elif draw < style.small_room_prob + style.big_room_prob:
            piece, use = float(rng.uniform(2.0, 3.0) * rng.uniform(lo, hi)) + WALL, "big"
        else:
            piece, use = float(rng.uniform(lo, hi)) + WALL, "room"
        if remaining - piece < lo * 0.7:
            piece, use = remaining, "big" if remaining > 2 * hi else "room"
        pieces.append((min(piece, remaining), use))
        remaining -= piece
    if remaining > 1e-9:
        if remaining < 1.6 + WALL and pieces:
            width, use = pieces.pop()
            pieces.append((width + remaining, use))
        else:
            pieces.append((remaining, "small" if remaining < 3.0 else "room"))
    return pieces


def _strip(
    wing: Wing,
    plan: Plan,
    u0: float,
    u1: float,
    v0: float,
    v1: float,
    rng: np.random.Generator,
    corridor_side: int | None,
    shaft_prob: float = 0.0,
) -> list[float]:
    """Partition ``[u0, u1] x [v0, v1]`` into rooms side by side along u; return the inner boundaries."""
    u = u0
    bounds = []
    for width, use in room_widths(u1 - u0, wing.style, rng):
        if use == "small" and shaft_prob > 0 and rng.random() < shaft_prob:
            use = "shaft"
        plan.rooms.append(RoomSpec(wing.rect(u, v0, u + width, v1), use, wing.style.name))
        u += width
        bounds.append(u)
    inner = bounds[:-1]
    if corridor_side is not None and wing.style.recess_prob > 0:
        depth = v1 - v0
        for b in inner:
            if rng.random() < wing.style.recess_prob:
                half = float(rng.uniform(0.6, 1.4))
                deep = min(float(rng.uniform(0.5, 1.1)), 0.3 * depth)
                rv0, rv1 = (v1 - deep, v1) if corridor_side > 0 else (v0, v0 + deep)
                plan.recesses.append(wing.rect(b - half, rv0, b + half, rv1))
    return inner


def _end_block(wing: Wing, plan: Plan, u0: float, u1: float, rng: np.random.Generator) -> None:
    """Rooms across the whole width of the wing, between u0 and u1."""
    lo, hi = wing.style.room_width
    v = 0.0
    for width in split_length(wing.width, max(3.5, 1.2 * lo), max(7.0, 1.8 * hi), rng):
        plan.rooms.append(RoomSpec(wing.rect(u0, v, u1, v + width), "end", wing.style.name))
        v += width


def _core(wing: Wing, plan: Plan, u0: float, u1: float, v0: float, v1: float, rng: np.random.Generator) -> None:
    """A core section between two corridors: a hall, or two strips of rooms back to back."""
    depth = v1 - v0
    if (u1 - u0) * depth >= 80.0 and rng.random() < wing.style.hall_prob:
        pieces = split_length(u1 - u0, 12.0, 36.0, rng)
        u = u0
        for piece in pieces:
            plan.rooms.append(RoomSpec(wing.rect(u, v0, u + piece, v1), "hall", wing.style.name))
            u += piece
        return
    split = v0 + depth * float(rng.uniform(0.42, 0.58))
    _strip(wing, plan, u0, u1, v0, split, rng, corridor_side=-1, shaft_prob=0.35)
    _strip(wing, plan, u0, u1, split, v1, rng, corridor_side=+1, shaft_prob=0.35)


def wing_plan(wing: Wing, rng: np.random.Generator) -> Plan:
    """Lay out one wing: its rooms, corridors, cross corridors, recesses and lobby, in plan metres."""
    plan = Plan()
    a0, a1 = wing.end_depth
    length = wing.length
    if a0 > 0:
        _end_block(wing, plan, 0.0, a0, rng)
    if a1 > 0:
        _end_block(wing, plan, length - a1, length, rng)
    corridors = wing.corridor_indices()
    corridor_width = wing.bands[corridors[0]].depth
    cuts = [a0, length - a1]
    for c in wing.cross:
        cuts += [c - corridor_width / 2, c + corridor_width / 2]
    cuts = sorted(cuts)
    for i, band in enumerate(wing.bands):
        v0, v1 = wing.band_range(i)
        if band.kind == "rooms":
            side = +1 if i + 1 < len(wing.bands) and wing.bands[i + 1].kind == "corridor" else -1
            _strip(wing, plan, a0, length - a1, v0, v1, rng, corridor_side=side)
        elif band.kind == "core":
            for s0, s1 in zip(cuts[::2], cuts[1::2]):
                if s1 - s0 > 2.0:
                    _core(wing, plan, s0, s1, v0, v1, rng)
    for i in corridors:
        v0, v1 = wing.band_range(i)
        plan.corridors.append((wing.rect(a0, v0, length - a1, v1), wing.axis, wing.style.name))
    if wing.cross:
        first, last = wing.band_range(corridors[0])[0], wing.band_range(corridors[-1])[1]
        cross_axis = "y" if wing.horizontal else "x"
        for c in wing.cross:
            plan.corridors.append(
                (wing.rect(c - corridor_width / 2, first, c + corridor_width / 2, last), cross_axis, wing.style.name)
            )
    if wing.lobby and length - a0 - a1 > 14.0:
        _lobby(wing, plan, rng)
    return plan


def _lobby(wing: Wing, plan: Plan, rng: np.random.Generator) -> None:
    """An entrance hall: the first corridor widened over one neighbouring room band, near mid-length."""
    a0, a1 = wing.end_depth
    index = wing.corridor_indices()[0]
    span = float(rng.uniform(5.0, 10.0))
    span = min(span, 0.35 * (wing.length - a0 - a1))
    centre = 0.5 * wing.length + float(rng.uniform(-0.15, 0.15)) * (wing.length - a0 - a1)
    v0, v1 = wing.band_range(index)
    side = index - 1 if index > 0 and (index + 1 >= len(wing.bands) or rng.random() < 0.5) else index + 1
    if 0 <= side < len(wing.bands) and wing.bands[side].kind == "rooms":
        s0, s1 = wing.band_range(side)
        v0, v1 = min(v0, s0), max(v1, s1)
    plan.lobbies.append((wing.rect(centre - span / 2, v0, centre + span / 2, v1), wing.style.name))
