"""How long what reads short stays where it is: the fit of ``short_lifetime`` (s) and ``short_fleeting_share``.

The model (:mod:`slamtrials.sim.unmapped`): a new run of short readings is gone by the next scan with
probability ``short_fleeting_share`` (something moving), else it leaves a thing that stays for an
exponential time of mean ``short_lifetime``. Real logs need both: a single lifetime cannot give their
curve, whose first step falls more steeply, and whose tail lasts longer, than one exponential allows.

The statistic. For base frames ``k`` spread evenly over the log, a short reading of frame ``k`` (a kept
beam, :mod:`slamtrials.calibration.beams`, that returned below the fit's short cut,
:meth:`~slamtrials.calibration.laser.LaserFit.short_below`) *persists at lag L* when frame ``k + L`` has a
short reading whose end point lies within ``persistence_radius`` of its own (map frame). The persistence
curve ``p(L)`` is the share of the base frames' short readings that persist, at each lag of
``lifetime_lags`` (seconds, turned into whole frames by the log's median frame step).

The model's side. ``p(L)`` depends on more than how long things stay: how much of a thing a later scan
still sees from where the robot has moved, how often an unrelated short reading lands within the radius
by chance, how wide things are. So the lifetime is fitted by simulation, the way a replica sees it: the
simulator's laser model (:func:`slamtrials.sim.laser_errors.apply_laser_errors` with the fitted noise,
short-reading and dropout values and a lifetime ``tau``) reads the ranges cast from the reference path in
the reference map, every frame in order (any scan may leave things), and the same statistic is taken on
the same beams. That is done for ``tau = 0`` (short readings drawn anew for every scan) and for every
pair of ``tau`` in ``lifetime_grid`` and fleeting share ``g`` in ``fleeting_grid``, all with the same
random numbers, so that the curves differ by the two values only.
No warm-up is needed: a thing's remaining lifetime is exponential whenever it is seen.

The fit. ``(tau, g)`` minimises the sum over the lags of ``(p_real - p_model(tau, g))^2``, the model's
curves interpolated bilinearly between neighbouring grid values (in ``g`` linearly; in ``tau``
geometrically, and linearly between 0 and the first). A best ``tau`` at the grid's largest value means "at
least that" (:attr:`LifetimeFit.at_bound`). The uncertainties are the standard deviations over bootstrap
replicates that resample blocks of base frames, the real counts and the model's together.

Assumptions (docs/realism.md, "Calibration"): a wall the reference draws in the wrong place reads short at
the same place for as long as it is in view, and counts here as a thing that stays; the frames between
the reference's SLAM updates are placed by odometry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.calibration.beams import FrameCast, FrameCaster
from slamtrials.calibration.laser import LaserFit
from slamtrials.calibration.model_config import fitted_laser_config
from slamtrials.calibration.reference import Reference
from slamtrials.calibration.settings import CalibrationSettings
from slamtrials.record import RunRecord
from slamtrials.sim.laser_errors import apply_laser_errors
from slamtrials.sim.unmapped import UnmappedScan, UnmappedThings

__all__ = ["LifetimeFit", "fit_lifetime", "model_laser_values"]

_STEPS = 64  # interpolation steps between neighbouring grid lifetimes
_SHARE_STEPS = 20  # and between neighbouring fleeting shares


@dataclass(frozen=True, eq=False)
class LifetimeFit:
    """The fitted ``short_lifetime`` and the curves behind it.

    Attributes
    ----------
    lifetime:
        Fitted mean lifetime (s) of the things that stay.
    stderr:
        Its block-bootstrap standard error (s).
    fleeting:
        Fitted share of the new runs of short readings that leave no thing.
    fleeting_stderr:
        Its block-bootstrap standard error.
    lags:
        int64 ``[L]`` lags (frames).
    lag_seconds:
        float64 ``[L]`` the lags (s): frames times the log's median frame step.
    real:
        float64 ``[L]`` the log's persistence curve (share of short readings that persist at each lag).
    grid:
        float64 ``[G]`` lifetimes simulated (s), the first 0 (short readings drawn anew for every scan).
    fleeting_grid:
        float64 ``[F]`` fleeting shares simulated.
    model:
        float64 ``[F, G, L]`` the model's persistence curve for each fleeting share and lifetime (the
        lifetime-0 curve, the same for every share, is repeated).
    fitted:
        float64 ``[L]`` the model's curve at the fitted values (interpolated).
    short_readings:
        Short readings of the log's base frames.
    base_frames:
        Base frames used.
    at_bound:
        The best lifetime is the grid's largest: the log's things stay at least that long.
    """

    lifetime: float
    stderr: float
    fleeting: float
    fleeting_stderr: float
    lags: NDArray[np.int64]
    lag_seconds: NDArray[np.float64]
    real: NDArray[np.float64]
    grid: NDArray[np.float64]
    fleeting_grid: NDArray[np.float64]
    model: NDArray[np.float64]
    fitted: NDArray[np.float64]
    short_readings: int
    base_frames: int
    at_bound: bool


@dataclass(frozen=True, eq=False)
class _Counts:
    """Per base frame: short readings ``short`` int64 ``[N]`` and how many persist at each lag ``[N, L]``."""

    short: NDArray[np.int64]
    persist: NDArray[np.int64]

    def curve(self, index: NDArray[np.int64] | None = None) -> NDArray[np.float64]:
        """float64 ``[L]``: the persistence shares over the base frames ``index`` (default all)."""
        short = self.short if index is None else self.short[index]
        persist = self.persist if index is None else self.persist[index]
        return persist.sum(axis=0) / max(float(short.sum()), 1.0)

    @classmethod
    def of(
        cls,
        readings: NDArray[np.float32],
        casts: list[FrameCast],
        below: list[NDArray[np.float64]],
        base: NDArray[np.int64],
        lags: NDArray[np.int64],
        angles: NDArray[np.float64],
        limit: float,
        radius: float,
    ) -> _Counts:
        """The persistence counts of ``readings`` ``[T, B]`` (m) at the base frames ``[N]`` and lags ``[L]``."""
        needed = np.unique(np.concatenate([base, (base[:, None] + lags[None, :]).ravel()]))
        ends = {
            int(k): _short_ends(readings[k].astype(np.float64), casts[k], below[k], angles, limit)
            for k in needed.tolist()
        }
        short = np.array([ends[int(k)].shape[0] for k in base], dtype=np.int64)
        persist = np.array(
            [[_persisting(ends[int(k)], ends[int(k + lag)], radius) for lag in lags] for k in base], dtype=np.int64
        ).reshape(base.size, lags.size)
        return cls(short=short, persist=persist)


def model_laser_values(fit: LaserFit) -> dict[str, float]:
    """The laser values the simulator is given for ``fit`` (as :meth:`Calibration.profile` writes them):
    rates capped at 1, a run shorter than one beam taken as none (independent beams), the position power
    and the rise of the short-reading chance with the range as fitted."""
    as_fitted = ("short_position_power", "short_range_scale", "short_range_shape")
    values = {k: float(min(v, 1.0)) for k, v in fit.values.items() if k not in ("short_run_beams", *as_fitted)}
    values.update({k: float(fit.values[k]) for k in as_fitted})
    run = fit.values["short_run_beams"]
    values["short_run_beams"] = float(run) if run >= 1.0 and values["short_rate"] > 0.0 else 0.0
    return values


def _short_ends(
    reading: NDArray[np.float64], cast: FrameCast, below: NDArray[np.float64], angles: NDArray[np.float64], limit: float
) -> NDArray[np.float64]:
    """float64 ``[K, 2]``: end points (map frame, m) of the frame's short readings among its kept beams."""
    short = cast.kept & (reading < limit) & (reading < below)
    heading = cast.laser_pose[2] + angles[short]
    r = reading[short]
    x, y = cast.laser_pose[0] + r * stablemath.cos(heading), cast.laser_pose[1] + r * stablemath.sin(heading)
    return np.stack([x, y], axis=1)


