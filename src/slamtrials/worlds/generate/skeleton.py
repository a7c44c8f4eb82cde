"""Building shapes: wings sized and placed so that the gross footprint is near a target area.

Shapes: ``bar`` (one double-loaded corridor), ``racetrack`` (two corridors around a core of rooms and
halls, joined by cross corridors), and the multi-wing shapes ``L``, ``T``, ``Z``, ``U``, ``H``,
``cross``, ``comb`` and ``fishbone``: a horizontal *spine* wing with *arms* perpendicular to it
whose corridors run into the spine's corridor through junctions.
"""

from __future__ import annotations

import numpy as np

from slamtrials.worlds.generate.kinds import STYLES, KindSpec, Style
from slamtrials.worlds.generate.layout import WALL, Band, Wing, wing_plan
from slamtrials.worlds.generate.plan import Plan, Rect

__all__ = ["choose_shape", "build_plan", "SHAPES"]

#: Arms of each multi-wing shape: (position, side) with position "end0", "end1", "mid" or a fraction.
SHAPES: dict[str, list[tuple[str | float, int]]] = {
    "L": [("end0", +1)],
    "T": [("mid", +1)],
    "Z": [("end0", +1), ("end1", -1)],
    "U": [("end0", +1), ("end1", +1)],
    "H": [("end0", +1), ("end0", -1), ("end1", +1), ("end1", -1)],
    "cross": [("mid", +1), ("mid", -1)],
}


def _depth(style: Style, rng: np.random.Generator) -> float:
    return float(rng.uniform(*style.depth)) + WALL


def _corridor(style: Style, rng: np.random.Generator) -> float:
    return float(rng.uniform(*style.corridor)) + WALL


def _bands(style: Style, rng: np.random.Generator, corridors: int, single_loaded: bool = False) -> tuple[Band, ...]:
    """Bands across a wing with ``corridors`` (1 or 2) corridors."""
    cw = _corridor(style, rng)
    if corridors == 1:
        if single_loaded:
            return (Band("rooms", _depth(style, rng)), Band("corridor", cw))
        return (Band("rooms", _depth(style, rng)), Band("corridor", cw), Band("rooms", _depth(style, rng)))
    core = float(rng.uniform(1.7, 2.3)) * (style.depth[0] + style.depth[1]) / 2 + WALL
    return (
        Band("rooms", _depth(style, rng)),
        Band("corridor", cw),
        Band("core", core),
        Band("corridor", cw),
        Band("rooms", _depth(style, rng)),
    )


def _width(bands: tuple[Band, ...]) -> float:
    return sum(b.depth for b in bands)


def choose_shape(spec: KindSpec, gross: float, rng: np.random.Generator) -> str:
    """Pick a building shape suited to the kind and to a gross footprint of ``gross`` m^2."""
    if spec.name == "house":
        return "bar"
    style = STYLES[spec.styles[0]]
    bar_width = sum(style.depth) + sum(style.corridor) / 2 + 3 * WALL
    if spec.name == "multiwing":
        if gross < 2500:
            options = ["L", "T", "Z"] + (["U"] if gross >= 1800 else [])
        elif gross < 6000:
            options = ["U", "H", "T", "cross"] + (["comb"] if gross >= 4500 else [])
        else:
            options = ["H", "comb", "fishbone"]
        return options[int(rng.integers(len(options)))]
    bar_length = gross / bar_width
    if bar_length <= 55.0:
        return "bar"
    if gross <= 2500:
        options = ["racetrack", "L", "T"] + (["bar"] if bar_length <= 85.0 else [])
    elif gross <= 5500:
        options = ["racetrack", "U", "H", "T"]
    else:
        options = ["H", "comb", "fishbone"]
    return options[int(rng.integers(len(options)))]


def build_plan(spec: KindSpec, shape: str, design: float, gross: float, rng: np.random.Generator) -> Plan:
    """Lay out a building of the given shape whose gross footprint is about ``gross`` m^2.

    Structural choices (single- or double-loaded corridors, number of arms, wide arms) follow the
    ``design`` area, so that tuning ``gross`` changes lengths only.

    The plan is shifted so that it starts at (0, 0).
    """
    if shape in ("bar", "racetrack"):
        plan = _single(spec, shape, design, gross, rng)
    else:
        plan = _arms(spec, shape, design, gross, rng)
    plan.shape = shape
    box = plan.bounds()
    shifted = plan.shifted(-box.x0, -box.y0)
    shifted.shape = shape
    return shifted


def _pick_style(spec: KindSpec, rng: np.random.Generator) -> Style:
    return STYLES[spec.styles[int(rng.integers(len(spec.styles)))]]


