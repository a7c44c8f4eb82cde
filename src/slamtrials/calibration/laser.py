"""The laser fit: range noise by range bin, short readings and dropouts, from a :class:`BeamSample`.

Residual of a beam: ``e = reading - cast``. Per range bin (by the cast range) of the beams that
returned something, the Gaussian core of the residuals gives the bin's noise sigma
(:func:`~slamtrials.calibration.stats.central_sigma`: MAD start, then the truncation-corrected standard
deviation within ``core_cut`` sigmas of the median); a weighted line through the bins' sigmas (weights
``n / sigma^2``, the inverse variance of a sigma estimated from ``n`` values, up to a factor) gives
``range_noise_std + range_noise_per_m r``, both non-negative.

Short readings: a beam that returned more than ``short_sigmas`` (``k``) sigmas short of the cast range
moved by its bin's median residual (the wall ``w``). Where they stand: the model puts a short reading at
``min_range + v (w - min_range)`` with ``v`` of density ``(a + 1) v^a`` (:mod:`slamtrials.sim.shortdistance`);
``a = short_position_power`` is the maximum-likelihood fit to the short readings that start a run (the
beam before them in the scan is kept and not short: the run's later beams read the same distance against
other walls) and stand at least ``g0 = max(k sigma(w), position_floor)`` before the wall, each seen only
up to ``t = 1 - g0 / (w - min_range)``, which has the closed form ``a + 1 = n / sum(ln(t_i / v_i))`` (clamped to [0, 50]; 0 with
fewer than ``position_min_short`` readings). A reading is then seen short with probability ``(1 - k
sigma(w) / (w - min_range))^(a + 1)``; with it, the chance of a short reading by the wall's range
(``short_rate``, and ``short_range_scale`` and ``short_range_shape`` when it rises with the range) is
the maximum-likelihood fit of :mod:`slamtrials.calibration.shortchance`, the Gaussian tail's false
alarms counted in. Their runs:
among pairs of neighbouring kept beams of one scan whose first is short, the share whose second is short
too (counted only where the neighbour's wall is far enough behind the first one's reading for it to be
seen short: a run is one object at one distance) is the chain's ``q``, and ``short_run_beams = 1 / (1 -
q)`` (the mean run; independent beams give ``1 / (1 - short_rate)``, about 1.1).

Edge readings (:mod:`slamtrials.sim.edges`): a kept beam is on the far side of an edge when a neighbour
within the edge reach has a cast wall more than ``EDGE_MIN_STEP`` nearer (``sample.nearer``); it reads the
edge when its reading lies within ``k`` sigmas of that nearer wall (moved by its bin's median residual),
the sigmas of a first fit on all beams. ``edge_chance`` is the share of the far-side beams that read the
edge, among those whose own wall's window lies wholly beyond the nearer wall's (where the step is not
much larger than the noise, a reading cannot tell the two walls apart) and that returned no shorter than
the nearer wall's window (a reading short of both walls is a short
reading whichever wall it was). The edge readings are then taken as readings of the nearer wall (their
cast is replaced by it) and everything is fitted again, so that they are not counted as short readings.
A short reading of the far wall that lands in the window cannot be told from an edge reading: the
number the fitted short-reading model expects there is taken off the count of edge readings (the short
readings' own fit misses those few, a small undercount of ``short_rate``: about 3 % of it in the tests).

Dropouts: the share of kept beams that returned nothing, fitted per beam by non-negative least squares
as ``(1 - p(r)) (dropout_rate + dropout_per_m r + dropout_grazing (1 - |cos i|))``, ``p(r)`` the beam's
chance of a short reading (a short reading replaces a dropout in the model).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.calibration.beams import BeamSample
from slamtrials.calibration.settings import CalibrationSettings
from slamtrials.calibration.shortchance import fit_short_chance
from slamtrials.calibration.stats import central_sigma, nonnegative_least_squares, robust_sigma
from slamtrials.sim.edges import EDGE_MIN_STEP
from slamtrials.sim.shortrate import short_chances

__all__ = ["LaserFit", "LaserBins", "fit_laser", "position_power", "LASER_VALUES", "POSITION_POWER_BOUNDS"]

#: The fitted laser values, in the order of the profile's fields.
LASER_VALUES = (
    "range_noise_std",
    "range_noise_per_m",
    "short_rate",
    "short_run_beams",
    "short_position_power",
    "short_range_scale",
    "short_range_shape",
    "dropout_rate",
    "dropout_per_m",
    "dropout_grazing",
    "edge_chance",
    "edge_reach",
)


@dataclass(frozen=True, eq=False)
class LaserBins:
    """Per range bin (only bins with enough beams): float64 ``[K]`` arrays.

    Attributes
    ----------
    low, high:
        Bin edges (m).
    range_mean:
        Mean cast range of the bin's beams (m).
    beams:
        Kept beams in the bin.
    centre:
        Median residual of the returned beams (m): the map's offset (cell sides are not wall surfaces).
    sigma:
        Noise sigma of the Gaussian core (m).
    core_share:
        Share of the returned beams within ``core_cut`` sigmas of the median.
    no_return:
        Share of the bin's beams that returned nothing.
    short:
        Share of the bin's beams read short (beyond ``short_sigmas`` sigmas).
    """

    low: NDArray[np.float64]
    high: NDArray[np.float64]
    range_mean: NDArray[np.float64]
    beams: NDArray[np.float64]
    centre: NDArray[np.float64]
    sigma: NDArray[np.float64]
    core_share: NDArray[np.float64]
    no_return: NDArray[np.float64]
    short: NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class LaserFit:
    """The laser's fitted values (:data:`LASER_VALUES`) and the figures behind them.

    Attributes
    ----------
    values:
        Field name -> value (profile units).
    bins:
        The per-bin table.
    beams:
        Kept beams.
    robust_sigma:
        1.4826 MAD of all returned beams' residuals (m), all ranges together.
    off_share:
        Share of kept beams that returned something more than 0.2 m from the cast range.
    no_return_share:
        Share of kept beams that returned nothing.
    edge_beams:
        Kept beams on the far side of an edge (counted for ``edge_chance``).
    edge_readings:
        Beams among them read as edge readings (their cast replaced by the nearer wall).
    short_share, long_share:
        Shares of the returned kept beams read more than ``short_sigmas`` sigmas short of / beyond the
        cast range (from the bin's centre), the Gaussian tail's expected count taken out. Long readings
        are not modelled (the simulated laser never reads past a wall): they come from glass and open
        doors, and from the reference's own pose and map errors, which make readings go long as often
        as short (docs/realism.md, "Assumptions").
    """

    values: dict[str, float]
    bins: LaserBins
    beams: int
    robust_sigma: float
    off_share: float
    no_return_share: float
    short_share: float
    long_share: float
    edge_beams: int = 0
    edge_readings: int = 0

    def short_below(self, cast: NDArray[np.float64], short_sigmas: float) -> NDArray[np.float64]:
        """float64 ``[N]``: the reading (m) below which a beam whose cast range is ``cast`` ``[N]`` (m) reads
        short, as the fit counts them: ``short_sigmas`` fitted noise sigmas short of the cast range moved by
        its range bin's median residual (by none outside the table's bins)."""
        v = self.values
        sigma = np.maximum(v["range_noise_std"] + v["range_noise_per_m"] * cast, 1e-9)
        offset = np.zeros_like(cast)
        for low, high, centre in zip(self.bins.low, self.bins.high, self.bins.centre):
            offset[(cast >= low) & (cast < high)] = centre
        return cast + offset - short_sigmas * sigma


#: Bounds of the fitted position power: 0 is uniform along the beam; 50 puts nearly every thing at the wall.
POSITION_POWER_BOUNDS = (0.0, 50.0)


def position_power(
    reading: NDArray[np.float64],
    wall: NDArray[np.float64],
    cut: NDArray[np.float64],
    range_min: float,
    floor: float,
    min_short: int,
) -> float:
    """The maximum-likelihood ``short_position_power`` of short readings ``[N]`` (m) on beams whose walls are
    at ``wall`` ``[N]`` (m), each counted short below ``wall - cut`` (``cut`` ``[N]``, m): only those at least
    ``max(cut, floor)`` before the wall, their density truncated there (see the module docstring)."""
    least = np.maximum(cut, floor)
    span = wall - range_min
    used = (wall - reading >= least) & (span > least) & (reading > range_min)
    n = int(np.count_nonzero(used))
    if n < min_short:
        return 0.0
    v = (reading[used] - range_min) / span[used]
    top = 1.0 - least[used] / span[used]
    spread = float(np.sum(stablemath.log(top) - stablemath.log(v)))
    if spread <= 0.0:
        return POSITION_POWER_BOUNDS[1]
    return float(min(max(n / spread - 1.0, POSITION_POWER_BOUNDS[0]), POSITION_POWER_BOUNDS[1]))


def _normal_tail(k: float) -> float:
    return 0.5 * math.erfc(k / math.sqrt(2.0))


def _mean_run(
    sample: BeamSample, short: NDArray[np.bool_], short_below: NDArray[np.float64], false_share: float, rate: float
) -> float:
    """``1 / (1 - q)``: ``q`` the share of short beams whose kept neighbour in the scan reads short too,
    among those whose neighbour would be seen short at their reading (a run is one object at one
    distance: a neighbour whose wall is nearer reads the wall); 0 when there is no such pair.
    ``short_below`` ``[N]``: the reading below which each beam counts as short (m). ``false_share`` of
    the short beams are the noise's tail, whose neighbours read short at the plain ``rate``: they are
    taken out of the share."""
    neighbours = (sample.frame[1:] == sample.frame[:-1]) & (sample.beam[1:] == sample.beam[:-1] + 1)
    first = neighbours & short[:-1] & (sample.reading[:-1] < short_below[1:])
    pairs = int(np.count_nonzero(first))
    if pairs == 0:
        return 0.0
    seen = float(np.count_nonzero(first & short[1:])) / pairs
    stay = (seen - false_share * rate) / (1.0 - false_share) if false_share < 1.0 else seen
    return 1.0 / (1.0 - min(max(stay, 0.0), 0.999))


def fit_laser(sample: BeamSample, settings: CalibrationSettings, range_min: float) -> LaserFit | None:
    """Fit the laser's error models to ``sample``; None when fewer than two range bins have enough beams.

    The noise is fitted twice: on every returned beam, then without the neighbours of the short beams
    the first fit finds (the edge of an object not in the map reads a little short, inside the Gaussian
    core); the second fit is the result. Between the two, the first fit's sigmas find the edge readings
    (module docstring), which the second fit takes as readings of the nearer wall.
    """
    back = ~sample.no_return
    first = _fit(sample, settings, range_min, back)
    if first is None:
        return None
    far, edge = edge_readings(sample, first[0], settings.short_sigmas)
    walls = sample.with_cast(np.where(edge, sample.nearer, sample.cast))
    second = _fit(walls, settings, range_min, back & ~_next_to(sample, first[1] & ~edge))
    if second is None:
        return None
    fit = second[0]
    counted = int(np.count_nonzero(far))
    landed = _short_readings_in_window(sample, fit, far, settings.short_sigmas, range_min)
    chance = max(float(np.count_nonzero(edge)) - landed, 0.0) / counted if counted else 0.0
    values = {**fit.values, "edge_chance": chance, "edge_reach": settings.edge_reach}
    return dataclasses.replace(fit, values=values, edge_beams=counted, edge_readings=int(np.count_nonzero(edge)))


def _short_readings_in_window(
    sample: BeamSample, fit: LaserFit, counted: NDArray[np.bool_], short_sigmas: float, range_min: float
) -> float:
    """How many of the ``counted`` far-side beams ``[N]`` the fitted short-reading model expects to read short
    of their own wall into the nearer wall's window: readings an edge reading cannot be told from."""
    v = fit.values
    wall = fit.short_below(sample.cast[counted], 0.0)
    near = sample.nearer[counted]
    low = fit.short_below(near, short_sigmas)
    high = 2.0 * fit.short_below(near, 0.0) - low
    span = np.maximum(wall - range_min, 1e-9)
    power = v["short_position_power"] + 1.0
    below = stablemath.power(np.clip((low - range_min) / span, 0.0, 1.0), power)
    above = stablemath.power(np.clip((high - range_min) / span, 0.0, 1.0), power)
    chance = short_chances(wall, v["short_rate"], v["short_range_scale"], v["short_range_shape"])
    return math.fsum((chance * (above - below)).tolist())  # exactly rounded: the same on every CPU


