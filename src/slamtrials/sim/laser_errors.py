"""The laser's error models: range noise, short readings and dropouts, applied to the true ranges.

For a scan of ``B`` beams with true ranges ``r`` (the exact cast distances, ``max_range`` where nothing
is hit), the reading of beam ``i`` is:

0. **edges** (``edge_chance > 0``): a beam next to a wall more than 0.3 m nearer (within ``edge_reach``)
   takes that wall's range for its true range with probability ``edge_chance``
   (:mod:`slamtrials.sim.edges`); everything below then applies to the range it takes;
1. **noise** (beams that hit something): ``r + (range_noise_std + range_noise_per_m r) z``;
2. **dropout** (beams that hit something): no return (``max_range``) with probability
   ``dropout_rate + dropout_per_m r + dropout_grazing (1 - |cos incidence|)``, capped at 1; the
   incidence is the angle between the beam and the normal of the cell side it enters (walls are the
   sides of occupied cells, so the normal is along x or y);
3. **short reading** (any beam): with probability ``short_rate`` (or, with ``short_range_scale > 0``, a
   probability that rises to it with the beam's range: :mod:`slamtrials.sim.shortrate`) something not
   in the map returns the beam first; the reading is ``min_range + v (r - min_range)``, ``v = u^(1 / (a + 1))`` for ``u``
   uniform in [0, 1) and ``a = short_position_power`` (0: ``v = u``, uniform along the beam;
   :mod:`slamtrials.sim.shortdistance`), and neither noise nor dropout applies to it. With ``short_run_beams`` ``L >= 1`` the short beams come in runs
   (a Markov chain along the scan: short after a short beam with probability ``1 - 1 / L``, after
   another with :func:`~slamtrials.sim.config.start_chances`, the first beam with its own chance);
   a run is one object at the distance drawn for its first beam, ``d = min_range + v (r_first -
   min_range)``, and a beam of the run whose true range is not beyond ``d`` keeps its own reading;

4. **things that stay** (``short_lifetime > 0``): a run of short readings is a thing that stays where
   it was seen for a while, read again by later scans, unless it is one of the ``short_fleeting_share``
   that are gone by the next scan (:mod:`slamtrials.sim.unmapped`);

then clipped to ``[min_range, max_range]``. Draws, from the run's stream, in this order and only for
the models that are on: ``B`` uniforms (edges), ``B`` standard normals (noise), ``B`` uniforms (dropout), ``B`` uniforms then
``B`` uniforms (short: whether, where; the same with runs), then ``B`` uniforms (each thing's lifetime,
with ``short_lifetime > 0``). Their number never depends on what the beams hit, so a run's
stream is the same whatever the world looks like. With every rate 0 nothing is drawn (the paper's
noise-free laser).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.sim.config import LaserConfig, start_chances
from slamtrials.sim.edges import edge_ranges, nearest_neighbour_range, reach_in_beams
from slamtrials.sim.shortdistance import short_distance
from slamtrials.sim.shortrate import short_chances
from slamtrials.sim.unmapped import UnmappedScan

__all__ = ["apply_laser_errors", "incidence_cosines"]


#: Half the length (cells) of the piece of ray around a hit point that tells which cell side it crossed:
#: far above the float32 error of a range in cells (about 1e-7 relative), far below a cell.
_PROBE = 1e-3


@njit(cache=True, fastmath=False, nogil=True)
def _incidence(ox, oy, theta, angles, t, out):  # pragma: no cover - compiled
    for b in range(angles.shape[0]):
        a = theta + angles[b]
        c = math.cos(a)
        s = math.sin(a)
        u = ox + t[b] * c
        v = oy + t[b] * s
        # the side the ray crosses at the hit: a vertical one (x = integer) when the column changes
        # across the hit point, a horizontal one when the row does
        crosses_column = math.floor(u - _PROBE * c) != math.floor(u + _PROBE * c)
        crosses_row = math.floor(v - _PROBE * s) != math.floor(v + _PROBE * s)
        if crosses_column and not crosses_row:
            out[b] = abs(c)
        elif crosses_row and not crosses_column:
            out[b] = abs(s)
        else:  # a corner: the coordinate closer to an integer
            du = abs(u - math.floor(u + 0.5))
            dv = abs(v - math.floor(v + 0.5))
            out[b] = abs(c) if du <= dv else abs(s)


@njit(cache=True, fastmath=False, nogil=True)
def _short_runs(whether, where, r, reading, rate, stay, start, min_range, power):  # pragma: no cover - compiled
    short = False
    distance = 0.0
    for b in range(r.shape[0]):
        chance = rate[b] if b == 0 else (stay if short else start[b])
        now = whether[b] < chance
        if now and not short:
            distance = short_distance(where[b], r[b], min_range, power)
        short = now
        if short and distance < r[b]:
            reading[b] = distance


@njit(cache=True, fastmath=False, nogil=True)
def _short_distances(where, r, min_range, power, out):  # pragma: no cover - compiled
    for b in range(r.shape[0]):
        out[b] = short_distance(where[b], r[b], min_range, power)


def incidence_cosines(
    origin_uv: tuple[float, float], theta: float, angles: NDArray[np.float64], ranges_cells: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``|cos(incidence)|`` ``[B]`` of each beam on the cell side it hits.

    Parameters
    ----------
    origin_uv:
        The laser's position in map coordinates (cells, :func:`slamtrials.worlds.world_to_map`).
    theta:
        The laser's heading in the map frame (rad).
    angles:
        float64 ``[B]`` beam angles in the laser frame (rad).
    ranges_cells:
        float64 ``[B]`` true ranges in cells.
    """
    angles = np.ascontiguousarray(angles, dtype=np.float64)
    out = np.empty(angles.shape[0], dtype=np.float64)
    _incidence(float(origin_uv[0]), float(origin_uv[1]), float(theta), angles, np.ascontiguousarray(ranges_cells), out)
    return out