def _single(spec: KindSpec, shape: str, design: float, gross: float, rng: np.random.Generator) -> Plan:
    """A single wing: a bar (one corridor) or a racetrack (two corridors and a core)."""
    style = _pick_style(spec, rng)
    corridors = 2 if shape == "racetrack" else 1
    single_loaded = corridors == 1 and design < 2.2 * (style.depth[0] + style.corridor[0]) * style.room_width[1]
    bands = _bands(style, rng, corridors, single_loaded=single_loaded)
    width = _width(bands)
    depth = bands[0].depth
    ends = [float(rng.random()) for _ in range(2)]
    extra = [float(rng.uniform(0.9, 1.3)) * depth for _ in range(2)]
    length = gross / width
    end_depth = []
    for draw, e in zip(ends, extra):
        wanted = corridors == 2 or draw < (0.9 if style.name == "house" else 0.6)
        end_depth.append(e if wanted and length > 2.5 * e + 6.0 else 0.0)
    cross = _cross(length, (end_depth[0], end_depth[1]), bands[1].depth, rng) if corridors == 2 else ()
    wing = Wing(
        0.0, 0.0, True, length, bands, (end_depth[0], end_depth[1]), cross, style, lobby=rng.random() < style.lobby_prob
    )
    return wing_plan(wing, rng)


