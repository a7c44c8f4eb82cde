"""Features along corridors and in lobbies, so that a scan matcher never sees a bare, uniform tube.

Every few metres of corridor gets something on its walls: pilasters (wall columns), notice boards and
extinguisher cabinets, benches, lockers in schools, and free-standing columns where the corridor is
wide enough. Lobbies get columns, a desk and benches. All items go through :class:`Placer`, so a
1 m wide passage always remains.
"""

from __future__ import annotations

import numpy as np

from slamtrials.worlds.generate.furniture import along_walls, pillars
from slamtrials.worlds.generate.placement import Placer
from slamtrials.worlds.generate.plan import Plan
from slamtrials.worlds.generate.raster import CIRCULATION

__all__ = ["furnish_circulation"]

#: Wall features: name -> (length range m, depth range m).
FEATURES = {
    "pilaster": ((0.3, 0.6), (0.15, 0.3)),
    "board": ((0.5, 1.6), (0.08, 0.15)),
    "bench": ((1.2, 2.2), (0.4, 0.5)),
    "lockers": ((2.0, 6.0), (0.35, 0.45)),
    "cabinet": ((0.5, 1.2), (0.3, 0.6)),
}

#: Style -> (feature names, probabilities).
MIX = {
    "office": (("pilaster", "board", "bench", "cabinet"), (0.45, 0.3, 0.1, 0.15)),
    "school": (("pilaster", "board", "bench", "lockers"), (0.3, 0.2, 0.1, 0.4)),
    "lab": (("pilaster", "board", "cabinet", "bench"), (0.4, 0.25, 0.3, 0.05)),
    "house": (("board", "cabinet"), (0.5, 0.5)),
}


def _wall_rows(occ: np.ndarray, centre: int, col: int, reach: int) -> tuple[int, int]:
    """Rows of the first occupied cells above and below ``centre`` in column ``col`` (-1 if none in reach)."""
    top = occ[max(0, centre - reach) : centre, col]
    bottom = occ[centre : centre + reach, col]
    up = np.flatnonzero(top)
    down = np.flatnonzero(bottom)
    return (max(0, centre - reach) + int(up[-1]) if len(up) else -1, centre + int(down[0]) if len(down) else -1)


def _corridor(p: Placer, rows: slice, cols: slice, horizontal: bool, style: str, rng: np.random.Generator) -> None:
    occ = p.occupied if horizontal else p.occupied.T
    if not horizontal:
        rows, cols = cols, rows
    centre = (rows.start + rows.stop) // 2
    reach = (rows.stop - rows.start) // 2 + p.px(1.5)
    names, probs = MIX.get(style, MIX["office"])
    pos = cols.start + p.px(float(rng.uniform(0.5, 3.0)))
    while pos < cols.stop:
        name = names[int(rng.choice(len(names), p=probs))]
        length_m, depth_m = (float(rng.uniform(*r)) for r in FEATURES[name])
        n, d = p.px(length_m), p.px(depth_m)
        top, bottom = _wall_rows(occ, centre, pos, reach)
        sides = ["N", "S"] if name == "pilaster" and rng.random() < 0.5 else ["N" if rng.random() < 0.5 else "S"]
        for side in sides:
            if side == "N" and top >= 0:
                _put(p, horizontal, top + 1, pos - n // 2, d, n, "N")
            elif side == "S" and bottom >= 0:
                _put(p, horizontal, bottom - d, pos - n // 2, d, n, "S")
        if top >= 0 and bottom >= 0 and (bottom - top) * p.grid.resolution > 2.7 and rng.random() < 0.25:
            s = p.px(float(rng.uniform(0.3, 0.45)))
            _put(p, horizontal, (top + bottom - s) // 2, pos + p.px(1.5), s, s, "", round_=rng.random() < 0.5)
        pos += p.px(float(rng.uniform(2.0, 4.5)))


def _put(p: Placer, horizontal: bool, r: int, c: int, h: int, w: int, back: str, round_: bool = False) -> bool:
    """Place in corridor frame (rows across, cols along); transpose for vertical corridors."""
    if horizontal:
        return p.put(CIRCULATION, r, c, h, w, back, round_=round_)
    swap = {"N": "W", "S": "E", "W": "N", "E": "S"}
    return p.put(CIRCULATION, c, r, w, h, "".join(swap[s] for s in back), round_=round_)


def furnish_circulation(p: Placer, plan: Plan, rng: np.random.Generator) -> None:
    """Put features along every corridor of the plan and into every lobby."""
    grid = p.grid
    for rect, axis, style in plan.corridors:
        rows, cols = grid.slices(rect)
        if rows.stop - rows.start < 2 or cols.stop - cols.start < 2:
            continue
        _corridor(p, rows, cols, axis == "x", style, rng)
    for rect, _style in plan.lobbies:
        rows, cols = grid.slices(rect)
        inside = ~p.occupied[rows, cols] & (p.labels[rows, cols] == CIRCULATION)
        if not inside.any():
            continue
        r_idx, c_idx = np.flatnonzero(inside.any(axis=1)), np.flatnonzero(inside.any(axis=0))
        box = (
            rows.start + int(r_idx[0]),
            rows.start + int(r_idx[-1]) + 1,
            cols.start + int(c_idx[0]),
            cols.start + int(c_idx[-1]) + 1,
        )
        pillars(p, CIRCULATION, box, rng, spacing=float(rng.uniform(4.5, 7.0)))
        along_walls(p, CIRCULATION, box, rng, 3, (1.2, 2.5), (0.4, 0.6))
