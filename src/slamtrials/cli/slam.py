"""``slamtrials slam``: run a SLAM algorithm over a run folder, CARMEN log or ROS bag and write its outputs.

A thin wrapper over :mod:`slamtrials.slamrun` (see there for the output files). ``--set key=value``
values are read as YAML (``--set resolution=0.1``, ``--set initial_pose=[1, 2, 0]``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from slamtrials.cli.common import make_console
from slamtrials.errors import ConfigError

__all__ = ["slam", "register", "parse_settings"]


def parse_settings(settings: list[str]) -> dict[str, Any]:
    """``["key=value", ...]`` as a dict, each value parsed with ``yaml.safe_load``.

    Raises
    ------
    ConfigError
        An item without ``=`` or a key, or a value that is not YAML.
    """
    import yaml

    values: dict[str, Any] = {}
    for item in settings:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ConfigError(f"--set expects key=value, got {item!r}")
        try:
            values[key] = yaml.safe_load(text) if text.strip() else None
        except yaml.YAMLError as exc:
            problem = str(exc).splitlines()[0]
            raise ConfigError(f"--set {key}: {text!r} is not a YAML value ({problem})") from None
    return values


def slam(
    algorithm: Annotated[str, typer.Option("--algorithm", "-a", help="Registered SLAM algorithm (built-in: gmapping, karto, odometry).")],
    input_: Annotated[Path, typer.Option("--input", "-i", help="Run folder, CARMEN log (.clf/.log, .gz) or ROS bag.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Folder for trajectory.tum/.clf, map.yaml/.pgm/.png, timing.csv, slam.json.")],
    preset: Annotated[str | None, typer.Option("--preset", "-p", help="Named parameter set of the algorithm.")] = None,
    settings: Annotated[list[str] | None, typer.Option("--set", help="Parameter override key=value (value read as YAML); repeatable.")] = None,
    seed: Annotated[int, typer.Option("--seed", "-s", help="Seed of the algorithm's random draws.")] = 0,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace SLAM outputs already in --out.")] = False,
) -> None:
    """Run SLAM algorithm ALGORITHM over a recording and write its trajectory, map and timings."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    from slamtrials.slamrun import SLAM_FILE, load_recording, run_slam, write_slam_outputs

    if seed < 0:
        raise ConfigError(f"--seed must be a non-negative integer, got {seed}")
    if (out / SLAM_FILE).exists() and not overwrite:
        raise ConfigError(f"{out}: already holds SLAM outputs; choose another --out or pass --overwrite")
    overrides = parse_settings(settings or [])
    from slamtrials.slam import get_algorithm, resolve_config

    resolve_config(get_algorithm(algorithm), preset=preset, overrides=overrides)  # fail before reading the input
    record = load_recording(input_)
    console = make_console()
    columns = (TextColumn(f"{algorithm}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=True, disable=not console.is_terminal) as progress:
        task = progress.add_task("slam", total=len(record))
        result = run_slam(record, algorithm, preset=preset, overrides=overrides, seed=seed, source=str(input_),
                          on_frame=lambda k, total: progress.update(task, completed=k + 1))
    written = write_slam_outputs(result, out, overwrite=overwrite)
    mean_ms = 1000.0 * float(result.timing.mean())
    names = ", ".join(p.name for p in written)
    console.print(f"{out}: {len(record)} frames, {result.updates} updates, {mean_ms:.2f} ms per frame; wrote {names}",
                  soft_wrap=True, highlight=False)


def register(app: typer.Typer) -> None:
    """Add the ``slam`` command to ``app``."""
    app.command("slam")(slam)
