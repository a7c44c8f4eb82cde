"""``slamtrials demo``: the README's main job (scripted tours through bundled worlds)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.main import make_console
from slamtrials.demo import DEMO_WORLDS


def demo(
    out: Annotated[Path, typer.Option("--out", "-o", help="Folder for the run folders and pictures.")] = Path("results/demo"),
    world: Annotated[list[str] | None, typer.Option("--world", "-w", help="Bundled world or floor-plan file (repeatable).")] = None,
    seed: Annotated[int, typer.Option("--seed", "-s", help="Seed of every random draw.")] = 1,
) -> None:
    """Simulate a scripted tour through a few bundled worlds; write run folders and pictures."""
    from rich.table import Table

    from slamtrials.demo import run_demo

    console = make_console()
    table = Table(title="Scripted tours, paper robot; drift = odometry end-point error")
    for column in ("world", "frames", "sim s", "wall s", "speed", "path m", "drift m", "outcome"):
        table.add_column(column, justify="left" if column in ("world", "outcome") else "right", no_wrap=True)

    def show(run) -> None:
        console.print(f"  {run.world}: {run.frames} frames -> {run.folder}")
        table.add_row(
            run.world, str(run.frames), f"{run.simulated_s:.0f}", f"{run.wall_s:.1f}",
            f"{run.simulated_s / max(run.wall_s, 1e-9):.0f}x", f"{run.distance_m:.1f}",
            f"{run.odometry_drift_m:.2f}", run.outcome,
        )

    run_demo(out, tuple(world) if world else DEMO_WORLDS, seed=seed, on_run=show)
    console.print(table)
    console.print(f"Pictures: {out}/runs/<world>/000/run.png")


def register(app: typer.Typer) -> None:
    """Add the ``demo`` command to ``app``."""
    app.command("demo")(demo)
