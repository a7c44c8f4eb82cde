"""Stage ``.world`` files: the floorplan bitmap, its size and pose, and the robot's start pose.

What Stage (4.x, ``libstage``) does with a floorplan, and what this loader reproduces:

* **Obstacle pixels** are those whose first channel (grey, or red) is <= 127
  (``rotrects_from_image_file``); Stage turns them into rectangles.
* **Scale**: the bounding box of the obstacle pixels, not the whole image, is stretched to the model's
  ``size [sx sy sz]`` metres (``BlockGroup::CalcSize``), separately in x and y, so white margins around
  the walls do not count and the two scales may differ.
* **Placement**: the centre of that bounding box sits at the model's ``pose [x y z yaw]`` (plus its
  ``origin`` offset, if any); yaw in degrees, counter-clockwise.

The loader crops the image to that bounding box and resamples it to a square grid (``resolution``:
by default the finer of the two scales; nearest neighbour when refining, "any obstacle pixel makes
the cell an obstacle" when coarsening, so walls survive either way). Beyond the bounding box is wall
(Stage's ``boundary 1`` floorplans end there too). Inside it, a cell is free only where the bitmap is
bright: grey >= ``free_level`` (0.9 by default, as for bare images), so mid-grey "unknown" of ROS maps
used as Stage bitmaps is wall here, although Stage itself would let a robot drive through it. A yaw
that is a multiple of 90 degrees is applied by rotating the grid (origin theta stays 0); any other yaw
becomes the origin's theta.

The start pose is the pose of the first top-level model whose type resolves, through ``define``
chains, to ``position`` (``pioneer2dx``, ``pr2``, ...). When an ``include`` file is missing so the chain
cannot be followed, the first model whose type chain names a well-known robot (pioneer, robot, pr2,
roomba, ...) is taken; else :class:`World` picks a start pose.

Syntax handled: ``#`` comments, ``include "file"`` (relative to the including file; missing includes
are skipped with a log message), ``define NAME BASE ( ... )``, nested ``type ( ... )`` models,
``key value``, ``key [a b c]``, quoted strings, ``unit_length`` ("m", "cm", "mm") and ``unit_angle``
("degrees", "radians"). Poses with three numbers are Stage 2's ``[x y yaw]``.
"""

from __future__ import annotations

import logging
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import FormatError, WorldError
from slamtrials.geometry import compose
from slamtrials.worlds.formats.image import DEFAULT_FREE_LEVEL, check_resolution, read_pixels
from slamtrials.worlds.world import World

__all__ = ["load_stage_world", "parse_worldfile", "STAGE_OBSTACLE_MAX"]

log = logging.getLogger(__name__)

#: Stage's pixel rule: first channel <= this (of 255) is an obstacle.
STAGE_OBSTACLE_MAX = 127
#: Stage's built-in model types (a define chain ending in one of these is resolved).
STAGE_BASE_TYPES = frozenset(
    "model position ranger laser sonar blobfinder fiducial camera gripper actuator blinkenlight "
    "lightindicator bumper wifi loadcell powerpack".split()
)
_ROBOT_HINT = re.compile(r"pioneer|robot|pr2|position|roomba|erratic|turtlebot|amigobot|youbot", re.IGNORECASE)
_UNIT_LENGTH = {"m": 1.0, "cm": 0.01, "mm": 0.001}
_MAX_INCLUDE_DEPTH = 16

_TOKEN = re.compile(
    r"""(?P<comment>\#[^\n]*)
      | (?P<string>"[^"\n]*")
      | (?P<number>[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?(?![A-Za-z_]))
      | (?P<word>[A-Za-z_][A-Za-z0-9_.\-]*)
      | (?P<punct>[()\[\]])
      | (?P<newline>\n)
      | (?P<space>[ \t\r\f\v,]+)
      | (?P<bad>.)""",
    re.VERBOSE,
)

Value = float | str


@dataclass
class Prop:
    """One ``key value`` or ``key [values]`` line: its values, and where it was written."""

    values: tuple[Value, ...]
    file: Path
    line: int


@dataclass
class Entity:
    """A model block ``type ( ... )`` or a ``define name base ( ... )``."""

    type: str
    file: Path
    line: int
    props: dict[str, Prop] = field(default_factory=dict)
    children: list[Entity] = field(default_factory=list)