def _cross(wing_len: float, end_depth: tuple[float, float], cw: float, rng: np.random.Generator) -> tuple[float, ...]:
    """Cross-corridor centres: one at each end of the corridors and one every 28-42 m between."""
    first, last = end_depth[0] + cw / 2, wing_len - end_depth[1] - cw / 2
    count = max(0, int((last - first) // float(rng.uniform(28.0, 42.0))))
    return tuple(float(c) for c in np.linspace(first, last, count + 2))


def _arm_layout(shape: str, design: float, per_side_max: int) -> list[tuple[str | float, int]]:
    """Arms of a shape; comb and fishbone get more arms for bigger designs, at most ``per_side_max``."""
    if shape in SHAPES:
        return list(SHAPES[shape])
    if shape == "comb":
        n = int(np.clip(min(round(design / 1800.0), per_side_max), 2, 6))
        return [("end0", +1)] + [(i / (n - 1), +1) for i in range(1, n - 1)] + [("end1", +1)]
    n = int(np.clip(min(round(design / 3500.0), per_side_max), 2, 4))  # fishbone: arms on both sides
    arms: list[tuple[str | float, int]] = []
    for i in range(n):
        pos: str | float = "end0" if i == 0 else "end1" if i == n - 1 else i / (n - 1)
        arms += [(pos, +1), (pos, -1)]
    return arms


def _per_side_max(spec: KindSpec, spine_width: float, design: float, gap: float) -> int:
    """How many arms fit along one side of a spine that takes at most half the design area."""
    arm_width = max(sum(STYLES[s].depth) + sum(STYLES[s].corridor) / 2 + 3 * WALL for s in spec.styles)
    budget = 0.5 * design / spine_width
    return max(2, int((budget + gap) // (arm_width + gap)))


def _arm_sizes(layout, narrow, wide, spine_bands, design, gross, gaps, rng):
    """Spine length (m), each arm's bands, and each arm's length (m).

    Arms are ``rho`` times as long as the spine (0.4-0.7 when arms go both ways, 0.6-1.0 when one
    way), within 20 %. A building of 4,000 m^2 or more with at most four arms whose spine would be
    longer than 1.6 sqrt(design) gets arms with two corridors (twice as wide, so half as long). The spine is at
    least as long as the arms on one side need, side by side with courtyards between them.
    """
    both = any(side < 0 for _, side in layout)
    rho = float(rng.uniform(0.4, 0.7)) if both else float(rng.uniform(0.6, 1.0))
    shares = np.array([float(rng.uniform(0.8, 1.2)) for _ in layout])
    ws = _width(spine_bands)

    def spine_for(area: float, widths: np.ndarray) -> float:
        return area / (ws + rho * float(np.sum(shares * widths)))

    bands = list(narrow)
    if (
        len(layout) <= 4
        and design >= 4000
        and spine_for(design, np.array([_width(b) for b in narrow])) > 1.6 * np.sqrt(design)
    ):
        bands = list(wide)
    wa = np.array([_width(b) for b in bands])
    spine_len = spine_for(gross, wa)
    arm_len = rho * shares * spine_len
    need = 0.0
    for side in (+1, -1):
        on_side = [i for i, (_, s) in enumerate(layout) if s == side]
        if on_side:
            need = max(
                need, float(np.sum(wa[on_side])) + gaps * (len(on_side) - 1) + (0.0 if len(on_side) > 1 else 4.0)
            )
    if spine_len < need:
        spine_len = need
        rest = max(gross - ws * spine_len, 0.15 * gross)
        arm_len = rest * shares / float(np.sum(shares * wa))
    return float(spine_len), bands, [float(v) for v in np.maximum(arm_len, 0.9 * wa)]


def _arms(spec: KindSpec, shape: str, design: float, gross: float, rng: np.random.Generator) -> Plan:
    """A spine with arms; the arms' corridors join the spine's corridors, often through a junction lobby.

    See :func:`_arm_sizes` for the proportions.
    """
    spine_style = _pick_style(spec, rng)
    spine_bands = _bands(spine_style, rng, 2 if design > 5000 and rng.random() < 0.7 else 1)
    gaps = float(rng.uniform(9.0, 16.0))
    layout = _arm_layout(shape, design, _per_side_max(spec, _width(spine_bands), design, gaps))
    arm_styles = [_pick_style(spec, rng) for _ in layout]
    narrow = [_bands(s, rng, 1) for s in arm_styles]
    wide = [_bands(s, rng, 2) for s in arm_styles]
    spine_len, arm_bands, arm_len = _arm_sizes(layout, narrow, wide, spine_bands, design, gross, gaps, rng)
    ws = _width(spine_bands)
    centres = []
    for (pos, _), bands in zip(layout, arm_bands):
        w = _width(bands)
        if pos == "end0":
            centres.append(w / 2)
        elif pos == "end1":
            centres.append(spine_len - w / 2)
        elif pos == "mid":
            centres.append(spine_len / 2 + float(rng.uniform(-0.1, 0.1)) * spine_len)
        else:
            centres.append(w / 2 + float(pos) * (spine_len - w))
    end_depth = [0.0, 0.0]
    for (pos, _), bands in zip(layout, arm_bands):
        if pos == "end0":
            end_depth[0] = bands[0].depth if end_depth[0] == 0 else min(end_depth[0], bands[0].depth)
        elif pos == "end1":
            end_depth[1] = bands[-1].depth if end_depth[1] == 0 else min(end_depth[1], bands[-1].depth)
    for k in range(2):
        if end_depth[k] == 0 and rng.random() < 0.6:
            end_depth[k] = float(rng.uniform(0.9, 1.2)) * spine_bands[0].depth
    ends = (end_depth[0], end_depth[1])
    cross = _cross(spine_len, ends, spine_bands[1].depth, rng) if len(spine_bands) > 3 else ()
    spine = Wing(
        0.0, 0.0, True, spine_len, spine_bands, ends, cross, spine_style, lobby=rng.random() < spine_style.lobby_prob
    )
    plan = wing_plan(spine, rng)
    spine_corr = [spine.band_range(i) for i in spine.corridor_indices()]
    for (_pos, side), bands, style, centre, length in zip(layout, arm_bands, arm_styles, centres, arm_len):
        x0 = centre - _width(bands) / 2
        tip = float(rng.uniform(0.9, 1.3)) * bands[0].depth if len(bands) > 3 or rng.random() < 0.65 else 0.0
        y0 = ws if side > 0 else -float(length)
        arm_ends = (0.0, tip) if side > 0 else (tip, 0.0)
        arm_cross = _cross(float(length), arm_ends, bands[1].depth, rng) if len(bands) > 3 else ()
        arm = Wing(x0, y0, False, float(length), bands, arm_ends, arm_cross, style)
        plan.extend(wing_plan(arm, rng))
        sy0, sy1 = spine_corr[-1] if side > 0 else spine_corr[0]
        for index in arm.corridor_indices():
            c0, c1 = arm.band_range(index)
            cx0, cx1 = x0 + c0, x0 + c1
            link = Rect(cx0, sy0, cx1, ws) if side > 0 else Rect(cx0, 0.0, cx1, sy1)
            plan.corridors.append((link, "y", style.name))
        if rng.random() < 0.5:
            c0, c1 = arm.band_range(arm.corridor_indices()[0])
            cx0, cx1 = x0 + c0, x0 + c1
            grow_x, grow_y = float(rng.uniform(1.5, 3.5)), float(rng.uniform(1.5, 3.5))
            lobby = Rect(
                max(0.0, cx0 - grow_x),
                sy0 - (grow_y if side < 0 else 0.0),
                min(spine_len, cx1 + grow_x),
                sy1 + (grow_y if side > 0 else 0.0),
            )
            plan.lobbies.append((lobby, style.name))
    return plan
