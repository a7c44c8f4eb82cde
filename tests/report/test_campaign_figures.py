"""Campaign figures drawn on Agg Figures: what is drawn is read back from the Axes artists and checked."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from scipy import stats

from slamtrials.geometry import compose
from slamtrials.metric.rule import SamplingRule
from slamtrials.metric.sampling import sample_relations
from slamtrials.metric.stats import environment_stats
from slamtrials.record import OccupancyGrid, Trajectory
from slamtrials.report import campaign_figures as cf
from slamtrials.report.compare import compare_campaigns
from slamtrials.report.tables import world_summary

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _figure(ncols: int = 1) -> tuple[Figure, list]:
    fig = Figure(figsize=(4 * ncols, 3), dpi=60)
    FigureCanvasAgg(fig)
    return fig, list(np.atleast_1d(fig.subplots(1, ncols)))


def _line(ax, gid: str):
    found = [line for line in ax.lines if line.get_gid() == gid]
    assert len(found) == 1, f"expected one line with gid {gid!r}, found {len(found)}"
    return found[0]


@pytest.fixture
def runs() -> pd.DataFrame:
    rng = np.random.default_rng(4)
    rows = []
    for world, mean, n in (("office", 0.2, 12), ("school", 0.3, 9), ("campus", 0.25, 15)):
        values = rng.normal(mean, 0.02, n)
        if world == "school":
            values[3] = 0.9  # a clear outlier
        for k, v in enumerate(values):
            rows.append(
                {
                    "world": world,
                    "run": 100 + k,
                    "seed": k,
                    "eps_t": v,
                    "eps_r": v / 8,
                    "duration_s": 60.0,
                    "wall_s": 2.0,
                    "termination": ["map_stable", "timeout", "stuck"][k % 3 if world != "office" else 0],
                    "mapped": 0.7 + 0.3 * (k % 4) / 3,
                }
            )
    return pd.DataFrame(rows)


def test_world_errors_bars_sorted_largest_first_with_mean_and_band(runs: pd.DataFrame) -> None:
    _fig, (ax,) = _figure()
    cf.draw_world_errors(ax, runs, "office", "eps_t", confidence=0.99)
    office = runs[runs["world"] == "office"]
    heights = [bar.get_height() for bar in ax.containers[0]]
    assert heights == sorted(heights, reverse=True)
    assert heights == pytest.approx(sorted(office["eps_t"], reverse=True))
    expected_runs = office.sort_values("eps_t", ascending=False)["run"].astype(str).tolist()
    assert [label.get_text() for label in ax.get_xticklabels()] == expected_runs
    st = environment_stats(office["eps_t"], confidence=0.99)
    assert _line(ax, "mean").get_ydata()[0] == pytest.approx(st.mean)
    (band,) = [p for p in ax.patches if p.get_gid() == "ci"]
    assert (band.get_bbox().y0, band.get_bbox().y1) == pytest.approx((st.ci_low, st.ci_high))
    with pytest.raises(ValueError, match="nowhere"):
        cf.draw_world_errors(ax, runs, "nowhere")


def test_sorted_error_curves_one_per_world(runs: pd.DataFrame) -> None:
    _fig, (ax,) = _figure()
    cf.draw_sorted_errors(ax, runs, metric="eps_r")
    assert [line.get_gid() for line in ax.lines] == ["world:campus", "world:office", "world:school"]
    y = _line(ax, "world:school").get_ydata()
    assert list(y) == sorted(y, reverse=True) and len(y) == 9


def test_all_runs_marks_exactly_the_tables_outliers(runs: pd.DataFrame) -> None:
    _fig, (ax,) = _figure()
    cf.draw_all_runs(ax, runs, "eps_t")
    outliers, inliers = _line(ax, "outliers"), _line(ax, "runs")
    expected = int(world_summary(runs)["eps_t_outliers"].sum())
    assert expected >= 1
    assert len(outliers.get_xdata()) == expected
    assert 0.9 in list(outliers.get_ydata())
    assert len(outliers.get_xdata()) + len(inliers.get_xdata()) == len(runs)
    # Every point sits in its world's column: x rounds to the tick of the world it belongs to.
    ticks = {label.get_text(): pos for label, pos in zip(ax.get_xticklabels(), ax.get_xticks())}
    assert list(ticks) == ["campus", "office", "school"]
    for x, y in zip(inliers.get_xdata(), inliers.get_ydata()):
        (world,) = runs.loc[runs["eps_t"] == y, "world"]  # values are drawn unchanged
        assert round(x) == ticks[world]
    means = _line(ax, "means").get_ydata()
    assert means == pytest.approx(runs.groupby("world")["eps_t"].mean().sort_index().to_numpy())
    cf.draw_all_runs(ax2 := _figure()[1][0], runs, "eps_t", order="mean")
    assert [label.get_text() for label in ax2.get_xticklabels()] == ["office", "campus", "school"]


def test_sampling_check_fits_the_sample_mean_and_std() -> None:
    values = np.random.default_rng(8).normal(0.42, 0.015, 200)
    _fig, (ax,) = _figure()
    mu, sigma = cf.draw_sampling_check(ax, values)
    assert mu == pytest.approx(values.mean()) and sigma == pytest.approx(values.std(ddof=1))
    curve = _line(ax, "normal_fit")
    x, y = curve.get_xdata(), curve.get_ydata()
    assert y == pytest.approx(stats.norm.pdf(x, values.mean(), values.std(ddof=1)))
    assert x[np.argmax(y)] == pytest.approx(values.mean(), abs=(x[1] - x[0]))
    area = sum(bar.get_height() * bar.get_width() for bar in ax.patches)
    assert area == pytest.approx(1.0)  # a density histogram
    _fig, (ax,) = _figure()
    assert cf.draw_sampling_check(ax, values, normal_fit=False) is None
    assert not [line for line in ax.lines if line.get_gid() == "normal_fit"]


def _run_trajectories() -> tuple[Trajectory, Trajectory]:
    rng = np.random.default_rng(0)
    n = 300
    t = np.arange(n) * 0.1
    truth = np.c_[np.cumsum(np.full(n, 0.05)), 0.5 * np.sin(t), 0.1 * np.cos(t)]
    estimate = truth + rng.normal(0.0, 0.02, (n, 3))
    return Trajectory(t=t, poses=truth), Trajectory(t=t.copy(), poses=estimate)


def test_repeated_sampling_means_uses_spawned_seeds() -> None:
    truth, estimate = _run_trajectories()
    options = {"rule": SamplingRule(rule="paper", pilot=100, margin_t=0.01)}
    means = cf.repeated_sampling_means(truth, estimate, 12, 7, **options)
    assert means.shape == (12,) and np.isfinite(means).all() and np.unique(means).size == 12
    children = np.random.SeedSequence(7).spawn(12)
    for k in (0, 11):
        sampled = sample_relations(truth, estimate, rng=np.random.default_rng(children[k]), **options)
        assert means[k] == pytest.approx(sampled.errors.translational.mean())
    assert np.array_equal(means, cf.repeated_sampling_means(truth, estimate, 12, 7, **options))
    from_generator = cf.repeated_sampling_means(truth, estimate, 3, np.random.default_rng(1), **options)
    assert np.array_equal(
        from_generator, cf.repeated_sampling_means(truth, estimate, 3, np.random.default_rng(1), **options)
    )
    rotational = cf.repeated_sampling_means(truth, estimate, 3, 7, component="rotational", **options)
    assert not np.allclose(rotational, means[:3])
    with pytest.raises(ValueError, match="repeats"):
        cf.repeated_sampling_means(truth, estimate, 0, 7)


def test_map_drawn_in_metres_with_the_cell_values() -> None:
    grid = np.zeros((4, 6), dtype=np.int8)
    grid[0, 0] = 100  # top-left cell: occupied
    grid[3, 5] = -1  # bottom-right cell: unknown
    occupancy = OccupancyGrid(grid=grid, resolution=0.5, origin=np.array([-1.0, 2.0, 0.0]))
    _fig, (ax,) = _figure()
    cf.draw_map(ax, occupancy, "good map")
    image = ax.images[0]
    assert image.get_extent() == pytest.approx([0.0, 3.0, 0.0, 2.0])  # placed by the image's transform
    assert ax.get_xlim() == pytest.approx((-1.0, 2.0)) and ax.get_ylim() == pytest.approx((2.0, 4.0))
    rgb = np.asarray(image.get_array())
    assert rgb[0, 0] == pytest.approx([0, 0, 0]) and rgb[3, 5] == pytest.approx([0.78] * 3)
    assert rgb[1, 1] == pytest.approx([1, 1, 1])
    assert ax.get_title() == "good map"
    # The top-left cell's centre, through the image transform, lands at x = -0.75, y = 3.75 in data coordinates.
    to_data = image.get_transform() - ax.transData
    assert to_data.transform([0.25, 1.75]) == pytest.approx([-0.75, 3.75])
    turned = OccupancyGrid(grid=grid, resolution=0.5, origin=np.array([0.0, 0.0, math.pi / 2]))
    _fig, (ax,) = _figure()
    cf.draw_map(ax, turned)
    assert ax.get_xlim() == pytest.approx((-2.0, 0.0)) and ax.get_ylim() == pytest.approx((0.0, 3.0))


def test_trajectories_align_the_estimate_through_its_first_pose() -> None:
    truth, _ = _run_trajectories()
    map_from_world = np.array([3.0, -2.0, 0.7])
    estimate = compose(map_from_world, truth.poses)  # the same path seen in another frame
    _fig, (ax,) = _figure()
    aligned = cf.draw_trajectories(ax, truth.poses, estimate)
    assert aligned == pytest.approx(truth.poses, abs=1e-9)
    line = _line(ax, "estimate")
    assert line.get_xdata() == pytest.approx(truth.poses[:, 0]) and line.get_ydata() == pytest.approx(truth.poses[:, 1])
    # With timestamps: an estimate that starts at the 50th true pose is anchored there.
    late = Trajectory(t=truth.t[50:].copy(), poses=estimate[50:])
    _fig, (ax,) = _figure()
    assert cf.draw_trajectories(ax, truth, late) == pytest.approx(truth.poses[50:], abs=1e-9)


def test_run_on_map_draws_the_estimate_as_recorded_and_the_truth_fitted_onto_it() -> None:
    truth, _ = _run_trajectories()
    map_from_world = np.array([-4.0, 6.0, 2.2])
    estimate = compose(map_from_world, truth.poses + np.r_[0.0, 0.03, 0.0])  # map frame, 3 cm off in y
    grid = np.full((200, 300), -1, dtype=np.int8)
    grid[80:120, 100:180] = 0  # the known part of the map
    occupancy = OccupancyGrid(grid=grid, resolution=0.1, origin=np.array([-20.0, -5.0, 0.0]))
    _fig, (ax,) = _figure()
    fit = cf.draw_run_on_map(ax, occupancy, truth.poses, estimate, title="best")
    drawn_estimate, drawn_truth = _line(ax, "estimate"), _line(ax, "truth")
    assert drawn_estimate.get_xdata() == pytest.approx(estimate[:, 0])  # not moved: the map's frame
    assert drawn_truth.get_xdata() == pytest.approx(fit.truth[:, 0]) and drawn_truth.get_ydata() == pytest.approx(
        fit.truth[:, 1]
    )
    assert fit.map_from_world[2] == pytest.approx(map_from_world[2], abs=1e-9)
    assert fit.max_distance == pytest.approx(0.0, abs=1e-9)  # shifting the whole path is rigid too: the fit takes it
    assert _line(ax, "start").get_xdata() == pytest.approx([estimate[0, 0]])
    assert len(ax.images) == 1 and ax.get_title() == "best"
    # the view holds the known cells and both paths (plus the margin), not the whole unknown grid
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    known_x, known_y = (-20.0 + 10.0, -20.0 + 18.0), (-5.0 + 8.0, -5.0 + 12.0)
    xs, ys = np.r_[estimate[:, 0], fit.truth[:, 0]], np.r_[estimate[:, 1], fit.truth[:, 1]]
    assert x0 == pytest.approx(min(known_x[0], xs.min()) - 0.5) and x1 == pytest.approx(max(known_x[1], xs.max()) + 0.5)
    assert y0 == pytest.approx(min(known_y[0], ys.min()) - 0.5) and y1 == pytest.approx(max(known_y[1], ys.max()) + 0.5)
    _fig, (ax,) = _figure()
    cf.draw_run_on_map(ax, None, truth.poses, estimate, legend=False)
    assert not ax.images and ax.get_legend() is None and len(_line(ax, "truth").get_xdata()) == len(truth.poses)


def test_world_order_is_the_one_given(runs: pd.DataFrame) -> None:
    order = ["school", "office", "campus"]  # neither by name nor by mean
    _fig, axes = _figure(3)
    cf.draw_all_runs(axes[0], runs, "eps_t", order=order)
    counts = cf.draw_termination(axes[1], runs, order)
    means = cf.draw_explored(axes[2], runs, order)
    for ax in axes:
        assert [label.get_text() for label in ax.get_xticklabels()] == order
    assert list(counts.index) == order and list(means.index) == order
    assert counts.sum(axis=1).tolist() == [9, 12, 15]
    assert means.to_numpy() == pytest.approx(runs.groupby("world")["mapped"].mean()[order].to_numpy())
    # the box-plot means follow the same order
    assert _line(axes[0], "means").get_ydata() == pytest.approx(runs.groupby("world")["eps_t"].mean()[order])
    # worlds without runs are skipped; a world of runs that the order does not list is an error
    _fig, (ax,) = _figure()
    cf.draw_termination(ax, runs, ["nowhere", *order])
    assert [label.get_text() for label in ax.get_xticklabels()] == order
    with pytest.raises(ValueError, match="campus"):
        cf.draw_explored(ax, runs, ["school", "office"])


def test_termination_stacks_count_every_run(runs: pd.DataFrame) -> None:
    _fig, (ax,) = _figure()
    counts = cf.draw_termination(ax, runs)
    assert [c.get_label() for c in ax.containers] == ["map_stable", "stuck", "timeout"]
    totals = np.sum([[bar.get_height() for bar in c] for c in ax.containers], axis=0)
    assert totals.tolist() == runs.groupby("world").size().sort_index().tolist()
    first, second = ax.containers[0], ax.containers[1]
    assert [b.get_y() for b in second] == pytest.approx([b.get_height() for b in first])  # stacked
    assert counts.loc["office", "map_stable"] == 12
    missing = runs.assign(termination=None)
    _fig, (ax,) = _figure()
    assert list(cf.draw_termination(ax, missing).columns) == ["unknown"]


def test_explored_fraction_means_per_world(runs: pd.DataFrame) -> None:
    _fig, (ax,) = _figure()
    means = cf.draw_explored(ax, runs)
    expected = runs.groupby("world")["mapped"].mean().sort_index()
    assert _line(ax, "means").get_ydata() == pytest.approx(expected.to_numpy())
    assert list(means.index) == list(expected.index)
    assert len(_line(ax, "runs").get_xdata()) == len(runs)
    with pytest.raises(ValueError, match="'mapped'"):
        cf.draw_explored(ax, runs.drop(columns="mapped"))


def _comparison(runs: pd.DataFrame):
    b = runs.copy()
    shift = b["world"].map({"office": -0.05, "school": 0.0, "campus": 0.2})
    b["eps_t"] = b["eps_t"] + shift
    return compare_campaigns(runs, b, labels=("gmapping", "karto"))


def test_comparison_forest_plot_and_trap_markers(runs: pd.DataFrame) -> None:
    comparison = _comparison(runs)
    rows = comparison.for_metric("eps_t")
    _fig, (ax,) = _figure()
    cf.draw_comparison(ax, comparison, "eps_t")
    drawn = {c.get_label(): c for c in ax.containers}
    assert set(drawn) == {"karto better", "gmapping better", "no significant difference"}
    assert drawn["karto better"].lines[0].get_xdata() == pytest.approx(
        rows.loc[rows["world"] == "office", "difference"]
    )
    assert drawn["gmapping better"].lines[0].get_xdata() == pytest.approx(
        rows.loc[rows["world"] == "campus", "difference"]
    )
    trap = _line(ax, "trap")
    reversed_rows = rows[np.sign(rows["trap_difference"]) == -np.sign(rows["difference"])]
    assert len(trap.get_xdata()) == len(reversed_rows) >= 1
    assert sorted(trap.get_xdata()) == pytest.approx(sorted(reversed_rows["trap_difference"]))
    # Worlds from top to bottom in the table's order.
    position = {label.get_text(): y for label, y in zip(ax.get_yticklabels(), ax.get_yticks())}
    assert sorted(position, key=position.get, reverse=True) == list(rows["world"])


def test_every_figure_saves_as_png_and_pdf(runs: pd.DataFrame, tmp_path: Path) -> None:
    fig, axes = _figure(4)
    cf.draw_world_errors(axes[0], runs, "school")
    cf.draw_all_runs(axes[1], runs)
    cf.draw_termination(axes[2], runs)
    cf.draw_comparison(axes[3], _comparison(runs))
    png, pdf = cf.save_figure(fig, tmp_path / "figs" / "campaign.v1")
    assert (png.name, pdf.name) == ("campaign.v1.png", "campaign.v1.pdf")
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert pdf.read_bytes()[:5] == b"%PDF-"
    assert sorted(p.name for p in png.parent.iterdir()) == ["campaign.v1.pdf", "campaign.v1.png"]  # no temp files
    fig, axes = _figure(4)
    cf.draw_sampling_check(axes[0], np.random.default_rng(1).normal(0.3, 0.01, 50))
    cf.draw_map(axes[1], OccupancyGrid(grid=np.zeros((5, 5), np.int8), resolution=0.1, origin=np.zeros(3)), "map")
    truth, estimate = _run_trajectories()
    cf.draw_trajectories(axes[2], truth, estimate)
    cf.draw_explored(axes[3], runs)
    for path in cf.save_figure(fig, tmp_path / "more"):
        assert path.stat().st_size > 100


def test_figure_modules_never_use_pyplot() -> None:
    for module in (cf,):
        tree = ast.parse(Path(module.__file__).read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [node.module or ""] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
                assert not any("pyplot" in name or name == "pylab" for name in names)
                assert not any(alias.name in ("pyplot", "use") for alias in node.names)


def test_the_sampling_legend_stays_off_the_histogram():
    """Fig. 3: the legend (with its long normal-fit label) sits below the axes, not over the bars."""
    fig = Figure(figsize=(11, 3.8), dpi=100, layout="constrained")
    canvas = FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2)
    for ax in axes:
        cf.draw_sampling_check(ax, np.random.default_rng(3).normal(0.225, 0.0008, 200))
    canvas.draw()
    renderer = canvas.get_renderer()
    for ax in axes:
        legend = ax.get_legend().get_window_extent(renderer)
        assert legend.y1 <= ax.get_window_extent(renderer).y0
        assert fig.bbox.y0 <= legend.y0  # and inside the figure