def apply_laser_errors(
    true_ranges: NDArray[np.float32],
    config: LaserConfig,
    rng: np.random.Generator,
    incidence: NDArray[np.float64] | None = None,
    unmapped: UnmappedScan | None = None,
    nearer: NDArray[np.float64] | None = None,
) -> NDArray[np.float32]:
    """The readings float32 ``[B]`` (m) for ``true_ranges`` float32 ``[B]`` (m) (see the module docstring).

    ``nearer`` (``[B]`` m): each beam's nearest neighbouring true range for the edge model; by default it is
    found in ``true_ranges`` itself, as one scan's beams in order (the calibration, whose beams are not a
    scan, gives it). ``incidence`` (``[B]`` ``|cos|``, :func:`incidence_cosines`) is needed when ``dropout_grazing > 0``;
    ``unmapped`` (the run's things not in the map, and where and when this scan is taken) when
    ``short_lifetime > 0`` (:mod:`slamtrials.sim.unmapped`).
    """
    cfg = config
    r = true_ranges.astype(np.float64)
    count = r.shape[0]
    if cfg.edge_chance > 0.0:
        uniforms = np.asarray(rng.random(count), dtype=np.float64)
        if nearer is None:
            nearer = nearest_neighbour_range(r, reach_in_beams(cfg.edge_reach, cfg.angle_increment))
        r = edge_ranges(r, nearer, uniforms, cfg.edge_chance)
    hit = r < float(np.float32(cfg.max_range))
    reading = r.copy()
    if cfg.range_noise_std > 0.0 or cfg.range_noise_per_m > 0.0:
        z = rng.standard_normal(count)
        sigma = cfg.range_noise_std + cfg.range_noise_per_m * r
        reading = np.where(hit, r + sigma * z, r)
    if cfg.dropout_rate > 0.0 or cfg.dropout_per_m > 0.0 or cfg.dropout_grazing > 0.0:
        chance = cfg.dropout_rate + cfg.dropout_per_m * r
        if cfg.dropout_grazing > 0.0:
            if incidence is None:
                raise ValueError("dropout_grazing needs the beams' incidence cosines")
            chance = chance + cfg.dropout_grazing * (1.0 - incidence)
        dropped = hit & (rng.random(count) < chance)
        reading = np.where(dropped, cfg.max_range, reading)
    if cfg.short_rate > 0.0:
        rates = short_chances(r, cfg.short_rate, cfg.short_range_scale, cfg.short_range_shape)
    if cfg.short_rate > 0.0 and cfg.short_lifetime > 0.0:
        if unmapped is None:
            raise ValueError("short_lifetime needs the scan's pose and time (an UnmappedScan)")
        draws = np.asarray(rng.random((3, count)), dtype=np.float64)  # whether, where, lifetime: B each
        reading = unmapped.things.apply(
            unmapped,
            r,
            np.asarray(reading, dtype=np.float64),
            draws[0],
            draws[1],
            draws[2],
            rates,
            cfg.short_run_beams,
            cfg.min_range,
            cfg.short_lifetime,
            cfg.short_fleeting_share,
            cfg.short_position_power,
        )
    elif cfg.short_rate > 0.0 and cfg.short_run_beams >= 1.0:
        whether = rng.random(count)
        where = rng.random(count)
        stay = 1.0 - 1.0 / cfg.short_run_beams
        reading = np.array(reading, dtype=np.float64)  # a copy: the kernel writes into it
        _short_runs(
            whether,
            where,
            r,
            reading,
            rates,
            stay,
            start_chances(rates, cfg.short_run_beams),
            cfg.min_range,
            cfg.short_position_power,
        )
    elif cfg.short_rate > 0.0:
        short = rng.random(count) < rates
        where = rng.random(count)
        if cfg.short_position_power > 0.0:
            distance = np.empty(count)
            _short_distances(where, r, cfg.min_range, cfg.short_position_power, distance)
        else:
            distance = cfg.min_range + where * np.maximum(r - cfg.min_range, 0.0)
        reading = np.where(short, distance, reading)
    return np.clip(reading, cfg.min_range, cfg.max_range).astype(np.float32)
