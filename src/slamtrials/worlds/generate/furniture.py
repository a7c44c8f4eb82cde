"""Furniture recipes: what stands in each kind of room (desks, tables, benches, shelves, pillars).

A recipe gets the room's interior box and tries items through :class:`Placer`, which refuses any
item that would narrow a passage below 1 m; so a recipe may ask for more than fits. Sizes are in
metres (typical real furniture: desks 1.6 x 0.8, lab benches 0.75 deep, island benches 1.5 wide).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from slamtrials.worlds.generate.placement import SIDES, Placer

__all__ = ["furnish_room", "pillars", "island_grid", "RECIPES"]

Box = tuple[int, int, int, int]
Recipe = Callable[[Placer, int, Box, np.random.Generator], None]


def _u(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(rng.uniform(lo, hi))


def _where(rng: np.random.Generator) -> float | str:
    draw = rng.random()
    return "start" if draw < 0.3 else "end" if draw < 0.6 else float(rng.random())


def _side(rng: np.random.Generator) -> str:
    return SIDES[int(rng.integers(4))]


def along_walls(
    p: Placer,
    label: int,
    box: Box,
    rng: np.random.Generator,
    count: int,
    length: tuple[float, float],
    depth: tuple[float, float],
    tries: int = 6,
) -> int:
    """Up to ``count`` items against random walls; returns how many went in."""
    done = 0
    for _ in range(count * tries):
        if done >= count:
            break
        done += p.against(label, box, _side(rng), _u(rng, *length), _u(rng, *depth), _where(rng))
    return done


def island_grid(
    p: Placer,
    label: int,
    box: Box,
    rng: np.random.Generator,
    item: tuple[float, float],
    aisle: float,
    gap: float = 1.0,
    skip: float = 0.0,
    round_: bool = False,
) -> int:
    """Free-standing items of ``item = (rows_m, cols_m)`` on a grid with ``aisle`` m between them."""
    r0, r1, c0, c1 = box
    h, w = p.px(item[0]), p.px(item[1])
    step_r, step_c = h + p.px(aisle), w + p.px(aisle)
    margin = p.px(gap)
    rows = max(0, (r1 - r0 - 2 * margin - h) // step_r + 1)
    cols = max(0, (c1 - c0 - 2 * margin - w) // step_c + 1)
    off_r = r0 + (r1 - r0 - (rows - 1) * step_r - h) // 2 if rows else r0
    off_c = c0 + (c1 - c0 - (cols - 1) * step_c - w) // 2 if cols else c0
    done = 0
    for i in range(int(rows)):
        for j in range(int(cols)):
            if skip and rng.random() < skip:
                continue
            done += p.put(label, off_r + i * step_r, off_c + j * step_c, h, w, gap=gap, round_=round_)
    return done


def pillars(p: Placer, label: int, box: Box, rng: np.random.Generator, spacing: float | None = None) -> int:
    """Structural columns on a regular grid (0.4-0.6 m, square or round)."""
    size = _u(rng, 0.4, 0.6)
    spacing = spacing or _u(rng, 5.5, 8.0)
    return island_grid(p, label, box, rng, (size, size), spacing - size, gap=1.0, round_=rng.random() < 0.4)


def _office(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    area = _area(p, box)
    if area < 7.0:
        along_walls(p, label, box, rng, 3, (0.8, 2.0), (0.35, 0.5))
        return
    if area > 16.0 and rng.random() < 0.3:
        _meeting(p, label, box, rng)
        return
    along_walls(p, label, box, rng, 1 if area < 12 else 2 + (area > 22), (1.4, 1.8), (0.7, 0.8), tries=10)
    along_walls(p, label, box, rng, 2 + (area > 16), (0.6, 2.0), (0.4, 0.5), tries=10)
    if area > 14.0 and rng.random() < 0.4:
        d = _u(rng, 0.8, 1.1)
        _centre(p, label, box, d, d, round_=True)


def _meeting(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    r0, r1, c0, c1 = box
    hm, wm = (r1 - r0) * p.grid.resolution, (c1 - c0) * p.grid.resolution
    long_, short = max(hm, wm) - 2.6, min(hm, wm) - 2.6
    if short >= 0.9:
        size = (min(short, 1.4), min(long_, 6.0))
        _centre(p, label, box, *(size if wm >= hm else size[::-1]))
    along_walls(p, label, box, rng, 1, (1.2, 2.4), (0.4, 0.5))


def _open_plan(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    if _area(p, box) > 120:
        pillars(p, label, box, rng)
    along_walls(p, label, box, rng, 3, (1.0, 3.0), (0.4, 0.5))
    block = (1.5, _u(rng, 1.6, 3.4)) if rng.random() < 0.5 else (_u(rng, 1.6, 3.4), 1.5)
    island_grid(p, label, box, rng, block, _u(rng, 1.1, 1.6), skip=0.1)


def _centre(p: Placer, label: int, box: Box, hm: float, wm: float, round_: bool = False) -> bool:
    r0, r1, c0, c1 = box
    h, w = p.px(hm), p.px(wm)
    return p.put(label, (r0 + r1 - h) // 2, (c0 + c1 - w) // 2, h, w, round_=round_)


def _area(p: Placer, box: Box) -> float:
    r0, r1, c0, c1 = box
    return (r1 - r0) * (c1 - c0) * p.grid.resolution**2


def _classroom(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    along_walls(p, label, box, rng, 2, (1.5, 4.0), (0.45, 0.6))
    r0, r1, c0, c1 = box
    wide = (c1 - c0) >= (r1 - r0)
    table = (0.6, _u(rng, 1.2, 2.6))
    island_grid(p, label, box, rng, table if wide else table[::-1], _u(rng, 1.0, 1.3), skip=0.05)


def _school_small(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    if _area(p, box) < 12:
        along_walls(p, label, box, rng, 3, (0.8, 2.4), (0.4, 0.6))
    else:
        _office(p, label, box, rng)


def _school_hall(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    draw = rng.random()
    pillars(p, label, box, rng)
    if draw < 0.4:  # library: rows of shelves
        r0, r1, c0, c1 = box
        shelf = (0.5, _u(rng, 3.0, 5.0))
        island_grid(p, label, box, rng, shelf if (c1 - c0) >= (r1 - r0) else shelf[::-1], _u(rng, 1.2, 1.6))
        along_walls(p, label, box, rng, 4, (2.0, 5.0), (0.35, 0.45))
    elif draw < 0.7:  # gym: benches along the walls
        along_walls(p, label, box, rng, 4, (2.5, 5.0), (0.4, 0.5))
    else:  # assembly hall: rows of seats
        _classroom(p, label, box, rng)


def _lab(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    area = _area(p, box)
    if area < 8.0:
        along_walls(p, label, box, rng, 3, (0.8, 2.4), (0.45, 0.6))
        return
    if area < 16.0:
        _office(p, label, box, rng)
        along_walls(p, label, box, rng, 1, (1.0, 2.0), (0.6, 0.8))
        return
    along_walls(p, label, box, rng, 4 + int(area // 20), (1.8, 4.5), (0.7, 0.8))  # wall benches
    along_walls(p, label, box, rng, 1 + int(area > 35), (1.2, 1.8), (0.8, 0.9))  # fume hoods
    along_walls(p, label, box, rng, 3, (0.6, 1.2), (0.5, 0.6))  # cabinets, fridges
    r0, r1, c0, c1 = box
    bench = (1.5, _u(rng, 2.4, 4.0))
    island_grid(p, label, box, rng, bench if (c1 - c0) >= (r1 - r0) else bench[::-1], _u(rng, 1.1, 1.5), skip=0.1)
    for _ in range(int(area // 6)):  # instruments, carts, small tables
        r, c = int(rng.integers(r0, max(r0 + 1, r1))), int(rng.integers(c0, max(c0 + 1, c1)))
        s1, s2 = p.px(_u(rng, 0.5, 1.1)), p.px(_u(rng, 0.5, 1.1))
        p.put(label, r, c, s1, s2, round_=rng.random() < 0.3)


def _workshop(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    pillars(p, label, box, rng)
    along_walls(p, label, box, rng, 6, (1.5, 5.0), (0.7, 1.0))
    r0, r1, c0, c1 = box
    for _ in range(int(_area(p, box) // 10)):  # machines
        r, c = int(rng.integers(r0, max(r0 + 1, r1))), int(rng.integers(c0, max(c0 + 1, c1)))
        p.put(label, r, c, p.px(_u(rng, 0.8, 3.0)), p.px(_u(rng, 0.8, 3.0)), gap=1.2)


def _house(p: Placer, label: int, box: Box, rng: np.random.Generator) -> None:
    area = _area(p, box)
    if area < 6.0:  # bathroom, storage
        along_walls(p, label, box, rng, 2, (0.8, 1.7), (0.5, 0.75))
    elif area < 16.0 and rng.random() < 0.75:  # bedroom or kitchen
        if rng.random() < 0.7:
            p.against(label, box, _side(rng), _u(rng, 1.4, 1.6), 2.0, _where(rng)) or p.against(
                label, box, _side(rng), _u(rng, 0.9, 1.2), 2.0, _where(rng)
            )
            along_walls(p, label, box, rng, 2, (1.0, 2.0), (0.5, 0.6))
        else:
            along_walls(p, label, box, rng, 3, (1.5, 3.0), (0.6, 0.6))
    else:  # living room
        along_walls(p, label, box, rng, 1, (2.0, 2.6), (0.85, 0.95))
        along_walls(p, label, box, rng, 2, (1.2, 2.0), (0.4, 0.5))
        _centre(p, label, box, _u(rng, 0.8, 1.0), _u(rng, 1.2, 1.8))


#: (style, role) -> recipe. Roles: "small", "room", "big", "hall".
RECIPES: dict[tuple[str, str], Recipe] = {
    ("office", "small"): _office,
    ("office", "room"): _office,
    ("office", "big"): _open_plan,
    ("office", "hall"): _open_plan,
    ("school", "small"): _school_small,
    ("school", "room"): _classroom,
    ("school", "big"): _classroom,
    ("school", "hall"): _school_hall,
    ("lab", "small"): _lab,
    ("lab", "room"): _lab,
    ("lab", "big"): _lab,
    ("lab", "hall"): _workshop,
    ("house", "small"): _house,
    ("house", "room"): _house,
    ("house", "big"): _house,
    ("house", "hall"): _house,
}


def furnish_room(p: Placer, label: int, box: Box, use: str, style: str, rng: np.random.Generator) -> None:
    """Furnish one room with the recipe of its style and role (role from its use and floor area)."""
    area = _area(p, box)
    if use == "hall" or area > 110.0:
        role = "hall"
    elif area < 9.0 or use == "small":
        role = "small" if area < 14.0 else "room"
    elif use == "big" or area > 45.0:
        role = "big"
    else:
        role = "room"
    if style == "school" and role == "room" and area < 30.0:
        role = "small"
    RECIPES[(style, role)](p, label, box, rng)