@dataclass
class WorldFile:
    """A parsed world file with its includes merged in.

    ``props`` are the top-level properties, ``models`` the top-level model instances in file order,
    ``defines`` name -> the ``define`` block (its ``type`` is the base), ``missing_includes`` the
    include files that could not be found.
    """

    path: Path
    props: dict[str, Prop] = field(default_factory=dict)
    models: list[Entity] = field(default_factory=list)
    defines: dict[str, Entity] = field(default_factory=dict)
    missing_includes: list[str] = field(default_factory=list)


def _tokens(path: Path, text: str) -> list[tuple[str, str, int]]:
    """(kind, text, line) for every meaningful token of ``text``."""
    out = []
    line = 1
    for match in _TOKEN.finditer(text):
        kind = match.lastgroup
        if kind == "newline":
            line += 1
        elif kind == "bad":
            raise FormatError(path, f"unexpected character {match.group()!r}", line=line)
        elif kind not in ("space", "comment"):
            out.append((kind, match.group(), line))
    return out


class _Parser:
    def __init__(self, path: Path, text: str, on_include: Callable[[str, int], None]):
        self.path = path
        self.toks = _tokens(path, text)
        self.pos = 0
        self.on_include = on_include

    def peek(self, ahead: int = 0) -> tuple[str, str, int] | None:
        i = self.pos + ahead
        return self.toks[i] if i < len(self.toks) else None

    def take(self, what: str) -> tuple[str, str, int]:
        tok = self.peek()
        if tok is None:
            last = self.toks[-1][2] if self.toks else 1
            raise FormatError(self.path, f"unexpected end of file, expected {what}", line=last)
        self.pos += 1
        return tok

    def fail(self, tok: tuple[str, str, int], expected: str) -> FormatError:
        return FormatError(self.path, f"expected {expected}, found {tok[1]!r}", line=tok[2])

    def value(self, tok: tuple[str, str, int]) -> Value:
        kind, text, _ = tok
        if kind == "number":
            return float(text)
        if kind == "string":
            return text[1:-1]
        if kind == "word":
            return text
        raise self.fail(tok, "a number or a string")

    def body(self, owner: Entity | WorldFile, *, top: bool) -> None:
        """Parse statements until ')' (or end of file at top level) into ``owner``."""
        while True:
            tok = self.peek()
            if tok is None:
                if top:
                    return
                raise FormatError(self.path, "the block opened here is never closed with ')'", line=owner.line)
            kind, text, line = tok
            if kind == "punct" and text == ")":
                if top:
                    raise FormatError(self.path, "')' without a matching '('", line=line)
                self.pos += 1
                return
            if kind != "word":
                raise self.fail(tok, "a property name, a model or 'define'/'include'")
            self.pos += 1
            nxt = self.peek()
            if text == "include" and top:
                file_tok = self.take("an include file name")
                if file_tok[0] != "string":
                    raise self.fail(file_tok, 'a quoted include file name, as in include "pioneer.inc"')
                self.on_include(file_tok[1][1:-1], line)
            elif text == "define":
                name = self.take("a define name")
                base = self.take("the base model of the define")
                if name[0] != "word" or base[0] != "word":
                    raise self.fail(name if name[0] != "word" else base, "define NAME BASE ( ... )")
                open_ = self.take("'('")
                if open_[1] != "(":
                    raise self.fail(open_, "'(' after define NAME BASE")
                entity = Entity(type=base[1], file=self.path, line=line)
                self.body(entity, top=False)
                if isinstance(owner, WorldFile):
                    owner.defines[name[1]] = entity
                else:
                    raise FormatError(self.path, "define is only allowed at the top level", line=line)
            elif nxt is not None and nxt[1] == "(":
                self.pos += 1
                entity = Entity(type=text, file=self.path, line=line)
                self.body(entity, top=False)
                (owner.models if isinstance(owner, WorldFile) else owner.children).append(entity)
            else:
                owner.props[text] = Prop(self.prop_values(text, line), self.path, line)

    def prop_values(self, key: str, line: int) -> tuple[Value, ...]:
        tok = self.take(f"a value for {key!r}")
        if tok[1] == "[":
            values = []
            while True:
                item = self.take(f"']' closing the list of {key!r} (opened at line {line})")
                if item[1] == "]":
                    return tuple(values)
                values.append(self.value(item))
        after = self.peek()
        if tok[0] == "word" and after is not None and after[1] == "(":
            raise FormatError(self.path, f"property {key!r} has no value", line=line)
        return (self.value(tok),)


