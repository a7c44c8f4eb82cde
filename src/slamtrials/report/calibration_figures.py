"""The page of figures of a calibration (``slamtrials calibrate``), drawn on a given matplotlib Figure.

Seven panels and the fitted values: the laser residuals, real against the fitted model drawn for the
same beams; the noise sigma by range bin with the fitted line; short readings and no-returns by range
bin, real against fitted; how long short readings persist, real against the replayed model; the
odometry's arc-length and heading errors by window length against the fitted growth; where short
readings stand along their beams, real against fitted (every short beam, so also those nearer the wall
than the position fit's floor and a run's later beams).
"""

from __future__ import annotations

import numpy as np

from slamtrials.calibration import Calibration

__all__ = ["draw_calibration_page"]


def _binned_share(ranges, flags, low, high):
    out = np.full(low.size, np.nan)
    for i in range(low.size):
        sel = (ranges >= low[i]) & (ranges < high[i])
        if sel.any():
            out[i] = float(np.mean(flags[sel]))
    return out


def draw_calibration_page(fig, calibration: Calibration, title: str = "") -> None:
    """Draw the panels of ``calibration`` on ``fig`` (a matplotlib Figure, e.g. 16 x 9.5 inches)."""
    from matplotlib.ticker import NullFormatter

    cal = calibration
    axes = fig.subplots(2, 4)
    bins = cal.laser.bins
    values = {v.name: v.value for v in cal.fitted}

    ax = axes[0, 0]
    edges = np.linspace(-1.0, 1.0, 161)
    back = ~cal.no_return
    model_back = ~cal.model_no_return
    ax.hist(np.clip(cal.residuals[back], -1, 1), bins=edges, histtype="step", color="tab:blue", label="real")
    ax.hist(
        np.clip(cal.model_residuals[model_back], -1, 1),
        bins=edges,
        histtype="step",
        color="tab:orange",
        label="fitted model",
    )
    ax.set_yscale("log")
    ax.set_xlabel("reading - cast range (m), clipped to +-1 m")
    ax.set_ylabel("beams")
    ax.set_title("laser residuals (beams that returned)")
    ax.legend(fontsize=8)

    ax = axes[0, 1]
    width = bins.high - bins.low
    ax.errorbar(
        bins.range_mean,
        bins.sigma,
        yerr=bins.sigma / np.sqrt(2.0 * bins.beams),
        fmt="o",
        color="tab:blue",
        label="core sigma per range bin",
    )
    r = np.linspace(0.0, float(bins.high[-1]), 100)
    ax.plot(r, values["range_noise_std"] + values["range_noise_per_m"] * r, color="tab:orange", label="fit a + b r")
    ax.plot(bins.range_mean, bins.centre, "s", color="tab:gray", markersize=3, label="median residual (map offset)")
    ax.set_xscale("log")
    ax.set_xlim(max(float(bins.low[0]), 0.1), float(bins.high[-1]))
    ax.set_xlabel("cast range (m)")
    ax.set_ylabel("m")
    ax.set_title("range noise")
    ax.legend(fontsize=8)
    del width

    ax = axes[0, 2]
    model_short = (
        cal.model_residuals < -3.0 * (values["range_noise_std"] + values["range_noise_per_m"] * cal.no_return_range)
    ) & model_back
    ax.plot(bins.range_mean, bins.no_return, "o-", color="tab:blue", label="no return, real")
    ax.plot(
        bins.range_mean,
        _binned_share(cal.no_return_range, cal.model_no_return, bins.low, bins.high),
        "o--",
        color="tab:orange",
        label="no return, fitted",
    )
    ax.plot(bins.range_mean, bins.short, "^-", color="tab:green", label="short, real")
    ax.plot(
        bins.range_mean,
        _binned_share(cal.no_return_range, model_short, bins.low, bins.high),
        "^--",
        color="tab:red",
        label="short, fitted",
    )
    ax.set_xscale("log")
    ax.set_xlabel("cast range (m)")
    ax.set_ylabel("share of beams")
    ax.set_title("short readings, no returns (at mapped walls)")
    ax.legend(fontsize=8)

    ax = axes[0, 3]
    life = cal.lifetime
    if life is None:
        ax.axis("off")
        ax.text(0.0, 0.5, "short readings' lifetime: not fitted\n(too few short readings)", fontsize=9)
    else:
        for g in range(life.fleeting_grid.size):
            for i in range(1, life.grid.size):
                ax.plot(life.lag_seconds, life.model[g, i], "-", color="tab:gray", alpha=0.15, linewidth=0.8)
        ax.plot(life.lag_seconds, life.model[0, 0], ":", color="tab:gray", label="model, drawn anew each scan")
        ax.plot(life.lag_seconds, life.real, "o", color="tab:blue", label="real")
        ax.plot(
            life.lag_seconds,
            life.fitted,
            "-",
            color="tab:orange",
            label=f"fitted: {life.lifetime:.3g} s, {100 * life.fleeting:.0f} % fleeting",
        )
        ax.set_xlabel("time later (s)")
        ax.set_ylabel("share read short again within the radius")
        ax.set_title("persisting short readings (grey: grid)")
        ax.legend(fontsize=8)

    win = cal.odometry.windows
    ax = axes[1, 0]
    ax.plot(win.distance, win.rms_linear, "o", color="tab:blue", label="real (bias removed)")
    ax.plot(win.distance, win.fit_linear, "-", color="tab:orange", label="fitted model")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("mean distance per window (m)")
    ax.set_ylabel("RMS arc-length error (m)")
    ax.set_title("odometry: distance error growth")
    ax.legend(fontsize=8)

    ax = axes[1, 1]
    ax.plot(win.distance, win.rms_angular, "o", color="tab:blue", label="real (bias removed)")
    ax.plot(win.distance, win.raw_angular, "x", color="tab:gray", label="real (bias in)")
    ax.plot(win.distance, win.fit_angular, "-", color="tab:orange", label="fitted model")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("mean distance per window (m)")
    ax.set_ylabel("RMS heading error (rad)")
    ax.set_title("odometry: heading error growth")
    ax.legend(fontsize=8)

    ax = axes[1, 3]
    cast = cal.no_return_range
    real_short = back & (cal.residuals < cal.laser.short_below(cast, 3.0) - cast)
    edges = np.linspace(0.0, 1.0, 21)
    for short, residuals, color, label in (
        (real_short, cal.residuals, "tab:blue", "real"),
        (model_short, cal.model_residuals, "tab:orange", "fitted model"),
    ):
        if short.any():
            fraction = np.clip((cast[short] + residuals[short]) / cast[short], 0.0, 1.0)
            ax.hist(fraction, bins=edges, density=True, histtype="step", color=color, label=label)
    power = values.get("short_position_power", 0.0)
    v = np.linspace(0.0, 1.0, 101)
    ax.plot(v, (power + 1.0) * v**power, ":", color="tab:gray", label=f"(a + 1) v^a, a = {power:.3g}")
    ax.set_xlabel("short reading / cast range")
    ax.set_ylabel("density")
    ax.set_title("short readings along the beam")
    ax.legend(fontsize=8)

    ax = axes[1, 2]
    ax.axis("off")
    lines = [f"{v.name} = {v.value:.4g} +- {v.stderr:.2g} {v.unit}".rstrip() for v in cal.fitted]
    lines.append(f"(+- one block-bootstrap standard error, {cal.bootstrap} replicates)")
    lines.append(f"reference: {cal.reference}")
    ax.text(0.0, 1.0, "\n".join(lines), va="top", family="monospace", fontsize=7, wrap=True)
    for ax in axes.ravel():
        if ax.get_xscale() == "log":  # the minor ticks' labels overlap on short decades
            ax.xaxis.set_minor_formatter(NullFormatter())
    if title:
        fig.suptitle(title)