def _persisting(now: NDArray[np.float64], later: NDArray[np.float64], radius: float) -> int:
    """How many points of ``now`` ``[K, 2]`` have a point of ``later`` ``[M, 2]`` within ``radius`` (m)."""
    if now.shape[0] == 0 or later.shape[0] == 0:
        return 0
    dx = now[:, None, 0] - later[None, :, 0]
    dy = now[:, None, 1] - later[None, :, 1]
    return int(np.count_nonzero(np.any(dx * dx + dy * dy <= radius * radius, axis=1)))


def _replay(
    casts: list[FrameCast],
    t: NDArray[np.float64],
    values: dict[str, float],
    lifetime: float,
    fleeting: float,
    record: RunRecord,
    angles: NDArray[np.float64],
    seed: int,
) -> NDArray[np.float32]:
    """float32 ``[T, B]``: the simulator's laser model with ``values``, ``lifetime`` and ``fleeting`` reading the
    cast ranges of every frame in order, its draws from ``seed``."""
    laser = record.laser
    config = fitted_laser_config(laser, values, short_lifetime=lifetime, short_fleeting_share=fleeting)
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    things = UnmappedThings()
    out = np.empty((len(casts), angles.size), dtype=np.float32)
    grazing = config.dropout_grazing > 0.0
    for k, cast in enumerate(casts):
        scan = UnmappedScan(things, cast.laser_pose, angles, float(laser.angle_increment), float(t[k]))
        out[k] = apply_laser_errors(
            cast.ranges,
            config,
            rng,
            cast.incidence if grazing else None,
            scan if lifetime > 0.0 else None,
            nearer=cast.nearer,
        )
    return out