def edge_readings(
    sample: BeamSample, fit: LaserFit, short_sigmas: float
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """bool ``[N]`` twice: the far-side beams counted for ``edge_chance`` (returned, their own wall's window
    beyond the nearer wall's, and not short of the nearer wall's window), and those of them that read the
    nearer wall (module docstring)."""
    far_side = np.isfinite(sample.nearer) & (sample.nearer < sample.cast - EDGE_MIN_STEP) & ~sample.no_return
    near = np.where(far_side, sample.nearer, sample.cast)
    centre = fit.short_below(near, 0.0)  # the nearer wall moved by its bin's median residual
    low = fit.short_below(near, short_sigmas)
    high = 2.0 * centre - low
    # only where the walls' windows do not overlap: a reading of either wall tells which one it is
    apart = fit.short_below(sample.cast, short_sigmas) > high
    counted = far_side & apart & (sample.reading >= low)
    return counted, counted & (sample.reading <= high)


def _run_starts(sample: BeamSample, short: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """``[N]``: short beams whose previous beam in the scan is kept and not short: where a run of short
    readings starts, which reads the thing's distance as drawn (the run's later beams read the same
    distance against other walls)."""
    out = np.zeros(short.size, dtype=bool)
    follows = (sample.frame[1:] == sample.frame[:-1]) & (sample.beam[1:] == sample.beam[:-1] + 1)
    out[1:] = follows & short[1:] & ~short[:-1]
    return out


def _next_to(sample: BeamSample, marked: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """``[N]``: beams whose neighbour in the same scan is ``marked``."""
    neighbours = (sample.frame[1:] == sample.frame[:-1]) & (sample.beam[1:] == sample.beam[:-1] + 1)
    out = np.zeros(marked.size, dtype=bool)
    out[1:] |= neighbours & marked[:-1]
    out[:-1] |= neighbours & marked[1:]
    return out


def _fit(
    sample: BeamSample, settings: CalibrationSettings, range_min: float, core: NDArray[np.bool_]
) -> tuple[LaserFit, NDArray[np.bool_]] | None:
    """The fit with the noise taken from the ``core`` beams ``[N]``, and its short beams ``[N]``."""
    r, e, back = sample.cast, sample.reading - sample.cast, ~sample.no_return
    edges = np.asarray(settings.range_bins, dtype=np.float64)
    which = np.searchsorted(edges, r, side="right") - 1
    rows = []
    for b in range(len(edges) - 1):
        in_bin = which == b
        returned = in_bin & core
        if int(np.count_nonzero(returned)) < settings.min_bin_beams:
            continue
        mid, spread, inside = central_sigma(e[returned], cut=settings.core_cut)
        if not (math.isfinite(spread) and spread > 0.0):
            continue
        rows.append((b, float(np.mean(r[in_bin])), float(np.count_nonzero(in_bin)), mid, spread, inside))
    if len(rows) < 2:
        return None
    bin_index = np.array([row[0] for row in rows])
    r_mean = np.array([row[1] for row in rows])
    count = np.array([row[2] for row in rows])
    centre = np.array([row[3] for row in rows])
    sigma = np.array([row[4] for row in rows])
    share = np.array([row[5] for row in rows])
    a, b_ = nonnegative_least_squares([np.ones_like(r_mean), r_mean], sigma, count / sigma**2)
    beam_sigma = np.maximum(a + b_ * r, 1e-9)
    k = settings.short_sigmas
    # the bin's centre is the map's offset, not a reading error: shortness is counted from it
    offset = np.zeros_like(r)
    for row, b in enumerate(bin_index):
        offset[which == b] = centre[row]
    short = back & (e - offset < -k * beam_sigma)
    wall = r + offset
    starts = _run_starts(sample, short)
    power = position_power(
        sample.reading[starts],
        wall[starts],
        k * beam_sigma[starts],
        range_min,
        settings.position_floor,
        settings.position_min_short,
    )
    seen = stablemath.power(
        np.clip((wall - k * beam_sigma - range_min) / np.maximum(wall - range_min, 1e-9), 0.0, 1.0), power + 1.0
    )
    false_alarms = _normal_tail(k) * float(np.count_nonzero(back & ~short))
    chance = fit_short_chance(wall, short, seen, _normal_tail(k))
    chances = chance.at(wall)
    false_share = min(false_alarms / max(float(np.count_nonzero(short)), 1.0), 1.0)
    run_beams = _mean_run(sample, short, r + offset - k * beam_sigma, false_share, float(np.mean(chances)))
    y = sample.no_return.astype(np.float64) / (1.0 - chances)
    columns = [np.ones_like(r), r, 1.0 - sample.incidence]
    d0, d1, d2 = nonnegative_least_squares(columns, y)
    values = {
        "range_noise_std": a,
        "range_noise_per_m": b_,
        "short_rate": chance.rate,
        "short_run_beams": run_beams,
        "short_position_power": power,
        "short_range_scale": chance.scale,
        "short_range_shape": chance.shape,
        "dropout_rate": d0,
        "dropout_per_m": d1,
        "dropout_grazing": d2,
    }
    no_return = np.array([float(np.mean(sample.no_return[which == b])) for b in bin_index])
    short_share = np.array([float(np.mean(short[which == b])) for b in bin_index])
    returned_e = e[back]
    returned = max(float(np.count_nonzero(back)), 1.0)
    long = back & (e - offset > k * beam_sigma)
    tail = _normal_tail(k) * float(np.count_nonzero(back & ~short & ~long))
    fit = LaserFit(
        values=values,
        bins=LaserBins(
            low=edges[bin_index],
            high=edges[bin_index + 1],
            range_mean=r_mean,
            beams=count,
            centre=centre,
            sigma=sigma,
            core_share=share,
            no_return=no_return,
            short=short_share,
        ),
        beams=int(r.size),
        robust_sigma=robust_sigma(returned_e)[1],
        off_share=float(np.count_nonzero(back & (np.abs(e) > 0.2))) / max(r.size, 1),
        no_return_share=float(np.mean(sample.no_return)) if r.size else math.nan,
        short_share=max(0.0, (float(np.count_nonzero(short)) - tail) / returned),
        long_share=max(0.0, (float(np.count_nonzero(long)) - tail) / returned),
    )
    return fit, short
