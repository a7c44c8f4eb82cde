"""The report's Fig. 3, the relation-sampling check of one run: the run's mean error over many independent
samplings of relations (by the campaign's own rule), with a fitted normal and the value the campaign
recorded; which run is checked (:func:`choose_sampling_run`, :func:`parse_run`)."""

from __future__ import annotations

import logging
import warnings

import numpy as np

from slamtrials.campaign.config import MetricSettings
from slamtrials.errors import ConfigError, SlamtrialsError
from slamtrials.record import Trajectory
from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.figure_writer import FigureWriter
from slamtrials.report.tables import METRICS, SYMBOLS, UNITS

__all__ = ["sampling_check_section", "choose_sampling_run", "parse_run", "DEFAULT_REPEATS", "SECTION_ID"]

log = logging.getLogger(__name__)

#: The section's anchor.
SECTION_ID = "fig-3"
#: Samplings of the relation-sampling check (the paper's Fig. 3 uses 200).
DEFAULT_REPEATS = 200

_TITLE = "Fig. 3: the relation-sampling check"


def parse_run(spec: str | tuple[str, int]) -> tuple[str, int]:
    """``"WORLD/IDX"`` (or ``(world, idx)``) as ``(world, idx)``.

    Raises
    ------
    ConfigError
        Not of that form.
    """
    if isinstance(spec, tuple):
        world, index = spec
        return str(world), int(index)
    world, sep, index = str(spec).rpartition("/")
    if not sep or not world or not index.strip().isdigit():
        raise ConfigError(f"run must be given as WORLD/INDEX (e.g. office_small_01/0), got {spec!r}")
    return world, int(index)


def choose_sampling_run(view: CampaignView, sampling_run: str | tuple[str, int] | None) -> tuple[str, int] | None:
    """The run to check as ``(world, run index)``: ``sampling_run`` when given, else the first finished run
    of the first world (in the campaign's order) that has one; None when no run has finished.

    Raises
    ------
    ConfigError
        ``sampling_run`` is malformed, unknown to the campaign, or not finished.
    """
    data = view.data
    if sampling_run is not None:
        world, index = parse_run(sampling_run)
        rows = data.runs[(data.runs["world"] == world) & (data.runs["run"] == index)]
        if rows.empty:
            raise ConfigError(f"{data.folder}: has no run {world}/{index} (worlds: {', '.join(data.worlds['world'])})")
        if rows["status"].iloc[0] != "done":
            raise ConfigError(f"{data.folder}: run {world}/{index} is not finished (status {rows['status'].iloc[0]})")
        return world, index
    for world in data.worlds["world"]:
        mine = view.done[view.done["world"] == world]
        if len(mine):
            return world, int(mine["run"].min())
    return None


def sampling_check_section(
    view: CampaignView, figs: FigureWriter, chosen: tuple[str, int] | None, *, repeats: int, seed: int
) -> str:
    """The section (HTML, ``id="fig-3"``): the check of run ``chosen`` (``(world, run index)``) over
    ``repeats`` samplings drawn from ``numpy.random.SeedSequence(seed)``, ``eps_t`` left and ``eps_r`` right,
    and a line with the spread of each against the margin of error; a note instead when the run's folder
    cannot be read or holds no SLAM estimate."""
    if chosen is None:
        return h.section(_TITLE, "<p>No finished run to check.</p>", id=SECTION_ID)
    world, index = chosen
    metric = MetricSettings.of_stored(view.data.config.get("metric", {}))
    try:
        means = _sampling_means(view, world, index, metric, repeats, seed)
    except SlamtrialsError as exc:
        log.warning("relation-sampling check of %s/%d: %s", world, index, exc)
        return h.section(_TITLE, h.notes([f"Run {world}/{index} could not be checked: {exc}"]), id=SECTION_ID)
    done = view.done
    row = done[(done["world"] == world) & (done["run"] == index)].iloc[0]
    margins = dict(zip(METRICS, metric.sampling.margins(float(row["eps_t"]), float(row["eps_r"]))))
    fig = figs.new(11, 3.8)
    for ax, (component, values), metric_name in zip(fig.subplots(1, 2), means.items(), METRICS):
        with warnings.catch_warnings():  # a run whose relations all have the same error: no spread to test
            warnings.filterwarnings("ignore", message=".*range zero.*", category=UserWarning)
            cf.draw_sampling_check(ax, values, xlabel=f"mean {component} error of one sampling ({UNITS[metric_name]})")
        ax.axvline(float(row[metric_name]), color="black", ls=":", lw=1.2, gid="campaign_value")
        ax.set_title(f"{world} run #{index}: {SYMBOLS[metric_name]} over {repeats} samplings", fontsize=9)
    caption = (
        f"The paper's Fig. 3 for run #{index} of {world}: the distribution of the run's mean error over {repeats} "
        f"independent samplings of relations (each by the campaign's {metric.sampling.describe()}), "
        f"with a fitted normal; dotted: the value the campaign recorded "
        f"({row['eps_t']:.4f} m, {row['eps_r']:.4f} rad). Sampling seed {seed}."
    )
    spread = [
        f"{SYMBOLS[m]}: mean {v.mean():.4g}, sd {v.std(ddof=1):.2g} over samplings (margin \u00b1{margins[m]:.2g})"
        for m, v in zip(METRICS, means.values())
    ]
    return h.section(
        _TITLE,
        figs.save(fig, "fig3_sampling", caption),
        "<p>" + h.esc("; ".join(spread)) + "</p>",
        id=SECTION_ID,
        intro="Is the sampled mean of one run approximately normal with a spread within the margin of error?",
    )


def _sampling_means(
    view: CampaignView, world: str, index: int, metric: MetricSettings, repeats: int, seed: int
) -> dict[str, np.ndarray]:
    """``{"translational": [repeats], "rotational": [repeats]}``: the run's mean error (m, rad) of each of
    ``repeats`` samplings of its relations by the campaign's rule.

    Raises
    ------
    SlamtrialsError
        The run folder cannot be read or holds no SLAM estimate.
    """
    record = view.read_record(world, index)
    if record.estimate is None:
        raise SlamtrialsError("the run folder holds no SLAM estimate")
    truth = Trajectory(t=record.t, poses=record.truth)
    estimate = Trajectory(t=record.t, poses=np.asarray(record.estimate, dtype=np.float64))
    odometry = Trajectory(t=record.t, poses=record.odometry)
    sequence = np.random.SeedSequence(int(seed))
    return {
        component: cf.repeated_sampling_means(
            truth,
            estimate,
            repeats,
            sequence,
            component=component,
            rule=metric.sampling,
            tolerance=metric.tolerance,
            odometry=odometry,
        )
        for component in ("translational", "rotational")
    }
