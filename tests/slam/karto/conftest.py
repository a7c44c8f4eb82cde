"""A synthetic world for the karto tests: a square corridor loop with landmarks, a ray caster and a
robot driving around it with drifting odometry."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from slamtrials.geometry import compose, ominus
from slamtrials.record import Frame, LaserGeometry


def _box(x0: float, y0: float, x1: float, y1: float) -> list[tuple[float, float, float, float]]:
    return [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]


def square_loop_segments() -> np.ndarray:
    """Walls ``[S, 4]`` (x0, y0, x1, y1): outer square of side 14 m, inner block of side 10 m (a 2 m
    corridor around it), with notches on the walls (none on the centre line the robot drives) so that no
    stretch of corridor looks like another."""
    walls = _box(-7, -7, 7, 7) + _box(-5, -5, 5, 5)
    features = [
        (-7.0, -3.0, -6.5, -2.4),
        (6.5, 1.0, 7.0, 1.8),
        (-2.0, 6.5, -1.2, 7.0),
        (2.5, -7.0, 3.3, -6.5),
        (-5.4, 2.0, -5.0, 2.8),
        (5.0, -3.5, 5.4, -2.5),
        (0.5, 5.0, 1.1, 5.4),
        (-3.6, -5.4, -2.6, -5.0),
        (-7.0, 4.5, -6.6, 4.8),
        (6.6, 5.0, 7.0, 5.6),
        (6.6, -6.0, 7.0, -5.4),
        (-5.6, -7.0, -5.0, -6.6),
    ]
    for box in features:
        walls += _box(*box)
    return np.array(walls, dtype=np.float64)


def raycast(pose: np.ndarray, angles: np.ndarray, segments: np.ndarray, range_max: float) -> np.ndarray:
    """Ranges ``[B]`` (float32) from laser pose ``pose`` along ``angles`` (laser frame) to the nearest wall;
    ``range_max`` where none is nearer."""
    heading = pose[2] + angles
    dx, dy = np.cos(heading)[:, None], np.sin(heading)[:, None]
    x0, y0, x1, y1 = (segments[:, k][None, :] for k in range(4))
    ex, ey = x1 - x0, y1 - y0
    qx, qy = x0 - pose[0], y0 - pose[1]
    den = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qx * ey - qy * ex) / den
        u = (qx * dy - qy * dx) / den
    hit = (np.abs(den) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
    ranges = np.where(hit, t, np.inf).min(axis=1)
    return np.minimum(ranges, range_max).astype(np.float32)


def square_path(laps: float = 1.0, step: float = 0.1, turn_step: float = 0.1) -> np.ndarray:
    """True poses ``[T, 3]`` driving counter-clockwise along the corridor's centre line (a square of side
    12 m) from (-6, -6), turning in place at the corners."""
    corners = [(-6.0, -6.0), (6.0, -6.0), (6.0, 6.0), (-6.0, 6.0)]
    poses = []
    heading = 0.0
    total_sides = int(round(4 * laps))
    for side in range(total_sides):
        (ax, ay), (bx, by) = corners[side % 4], corners[(side + 1) % 4]
        n = int(round(math.hypot(bx - ax, by - ay) / step))
        for k in range(n):
            poses.append((ax + (bx - ax) * k / n, ay + (by - ay) * k / n, heading))
        turns = int(round((math.pi / 2) / turn_step))
        for k in range(turns):
            poses.append((bx, by, heading + (math.pi / 2) * k / turns))
        heading += math.pi / 2
    poses.append((corners[total_sides % 4][0], corners[total_sides % 4][1], heading))
    out = np.array(poses)
    out[:, 2] = (out[:, 2] + math.pi) % (2 * math.pi) - math.pi
    return out


def drifting_odometry(truth: np.ndarray, *, turn_scale: float, travel_scale: float) -> np.ndarray:
    """Odometry ``[T, 3]`` that integrates the true steps with every turn scaled by ``turn_scale`` and
    every distance by ``travel_scale`` (a systematic drift), starting at the first true pose."""
    steps = ominus(truth[:-1], truth[1:])
    steps[:, :2] *= travel_scale
    steps[:, 2] *= turn_scale
    odometry = [truth[0]]
    for step in steps:
        odometry.append(compose(odometry[-1], step))
    return np.array(odometry)


LASER = LaserGeometry(angle_min=-0.75 * math.pi, angle_increment=1.5 * math.pi / 360, range_min=0.05, range_max=12.0)


@pytest.fixture(scope="session")
def square_loop() -> SimpleNamespace:
    """One lap of the corridor loop (and a bit more, so the robot drives back over its start): the
    laser, true poses, drifting odometry and the frames."""
    segments = square_loop_segments()
    truth = square_path(laps=1.25)
    odometry = drifting_odometry(truth, turn_scale=1.03, travel_scale=1.02)
    angles = LASER.beam_angles(361)
    frames = [
        Frame(
            t=0.25 * k,
            ranges=raycast(truth[k], angles, segments, LASER.range_max),
            odometry=odometry[k],
            truth=truth[k],
        )
        for k in range(truth.shape[0])
    ]
    return SimpleNamespace(laser=LASER, segments=segments, truth=truth, odometry=odometry, frames=frames, angles=angles)


@pytest.fixture(scope="session")
def synthetic() -> SimpleNamespace:
    """The synthetic world's pieces: walls, laser, ray caster."""
    return SimpleNamespace(segments=square_loop_segments(), laser=LASER, raycast=raycast)
