"""The SLAM registry: lookup, presets, validation messages, entry points, and a user-written algorithm."""

from __future__ import annotations

from importlib.metadata import EntryPoint

import numpy as np
import pytest
from pydantic import BaseModel, Field

import slamtrials.slam.base as base
from slamtrials.errors import ConfigError
from slamtrials.record import Frame, LaserGeometry, RunRecord, Trajectory
from slamtrials.slam import (
    ALGORITHMS,
    OccupancyGrid,
    OdometrySlam,
    SlamAlgorithm,
    get_algorithm,
    make_algorithm,
    register_algorithm,
)
from slamtrials.slamrun import run_slam

LASER = LaserGeometry.from_dict(
    {"angle_min": -1.0, "angle_increment": 0.5, "range_min": 0.0, "range_max": 10.0, "mount": [0.0, 0.0, 0.0]}
)


class ShiftedOdometry:
    """A user-written algorithm: odometry shifted by a configured offset, with an empty map."""

    name = "test-shifted"

    class Config(BaseModel):
        shift: float = Field(1.0, ge=-5.0, le=5.0)

    PRESETS = {"far": {"shift": 4.0}}

    def __init__(self, config, laser):
        self.config, self.laser = config, laser

    def reset(self, rng):
        self.updates, self._t, self._poses = 0, [], []

    def process(self, frame):
        pose = np.asarray(frame.odometry, dtype=np.float64) + [self.config.shift, 0.0, 0.0]
        self._t.append(frame.t)
        self._poses.append(pose)
        self.updates += 1
        return pose

    def occupancy(self):
        return OccupancyGrid(np.full((2, 2), -1, np.int8), 0.05, np.zeros(3))

    def trajectory(self):
        return Trajectory(np.array(self._t), np.array(self._poses).reshape(-1, 3))


def _record(n: int = 5) -> RunRecord:
    odometry = np.column_stack([np.arange(n) * 0.1, np.zeros(n), np.zeros(n)])
    return RunRecord(
        t=np.arange(n) * 0.1,
        scans=np.full((n, 5), 3.0, np.float32),
        odometry=odometry,
        truth=odometry.copy(),
        stalled=np.zeros(n, bool),
        laser=LASER,
    )


def test_builtin_odometry_is_registered_and_follows_the_protocol():
    assert get_algorithm("odometry") is OdometrySlam
    algorithm = make_algorithm("odometry", LASER)
    assert isinstance(algorithm, SlamAlgorithm)
    assert algorithm.config.resolution == 0.05 and algorithm.config.occ_thresh == 0.25


def test_unknown_algorithm_lists_known_names():
    with pytest.raises(ConfigError, match=r"unknown SLAM algorithm 'gmaping'; known: .*odometry"):
        get_algorithm("gmaping")


def test_preset_then_overrides():
    algorithm = make_algorithm("odometry", LASER, preset="gmapping", overrides={"angular_update": 0.25})
    assert algorithm.config.linear_update == 1.0 and algorithm.config.angular_update == 0.25
    with pytest.raises(ConfigError, match=r"no preset 'fast'; presets: every-frame, gmapping"):
        make_algorithm("odometry", LASER, preset="fast")


def test_unknown_parameter_lists_valid_ones():
    with pytest.raises(ConfigError, match=r"no parameter resolutoin; parameters: resolution, max_urange, occ_thresh"):
        make_algorithm("odometry", LASER, overrides={"resolutoin": 0.1})


def test_out_of_range_names_parameter_value_and_range():
    with pytest.raises(ConfigError) as info:
        make_algorithm("odometry", LASER, overrides={"occ_thresh": 1.5})
    message = str(info.value)
    assert "occ_thresh = 1.5" in message and ">= 0" in message and "< 1" in message and "\n" not in message
    with pytest.raises(ConfigError, match=r"resolution = 'big'"):
        make_algorithm("odometry", LASER, overrides={"resolution": "big"})