def parse_worldfile(path: str | Path) -> WorldFile:
    """Parse a Stage world file and, recursively, the files it includes.

    Raises
    ------
    FormatError
        The file is missing or does not follow the world-file syntax (names file and line).
    """
    path = Path(path)
    world = WorldFile(path=path)
    _parse_into(world, path, set(), depth=0)
    return world


def _parse_into(world: WorldFile, path: Path, seen: set[Path], depth: int) -> None:
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except FileNotFoundError:
        raise FormatError(path, "no such Stage world file") from None
    except OSError as exc:
        raise FormatError(path, f"cannot read the file ({exc})") from exc
    seen.add(path.resolve())

    def include(name: str, line: int) -> None:
        """Parse an included file into ``world`` right here, as Stage inlines it."""
        target = Path(name) if Path(name).is_absolute() else path.parent / name
        if target.resolve() in seen:
            return
        if depth >= _MAX_INCLUDE_DEPTH:
            raise FormatError(path, f"includes nested more than {_MAX_INCLUDE_DEPTH} deep at {name!r}", line=line)
        if not target.is_file():
            log.info("%s:%d: include %r not found; its defines are unknown", path, line, name)
            world.missing_includes.append(name)
            return
        _parse_into(world, target, seen, depth + 1)

    _Parser(path, text, include).body(world, top=True)


def type_chain(world: WorldFile, model_type: str) -> list[str]:
    """The define chain of a type, e.g. ``['autorob', 'fancypioneer2dx', 'pioneer2dx', 'position']``."""
    chain = [model_type]
    while chain[-1] in world.defines and len(chain) < 64:
        base = world.defines[chain[-1]].type
        if base in chain:
            break
        chain.append(base)
    return chain


def resolved_props(world: WorldFile, entity: Entity) -> dict[str, Prop]:
    """An instance's properties: those of its define chain, base first, overridden by its own."""
    props: dict[str, Prop] = {}
    for name in reversed(type_chain(world, entity.type)[:-1]):
        props.update(world.defines[name].props)
    props.update(entity.props)
    return props


def _numbers(prop: Prop, key: str, counts: tuple[int, ...]) -> list[float]:
    if len(prop.values) not in counts or not all(isinstance(v, float) for v in prop.values):
        expected = " or ".join(str(c) for c in counts)
        raise FormatError(prop.file, f"{key}: expected [{expected} numbers], got {list(prop.values)}", line=prop.line)
    return [float(v) for v in prop.values]  # type: ignore[arg-type]


def _string(prop: Prop, key: str) -> str:
    if len(prop.values) != 1 or not isinstance(prop.values[0], str):
        raise FormatError(prop.file, f"{key}: expected one quoted string, got {list(prop.values)}", line=prop.line)
    return prop.values[0]


class _Units:
    def __init__(self, world: WorldFile):
        length = world.props.get("unit_length")
        angle = world.props.get("unit_angle")
        self.metres = 1.0
        self.radians = math.pi / 180.0
        if length is not None:
            unit = _string(length, "unit_length")
            if unit not in _UNIT_LENGTH:
                raise FormatError(
                    length.file,
                    f"unit_length: expected one of {', '.join(_UNIT_LENGTH)}, got {unit!r}",
                    line=length.line,
                )
            self.metres = _UNIT_LENGTH[unit]
        if angle is not None:
            unit = _string(angle, "unit_angle")
            if unit not in ("degrees", "radians"):
                raise FormatError(angle.file, f"unit_angle: expected degrees or radians, got {unit!r}", line=angle.line)
            self.radians = 1.0 if unit == "radians" else math.pi / 180.0

    def pose(self, prop: Prop | None, key: str = "pose") -> NDArray[np.float64]:
        """Stage ``[x y z yaw]`` (or Stage 2 ``[x y yaw]``) -> float64 [3] (x, y, theta) in m and rad."""
        if prop is None:
            return np.zeros(3)
        values = _numbers(prop, key, (4, 3))
        x, y, yaw = (values[0], values[1], values[3]) if len(values) == 4 else values
        return np.array([x * self.metres, y * self.metres, yaw * self.radians])


