"""Checked placement of furniture: an item goes in only if it keeps every passage open.

Every item is an axis-aligned rectangle of free cells of one room (or of the circulation), at least
0.3 m from the door zones, and it comes with a *keep-clear zone* of width ``gap`` (1 m by default):

* a *free-standing* item: the ring ``gap`` wide all around it;
* a *wall* item, whose back touches a wall (not furniture) along its whole length: the band ``gap``
  deep in front of it, widened by ``gap`` to both sides; beside it, the nearest obstacle (if closer
  than ``gap``) must span the item's whole depth (a wall meeting its back wall, or an item as deep),
  so that the space beside it is a niche against the wall that leads nowhere;
* a *corner* item, touching walls with two sides: the band ``gap`` wide along both free sides.

An item goes in only if its zone holds no wall or other item (a wall item's widening: no obstacle
but those allowed beside it), and its body lies in no other item's zone. So two obstacles facing
each other across free space are always at least ``gap`` apart, and no passage narrower than that
is made.
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
    clear:
        bool ``[H, W]``: the keep-clear zones of the items placed so far.
    """

    occupied: NDArray[np.bool_]
    labels: NDArray[np.int32]
    reserved: NDArray[np.bool_]
    grid: Grid
    placed: int = 0
    walls: NDArray[np.bool_] = field(init=False, repr=False)
    clear: NDArray[np.bool_] = field(init=False, repr=False)

    def px(self, metres: float) -> int:
        """Metres -> whole cells (at least 1)."""
        return self.grid.px(metres)

    def _inside(self, r0: int, r1: int, c0: int, c1: int) -> bool:
        return 0 <= r0 < r1 <= self.occupied.shape[0] and 0 <= c0 < c1 <= self.occupied.shape[1]

    def __post_init__(self) -> None:
        self.walls = self.occupied.copy()
        self.clear = np.zeros_like(self.occupied)

    def _zones(
        self, r0: int, r1: int, c0: int, c1: int, back: str, g: int
    ) -> tuple[tuple[int, int, int, int], tuple[int, int, int, int]]:
        """(strict zone, widened zone) of an item, as (r0, r1, c0, c1); the strict zone must hold no wall."""
        if not back:
            box = (r0 - g, r1 + g, c0 - g, c1 + g)
            return box, box
        if len(back) == 1:
            front = {
                "N": (r1, r1 + g, c0, c1),
                "S": (r0 - g, r0, c0, c1),
                "W": (r0, r1, c1, c1 + g),
                "E": (r0, r1, c0 - g, c0),
            }[back]
            wide = {
                "N": (r1, r1 + g, c0 - g, c1 + g),
                "S": (r0 - g, r0, c0 - g, c1 + g),
                "W": (r0 - g, r1 + g, c1, c1 + g),
                "E": (r0 - g, r1 + g, c0 - g, c0),
            }[back]
            return front, wide
        box = (
            r0 - (g if "S" in back else 0),
            r1 + (g if "N" in back else 0),
            c0 - (g if "E" in back else 0),
            c1 + (g if "W" in back else 0),
        )
        return box, box

    def _sides_ok(self, r0: int, r1: int, c0: int, c1: int, back: str, g: int) -> bool:
        """Beside a wall item (up to ``g`` cells away, from its back to ``g`` beyond its front), the nearest
        obstacle must span the item's whole depth: a wall meeting the back wall, or an item at least as
        deep. Then the space beside the item is a niche, or open towards its front."""
        occ = self.occupied
        if back in ("W", "E"):  # work with the back at the top or bottom
            occ = occ.T
            r0, r1, c0, c1 = c0, c1, r0, r1
            back = "N" if back == "W" else "S"
        rows = slice(r0, r1 + g) if back == "N" else slice(r0 - g, r1)
        blocked = np.flatnonzero(occ[rows, c0 - g : c0].any(axis=0))
        if len(blocked) and not occ[r0:r1, c0 - g + int(blocked[-1])].all():
            return False
        blocked = np.flatnonzero(occ[rows, c1 : c1 + g].any(axis=0))
        return not (len(blocked) and not occ[r0:r1, c1 + int(blocked[0])].all())

    def fits(self, label: int, r0: int, c0: int, h: int, w: int, back: str = "", gap: float = 1.0) -> bool:
        """Whether an ``h x w`` cell item at (r0, c0) obeys the rules; ``back`` lists the sides that touch walls."""
        g = self.px(gap)
        r1, c1 = r0 + h, c0 + w
        strict, wide = self._zones(r0, r1, c0, c1, back, g)
        lo_r, hi_r = min(strict[0], wide[0], r0), max(strict[1], wide[1], r1)
        lo_c, hi_c = min(strict[2], wide[2], c0), max(strict[3], wide[3], c1)
        if not self._inside(lo_r - 1, hi_r + 1, lo_c - 1, hi_c + 1):
            return False
        occ, lab = self.occupied, self.labels
        body = (slice(r0, r1), slice(c0, c1))
        if occ[body].any() or (lab[body] != label).any() or self.clear[body].any():
            return False
        zone = (slice(strict[0], strict[1]), slice(strict[2], strict[3]))
        if occ[zone].any() or (lab[zone] != label).any():
            return False
        if len(back) == 1 and not self._sides_ok(r0, r1, c0, c1, back, g):
            return False
        walls = self.walls
        behind = {"N": walls[r0 - 1, c0:c1], "S": walls[r1, c0:c1], "W": walls[r0:r1, c0 - 1], "E": walls[r0:r1, c1]}
        if not all(behind[side].all() for side in back):
            return False
        rg = self.px(0.3)
        return not self.reserved[max(0, r0 - rg) : r1 + rg, max(0, c0 - rg) : c1 + rg].any()

    def put(
        self, label: int, r0: int, c0: int, h: int, w: int, back: str = "", gap: float = 1.0, round_: bool = False
    ) -> bool:
        """Place the item if it fits; ``round_`` draws the inscribed ellipse instead of the rectangle."""
        if h < 1 or w < 1 or not self.fits(label, r0, c0, h, w, back, gap):
            return False
        if round_:
            yy, xx = np.ogrid[:h, :w]
            cy, cx = (h - 1) / 2.0, (w - 1) / 2.0
            disk = ((yy - cy) / max(h / 2.0, 0.5)) ** 2 + ((xx - cx) / max(w / 2.0, 0.5)) ** 2 <= 1.0
            self.occupied[r0 : r0 + h, c0 : c0 + w] |= disk
        else:
            self.occupied[r0 : r0 + h, c0 : c0 + w] = True
        _strict, wide = self._zones(r0, r0 + h, c0, c0 + w, back, self.px(gap))
        zone = (slice(wide[0], wide[1]), slice(wide[2], wide[3]))
        self.clear[zone] |= (self.labels[zone] == label) & ~self.occupied[zone]
        self.placed += 1
        return True

    def against(
        self,
        label: int,
        box: tuple[int, int, int, int],
        side: str,
        length: float,
        depth: float,
        where: float | str,
        gap: float = 1.0,
    ) -> bool:
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
