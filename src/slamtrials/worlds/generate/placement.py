"""Checked placement of furniture: an item goes in only if it keeps every passage open.

The rules, which keep the free space of a room connected and passable for the robot:

* an item is an axis-aligned rectangle of free cells of one room (or of the circulation), away from
  the door zones (0.3 m);
* a *free-standing* item keeps ``gap`` metres (1 m by default) of free cells of its room all around;
* a *wall* item touches a wall (not furniture) with its back, the whole length of that side (in a
  corner: with two sides), and keeps ``gap`` metres free in front of it.

So no two items and no item and wall can be closer than the gap across a passage: whatever lies
between them is either at least a gap wide, or a niche against a wall (beside a wall item, in a
corner) that leads nowhere.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from slamtrials.worlds.generate.raster import Grid

__all__ = ["Placer", "SIDES"]

#: Wall sides of a room: N (top rows), S (bottom rows), W (left columns), E (right columns).
SIDES = ("N", "S", "W", "E")


@dataclass
class Placer:
    """Places items into ``occupied`` (modified in place) under the rules of this module.

    Attributes
    ----------
    occupied:
        bool ``[H, W]``: walls and items placed so far.
    labels:
        int32 ``[H, W]`` room labels.
    reserved:
        bool ``[H, W]``: door zones, kept free.
    grid:
        The raster, for metre -> cell conversions.
    walls:
        bool ``[H, W]``: ``occupied`` as it was before any item (what counts as a wall).
    """

    occupied: NDArray[np.bool_]
    labels: NDArray[np.int32]
    reserved: NDArray[np.bool_]
    grid: Grid
    placed: int = 0
    walls: NDArray[np.bool_] = field(init=False, repr=False)

    def px(self, metres: float) -> int:
        """Metres -> whole cells (at least 1)."""
        return self.grid.px(metres)

    def _inside(self, r0: int, r1: int, c0: int, c1: int) -> bool:
        return 0 <= r0 < r1 <= self.occupied.shape[0] and 0 <= c0 < c1 <= self.occupied.shape[1]

    def __post_init__(self) -> None:
        self.walls = self.occupied.copy()

    def fits(self, label: int, r0: int, c0: int, h: int, w: int, back: str = "", gap: float = 1.0) -> bool:
        """Whether an ``h x w`` cell item at (r0, c0) obeys the rules; ``back`` lists the sides that touch walls."""
        g = self.px(gap)
        r1, c1 = r0 + h, c0 + w

        def reach(side: str, opposite: str) -> int:
            return g if not back or opposite in back else 0

        er0, er1 = r0 - reach("N", "S"), r1 + reach("S", "N")
        ec0, ec1 = c0 - reach("W", "E"), c1 + reach("E", "W")
        if not self._inside(er0 - 1, er1 + 1, ec0 - 1, ec1 + 1):
            return False
        if self.occupied[er0:er1, ec0:ec1].any() or (self.labels[er0:er1, ec0:ec1] != label).any():
            return False
        walls = self.walls
        behind = {"N": walls[r0 - 1, c0:c1], "S": walls[r1, c0:c1], "W": walls[r0:r1, c0 - 1], "E": walls[r0:r1, c1]}
        if not all(behind[side].all() for side in back):
            return False
        rg = self.px(0.3)
        return not self.reserved[max(0, r0 - rg):r1 + rg, max(0, c0 - rg):c1 + rg].any()

    def put(self, label: int, r0: int, c0: int, h: int, w: int, back: str = "", gap: float = 1.0, round_: bool = False) -> bool:
        """Place the item if it fits; ``round_`` draws the inscribed ellipse instead of the rectangle."""
        if h < 1 or w < 1 or not self.fits(label, r0, c0, h, w, back, gap):
            return False
        if round_:
            yy, xx = np.ogrid[:h, :w]
            cy, cx = (h - 1) / 2.0, (w - 1) / 2.0
            disk = ((yy - cy) / max(h / 2.0, 0.5)) ** 2 + ((xx - cx) / max(w / 2.0, 0.5)) ** 2 <= 1.0
            self.occupied[r0:r0 + h, c0:c0 + w] |= disk
        else:
            self.occupied[r0:r0 + h, c0:c0 + w] = True
        self.placed += 1
        return True

    def against(self, label: int, box: tuple[int, int, int, int], side: str, length: float, depth: float,
                where: float | str, gap: float = 1.0) -> bool:
        """An item ``length`` m along wall ``side`` of the room box ``(r0, r1, c0, c1)``, ``depth`` m deep.

        ``where`` is a fraction 0..1 along the wall, or ``"start"``/``"end"`` to sit in a corner.
        """
        r0, r1, c0, c1 = box
        n, d = self.px(length), self.px(depth)
        along = (c1 - c0) if side in ("N", "S") else (r1 - r0)
        if n > along:
            return False
        if where == "start":
            offset, corner = 0, "W" if side in ("N", "S") else "N"
        elif where == "end":
            offset, corner = along - n, "E" if side in ("N", "S") else "S"
        else:
            offset, corner = int(round(float(where) * (along - n))), ""
        if side == "N":
            return self.put(label, r0, c0 + offset, d, n, "N" + corner, gap)
        if side == "S":
            return self.put(label, r1 - d, c0 + offset, d, n, "S" + corner, gap)
        if side == "W":
            return self.put(label, r0 + offset, c0, n, d, "W" + corner, gap)
        return self.put(label, r0 + offset, c1 - d, n, d, "E" + corner, gap)
