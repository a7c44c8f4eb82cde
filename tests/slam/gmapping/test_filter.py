"""The filter's per-reading rules (spec/gmapping.md, section 1) on short synthetic runs in a box room.

* a reading is processed on the first reading and when the odometry travel since the last processed
  one reaches linearUpdate, or the turn reaches angularUpdate, or (when temporalUpdate >= 0) more than
  temporalUpdate seconds passed;
* the first reading is only registered (no matching): every particle sits on the first odometry pose
  (composed with the laser mount: the filter tracks the laser);
* only beams with a return inside maxUrange and maxRange are registered into the particle maps;
* ``trajectory()`` holds one pose per reading, the processed ones from the best particle's path and
  the others carried by odometry from the processed reading nearest in time.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from slamtrials.geometry import compose, compose1, ominus
from slamtrials.record import Frame, LaserGeometry
from slamtrials.slam import make_algorithm

BEAMS = 181
LASER = LaserGeometry.from_dict(
    {
        "angle_min": -math.pi / 2,
        "angle_increment": math.pi / (BEAMS - 1),
        "range_min": 0.02,
        "range_max": 10.0,
        "mount": [0.0, 0.0, 0.0],
    }
)
HALF_X, HALF_Y = 4.0, 3.0


def box_scan(laser_pose: np.ndarray, laser: dict = LASER) -> np.ndarray:
    x, y, theta = laser_pose
    heading = theta + laser.angle_min + laser.angle_increment * np.arange(BEAMS)
    c, s = np.cos(heading), np.sin(heading)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (HALF_X - x) / c, (-HALF_X - x) / c)
        ty = np.where(s > 0, (HALF_Y - y) / s, (-HALF_Y - y) / s)
    return np.minimum(np.minimum(np.abs(tx), np.abs(ty)), laser.range_max).astype(np.float32)


def run(odometry: np.ndarray, times: np.ndarray, *, laser: dict = LASER, seed: int = 0, **overrides):
    """Feed frames (perfect odometry, ranges of the box) and return the algorithm and the readings at
    which ``updates`` went up."""
    algorithm = make_algorithm("gmapping", laser, overrides={"particles": 5, **overrides})
    algorithm.reset(np.random.default_rng(seed))
    processed = []
    mount = np.asarray(laser.mount, dtype=np.float64)
    for k, (t, pose) in enumerate(zip(times, odometry)):
        before = algorithm.updates
        algorithm.process(Frame(t=float(t), ranges=box_scan(compose1(pose, mount), laser), odometry=pose, truth=pose))
        if algorithm.updates > before:
            processed.append(k)
    return algorithm, processed


def expected_updates(
    odometry: np.ndarray, times: np.ndarray, linear: float, angular: float, temporal: float
) -> list[int]:
    """The spec's rule, written out."""
    out = [0]
    moved = turned = 0.0
    last_t = times[0]
    for k in range(1, len(odometry)):
        d = odometry[k] - odometry[k - 1]
        moved += math.hypot(d[0], d[1])
        turned += abs(math.remainder(d[2], 2 * math.pi))
        if moved >= linear or turned >= angular or (temporal >= 0 and times[k] - last_t > temporal):
            out.append(k)
            moved = turned = 0.0
            last_t = times[k]
    return out


def test_linear_update_threshold():
    n = 14
    odometry = np.column_stack([-2.0 + 0.3 * np.arange(n), np.zeros(n), np.zeros(n)])
    times = 0.1 * np.arange(n)
    algorithm, processed = run(odometry, times, linearUpdate=1.0)
    assert processed == expected_updates(odometry, times, 1.0, 0.5, -1.0)
    assert processed == [0, 4, 8, 12]  # 0.3 m steps: 1.2 m >= 1 m every 4th reading
    assert len(algorithm.lineage) == len(processed)


def test_angular_update_threshold():
    n = 10
    odometry = np.column_stack([np.zeros(n), np.zeros(n), 0.2 * np.arange(n)])
    times = 0.1 * np.arange(n)
    _, processed = run(odometry, times, angularUpdate=0.5)
    assert processed == expected_updates(odometry, times, 1.0, 0.5, -1.0)
    assert processed == [0, 3, 6, 9]


