"""``slamtrials worlds``: list the bundled worlds, show or describe a floor plan, generate a building."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.common import make_app, make_console
from slamtrials.errors import ConfigError

app = make_app(help="List, show, describe and generate floor plans.")

FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg")

WorldArg = Annotated[
    str,
    typer.Argument(
        metavar="NAME_OR_FILE",
        help="Bundled world name (see 'slamtrials worlds list') or floor-plan file (.png/.pgm, .yaml, .world, .json).",
    ),
]
ResolutionOpt = Annotated[
    float | None, typer.Option("--resolution", "-r", help="Metres per pixel, for a bare PNG/PGM floor plan.")
]


def _load(source: str, resolution: float | None):
    from slamtrials.worlds import load_world

    if resolution is not None and not (resolution > 0):
        raise ConfigError(f"--resolution must be a positive number of metres per pixel, got {resolution}")
    options = {} if resolution is None else {"resolution": resolution}
    return load_world(source, **options)


@app.command("list")
def list_worlds() -> None:
    """List the bundled worlds: name, kind, requested and free area, size in metres."""
    from rich.table import Table

    from slamtrials.worlds.catalog import catalog_entries

    table = Table(title="Bundled worlds (slamtrials worlds show NAME -o NAME.png)")
    table.add_column("name", no_wrap=True)
    for column, justify in (
        ("kind", "left"),
        ("shape", "left"),
        ("area m\u00b2", "right"),
        ("free m\u00b2", "right"),
        ("size m", "right"),
        ("rooms", "right"),
    ):
        table.add_column(column, justify=justify)
    for e in catalog_entries():
        table.add_row(
            e["name"],
            e["kind"],
            e.get("shape", ""),
            f"{e['area_m2']:,.0f}",
            f"{e['free_area_m2']:,.0f}",
            f"{e['width_m']:.0f} \u00d7 {e['height_m']:.0f}",
            str(e.get("rooms", "")),
        )
    make_console().print(table)


@app.command("show")
def show(
    world: WorldArg,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Picture to write (.png, .pdf, .svg); default NAME.png.")
    ] = None,
    resolution: ResolutionOpt = None,
    dpi: Annotated[int, typer.Option("--dpi", help="Dots per inch of the picture.", min=30, max=600)] = 120,
) -> None:
    """Draw a floor plan: walls black, free space white, start pose as an arrow, a scale bar in metres."""
    from slamtrials.report.figures import save_world_figure

    the_world = _load(world, resolution)
    out = out if out is not None else Path(f"{the_world.name}.png")
    if out.suffix.lower() not in FIGURE_SUFFIXES:
        raise ConfigError(
            f"--out {out}: unknown picture format {out.suffix!r}; use one of {', '.join(FIGURE_SUFFIXES)}"
        )
    if out.resolve() in _plan_files(world):
        raise ConfigError(f"--out {out}: is the floor plan itself (the map's image); choose another picture name")
    save_world_figure(the_world, out, dpi=dpi)
    typer.echo(f"wrote {out}")


def _plan_files(world: str) -> set[Path]:
    """The files a floor plan named by path is read from: the file and, for a ROS map YAML, its image."""
    path = Path(world)
    if not path.is_file():
        return set()
    files = {path.resolve()}
    if path.suffix.lower() in (".yaml", ".yml"):
        import yaml

        try:
            doc = yaml.safe_load(path.read_text(encoding="utf-8"))
        except (yaml.YAMLError, UnicodeDecodeError):
            return files
        if isinstance(doc, dict) and isinstance(doc.get("image"), str):
            files.add((path.parent / doc["image"]).resolve())
    return files


@app.command("info")
def info(world: WorldArg, resolution: ResolutionOpt = None) -> None:
    """Describe a floor plan: size, resolution, free and reachable free area, start pose, source."""
    from slamtrials.sim import SimConfig

    the_world = _load(world, resolution)
    width, height = the_world.size_m
    res = the_world.resolution
    reachable = the_world.area_of(the_world.reachable_free())
    radius = SimConfig().robot.radius
    by_robot = the_world.area_of(the_world.reachable_by_disc(radius))
    _labels, regions = the_world.free_regions
    x, y, theta = (float(v) for v in the_world.start)
    lines = [
        ("name", the_world.name),
        ("size", f"{the_world.width} x {the_world.height} px, {width:.2f} x {height:.2f} m"),
        ("resolution", f"{res:g} m/px"),
        ("origin", "({:.3f}, {:.3f}, {:.3f})".format(*(float(v) for v in the_world.origin))),
        ("free area", f"{the_world.free_area:,.1f} m^2 in {regions} connected region{'s' if regions != 1 else ''}"),
        ("reachable free area", f"{reachable:,.1f} m^2 (from the start pose)"),
        (
            "robot-reachable area",
            f"{by_robot:,.1f} m^2 (the paper's {radius:g} m robot; trials measure coverage on it)",
        ),
        ("start pose", f"x {x:.3f} m, y {y:.3f} m, theta {theta:.3f} rad"),
    ]
    meta = the_world.metadata
    for key in ("kind", "shape", "seed", "area_requested_m2", "rooms", "source", "format"):
        if key in meta:
            lines.append((key.replace("_", " "), str(meta[key])))
    if "doors" in meta:
        lines.append(("doors", str(len(meta["doors"]))))
    for key, value in lines:
        typer.echo(f"{key + ':':22s}{value}")


@app.command("generate")
def generate(
    kind: Annotated[str, typer.Option("--kind", "-k", help="Building kind: office, school, lab, multiwing or house.")],
    area: Annotated[
        float, typer.Option("--area", "-a", help="Requested free floor area in m^2 (e.g. 100 to 12,000 for offices).")
    ],
    out: Annotated[Path, typer.Option("--out", "-o", help="ROS map YAML to write (the PNG is written beside it).")],
    seed: Annotated[
        int, typer.Option("--seed", "-s", help="Seed; the same kind, area and seed give the same building.")
    ] = 0,
    name: Annotated[
        str | None, typer.Option("--name", "-n", help="World name stored in the map; default KIND_AREA_sSEED.")
    ] = None,
    resolution: Annotated[float, typer.Option("--resolution", "-r", help="Metres per pixel (0.01 to 0.2).")] = 0.05,
) -> None:
    """Generate a building floor plan and write it as a ROS map (YAML + PNG)."""
    from slamtrials.worlds.formats.rosmap_save import save_rosmap
    from slamtrials.worlds.generate import BUILDING_KINDS, KINDS, generate_world

    if kind not in BUILDING_KINDS:
        raise ConfigError(f"--kind: unknown building kind {kind!r}; expected one of {', '.join(BUILDING_KINDS)}")
    lo, hi = KINDS[kind].area_range
    if not (lo <= area <= hi):
        raise ConfigError(f"--area: {area:g} m^2 is outside the range of kind {kind!r}: {lo:g} to {hi:g} m^2")
    if seed < 0:
        raise ConfigError(f"--seed: expected a non-negative integer, got {seed}")
    if not (0.01 <= resolution <= 0.2):
        raise ConfigError(f"--resolution: {resolution:g} m/px is outside the allowed range 0.01 to 0.2 m/px")
    if out.suffix.lower() not in (".yaml", ".yml"):
        raise ConfigError(f"--out {out}: expected a .yaml file (a ROS map; the PNG is written beside it)")
    world = generate_world(kind, area, seed=seed, resolution=resolution, name=name)
    save_rosmap(world, out)
    width, height = world.size_m
    meta = world.metadata
    typer.echo(
        f"wrote {out}: {world.name}, {kind} ({meta['shape']}), {world.free_area:,.0f} m^2 free, "
        f"{width:.1f} x {height:.1f} m, {meta['rooms']} rooms, {len(meta['doors'])} doors, seed {seed}"
    )