def _candidates(
    grid: NDArray[np.float64], fleeting_grid: NDArray[np.float64], model: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Every interpolated candidate: lifetimes ``[C]`` (s), fleeting shares ``[C]``, curves ``[C, L]``."""
    a = np.arange(_STEPS, dtype=np.float64) / _STEPS
    taus, along = [], []  # along the lifetime, for every fleeting share at once: [F, n, L] pieces
    for i in range(grid.size - 1):
        low, high = grid[i], grid[i + 1]
        # stablemath, not numpy's power: the same bits on every CPU (numpy's differs with AVX-512)
        taus.append(low + (high - low) * a if low == 0.0 else low * stablemath.power(high / low, a))
        along.append((1.0 - a)[None, :, None] * model[:, i, None, :] + a[None, :, None] * model[:, i + 1, None, :])
    taus.append(grid[-1:])
    along.append(model[:, -1:, :])
    tau, by_tau = np.concatenate(taus), np.concatenate(along, axis=1)  # [n], [F, n, L]
    b = np.arange(_SHARE_STEPS, dtype=np.float64) / _SHARE_STEPS
    shares, curves = [], []
    for i in range(fleeting_grid.size - 1):
        shares.append(fleeting_grid[i] + (fleeting_grid[i + 1] - fleeting_grid[i]) * b)
        curves.append((1.0 - b)[:, None, None] * by_tau[i][None] + b[:, None, None] * by_tau[i + 1][None])
    shares.append(fleeting_grid[-1:])
    curves.append(by_tau[-1:])
    share = np.concatenate(shares)  # [m]
    curve = np.concatenate(curves)  # [m, n, L]
    return (
        np.broadcast_to(tau[None, :], curve.shape[:2]).ravel(),
        np.broadcast_to(share[:, None], curve.shape[:2]).ravel(),
        curve.reshape(-1, curve.shape[2]),
    )


def _best(real: NDArray[np.float64], curves: NDArray[np.float64]) -> int:
    """Index of the candidate curve ``[C, L]`` nearest ``real`` ``[L]`` in squares (the first of equal ones)."""
    return int(np.argmin(np.sum((curves - real[None, :]) ** 2, axis=1)))


def fit_lifetime(
    record: RunRecord, reference: Reference, laser: LaserFit, settings: CalibrationSettings, *, seed: int
) -> LifetimeFit | None:
    """Fit ``short_lifetime`` and ``short_fleeting_share`` (module docstring); None when the log's base frames hold fewer than
    ``lifetime_min_short`` short readings or the log is shorter than its longest lag."""
    step = float(np.median(np.diff(record.t)))
    lags = np.unique(np.maximum(np.rint(np.asarray(settings.lifetime_lags) / step).astype(np.int64), 1))
    frames = len(record)
    usable = frames - int(lags[-1])
    if usable < 1:
        return None
    base = np.arange(0, usable, max(1, math.ceil(usable / settings.lifetime_base_frames)), dtype=np.int64)
    caster = FrameCaster(record, reference, settings.edge_reach)
    casts = [caster.cast(k) for k in range(frames)]
    below = [laser.short_below(c.ranges.astype(np.float64), settings.short_sigmas) for c in casts]
    limit = float(record.laser.range_max)
    radius = settings.persistence_radius
    angles = caster.angles
    real = _Counts.of(record.scans, casts, below, base, lags, angles, limit, radius)
    if int(real.short.sum()) < settings.lifetime_min_short:
        return None
    values = model_laser_values(laser)
    grid = np.array([0.0, *settings.lifetime_grid])
    fleeting_grid = np.asarray(settings.fleeting_grid, dtype=np.float64)
    t = np.asarray(record.t, dtype=np.float64)

    def counts(tau: float, share: float) -> _Counts:
        readings = _replay(casts, t, values, tau, share, record, angles, seed)
        return _Counts.of(readings, casts, below, base, lags, angles, limit, radius)

    drawn_anew = counts(0.0, 0.0)
    model = [[drawn_anew] + [counts(float(life), float(g)) for life in grid[1:]] for g in fleeting_grid]
    curves = np.array([[m.curve() for m in row] for row in model])
    tau, share, candidates = _candidates(grid, fleeting_grid, curves)
    best = _best(real.curve(), candidates)
    rng = np.random.default_rng(np.random.SeedSequence([seed, grid.size]))
    blocks = base // settings.block_frames
    starts = np.searchsorted(blocks, np.arange(int(blocks[-1]) + 1), side="left")
    ends = np.searchsorted(blocks, np.arange(int(blocks[-1]) + 1), side="right")
    draws = []
    for _ in range(settings.bootstrap):
        chosen = rng.integers(0, starts.size, size=starts.size)
        index = np.concatenate([np.arange(starts[b], ends[b]) for b in chosen])
        again = _candidates(grid, fleeting_grid, np.array([[m.curve(index) for m in row] for row in model]))[2]
        pick = _best(real.curve(index), again)
        draws.append((tau[pick], share[pick]))
    spread = np.std(np.array(draws), axis=0, ddof=1) if len(draws) > 1 else np.full(2, math.nan)
    return LifetimeFit(
        lifetime=float(tau[best]),
        stderr=float(spread[0]),
        fleeting=float(share[best]),
        fleeting_stderr=float(spread[1]),
        lags=lags,
        lag_seconds=lags * step,
        real=real.curve(),
        grid=grid,
        fleeting_grid=fleeting_grid,
        model=curves,
        fitted=candidates[best],
        short_readings=int(real.short.sum()),
        base_frames=int(base.size),
        at_bound=float(tau[best]) >= float(grid[-1]),
    )
