"""Pictures of one run: the world, the true path, the odometry path, and the SLAM estimate if any."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from slamtrials.geometry import compose, inverse
from slamtrials.record import RunRecord
from slamtrials.worlds.world import World

__all__ = ["draw_run", "save_run_figure"]


def draw_run(ax, world: World, record: RunRecord) -> None:
    """Draw ``world`` with the run's true path (world frame), its odometry path and, when the record
    has one, its SLAM estimate, on a matplotlib Axes.

    The odometry path and the estimate are anchored at the first true pose, so their drift from the true
    path is what the odometry error, and what is left of it after SLAM, did over the run.
    """
    from slamtrials.report.figures import draw_world

    draw_world(ax, world)
    odometry_in_world = compose(record.truth[0], record.odometry)
    ax.plot(record.truth[:, 0], record.truth[:, 1], color="tab:blue", lw=1.2, label="ground truth")
    ax.plot(odometry_in_world[:, 0], odometry_in_world[:, 1], color="tab:red", lw=0.9, ls="--", label="odometry")
    if record.estimate is not None and len(record.estimate):
        world_from_map = compose(record.truth[0], inverse(record.estimate[0]))
        estimate_in_world = compose(world_from_map, record.estimate)
        ax.plot(estimate_in_world[:, 0], estimate_in_world[:, 1], color="tab:green", lw=0.9, label="SLAM estimate")
    stalls = record.stalled
    if np.any(stalls):
        ax.plot(record.truth[stalls, 0], record.truth[stalls, 1], "x", color="tab:orange", ms=5, label="stalled")
    ax.plot(*record.truth[-1, :2], "s", color="tab:blue", ms=5)
    ax.legend(loc="upper right", fontsize=7, framealpha=0.85)


def save_run_figure(world: World, record: RunRecord, path: str | Path, *, title: str | None = None) -> Path:
    """Render :func:`draw_run` into an image file (PNG by suffix) and return its path."""
    from matplotlib.figure import Figure

    from slamtrials.atomicfile import atomic_write

    width, height = world.size_m
    aspect = height / width if width > 0 else 1.0
    fig = Figure(figsize=(8.0, max(3.0, min(12.0, 8.0 * aspect)) + 0.6), dpi=120)
    ax = fig.add_subplot()
    draw_run(ax, world, record)
    if title:
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    path = Path(path)
    atomic_write(path, lambda handle: fig.savefig(handle, format=path.suffix.lstrip(".") or "png"))
    return path