def test_temporal_update_when_standing_still():
    n = 10
    odometry = np.zeros((n, 3))
    times = 0.1 * np.arange(n)
    _, still = run(odometry, times)
    assert still == [0]  # temporalUpdate off: standing still processes only the first reading
    _, processed = run(odometry, times, temporalUpdate=0.25)
    assert processed == expected_updates(odometry, times, 1.0, 0.5, 0.25)
    assert processed == [0, 3, 6, 9]


def test_first_reading_places_every_particle_on_the_first_odometry_pose_and_only_registers():
    """With a laser mount, the particles (laser poses) start at odometry (+) mount; the estimate returned
    is the base pose; nothing is matched (all log weights 0)."""
    laser = dataclasses.replace(LASER, mount=(0.2, -0.05, 0.1))
    start = np.array([0.5, -0.4, 0.3])
    algorithm = make_algorithm("gmapping", laser, overrides={"particles": 4})
    algorithm.reset(np.random.default_rng(0))
    estimate = algorithm.process(
        Frame(t=0.0, ranges=box_scan(compose1(start, np.array(laser.mount)), laser), odometry=start, truth=start)
    )
    np.testing.assert_allclose(estimate, start, atol=1e-12)
    np.testing.assert_allclose(algorithm.poses, np.tile(compose1(start, np.array(laser.mount)), (4, 1)), atol=1e-12)
    assert algorithm.updates == 1 and np.all(algorithm.log_weights == 0.0) and algorithm.resamplings == 0


def total_endpoints(algorithm, particle: int) -> int:
    directory = algorithm.maps.directories[particle]
    tiles = directory[directory >= 0]
    return int(algorithm.maps.count[tiles].sum())


def test_only_usable_returns_are_registered():
    """NaN, 0, below range_min, no-return (range_max) and beyond maxUrange readings are left out."""
    algorithm = make_algorithm("gmapping", LASER, overrides={"particles": 3, "maxUrange": 4.0})
    algorithm.reset(np.random.default_rng(0))
    ranges = box_scan(np.zeros(3))
    ranges[:10] = np.nan
    ranges[10:15] = 0.0
    ranges[15:18] = 0.01  # below range_min
    ranges[18:25] = LASER.range_max
    usable = (ranges > LASER.range_min) & (ranges < LASER.range_max) & (ranges <= 4.0)
    assert 50 < usable.sum() < BEAMS - 25  # some box walls are beyond 4 m
    algorithm.process(Frame(t=0.0, ranges=ranges, odometry=np.zeros(3), truth=np.zeros(3)))
    for p in range(3):
        assert total_endpoints(algorithm, p) == int(usable.sum())


def test_lskip_thins_matching_but_not_registration():
    """lskip chooses the beams the matcher and likelihood use; registerScan in the original adds every
    usable beam to the particle's map (spec: only zero/NaN/too-long beams are not registered)."""
    algorithm = make_algorithm("gmapping", LASER, overrides={"particles": 2, "lskip": 1})
    algorithm.reset(np.random.default_rng(0))
    ranges = box_scan(np.zeros(3))
    algorithm.process(Frame(t=0.0, ranges=ranges, odometry=np.zeros(3), truth=np.zeros(3)))
    assert total_endpoints(algorithm, 0) == BEAMS


def test_trajectory_has_one_pose_per_reading_carried_by_odometry_from_the_nearest_processed_one():
    n = 14
    odometry = np.column_stack([-2.0 + 0.3 * np.arange(n), 0.02 * np.arange(n), 0.01 * np.arange(n)])
    times = 0.1 * np.arange(n)
    algorithm, processed = run(odometry, times, linearUpdate=1.0)
    trajectory = algorithm.trajectory()
    np.testing.assert_array_equal(trajectory.t, times)
    path = algorithm.lineage.path(algorithm.best_particle)  # laser poses; the mount is 0 here
    np.testing.assert_allclose(trajectory.poses[processed], path, atol=1e-12)
    for k in range(n):
        before = max(j for j in processed if j <= k)
        after = min((j for j in processed if j > k), default=before)
        anchor = after if times[after] - times[k] < times[k] - times[before] else before
        expected = compose(trajectory.poses[anchor], ominus(odometry[anchor], odometry[k]))
        np.testing.assert_allclose(trajectory.poses[k], expected, atol=1e-9)
    # perfect odometry in a box: the matcher keeps the estimate on the true path (within a few cm)
    assert np.max(np.hypot(*(trajectory.poses[:, :2] - odometry[:, :2]).T)) < 0.05
