"""``slamtrials calibrate``: fit the simulator's error models to a real log and write the profile.

A thin wrapper over :mod:`slamtrials.calibration`: it reads the log (and its benchmark relations, with
``--relations``), checks that it can be calibrated from and that the relations are the log's (before
anything runs), runs the SLAM algorithm for the reference, fits, prints the values with their
uncertainty, and writes the profile YAML (:func:`slamtrials.campaign.profilefile.write_profile`) and a
PNG page of figures next to it. Relations are given explicitly, as to ``validate``: none is picked up
from beside the log.
"""

from __future__ import annotations

import datetime as _dt
import math
import re
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from slamtrials.cli.common import make_console
from slamtrials.errors import ConfigError

if TYPE_CHECKING:
    from slamtrials.calibration import Calibration

__all__ = ["calibrate", "register", "format_calibration", "profile_name"]

_COMPRESSED = (".gz", ".bz2")


def profile_name(log: Path) -> str:
    """The profile's name from the log's file name: ``mit-csail.clf`` -> ``mit-csail``,
    ``fr079.clf.bz2`` -> ``fr079``; characters a profile name does not allow become ``_``."""
    name = log.name
    for suffix in _COMPRESSED:
        name = name.removesuffix(suffix)
    stem = Path(name).stem or "log"
    return re.sub(r"[^A-Za-z0-9_.\-]", "_", stem)[:100]


def format_calibration(cal: Calibration, log: str) -> str:
    """The printed fit: the log's residual figures, then every value +- its standard error."""
    laser, odo = cal.laser, cal.odometry
    lines = [f"{log}: {cal.frames} frames; reference: {cal.reference}"]
    if cal.odometry_reference and cal.odometry_reference != cal.reference:
        lines[-1] += f"; odometry against {cal.odometry_reference}"
    lines.append(
        f"laser: {laser.beams} beams of {cal.laser_frames} frames hit a mapped wall through known free space; "
        "robust sigma of their residuals "
        f"{laser.robust_sigma:.4f} m, {100 * laser.off_share:.1f} % off by more than 0.2 m, "
        f"{100 * laser.no_return_share:.2f} % no return; past the short-reading cut "
        f"{100 * laser.short_share:.1f} % short, {100 * laser.long_share:.1f} % long (not modelled: glass, "
        "open doors, and the reference's own pose and map errors)"
    )
    value = {v.name: v for v in cal.fitted}

    def row(name: str, note: str = "") -> str:
        v = value[name]
        if v.value == 0.0 and not note:
            note = "  at its bound 0 (the fit would go negative)"
        return f"  {name:<22} {v.value:>10.5f} +- {v.stderr:<9.5f} {v.unit:<8}{note}".rstrip()

    for name in (
        "range_noise_std",
        "range_noise_per_m",
        "short_rate",
        "short_range_scale",
        "short_range_shape",
        "short_run_beams",
        "short_position_power",
        "dropout_rate",
        "dropout_per_m",
        "dropout_grazing",
        "edge_chance",
    ):
        lines.append(row(name, " " if name == "edge_chance" else ""))
        if name == "short_range_scale":
            lines[-1] += "  (the chance rises to short_rate as 1 - exp(-(r / scale)^shape); 0: constant)"
        if name == "short_position_power":
            lines[-1] += "  (where they stand: density (a + 1) v^a of the beam fraction v; 0 is uniform)"
        if name == "edge_chance":
            lines[-1] += (
                f"  (of {laser.edge_beams} beams next to a wall more than 0.3 m nearer within "
                f"edge_reach {value['edge_reach'].value:.4g} rad, {laser.edge_readings} read it)"
            )
    life = cal.lifetime
    if life is None:
        lines.append("  short_lifetime, short_fleeting_share: not fitted (too few short readings); 0 in the profile")
    else:
        bound = "  (at the grid's largest: at least this)" if life.at_bound else ""
        lines.append(row("short_lifetime", bound or " "))
        lines.append(row("short_fleeting_share", " "))
        curve = ", ".join(f"{s:.2f} s {r:.3f} / {f:.3f}" for s, r, f in zip(life.lag_seconds, life.real, life.fitted))
        lines.append(
            f"  short readings still read short within the radius after (real / fitted; {life.short_readings} "
            f"short readings of {life.base_frames} frames): {curve}"
        )
    rel = odo.relations
    if rel is None:
        lines.append(
            f"odometry against the SLAM path: {odo.anchors} reference frames beyond odometry, {odo.distance:.1f} m, "
            f"{odo.rotation:.1f} rad (the fit holds the reference's own errors; give --relations where the log "
            "has benchmark relations)"
        )
    else:
        lines.append(
            f"odometry against benchmark relations: {rel.total} in the file, {rel.matched} on two frames of the log, "
            f"{rel.long} long ones not used (loop closures: a span that long is not one arc), {rel.used} used in "
            f"{rel.chains} chains, {odo.distance:.1f} m, {odo.rotation:.1f} rad"
        )
    lines[-1] += f"; noise as a random walk per metre and per radian (no step length; log step {odo.log_step:.3f} s)"
    what = "segments" if rel is None else "relations"
    if odo.conflicts:
        lines.append(
            f"  excluded: {odo.conflicts} {what} ({odo.conflict_distance:.2f} m) where the odometry moves against "
            f"the reference (a recording defect, e.g. reversing logged as driving forward), {odo.conflict_neighbours} "
            f"next to them (where a reversal starts or ends), and the {odo.excluded_windows} windows holding one"
        )
    else:
        lines.append(f"  excluded: no {what} where the odometry moves against the reference")
    lines.append(row("bias_linear", "  -> bias_linear_range +-|value| (one log is one draw)"))
    lines.append(row("bias_angular", "  -> bias_angular_range +-|value|"))
    for name in ("noise_linear_per_m", "noise_linear_per_rad", "noise_angular_per_rad", "noise_angular_per_m"):
        lines.append(row(name))
    lines.append(
        f"  error at a window's ends, not growing with it (not in the profile): {math.sqrt(odo.reference_linear):.4f} m, "
        f"{math.sqrt(odo.reference_angular):.4f} rad"
    )
    outliers = int(sum(odo.windows.outliers.tolist()))
    lines.append(
        f"  slips: not fitted; {odo.heavy_tail} single {what} beyond the noise, {outliers} windows in all left out "
        f"as outliers (beyond the outlier cut; cannot be told from jumps of the reference)"
    )
    lines.append(f"+- is one block-bootstrap standard error ({cal.bootstrap} replicates)")
    return "\n".join(lines)