def _floorplan(world: WorldFile) -> tuple[Entity, dict[str, Prop]]:
    candidates = []
    for model in world.models:
        props = resolved_props(world, model)
        if "bitmap" in props:
            candidates.append((model, props))
    if not candidates:
        raise FormatError(
            world.path, 'no floorplan: no top-level model has a bitmap (as in floorplan( bitmap "map.png" size [...] ))'
        )
    for model, props in candidates:
        if "floorplan" in type_chain(world, model.type):
            return model, props
    return candidates[0]


def _robot_start(world: WorldFile, units: _Units, floorplan: Entity) -> tuple[NDArray[np.float64] | None, str | None]:
    """(start pose, how it was found) from the first robot instance, or (None, None)."""
    models = [m for m in world.models if m is not floorplan]
    chains = [type_chain(world, m.type) for m in models]
    for model, chain in zip(models, chains):
        if "position" in chain:
            return units.pose(resolved_props(world, model).get("pose")), f"{model.type} (position model)"
    for model, chain in zip(models, chains):
        unresolved = chain[-1] not in STAGE_BASE_TYPES
        if unresolved and any(_ROBOT_HINT.search(name) for name in chain):
            return units.pose(
                resolved_props(world, model).get("pose")
            ), f"{model.type} (type name; include not available)"
    return None, None


