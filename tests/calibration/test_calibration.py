"""The calibration recovers known error-model values from a simulated recording (the truth as reference),
turns them into a valid profile, and refuses logs it cannot calibrate from."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.calibration import CalibrationSettings, Reference, calibrate, check_calibratable
from slamtrials.calibration.odometry import anchor_frames, fit_odometry, step_motion
from slamtrials.calibration.stats import central_sigma, nonnegative_least_squares, shortest_interval
from slamtrials.campaign.profilefile import read_profile, write_profile
from slamtrials.errors import CalibrationError
from slamtrials.sim.config import LaserConfig, OdometryConfig, SimConfig
from slamtrials.sim.tour import tour_waypoints
from slamtrials.sim.waypoints import simulate_waypoints
from slamtrials.worlds import load_world

#: The known values: every laser and odometry error model on, at sizes unlike each other.
LASER = {
    "range_noise_std": 0.02,
    "range_noise_per_m": 0.01,
    "short_rate": 0.2,
    "short_range_scale": 2.5,
    "short_range_shape": 1.5,
    "short_run_beams": 3.0,
    "short_position_power": 1.5,
    "dropout_rate": 0.02,
    "dropout_per_m": 0.004,
    "dropout_grazing": 0.1,
}
#: The edge model's reach (rad): a setting of the calibration (its default, 1 degree), written into the profile.
EDGE_REACH = CalibrationSettings().edge_reach
#: The odometry noise is a random walk per metre and per radian (m/sqrt(m), rad/sqrt(rad), m/sqrt(rad),
#: rad/sqrt(m)): the values before issue 32 (0.05 m/m, 0.1 rad/rad, 0.01 m/rad, 0.02 rad/m per 0.1 s step)
#: carried over to this tour's steps (0.055 m and 0.03 rad on average), rounded.
ODOMETRY = {
    "bias_linear": 0.03,
    "bias_angular": -0.08,
    "noise_linear_per_m": 0.012,
    "noise_angular_per_rad": 0.02,
    "noise_linear_per_rad": 0.006,
    "noise_angular_per_m": 0.005,
}


@pytest.fixture(scope="module")
def simulated():
    world = load_world("office_small_01")
    config = SimConfig(profile="paper", laser=LaserConfig(**LASER), odometry=OdometryConfig(**ODOMETRY))
    record = simulate_waypoints(world, tour_waypoints(world, num_goals=6), config, seed=5, max_time=600)
    assert record.metadata["outcome"] == "completed"
    return world, record


@pytest.fixture(scope="module")
def fitted(simulated):
    world, record = simulated
    reference = Reference.from_world(record.truth, world, "simulation truth")
    return calibrate(record, reference, CalibrationSettings(bootstrap=30), seed=1)


@pytest.mark.slow
@pytest.mark.parametrize("name", [*LASER, *ODOMETRY])
def test_fit_recovers_each_known_value_within_its_stated_uncertainty(fitted, name):
    value = fitted.value(name)
    truth = {**LASER, **ODOMETRY}[name]
    # the stated uncertainty is one bootstrap standard error; the 95 % interval is two. The one known bias:
    # short readings that stand within the noise's core at the wall (more of them the larger the position
    # power, and on the long beams, where most of them are) widen the core a little, which the fit cannot
    # tell from noise (here +1 to +2.5 %; docs/realism.md)
    bias = 0.025 * truth if name in ("range_noise_std", "range_noise_per_m") else 0.0
    # The odometry's scale biases: their block-bootstrap error is about half their spread over seeds (12
    # seeds of this tour, issue 32: bias_angular spreads 0.0035 rad/rad where the bootstrap says 0.0018;
    # a few long turns decide the slope, and resampling blocks does not vary them enough), so they are
    # held to twice their stated error (docs/realism.md, "Calibration")
    stated = value.stderr * (2.0 if name.startswith("bias_") else 1.0)
    assert abs(value.value - truth) <= 2.0 * stated + bias, (value, truth)
    # and it is an uncertainty worth stating: well below the value itself
    assert 0.0 < value.stderr < 0.25 * abs(truth), value


@pytest.mark.slow
def test_without_edge_readings_the_fit_finds_next_to_none(fitted):
    # the short readings that land at a nearer wall are expected by the short-reading model and taken off
    edge = fitted.value("edge_chance")
    assert edge.value < 0.01 and edge.value <= 2.0 * edge.stderr + 0.002, edge
    assert fitted.value("edge_reach").value == EDGE_REACH
    assert fitted.profile("p", "").laser["edge_reach"] == EDGE_REACH


@pytest.mark.slow
@pytest.mark.parametrize("chance", [0.25])
def test_edge_chance_is_recovered_and_its_readings_are_not_counted_short(chance):
    world = load_world("office_small_01")
    laser = {"range_noise_std": 0.02, "short_rate": 0.1, "short_run_beams": 3.0, "dropout_rate": 0.02}
    config = SimConfig(profile="paper", laser=LaserConfig(**laser, edge_chance=chance, edge_reach=EDGE_REACH))
    record = simulate_waypoints(world, tour_waypoints(world, num_goals=3), config, seed=7, max_time=300)
    reference = Reference.from_world(record.truth, world, "simulation truth")
    fit = calibrate(record, reference, CalibrationSettings(bootstrap=10, min_distance=5.0), seed=2)
    edge, short = fit.value("edge_chance"), fit.value("short_rate")
    assert abs(edge.value - chance) <= 3.0 * edge.stderr, edge
    assert 0.0 < edge.stderr < 0.1 * chance
    # the short readings of the far wall that land at the nearer wall are the edge fit's: a few per cent of them
    assert 0.95 * 0.1 - 2.0 * short.stderr <= short.value <= 0.1 + 2.0 * short.stderr, short


@pytest.mark.slow
def test_fit_reports_the_residual_figures_of_the_simulated_laser(fitted):
    laser = fitted.laser
    assert laser.beams > 100_000
    # the no-return share is the dropout model's average, less the short readings that replace it
    assert 0.02 < laser.no_return_share < 0.08
    assert laser.bins.sigma[0] < laser.bins.sigma[-1]  # noise grows with range
    # the map is the true world and the path the true one: no offset, no error of the reference
    assert np.all(np.abs(laser.bins.centre) < 0.01)
    assert fitted.odometry.reference_linear < 1e-4 and fitted.odometry.reference_angular < 1e-4


@pytest.mark.slow
def test_profile_holds_the_fit_with_symmetric_bias_ranges_and_round_trips(fitted, tmp_path):
    profile = fitted.profile("sim-test", "fitted to a simulated tour")
    lin, ang = abs(fitted.value("bias_linear").value), abs(fitted.value("bias_angular").value)
    assert profile.odometry["bias_linear_range"] == pytest.approx((-lin, lin))
    assert profile.odometry["bias_angular_range"] == pytest.approx((-ang, ang))
    assert profile.laser["range_noise_std"] == pytest.approx(fitted.value("range_noise_std").value)
    assert "slip_per_m" not in profile.odometry
    write_profile(tmp_path / "p.yaml", profile, header="test")
    assert read_profile(tmp_path / "p.yaml") == profile
    config = SimConfig(profile=profile)  # a simulator takes it
    assert config.laser.short_rate == pytest.approx(fitted.value("short_rate").value)


def test_anchor_frames_skip_frames_the_reference_carries_by_odometry(simulated):
    _, record = simulated
    reference = record.truth.copy()
    # a SLAM-like reference: between updates every 5 frames, it moves with the odometry
    for k in range(1, len(record)):
        if k % 5:
            from slamtrials.geometry import compose, ominus

            reference[k] = compose(reference[k - 1], ominus(record.odometry[k - 1], record.odometry[k]))
    anchors = anchor_frames(reference, record.odometry)
    assert anchors[0] == 0
    assert set(anchors[1:].tolist()) <= set(range(0, len(record), 5))
    steps = step_motion(reference, record.odometry)
    carried = np.setdiff1d(np.arange(1, len(record)), anchors)
    np.testing.assert_allclose(steps.odo_turn[carried - 1], steps.turn[carried - 1], atol=1e-9)


def test_too_short_or_motionless_logs_are_refused(simulated):
    _, record = simulated
    from dataclasses import replace

    short = replace(
        record,
        t=record.t[:50],
        scans=record.scans[:50],
        odometry=record.odometry[:50],
        truth=record.truth[:50],
        stalled=record.stalled[:50],
    )
    with pytest.raises(CalibrationError, match="at least 200"):
        check_calibratable(short, min_frames=200, min_distance=10.0, min_rotation=6.3)
    still = replace(record, odometry=np.zeros_like(record.odometry))
    with pytest.raises(CalibrationError, match="no odometry"):
        check_calibratable(still, min_frames=200, min_distance=10.0, min_rotation=6.3)


def test_robust_estimators_find_the_gaussian_core_among_one_sided_outliers():
    rng = np.random.default_rng(0)
    core = rng.normal(0.03, 0.05, 4000)
    outliers = -rng.uniform(0.0, 8.0, 6000)  # 60 % short readings: the median and the MAD are lost
    values = np.concatenate([core, outliers])
    centre, sigma = shortest_interval(values)
    assert abs(centre - 0.03) < 0.02 and 0.02 < sigma < 0.2  # a start: wide when the core is under half
    centre, sigma, _ = central_sigma(values)
    assert centre == pytest.approx(0.03, abs=0.01)
    assert sigma == pytest.approx(0.05, rel=0.1)


def test_nonnegative_least_squares_drops_a_column_that_would_go_negative():
    x = np.linspace(0.0, 1.0, 50)
    y = 2.0 + 0.0 * x - 0.3 * x  # the unconstrained slope is negative
    a, b = nonnegative_least_squares([np.ones_like(x), x], y)
    assert b == 0.0 and a == pytest.approx(float(np.mean(y)))


def _reversed_spans(record, spans):
    """The record's odometry with the translation of every step inside ``spans`` negated (reversing logged
    as driving forward, or the other way round, as in fr079), composed from the first pose."""
    from slamtrials.geometry import compose1, ominus1

    odometry = record.odometry
    flipped = np.empty_like(odometry)
    flipped[0] = odometry[0]
    for k in range(1, len(record)):
        step = ominus1(odometry[k - 1], odometry[k])
        if any(a <= k < b for a, b in spans):
            step = np.array([-step[0], -step[1], step[2]])
        flipped[k] = compose1(flipped[k - 1], step)
    return flipped


@pytest.mark.slow
def test_odometry_that_moves_against_the_reference_is_left_out_not_fitted_as_noise(simulated, fitted):
    _, record = simulated
    spans = [(int(a), int(a) + 25) for a in np.linspace(50, len(record) - 80, 6)]
    defect = _reversed_spans(record, spans)
    steps = step_motion(record.truth, defect)
    anchors = anchor_frames(record.truth, defect)
    log_step = float(np.median(np.diff(record.t)))
    kept = fit_odometry(steps, anchors, CalibrationSettings(), log_step)
    assert kept is not None
    moving = np.abs(step_motion(record.truth, record.odometry).length) >= 0.02
    inside = np.zeros(len(record) - 1, dtype=bool)
    for a, b in spans:
        inside[a - 1 : b - 1] = True
    assert kept.conflicts == np.count_nonzero(moving & inside) > 60
    for name in ("noise_linear_per_m", "noise_linear_per_rad", "noise_angular_per_rad", "noise_angular_per_m"):
        clean = fitted.value(name)
        assert abs(kept.values[name] - clean.value) <= 2.0 * clean.stderr, (name, kept.values[name], clean)
    # the same defect fitted as noise: the linear noise grows many times
    absorbed = fit_odometry(steps, anchors, CalibrationSettings(direction_min_step=1.0), log_step)
    assert absorbed is not None and absorbed.conflicts == 0
    assert absorbed.values["noise_linear_per_m"] + absorbed.values["noise_linear_per_rad"] > 3.0 * (
        kept.values["noise_linear_per_m"] + kept.values["noise_linear_per_rad"]
    )


@pytest.mark.slow
def test_long_readings_are_counted_apart_and_none_come_from_the_simulated_laser(fitted):
    # the simulated laser reads short (objects not in the map) but never past a wall, and here the
    # reference is the truth: beyond the cut there are short readings and, tails taken out, no long ones
    laser = fitted.laser
    assert laser.short_share > 0.04
    assert laser.long_share < 0.002