def test_user_algorithm_registered_works_end_to_end():
    try:
        register_algorithm(ShiftedOdometry)
        result = run_slam(_record(), "test-shifted", preset="far", seed=3)
        np.testing.assert_allclose(result.trajectory.poses[:, 0], np.arange(5) * 0.1 + 4.0)
        assert result.updates == 5 and result.config.model_dump() == {"shift": 4.0} and result.timing.shape == (5,)
        with pytest.raises(ConfigError, match=r"shift = 9.*<= 5"):
            run_slam(_record(), "test-shifted", overrides={"shift": 9})
    finally:
        ALGORITHMS.pop("test-shifted", None)


def test_registration_checks_the_contract():
    class Incomplete:
        name = "incomplete"

    with pytest.raises(ConfigError, match=r"lacks Config, PRESETS, reset"):
        register_algorithm(Incomplete)
    assert "incomplete" not in ALGORITHMS


def test_entry_point_is_found_and_registered(monkeypatch):
    point = EntryPoint(name="test-shifted", value=f"{__name__}:ShiftedOdometry", group=base.ENTRY_POINT_GROUP)
    monkeypatch.setattr(base, "_entry_points", lambda: {"test-shifted": point})
    import sys

    monkeypatch.setitem(sys.modules, __name__, sys.modules[ShiftedOdometry.__module__])
    try:
        assert "test-shifted" in base.known_algorithms()
        assert get_algorithm("test-shifted") is ShiftedOdometry
    finally:
        ALGORITHMS.pop("test-shifted", None)
    broken = EntryPoint(name="broken", value="no_such_module_xyz:Thing", group=base.ENTRY_POINT_GROUP)
    monkeypatch.setattr(base, "_entry_points", lambda: {"broken": broken})
    with pytest.raises(ConfigError, match=r"'broken' .*failed to load"):
        get_algorithm("broken")


def test_frames_feed_the_protocol():
    algorithm = make_algorithm("odometry", LASER)
    algorithm.reset(np.random.default_rng(0))
    pose = algorithm.process(Frame(0.0, np.full(5, 3.0, np.float32), np.array([1.0, 2.0, 0.5]), np.zeros(3)))
    np.testing.assert_allclose(pose, [0.0, 0.0, 0.0])  # the first frame is at the initial pose
    assert algorithm.updates == 1 and len(algorithm.trajectory()) == 1


class TruthReader(ShiftedOdometry):
    """A plug-in that reaches for the ground truth (it would score 0 m if it got it)."""

    name = "test-truth-reader"

    def process(self, frame):
        pose = np.asarray(frame.truth, dtype=np.float64)
        self._t.append(frame.t)
        self._poses.append(pose)
        self.updates += 1
        return pose


def test_an_algorithm_is_given_no_ground_truth_offline_or_in_a_trial():
    from slamtrials.trial import TrialConfig, run_trial
    from slamtrials.worlds import World

    register_algorithm(TruthReader)
    try:
        with pytest.raises(AttributeError, match="truth"):
            run_slam(_record(), "test-truth-reader")
        occupied = np.ones((60, 100), bool)
        occupied[10:50, 10:90] = False
        world = World(occupied, 0.05, name="box", start=np.array([1.0, 1.0, 0.0]))
        config = TrialConfig.from_dict(
            {"slam": {"algorithm": "test-truth-reader", "preset": None}, "termination": {"max_time": 5.0}}
        )
        with pytest.raises(AttributeError, match="truth"):
            run_trial(world, config, seed=1)
    finally:
        ALGORITHMS.pop("test-truth-reader", None)


def test_a_frame_gives_its_sensor_data_and_not_its_truth():
    frame = Frame(t=1.5, ranges=np.ones(3, np.float32), odometry=np.zeros(3), truth=np.ones(3))
    reading = frame.reading()
    assert reading.t == 1.5 and reading.ranges is frame.ranges and reading.odometry is frame.odometry
    assert not hasattr(reading, "truth")
