"""Things not in the map that stay where a scan saw them: short readings that persist (``short_lifetime``).

Why. In a real log what reads short is mostly something that stays put for seconds (a person standing,
a chair, a door left open): of the short readings of one scan of the shared logs, 49 to 64 % have a
short reading of the next scan within 0.15 m of their end point, and 21 to 30 % of the scan ten later
(docs/realism.md, "Assumptions"). SLAM can match such a thing like any wall. Short readings drawn anew
for every scan are things that jump about, which only hurt.

What. With ``short_lifetime`` ``> 0`` a run of short readings (:mod:`slamtrials.sim.laser_errors`, item
3: one thing at one distance ``d``) leaves a thing in the world: the chord at distance ``d`` across the
run's beams (from half a beam before its first to half a beam after its last), in world coordinates,
with a lifetime drawn from an exponential distribution of mean ``short_lifetime`` seconds, unless the
run is one of the ``short_fleeting_share`` that leave nothing (things that move on at once). Every later
scan casts its beams against the things still alive; a beam that meets one before its wall (and not
within ``min_range``) reads the distance to it, with neither noise nor dropout (as a short reading).
New runs are then drawn along the scan as before on the beams no thing covers, at the rate that makes
each beam read short with its chance (``short_rate``, or the chance by range of
:mod:`slamtrials.sim.shortrate`) on average whatever the covered share (``(chance - covered) / (1 -
covered)``, at least 0, the covered share counted among beams of about the same chance: :func:`_fresh_rates`),
so ``short_rate`` keeps its meaning and the calibration's value. Things never stop the robot (they are in the laser's world only).

Draws: as without lifetime, then ``B`` more uniforms per scan (each beam's lifetime, used only by the
first beam of a new run), whatever the beams hit. The one uniform ``u`` of a run decides both: below
``short_fleeting_share`` ``g`` the run leaves nothing, else its thing lives ``-short_lifetime log((1 - u) /
(1 - g))`` seconds (the exponential, as ``(u - g) / (1 - g)`` is uniform given ``u >= g``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from slamtrials.sim.config import start_chances
from slamtrials.sim.shortdistance import short_distance

__all__ = ["UnmappedThings", "UnmappedScan"]


@njit(cache=True, fastmath=False, nogil=True)
def _cast_at_things(segments, ox, oy, heading, first_angle, increment, true_r, min_range, out):  # pragma: no cover
    """Shortest distance ``out[b]`` along beam ``b`` to a segment ``[S, 4]`` (x1, y1, x2, y2, world frame) that
    is nearer than ``true_r[b]`` and not within ``min_range``; ``inf`` where none is."""
    beams = out.shape[0]
    for b in range(beams):
        out[b] = math.inf
    for s in range(segments.shape[0]):
        x1, y1, x2, y2 = segments[s, 0], segments[s, 1], segments[s, 2], segments[s, 3]
        b1 = math.atan2(y1 - oy, x1 - ox) - heading
        b2 = math.atan2(y2 - oy, x2 - ox) - heading
        b1 = (b1 + math.pi) % (2.0 * math.pi) - math.pi
        b2 = (b2 + math.pi) % (2.0 * math.pi) - math.pi
        lo, hi = min(b1, b2), max(b1, b2)
        # the beams between the end points' bearings: [lo, hi], or [hi, pi) and [-pi, lo] across the back
        for part in range(2):
            if hi - lo <= math.pi:
                if part == 1:
                    break
                start, stop = lo, hi
            elif part == 0:
                start, stop = hi, math.pi
            else:
                start, stop = -math.pi, lo
            k0 = max(int(math.ceil((start - first_angle) / increment - 1e-9)), 0)
            k1 = min(int(math.floor((stop - first_angle) / increment + 1e-9)), beams - 1)
            ex, ey = x2 - x1, y2 - y1
            for k in range(k0, k1 + 1):
                a = heading + first_angle + k * increment
                c, sn = math.cos(a), math.sin(a)
                denominator = c * ey - sn * ex
                if denominator == 0.0:
                    continue
                px, py = x1 - ox, y1 - oy
                t = (px * ey - py * ex) / denominator
                u = (px * sn - py * c) / denominator
                if 0.0 <= u <= 1.0 and min_range <= t < true_r[k] and t < out[k]:
                    out[k] = t


@njit(cache=True, fastmath=False, nogil=True)
def _new_runs(
    whether,
    where,
    life,
    r,
    reading,
    covered,
    rate,
    stay,
    start,
    min_range,
    lifetime,
    fleeting,
    power,
    t,
    ox,
    oy,
    heading,
    angles,
    half,
):  # pragma: no cover - compiled
    """The chain of :func:`slamtrials.sim.laser_errors._short_runs` on the beams no thing covers (a covered
    beam ends a run); writes the new short readings into ``reading`` and returns the new things:
    float64 ``[K, 4]`` chords and ``[K]`` times of death."""
    beams = r.shape[0]
    segments = np.empty((beams, 4))
    deaths = np.empty(beams)
    count = 0
    short = False
    distance = 0.0
    first = 0
    for b in range(beams + 1):
        now = False
        if b < beams and not covered[b]:
            chance = rate[b] if (b == 0 or covered[b - 1]) and not short else (stay[b] if short else start[b])
            now = whether[b] < chance
        if now and not short:
            distance = short_distance(where[b], r[b], min_range, power)
            first = b
        if short and not now and life[first] >= fleeting:  # the run first .. b - 1 ends: it leaves a thing
            a1 = heading + angles[first] - half
            a2 = heading + angles[b - 1] + half
            segments[count, 0] = ox + distance * math.cos(a1)
            segments[count, 1] = oy + distance * math.sin(a1)
            segments[count, 2] = ox + distance * math.cos(a2)
            segments[count, 3] = oy + distance * math.sin(a2)
            deaths[count] = t - lifetime * math.log(1.0 - (life[first] - fleeting) / (1.0 - fleeting))
            count += 1
        short = now
        if short and distance < r[b]:
            reading[b] = distance
    return segments[:count].copy(), deaths[:count].copy()


#: Classes of beams by their chance of reading short, within which the covered share is counted.
CHANCE_CLASSES = 8


def _fresh_rates(chances: NDArray[np.float64], covered: NDArray[np.bool_]) -> NDArray[np.float64]:
    """float64 ``[B]``: the chance of a new short reading on a beam no thing covers, such that each beam reads
    short with its ``chances`` ``[B]`` on average, given which beams things cover (``covered`` ``[B]``).

    With one chance ``p`` for every beam it is ``(p - c) / (1 - c)`` (at least 0), ``c`` the covered share
    of the scan. When the chance varies with the range, things stand where beams are likely to read short
    (far walls), so ``c`` is counted among beams of about the same chance: in :data:`CHANCE_CLASSES`
    classes of equal width from 0 to the largest chance.
    """
    share = float(np.count_nonzero(covered)) / max(chances.shape[0], 1)
    if chances.size == 0 or bool(np.all(chances == chances[0])):
        if share >= 1.0:
            return np.zeros_like(chances)
        return np.maximum(0.0, (chances - share) / (1.0 - share))
    top = float(np.max(chances))
    classes = np.minimum((chances * (CHANCE_CLASSES / top)).astype(np.int64), CHANCE_CLASSES - 1)
    beams = np.bincount(classes, minlength=CHANCE_CLASSES).astype(np.float64)
    hit = np.bincount(classes, weights=covered.astype(np.float64), minlength=CHANCE_CLASSES)
    cover = (hit / np.maximum(beams, 1.0))[classes]
    out = np.zeros_like(chances)
    open_ = cover < 1.0
    out[open_] = np.maximum(0.0, (chances[open_] - cover[open_]) / (1.0 - cover[open_]))
    return out


class UnmappedThings:
    """The things not in the map that are alive, in the world frame (see the module docstring)."""

    def __init__(self) -> None:
        self.segments = np.zeros((0, 4))  # float64 [S, 4]: x1, y1, x2, y2 (m, world frame)
        self.deaths = np.zeros(0)  # float64 [S]: time (s) each stops existing

    def __len__(self) -> int:
        return int(self.segments.shape[0])

    def apply(
        self,
        scan: UnmappedScan,
        true_ranges: NDArray[np.float64],
        reading: NDArray[np.float64],
        whether: NDArray[np.float64],
        where: NDArray[np.float64],
        life: NDArray[np.float64],
        short_rates: NDArray[np.float64],
        run_beams: float,
        min_range: float,
        lifetime: float,
        fleeting: float = 0.0,
        position_power: float = 0.0,
    ) -> NDArray[np.float64]:
        """The readings float64 ``[B]`` (m) with the things alive at ``scan.t`` and the new ones of this scan.

        ``true_ranges`` ``[B]`` the cast ranges (m), ``reading`` ``[B]`` the readings after noise and dropout
        (not changed), ``whether``, ``where``, ``life`` ``[B]`` uniforms in [0, 1); ``short_rates`` ``[B]`` each
        beam's chance of reading short (:mod:`slamtrials.sim.shortrate`); ``fleeting`` the share of new runs
        that leave no thing; ``position_power`` where the new things stand along their beams
        (:mod:`slamtrials.sim.shortdistance`).
        """
        alive = self.deaths > scan.t
        self.segments, self.deaths = self.segments[alive], self.deaths[alive]
        ox, oy, heading = (float(v) for v in scan.laser_pose)
        angles = np.ascontiguousarray(scan.angles, dtype=np.float64)
        at_thing = np.empty(angles.shape[0])
        _cast_at_things(
            self.segments, ox, oy, heading, float(angles[0]), scan.increment, true_ranges, min_range, at_thing
        )
        covered = at_thing < np.inf
        out = np.where(covered, at_thing, reading)
        rate = _fresh_rates(short_rates, covered)
        if run_beams >= 1.0:
            rate = np.minimum(rate, run_beams / (run_beams + 1.0))  # the most a chain of such runs can make short
            stay = np.full(rate.shape, 1.0 - 1.0 / run_beams)
            start = start_chances(rate, run_beams)
        else:
            stay = start = rate
        segments, deaths = _new_runs(
            whether,
            where,
            life,
            true_ranges,
            out,
            covered,
            rate,
            stay,
            start,
            min_range,
            lifetime,
            fleeting,
            position_power,
            float(scan.t),
            ox,
            oy,
            heading,
            angles,
            0.5 * scan.increment,
        )
        self.segments = np.concatenate([self.segments, segments])
        self.deaths = np.concatenate([self.deaths, deaths])
        return out


@dataclass(frozen=True, eq=False)
class UnmappedScan:
    """Where and when one scan is taken, for :class:`UnmappedThings`.

    Attributes
    ----------
    things:
        The run's things (state kept across scans).
    laser_pose:
        float64 ``[3]`` the laser's pose in the world frame (m, m, rad).
    angles:
        float64 ``[B]`` beam angles in the laser frame (rad), evenly spaced by ``increment``.
    increment:
        Angle between neighbouring beams (rad).
    t:
        Time of the scan (s).
    """

    things: UnmappedThings
    laser_pose: NDArray[np.float64]
    angles: NDArray[np.float64]
    increment: float
    t: float