def _axis_ranges(n_dest: int, n_src: int, step: float) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Source pixel ranges [start, stop) for each destination cell along one axis.

    ``step`` is the destination cell size in source pixels; both grids share their centre.
    """
    centres = (np.arange(n_dest) + 0.5 - n_dest / 2.0) * step + n_src / 2.0
    if step <= 1.0:  # refining: nearest neighbour, the source pixel under the cell centre
        start = np.floor(centres).astype(np.intp)
        stop = start + 1
    else:  # coarsening: every source pixel the cell overlaps
        start = np.floor(centres - step / 2.0 + 1e-9).astype(np.intp)
        stop = np.ceil(centres + step / 2.0 - 1e-9).astype(np.intp)
    start = np.clip(start, 0, n_src - 1)
    return start, np.clip(np.maximum(stop, start + 1), 1, n_src)


def resample_any(occupied: NDArray[np.bool_], shape: tuple[int, int], steps: tuple[float, float]) -> NDArray[np.bool_]:
    """Resample a bool grid to ``shape`` [H', W']: a cell is True if any source pixel it takes is True.

    ``steps`` = (rows, cols) destination cell size in source pixels. Vectorized with an integral image.
    """
    r0, r1 = _axis_ranges(shape[0], occupied.shape[0], steps[0])
    c0, c1 = _axis_ranges(shape[1], occupied.shape[1], steps[1])
    table = np.zeros((occupied.shape[0] + 1, occupied.shape[1] + 1), dtype=np.int64)
    np.cumsum(np.cumsum(occupied, axis=0, dtype=np.int64), axis=1, out=table[1:, 1:])
    counts = table[r1][:, c1] - table[r0][:, c1] - table[r1][:, c0] + table[r0][:, c0]
    return counts > 0


def load_stage_world(
    path: str | Path,
    *,
    name: str | None = None,
    resolution: float | None = None,
    free_level: float = DEFAULT_FREE_LEVEL,
) -> World:
    """Load the floorplan and robot start pose of a Stage world file.

    Parameters
    ----------
    path:
        The ``.world`` file. Its floorplan ``bitmap`` is found relative to the world file's folder.
    name:
        World name; defaults to the floorplan's ``name``, else the file name without suffix.
    resolution:
        Cell size (m) of the square output grid; default: the finer of Stage's x and y scales.
    free_level:
        Grey level in [0, 1] at or above which a bitmap pixel is free (see the module notes).

    Returns
    -------
    World
        The cropped, resampled floorplan in Stage's world frame (metres, y up), the robot's start
        pose (x, y, theta) in that frame when a robot instance was found. ``metadata`` holds the
        source, format ("stage"), bitmap, Stage's x/y scales (m/px) and how the start was found.

    Raises
    ------
    FormatError
        Syntax errors, no floorplan, no ``size``, a missing bitmap (message: world file, line and
        bitmap), an unreadable bitmap or one without obstacle pixels (Stage cannot scale it; message:
        the bitmap file).
    WorldError
        Bad ``resolution`` or ``free_level``, or no free space.
    """
    path = Path(path)
    if resolution is not None:
        resolution = check_resolution(resolution, path)
    if not 0.0 <= float(free_level) <= 1.0:
        raise WorldError(f"{path}: free_level must be a grey level between 0 and 1, got {free_level!r}")
    world = parse_worldfile(path)
    units = _Units(world)
    floorplan, props = _floorplan(world)
    bitmap_prop = props["bitmap"]
    bitmap = _string(bitmap_prop, "bitmap")
    size_prop = props.get("size")
    if size_prop is None:
        raise FormatError(
            path, f"the floorplan model (line {floorplan.line}) has no size [x y z] in metres", line=floorplan.line
        )
    size = np.array(_numbers(size_prop, "size", (3, 2))[:2]) * units.metres
    if not np.all(size > 0):
        raise FormatError(
            size_prop.file,
            f"size: the floorplan's size must be positive, got {list(size_prop.values)}",
            line=size_prop.line,
        )
    image_path = Path(bitmap) if Path(bitmap).is_absolute() else path.parent / bitmap
    if not image_path.is_file():
        raise FormatError(
            bitmap_prop.file, f"floorplan bitmap {bitmap!r} not found (looked for {image_path})", line=bitmap_prop.line
        )
    colour, _alpha = read_pixels(image_path)  # Stage ignores alpha
    first = colour[:, :, 0]
    obstacle = first <= STAGE_OBSTACLE_MAX
    rows = np.flatnonzero(obstacle.any(axis=1))
    cols = np.flatnonzero(obstacle.any(axis=0))
    if rows.size == 0:
        raise FormatError(
            image_path,
            f"the floorplan bitmap has no obstacle pixel (grey <= {STAGE_OBSTACLE_MAX}); Stage cannot scale it to size",
        )
    crop = (slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1))
    blocked = first[crop] < float(free_level) * 255.0
    src_h, src_w = blocked.shape
    scale = size / np.array([src_w, src_h])  # metres per source pixel (x, y)
    res = float(resolution) if resolution is not None else float(scale.min())
    dest = (max(2, int(round(size[1] / res))), max(2, int(round(size[0] / res))))
    grid = resample_any(blocked, dest, (res / scale[1], res / scale[0]))

    centre = compose(units.pose(props.get("pose")), units.pose(props.get("origin"), "origin"))
    quarter_turns = centre[2] / (math.pi / 2.0)
    if abs(quarter_turns - round(quarter_turns)) < 1e-9:
        grid = np.rot90(grid, k=int(round(quarter_turns)) % 4)
        half = np.array([grid.shape[1], grid.shape[0]]) * res / 2.0
        origin = np.array([centre[0] - half[0], centre[1] - half[1], 0.0])
    else:
        half = np.array([grid.shape[1], grid.shape[0], 0.0]) * res / 2.0
        origin = compose(centre, -half)
        origin[2] = centre[2]
    if grid.all():
        raise WorldError(
            f"{path}: the floorplan {bitmap!r} has no free space (no pixel brighter than free_level={free_level:g})"
        )

    start, how = _robot_start(world, units, floorplan)
    floor_name = props.get("name")
    metadata = {
        "source": str(path),
        "format": "stage",
        "bitmap": str(image_path),
        "stage_scale": [float(scale[0]), float(scale[1])],
        "bitmap_bbox_px": [int(cols[0]), int(rows[0]), int(src_w), int(src_h)],
        "free_level": float(free_level),
        "start_from": how or "automatic",
    }
    if world.missing_includes:
        metadata["missing_includes"] = list(world.missing_includes)
    world_name = name or (_string(floor_name, "name") if floor_name else path.stem)
    if start is not None:
        try:
            return World(occupied=grid, resolution=res, origin=origin, name=world_name, start=start, metadata=metadata)
        except WorldError:
            log.warning(
                "%s: the robot's pose (%.2f, %.2f) is not in free space; choosing a start pose",
                path,
                start[0],
                start[1],
            )
            metadata["start_from"] = f"automatic ({how} at ({start[0]:.2f}, {start[1]:.2f}) is not in free space)"
    return World(occupied=grid, resolution=res, origin=origin, name=world_name, start=None, metadata=metadata)