def calibrate(
    log: Annotated[Path, typer.Argument(help="Real log: CARMEN (.clf/.log, .gz, .bz2), ROS bag or run folder.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Profile YAML to write (.yaml or .yml).")],
    algorithm: Annotated[
        str, typer.Option("--algorithm", "-a", help="SLAM algorithm whose final path and map are the reference.")
    ] = "gmapping",
    preset: Annotated[str | None, typer.Option("--preset", "-p", help="Named parameter set of the algorithm.")] = None,
    settings: Annotated[
        list[str] | None, typer.Option("--set", help="Algorithm parameter key=value (value read as YAML); repeatable.")
    ] = None,
    seed: Annotated[int, typer.Option("--seed", "-s", help="Seed of the SLAM run and of the bootstrap.")] = 0,
    bootstrap: Annotated[int, typer.Option("--bootstrap", help="Bootstrap replicates of the uncertainty.")] = 100,
    figures: Annotated[
        Path | None, typer.Option("--figures", help="PNG page of figures (default: the profile's path with .png).")
    ] = None,
    name: Annotated[str | None, typer.Option("--name", help="Profile name (default: the log's file stem).")] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace an existing profile file.")] = False,
    relations: Annotated[
        Path | None,
        typer.Option(
            "--relations",
            "-r",
            help="The log's benchmark relations (Freiburg form): the odometry is fitted against them, not the SLAM path.",
        ),
    ] = None,
    tolerance: Annotated[
        float,
        typer.Option("--tolerance", help="Largest gap (s) between a relation timestamp and a frame (Freiburg: 0.1)."),
    ] = 0.1,
) -> None:
    """Fit the simulator's error models (laser noise, short readings, dropouts; odometry biases and noise)
    to the real log LOG, against a SLAM run's path and map, and write them as an error profile.

    With --relations the odometry is fitted against the log's benchmark relations (human-checked relative
    poses, independent of any SLAM run); without, against the SLAM path, which the printout says."""
    from pydantic import ValidationError
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    from slamtrials.calibration import CalibrationSettings, check_calibratable, slam_reference
    from slamtrials.calibration import calibrate as fit
    from slamtrials.cli.slam import parse_settings
    from slamtrials.errors import CalibrationError, validation_problems
    from slamtrials.slam import get_algorithm, resolve_config
    from slamtrials.slamrun import load_recording

    if out.suffix.lower() not in (".yaml", ".yml"):
        raise ConfigError(f"--out {out}: a profile is a YAML file; give a path ending in .yaml")
    if out.exists() and not overwrite:
        raise ConfigError(f"{out}: already exists; choose another --out or pass --overwrite")
    figure_path = figures if figures is not None else out.with_suffix(".png")
    if figure_path.suffix.lower() != ".png":
        raise ConfigError(f"--figures {figure_path}: the page of figures is a PNG; give a path ending in .png")
    if seed < 0:
        raise ConfigError(f"--seed must be a non-negative integer, got {seed}")
    if not (math.isfinite(tolerance) and 0.0 < tolerance <= 10.0):
        raise ConfigError(f"--tolerance must be in (0, 10] s, got {tolerance}")
    try:
        cfg = CalibrationSettings(bootstrap=bootstrap, relation_tolerance=tolerance)
    except ValidationError as exc:
        raise ConfigError("--bootstrap: " + validation_problems(exc)) from None
    overrides = parse_settings(settings or [])
    resolve_config(get_algorithm(algorithm), preset=preset, overrides=overrides)  # fail before reading the log
    record = load_recording(log)
    try:
        check_calibratable(
            record,
            min_frames=cfg.min_frames,
            min_distance=cfg.min_distance,
            min_rotation=cfg.min_rotation,
            min_gap=cfg.min_gap,
            max_tiny_share=cfg.min_step_share,
        )
    except CalibrationError as exc:
        raise CalibrationError(f"{log}: {exc}") from None
    rel = None
    if relations is not None:
        from slamtrials.calibration.odometry import check_relations_belong
        from slamtrials.io.relations import read_relations

        rel = read_relations(relations)
        try:
            check_relations_belong(record.t, rel, cfg.relation_tolerance)
        except CalibrationError as exc:
            raise CalibrationError(f"{relations}: {exc} ({log})") from None
    profile_id = name if name is not None else profile_name(log)
    console = make_console()
    columns = (TextColumn(f"{algorithm} reference"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=True, disable=not console.is_terminal) as progress:
        task = progress.add_task("slam", total=len(record))
        reference = slam_reference(
            record,
            algorithm,
            preset=preset,
            overrides=overrides,
            seed=seed,
            on_frame=lambda k, total: progress.update(task, completed=k + 1),
        )
    try:
        result = fit(
            record, reference, cfg, seed=seed, relations=rel, relations_source=relations.name if relations else ""
        )
    except CalibrationError as exc:
        raise CalibrationError(f"{log}: {exc}") from None
    today = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d")
    against = reference.source if rel is None else f"{reference.source} (laser), {result.odometry_reference} (odometry)"
    description = (
        f"fitted by slamtrials calibrate on {today} to the log {log.name} against {against}; "
        "biases as +- the measured per-run bias; odometry noise per metre and per radian; no slips"
    )
    try:
        profile = result.profile(profile_id, description)
    except ValidationError as exc:
        raise ConfigError(f"the fitted profile is not valid: {validation_problems(exc)}") from None
    from slamtrials.campaign.profilefile import write_profile

    text = format_calibration(result, str(log))
    write_profile(out, profile, header="\n".join(["slamtrials calibrate " + log.name, *text.splitlines()]))
    _write_figures(result, figure_path, f"{profile_id}: calibration against {reference.source}")
    console.print(text, soft_wrap=True, highlight=False)
    console.print(f"wrote {out} and {figure_path}", soft_wrap=True, highlight=False)


def _write_figures(result: Calibration, path: Path, title: str) -> None:
    import matplotlib.pyplot as plt

    from slamtrials.report.calibration_figures import draw_calibration_page

    fig = plt.figure(figsize=(16, 9.5), layout="constrained")
    try:
        draw_calibration_page(fig, result, title=title)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp.png")
        fig.savefig(tmp, dpi=90)
        tmp.replace(path)
    finally:
        plt.close(fig)


def register(app: typer.Typer) -> None:
    """Add the ``calibrate`` command to ``app``."""
    app.command("calibrate")(calibrate)
