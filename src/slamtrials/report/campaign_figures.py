"""Figures of a campaign, drawn on a given matplotlib Axes: the paper's Figs. 1, 3, 4, 5, 6 and more.

Every ``draw_*`` function draws on the Axes it is given and never picks a backend or calls pyplot; the
caller makes the Figure (``matplotlib.figure.Figure``) and saves it with :func:`save_figure`. Run tables
are pandas DataFrames with one row per finished run (columns ``world``, ``run``, ``eps_t`` in m, ``eps_r``
in rad, ``termination``, ``mapped``; each function names the columns it needs). Artists that tests and
callers may want to find carry a ``gid`` (e.g. ``"outliers"``, ``"normal_fit"``, ``"trap"``).

:func:`repeated_sampling_means` computes the data of the relation-sampling check (Fig. 3).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.ticker import MaxNLocator
from numpy.typing import ArrayLike, NDArray
from scipy import stats

from slamtrials.geometry import as_poses, compose, inverse
from slamtrials.metric.matching import DEFAULT_TOLERANCE
from slamtrials.metric.quantiles import Distribution
from slamtrials.metric.rule import SamplingRule
from slamtrials.metric.sampling import sample_relations
from slamtrials.metric.stats import environment_stats
from slamtrials.record import OccupancyGrid, Trajectory
from slamtrials.report.alignment import TruthAlignment, align_truth
from slamtrials.report.compare import (
    A_BETTER,
    B_BETTER,
    NO_DIFFERENCE,
    TOO_FEW,
    Comparison,
)
from slamtrials.report.tables import (
    OUTLIER_IQR,
    UNITS,
    check_metric,
    require_columns,
    world_outliers,
)

__all__ = [
    "save_figure",
    "draw_world_errors",
    "draw_sorted_errors",
    "draw_all_runs",
    "repeated_sampling_means",
    "draw_sampling_check",
    "map_picture",
    "draw_map",
    "draw_trajectories",
    "draw_run_on_map",
    "zoom_to_known",
    "draw_termination",
    "draw_explored",
    "draw_comparison",
    "draw_trap_pair",
    "METRIC_LABELS",
]

#: Axis labels of the metrics, with units.
METRIC_LABELS = {"eps_t": "translational error \u03b5t (m)", "eps_r": "rotational error \u03b5r (rad)"}
VERDICT_COLORS = {B_BETTER: "tab:green", A_BETTER: "tab:red", NO_DIFFERENCE: "tab:gray", TOO_FEW: "lightgray"}
GOLDEN = 0.6180339887498949


def save_figure(fig, path_without_suffix: str | Path, *, dpi: int = 150) -> list[Path]:
    """Save ``fig`` as ``<path>.png`` and ``<path>.pdf``, each atomically; return the two paths.

    The suffixes are appended to the whole name (``"fig.v2"`` gives ``"fig.v2.png"``). Folders are created.
    """
    from slamtrials.atomicfile import atomic_write

    base = Path(path_without_suffix)
    paths = []
    for fmt in ("png", "pdf"):
        path = base.with_name(f"{base.name}.{fmt}")
        atomic_write(path, lambda handle, fmt=fmt: fig.savefig(handle, format=fmt, dpi=dpi))
        paths.append(path)
    return paths


def _spread(n: int, width: float = 0.5) -> NDArray[np.float64]:
    """Deterministic horizontal offsets ``[n]`` in ``[-width/2, width/2)`` for a strip plot (golden-ratio sequence)."""
    return ((np.arange(n) * GOLDEN) % 1.0 - 0.5) * width


def _world_values(runs: pd.DataFrame, world: str, metric: str) -> tuple[NDArray[np.float64], NDArray]:
    values = check_metric(runs, metric)
    here = runs["world"].astype(str).to_numpy() == str(world)
    if not here.any():
        raise ValueError(f"runs has no run of world {world!r}")
    return values[here], runs["run"].to_numpy()[here]


def draw_world_errors(
    ax,
    runs: pd.DataFrame,
    world: str,
    metric: str = "eps_t",
    *,
    confidence: float = 0.99,
    distribution: Distribution = "t",
) -> None:
    """The runs' errors of one world as bars, largest first (the paper's Fig. 1), with the mean and its
    confidence band (quantile ``distribution``, :func:`slamtrials.metric.stats.environment_stats`).

    Bars are in ``ax.containers[0]``, labelled on the x axis by run index (up to 40 runs).
    """
    values, run_index = _world_values(runs, world, metric)
    order = np.argsort(-values, kind="stable")
    x = np.arange(1, len(values) + 1)
    ax.bar(x, values[order], width=0.8, color="tab:blue", label="runs", gid="runs")
    st = environment_stats(values, confidence=confidence, distribution=distribution)
    unit = UNITS[metric]
    ax.axhline(st.mean, color="tab:red", lw=1.5, label=f"mean {st.mean:.3g} {unit}", gid="mean")
    if st.n >= 2:
        ax.axhspan(
            st.ci_low,
            st.ci_high,
            color="tab:red",
            alpha=0.15,
            lw=0,
            gid="ci",
            label=f"{confidence:.0%} CI of the mean \u00b1{st.half_width:.2g} {unit}",
        )
    if len(x) <= 40:
        ax.set_xticks(x, labels=[str(r) for r in run_index[order]], fontsize=7)
    ax.set_xlabel("run (largest error first)")
    ax.set_ylabel(METRIC_LABELS[metric])
    ax.set_title(f"{world}: {st.n} runs", fontsize=10)
    top = max(float(values.max()) if values.size else 0.0, st.ci_high if st.n >= 2 else 0.0)
    if math.isfinite(top) and top > 0.0:
        ax.set_ylim(0.0, 1.4 * top)  # head room for the legend above the bars
    ax.legend(fontsize=7, loc="upper right", framealpha=0.9)


def draw_sorted_errors(ax, runs: pd.DataFrame, worlds: list[str] | None = None, metric: str = "eps_t") -> None:
    """The paper's Fig. 1 as printed: one curve per world of its runs' errors, largest first.

    ``worlds`` picks and orders the worlds (default: all, sorted).
    """
    check_metric(runs, metric)
    names = sorted(runs["world"].astype(str).unique()) if worlds is None else list(worlds)
    for world in names:
        values, _ = _world_values(runs, world, metric)
        ax.plot(
            np.arange(1, len(values) + 1),
            np.sort(values, kind="stable")[::-1],
            "o-",
            ms=3,
            lw=1.2,
            label=world,
            gid=f"world:{world}",
        )
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("run (largest error first)")
    ax.set_ylabel(METRIC_LABELS[metric])
    ax.legend(fontsize=7)


def _given_order(runs: pd.DataFrame, worlds: list[str] | None) -> list[str]:
    """``worlds`` (those with runs in ``runs``, in the given order), or every world of ``runs`` sorted by name."""
    present = runs["world"].astype(str)
    if worlds is None:
        return sorted(present.unique())
    names = [str(w) for w in worlds]
    missing = sorted(set(present.unique()) - set(names))
    if missing:
        raise ValueError(f"worlds does not list {', '.join(missing)}, which runs has")
    return [w for w in names if (present == w).any()]


def _world_order(runs: pd.DataFrame, values: NDArray[np.float64], order: str | list[str]) -> list[str]:
    names = runs["world"].astype(str)
    if not isinstance(order, str):
        return _given_order(runs, list(order))
    if order == "name":
        return sorted(names.unique())
    if order == "mean":
        return list(pd.Series(values, index=runs.index).groupby(names).mean().sort_values(kind="stable").index)
    raise ValueError(f"order must be 'name' or 'mean', got {order!r}")


def draw_all_runs(ax, runs: pd.DataFrame, metric: str = "eps_t", *, order: str | list[str] = "name") -> None:
    """All runs of all worlds (the paper's Fig. 5): a box per world, every run as a point, outliers marked.

    Outliers are those of :func:`slamtrials.report.tables.world_outliers` (beyond 1.5 IQR of the world's
    runs, the rule the tables count), drawn as red crosses in the Line2D with gid ``"outliers"``; the other
    runs are in gid ``"runs"``, world means in gid ``"means"``. The box whiskers use the same fences.

    Parameters
    ----------
    order:
        ``"name"`` (default), ``"mean"`` (increasing mean error) or a list of world names (e.g. the
        report's table order; it must name every world of ``runs``) along x.
    """
    values = check_metric(runs, metric)
    outlier = world_outliers(runs, metric).to_numpy()
    names = runs["world"].astype(str).to_numpy()
    worlds = _world_order(runs, values, order)
    position = {w: i + 1 for i, w in enumerate(worlds)}
    x = np.empty(len(values))
    for w in worlds:
        here = np.flatnonzero(names == w)
        x[here] = position[w] + _spread(len(here))
    groups = [values[names == w] for w in worlds]
    ax.boxplot(
        groups,
        positions=np.arange(1, len(worlds) + 1),
        widths=0.6,
        whis=OUTLIER_IQR,
        showfliers=False,
        manage_ticks=False,
        medianprops={"color": "tab:blue"},
    )
    ax.plot(x[~outlier], values[~outlier], "o", ms=2.5, color="0.35", alpha=0.7, label="runs", gid="runs")
    ax.plot(
        x[outlier],
        values[outlier],
        "x",
        ms=6,
        mew=1.5,
        color="tab:red",
        label=f"outliers ({int(outlier.sum())})",
        gid="outliers",
    )
    ax.plot(
        np.arange(1, len(worlds) + 1),
        [g.mean() for g in groups],
        "_",
        ms=14,
        mew=2,
        color="tab:orange",
        label="mean",
        gid="means",
    )
    ax.set_xticks(
        np.arange(1, len(worlds) + 1),
        labels=worlds,
        rotation=90 if len(worlds) > 8 else 0,
        fontsize=7 if len(worlds) > 20 else 8,
    )
    ax.set_xlim(0.3, len(worlds) + 0.7)
    ax.set_xlabel("world")
    ax.set_ylabel(METRIC_LABELS[metric])
    ax.legend(fontsize=7, loc="upper right")


def repeated_sampling_means(
    truth: Trajectory,
    estimate: Trajectory,
    repeats: int,
    rng: np.random.Generator | np.random.SeedSequence | int,
    *,
    component: str = "translational",
    rule: SamplingRule = SamplingRule(),
    tolerance: float = DEFAULT_TOLERANCE,
    odometry: Trajectory | None = None,
) -> NDArray[np.float64]:
    """Mean errors ``[repeats]`` of ``repeats`` independent relation samplings of one run (the paper's Fig. 3).

    Each repeat calls :func:`slamtrials.metric.sampling.sample_relations` with its own generator, spawned
    from ``rng`` (``Generator.spawn`` or ``SeedSequence.spawn``), so the result depends on ``rng`` alone.

    Parameters
    ----------
    truth, estimate:
        Ground-truth and estimated trajectories of the run.
    repeats:
        Number of samplings (the paper: 200).
    rng:
        Generator, SeedSequence or integer seed.
    component:
        ``"translational"`` (m, the default) or ``"rotational"`` (rad).
    rule:
        The sampling rule of each repeat.
    tolerance, odometry:
        Matching of the estimate to the ground truth (as in ``sample_relations``).
    """
    if repeats < 1:
        raise ValueError(f"repeats must be at least 1, got {repeats}")
    if component not in ("translational", "rotational"):
        raise ValueError(f"component must be 'translational' or 'rotational', got {component!r}")
    if isinstance(rng, np.random.Generator):
        generators = rng.spawn(repeats)
    else:
        sequence = rng if isinstance(rng, np.random.SeedSequence) else np.random.SeedSequence(rng)
        generators = [np.random.default_rng(child) for child in sequence.spawn(repeats)]
    means = np.empty(repeats)
    for k, generator in enumerate(generators):
        sampled = sample_relations(truth, estimate, rng=generator, rule=rule, tolerance=tolerance, odometry=odometry)
        means[k] = float(np.mean(getattr(sampled.errors, component)))
    return means


def draw_sampling_check(
    ax,
    sampled_means: ArrayLike,
    normal_fit: bool = True,
    *,
    bins: int | str = "auto",
    xlabel: str = "mean translational error of one sampling (m)",
) -> tuple[float, float] | None:
    """Histogram (density) of the mean error over repeated samplings with a fitted normal (the paper's Fig. 3).

    The normal has the sample mean and the sample standard deviation (divisor ``n - 1``) of the values; it
    is the Line2D with gid ``"normal_fit"``, and its label gives the Shapiro-Wilk p-value (3 to 5000 values).

    Returns
    -------
    (mean, std) of the fitted normal, or None when not fitted (``normal_fit`` False, or a zero spread).
    """
    v = np.asarray(sampled_means, dtype=np.float64).reshape(-1)
    if len(v) < 2 or not np.isfinite(v).all():
        raise ValueError(f"need at least 2 finite sampled means, got {len(v)} values")
    ax.hist(v, bins=bins, density=True, color="tab:blue", alpha=0.6, edgecolor="white", label=f"{len(v)} samplings")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("density")
    fit = None
    mu, sigma = float(v.mean()), float(v.std(ddof=1))
    if normal_fit and sigma > 0:
        x = np.linspace(min(v.min(), mu - 4 * sigma), max(v.max(), mu + 4 * sigma), 400)
        label = f"normal fit: mean {mu:.4g}, sd {sigma:.2g}"
        if 3 <= len(v) <= 5000:
            label += f" (Shapiro-Wilk p = {stats.shapiro(v).pvalue:.2g})"
        ax.plot(x, stats.norm.pdf(x, mu, sigma), color="tab:red", lw=1.5, label=label, gid="normal_fit")
        fit = (mu, sigma)
    # below the axes: inside, the long fit label covers the bars wherever it goes
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)
    return fit


def map_picture(grid: NDArray[np.int8]) -> NDArray[np.float64]:
    """RGB image ``[H, W, 3]`` of an occupancy grid: occupied (>= 50) black, unknown (< 0) grey, free white."""
    g = np.asarray(grid)
    rgb = np.ones(g.shape + (3,))
    rgb[g < 0] = 0.78
    rgb[g >= 50] = 0.0
    return rgb


def draw_map(ax, occupancy_grid: OccupancyGrid, title: str | None = None) -> None:
    """Draw a SLAM map (map frame, metres) for a map gallery (the paper's Figs. 4 and 7).

    The image spans ``W * resolution`` by ``H * resolution`` metres from the grid's origin (the lower-left
    corner of the lower-left cell), rotated by the origin's angle; row 0 is at the top.
    """
    from matplotlib.transforms import Affine2D

    g = occupancy_grid
    h, w = g.grid.shape
    width, height = w * g.resolution, h * g.resolution
    ox, oy, theta = (float(v) for v in g.origin)
    image = ax.imshow(map_picture(g.grid), extent=(0.0, width, 0.0, height), origin="upper", interpolation="nearest")
    placement = Affine2D().rotate(theta).translate(ox, oy)
    image.set_transform(placement + ax.transData)
    corners = placement.transform([[0, 0], [width, 0], [0, height], [width, height]])
    ax.set_xlim(corners[:, 0].min(), corners[:, 0].max())
    ax.set_ylim(corners[:, 1].min(), corners[:, 1].max())
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if title:
        ax.set_title(title, fontsize=9)


def _poses(trajectory: Trajectory | ArrayLike) -> NDArray[np.float64]:
    poses = trajectory.poses if isinstance(trajectory, Trajectory) else as_poses(trajectory)
    if poses.ndim != 2 or len(poses) == 0:
        raise ValueError(f"a trajectory needs poses [N, 3] with N >= 1, got shape {poses.shape}")
    return poses


def draw_trajectories(ax, truth: Trajectory | ArrayLike, estimate: Trajectory | ArrayLike) -> NDArray[np.float64]:
    """Draw the true and the estimated trajectory, the estimate moved into the world frame through its first pose.

    ``world_from_map = compose(truth[k], inverse(estimate[0]))``, where ``k = 0`` for plain pose arrays and,
    for two :class:`Trajectory` objects, the true pose nearest in time to the estimate's first timestamp.

    Parameters
    ----------
    truth, estimate:
        Trajectories or pose arrays ``[N, 3]``, ``[M, 3]`` (m, m, rad).

    Returns
    -------
    The aligned estimate ``[M, 3]`` (world frame) as drawn (gid ``"estimate"``; the truth is gid ``"truth"``).
    """
    true_poses, estimated = _poses(truth), _poses(estimate)
    k = 0
    if isinstance(truth, Trajectory) and isinstance(estimate, Trajectory):
        k = int(np.argmin(np.abs(truth.t - estimate.t[0])))
    aligned = compose(compose(true_poses[k], inverse(estimated[0])), estimated)
    ax.plot(true_poses[:, 0], true_poses[:, 1], color="tab:blue", lw=1.2, label="ground truth", gid="truth")
    ax.plot(aligned[:, 0], aligned[:, 1], color="tab:green", lw=1.0, label="SLAM estimate", gid="estimate")
    ax.plot(*true_poses[k, :2], "o", color="tab:blue", ms=4)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(fontsize=7, loc="upper right")
    return aligned


def zoom_to_known(ax, occupancy_grid: OccupancyGrid, *, also: ArrayLike | None = None, margin: float = 0.5) -> None:
    """Limit ``ax`` to the known (free or occupied) cells of an unrotated map, and the points ``also``
    (``[N, 2]``, m; non-finite rows ignored), plus ``margin`` metres; a rotated or empty map keeps its limits
    (widened to ``also``)."""
    grid = np.asarray(occupancy_grid.grid)
    ox, oy, theta = (float(v) for v in occupancy_grid.origin)
    known = grid >= 0
    if theta == 0.0 and known.any():
        rows, cols = np.flatnonzero(known.any(axis=1)), np.flatnonzero(known.any(axis=0))
        res, height = float(occupancy_grid.resolution), grid.shape[0]
        x0, x1 = ox + cols[0] * res, ox + (cols[-1] + 1) * res
        y0, y1 = oy + (height - rows[-1] - 1) * res, oy + (height - rows[0]) * res
    else:
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        margin = 0.0 if also is None else margin
    if also is not None:
        points = np.asarray(also, dtype=np.float64).reshape(-1, 2)
        points = points[np.isfinite(points).all(axis=1)]
        if len(points):
            x0, x1 = min(x0, float(points[:, 0].min())), max(x1, float(points[:, 0].max()))
            y0, y1 = min(y0, float(points[:, 1].min())), max(y1, float(points[:, 1].max()))
    ax.set_xlim(x0 - margin, x1 + margin)
    ax.set_ylim(y0 - margin, y1 + margin)


def draw_run_on_map(
    ax,
    occupancy_grid: OccupancyGrid | None,
    truth: ArrayLike,
    estimate: ArrayLike,
    *,
    title: str | None = None,
    legend: bool = True,
) -> TruthAlignment:
    """A run's final SLAM map with its estimated trajectory and its true trajectory on top, all in the map frame.

    The estimate is drawn as recorded (map frame, gid ``"estimate"``); the truth (world frame) is moved
    into the map frame by :func:`slamtrials.report.alignment.align_truth` (a least-squares rigid fit of
    the true positions onto the estimated ones) and drawn under it, wider and paler (gid ``"truth"``).
    The start of the estimate is a dot (gid ``"start"``). The view is the map's known cells and both paths.

    Parameters
    ----------
    occupancy_grid:
        The final map (map frame), or None to draw the paths alone.
    truth, estimate:
        ``[T, 3]`` true poses (world frame) and estimated poses (map frame) at the same timestamps.

    Returns
    -------
    The alignment drawn (its ``truth`` is the drawn true path, its ``rms`` the fit's residual).
    """
    estimated = _poses(estimate)
    fit = align_truth(truth, estimated)
    if occupancy_grid is not None:
        draw_map(ax, occupancy_grid, title=title)
    elif title:
        ax.set_title(title, fontsize=9)
    ax.plot(
        fit.truth[:, 0],
        fit.truth[:, 1],
        color="tab:blue",
        lw=2.6,
        alpha=0.55,
        label="ground truth (fitted)",
        gid="truth",
    )
    ax.plot(estimated[:, 0], estimated[:, 1], color="tab:red", lw=1.0, label="SLAM estimate", gid="estimate")
    first = int(np.argmax(fit.used))
    ax.plot(*estimated[first, :2], "o", color="tab:red", ms=5, label="start", gid="start")
    if occupancy_grid is not None:
        zoom_to_known(ax, occupancy_grid, also=np.vstack([fit.truth[:, :2], estimated[:, :2]]))
    ax.set_aspect("equal", adjustable="datalim" if occupancy_grid is None else "box")
    ax.set_xlabel("x (m, map frame)")
    ax.set_ylabel("y (m, map frame)")
    if legend:
        ax.legend(fontsize=8, loc="upper right", framealpha=0.85)
    return fit


def draw_termination(ax, runs: pd.DataFrame, worlds: list[str] | None = None) -> pd.DataFrame:
    """Termination reasons per world as stacked bars of run counts (one BarContainer per reason).

    Needs columns ``world`` and ``termination`` (missing reasons count as ``"unknown"``). ``worlds`` orders
    the worlds along x (it must name every world of ``runs``); default: sorted by name.

    Returns
    -------
    The counts drawn: worlds (in that order) by reasons (sorted).
    """
    require_columns(runs, ("world", "termination"))
    order = _given_order(runs, worlds)
    reasons = runs["termination"].astype(object).where(runs["termination"].notna(), "unknown").astype(str)
    counts = pd.crosstab(runs["world"].astype(str), reasons).reindex(order).sort_index(axis=1)
    x = np.arange(len(counts))
    bottom = np.zeros(len(counts))
    for reason in counts.columns:
        heights = counts[reason].to_numpy(dtype=float)
        ax.bar(x, heights, bottom=bottom, width=0.7, label=str(reason), gid=f"termination:{reason}")
        bottom += heights
    ax.set_xticks(x, labels=list(counts.index), rotation=90 if len(x) > 8 else 0, fontsize=7 if len(x) > 20 else 8)
    ax.set_xlabel("world")
    ax.set_ylabel("runs")
    ax.legend(title="termination", fontsize=7, title_fontsize=7)
    return counts


def draw_explored(ax, runs: pd.DataFrame, worlds: list[str] | None = None) -> pd.Series:
    """The explored (mapped) fraction of every run per world: points (gid ``"runs"``) and means (gid ``"means"``).

    Needs columns ``world`` and ``mapped`` (fraction 0..1; every value finite). ``worlds`` orders the
    worlds along x (it must name every world of ``runs``); default: sorted by name.

    Returns
    -------
    The mean mapped fraction per world (in that order), as drawn.
    """
    require_columns(runs, ("world", "mapped"))
    order = _given_order(runs, worlds)
    mapped = pd.to_numeric(runs["mapped"], errors="coerce").to_numpy(dtype=np.float64, na_value=np.nan)
    if not np.isfinite(mapped).all():
        row = runs.iloc[int(np.argmax(~np.isfinite(mapped)))]
        raise ValueError(f"runs: world {row['world']!r} has a non-finite mapped fraction ({row['mapped']!r})")
    names = runs["world"].astype(str).to_numpy()
    means = pd.Series(mapped, index=names).groupby(level=0).mean().reindex(order)
    x = np.empty(len(mapped))
    for i, w in enumerate(means.index):
        here = np.flatnonzero(names == w)
        x[here] = i + _spread(len(here))
    ax.plot(x, mapped, "o", ms=3, color="tab:blue", alpha=0.6, label="runs", gid="runs")
    ax.plot(np.arange(len(means)), means.to_numpy(), "_", ms=14, mew=2, color="tab:orange", label="mean", gid="means")
    ax.set_xticks(
        np.arange(len(means)),
        labels=list(means.index),
        rotation=90 if len(means) > 8 else 0,
        fontsize=7 if len(means) > 20 else 8,
    )
    ax.set_ylim(0.0, 1.05)
    ax.set_xlabel("world")
    ax.set_ylabel("explored fraction")
    ax.legend(fontsize=7, loc="lower right")
    return means


def draw_comparison(ax, comparison: Comparison, metric: str = "eps_t") -> None:
    """Forest plot of a comparison: per world, ``mean_B - mean_A`` with its interval, coloured by verdict.

    The intervals are those corrected like the p-values (``ci_adj_low``, ``ci_adj_high``; their level is
    ``comparison.intervals[metric]``), so an interval that excludes 0 goes with a significant verdict.

    Worlds run top to bottom in the table's order. Each verdict is one errorbar (gid ``"verdict:<v>"``):
    B better green, A better red, no significant difference grey. The Fig. 6 trap: a hollow black diamond
    (gid ``"trap"``) at the difference of the most misleading single-run pair (for a paired comparison,
    the same run of both campaigns), drawn where that pair contradicts the means (it lies on the other
    side of 0), with the fraction of contradicting pairs written at the right edge.
    """
    rows = comparison.for_metric(metric)
    if rows.empty:
        raise ValueError(f"the comparison has no rows for metric {metric!r}")
    name_a, name_b = comparison.labels
    y = np.arange(len(rows))[::-1].astype(float)
    diff = rows["difference"].to_numpy(dtype=float)
    low, high = rows["ci_adj_low"].to_numpy(dtype=float), rows["ci_adj_high"].to_numpy(dtype=float)
    xerr = np.nan_to_num(np.vstack([diff - low, high - diff]), nan=0.0)
    verdicts = rows["verdict"].to_numpy()
    for verdict, color in VERDICT_COLORS.items():
        sel = verdicts == verdict
        if sel.any():
            label = {B_BETTER: f"{name_b} better", A_BETTER: f"{name_a} better"}.get(verdict, verdict)
            ax.errorbar(
                diff[sel],
                y[sel],
                xerr=xerr[:, sel],
                fmt="o",
                color=color,
                ms=5,
                capsize=3,
                lw=2 if verdict in (A_BETTER, B_BETTER) else 1,
                label=label,
                gid=f"verdict:{verdict}",
            )
    trap = rows["trap_difference"].to_numpy(dtype=float)
    reversed_ = (np.sign(trap) == -np.sign(diff)) & (diff != 0)
    ax.plot(
        trap[reversed_],
        y[reversed_],
        "D",
        ms=6,
        mfc="none",
        mec="black",
        mew=1.2,
        label="most misleading run (paired: the same run on both sides)"
        if comparison.paired
        else "most misleading single-run pair",
        gid="trap",
    )
    for yi, fraction in zip(y, rows["trap_fraction"].to_numpy(dtype=float)):
        if math.isfinite(fraction):
            ax.annotate(f"{fraction:.0%}", xy=(1.01, yi), xycoords=("axes fraction", "data"), va="center", fontsize=7)
    ax.axvline(0.0, color="black", lw=0.8)
    ax.set_yticks(y, labels=list(rows["world"]))
    ax.set_ylim(-0.7, len(rows) - 0.3)
    ax.set_xlabel(f"{name_b} \u2212 {name_a}: difference of mean {METRIC_LABELS[metric]}")
    overall = comparison.overall.get(metric)
    level = comparison.intervals[metric]
    ax.set_title(
        f"{name_b} vs {name_a}, {comparison.pairing}"
        + (f": {overall.verdict}" if overall else "")
        + f"\n({level.label} intervals, {comparison.correction} correction;\nright: share of "
        + ("runs" if comparison.paired else "run pairs")
        + " that reverse the means)",
        fontsize=8,
    )
    ax.legend(fontsize=7, loc="best")


def draw_trap_pair(
    ax,
    low: NDArray[np.float64],
    high: NDArray[np.float64],
    labels: tuple[str, str],
    i_low: int,
    i_high: int,
    metric: str = "eps_t",
    colors: tuple[str, str] = ("tab:blue", "tab:orange"),
) -> None:
    """Two samples of run errors side by side (``low``: lower mean) with their means and the most misleading
    pair ringed (the paper's Fig. 6).

    ``low`` and ``high`` are float64 ``[N]`` and ``[M]`` run errors of ``metric`` (m or rad), ``labels``
    their names under the x axis. The pair ``(low[i_low], high[i_high])`` is the single-run comparison that
    contradicts the means the most; it is joined by a dashed line (gid ``"trap"``) when it is reversed. The
    means are lines with gids ``"mean:0"`` and ``"mean:1"``. ``colors`` are those of ``low`` and ``high``
    (a comparison keeps one colour per campaign).
    """
    for x, values, color in ((0, low, colors[0]), (1, high, colors[1])):
        offsets = ((np.arange(len(values)) * GOLDEN) % 1.0 - 0.5) * 0.35
        ax.plot(x + offsets, values, "o", ms=4, color=color, alpha=0.75)
        ax.plot([x - 0.3, x + 0.3], [values.mean()] * 2, color=color, lw=2.5, gid=f"mean:{x}")
    if low[i_low] > high[i_high]:
        ax.plot([0, 1], [low[i_low], high[i_high]], "k--", lw=1, gid="trap")
        ax.plot([0, 1], [low[i_low], high[i_high]], "o", ms=11, mfc="none", mec="red", mew=1.8)
    ax.set_xticks([0, 1], labels=list(labels), fontsize=8)
    ax.set_xlim(-0.6, 1.6)
    ax.set_ylabel(METRIC_LABELS[metric], fontsize=8)
