"""bench/bench_paper_validation.py: its configs are the paper's settings, and its table is right on fake rows."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import pytest

from slamtrials.campaign.config import CampaignConfig
from slamtrials.errors import ConfigError
from slamtrials.sim.profiles import DEFAULT_PROFILE
from slamtrials.worlds.catalog import catalog_entry

BENCH = Path(__file__).resolve().parents[2] / "bench"


def _load_bench():
    sys.path.insert(0, str(BENCH))  # the script imports its sibling benchutil
    try:
        spec = importlib.util.spec_from_file_location("bench_paper_validation", BENCH / "bench_paper_validation.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = module  # dataclasses look their module up there
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(BENCH))
    return module


bench = _load_bench()
HALL, LAB = bench.DEFAULT_CONFIGS


def test_hall_config_is_table_ii_s_robot():
    config = CampaignConfig.from_yaml(HALL)
    assert config.worlds == ["paper_hall_empty", "paper_hall_furnished"]
    laser, odometry = config.sim.laser, config.sim.odometry
    assert math.degrees(laser.fov) == pytest.approx(80.0)
    assert math.degrees(laser.angle_increment) == pytest.approx(1.0)
    assert laser.num_beams == 81 and laser.max_range == 30.0
    assert odometry.bias_linear_range == (-0.01, 0.01)
    assert [math.degrees(v) for v in odometry.bias_angular_range] == pytest.approx([-2.0, 2.0])
    assert config.sim.dt == pytest.approx(0.1)  # 10 Hz
    assert (config.slam.algorithm, config.slam.preset) == ("gmapping", "paper")
    assert config.runs.initial == config.runs.max_runs == 10


def test_lab_config_is_table_iii_s_robocom():
    config = CampaignConfig.from_yaml(LAB)
    assert config.worlds == ["paper_lab"]
    laser, odometry = config.sim.laser, config.sim.odometry
    assert math.degrees(laser.fov) == pytest.approx(270.0)
    assert math.degrees(laser.angle_increment) == pytest.approx(0.25)
    assert laser.num_beams == 1081 and laser.max_range == 20.0
    assert odometry.bias_linear_range == (-0.01, 0.01)
    assert [math.degrees(v) for v in odometry.bias_angular_range] == pytest.approx([-4.0, 4.0])
    assert (config.slam.algorithm, config.slam.preset) == ("gmapping", "paper")
    assert config.runs.initial == config.runs.max_runs == 10


def test_every_configured_world_is_bundled_and_has_the_paper_s_figures():
    for path in bench.DEFAULT_CONFIGS:
        for world in CampaignConfig.from_yaml(path).worlds:
            assert catalog_entry(world)["kind"] == "replica"
            assert world in bench.PAPER
    assert bench.PAPER["paper_hall_empty"].real_t == 0.189 and bench.PAPER["paper_lab"].sim_sr == 0.004


def test_the_replicas_follow_the_one_default_profile_and_their_bias_ranges_override_it():
    for path in bench.DEFAULT_CONFIGS:
        sim = bench.load_config(path, None).sim
        assert sim.profile_name == DEFAULT_PROFILE == "realistic" and sim.laser.range_noise_std > 0.0
        assert [o.key for o in sim.profile_overrides] == ["odometry.bias_linear_range", "odometry.bias_angular_range"]
        assert sim.profile_label == "realistic + 2 overrides"
        paper = bench.load_config(path, "paper").sim
        assert paper.profile_label == "paper + 2 overrides" and not paper.laser.has_errors


def test_profile_option_sets_sim_profile_and_the_configs_keep_their_bias_ranges():
    as_written = bench.load_config(HALL, None)
    assert as_written == CampaignConfig.from_yaml(HALL) and as_written.sim.profile_name == DEFAULT_PROFILE
    assert bench.load_config(HALL, DEFAULT_PROFILE) == as_written  # what a config without a profile gets
    inline = {"name": "noisy", "laser": {"range_noise_std": 0.02}, "odometry": {"bias_linear_range": [-0.2, 0.2]}}
    noisy = bench.load_config(HALL, inline).sim
    assert noisy.profile_name == "noisy" and noisy.laser.range_noise_std == 0.02
    assert noisy.odometry.bias_linear_range == (-0.01, 0.01)  # the setting's own bound wins over the profile's
    assert noisy.laser.num_beams == 81
    with pytest.raises(ConfigError, match="profile"):
        bench.load_config(HALL, "no_such_profile")


def test_profile_option_reads_a_profile_file(tmp_path):
    from slamtrials.campaign.profilefile import write_profile
    from slamtrials.sim.profiles import ErrorProfile

    path = write_profile(tmp_path / "fitted.yaml", ErrorProfile(name="fitted", laser={"short_rate": 0.1}, odometry={}))
    sim = bench.load_config(HALL, str(path)).sim
    assert sim.profile_name == "fitted" and sim.laser.short_rate == 0.1 and sim.laser.num_beams == 81


def _row(world, seed, eps_t, eps_r, profile="(config)", **extra):
    row = {
        "config": "c.yaml",
        "world": world,
        "profile": profile,
        "seed": str(seed),
        "reason": "no_frontiers",
        "mapped": "0.99",
        "observed": "0.995",
        "duration_s": "50.0",
        "wall_s": "2.0",
        "eps_t": str(eps_t),
        "eps_r": str(eps_r),
        "odometry_eps_t": "0.5",
        "odometry_eps_r": "0.1",
        "relations": "100",
        "error": "",
    }
    return {**row, **extra}


def test_summary_takes_mean_and_sample_std_and_leaves_failed_trials_out():
    rows = [
        _row("paper_lab", 0, 0.1, 0.01),
        _row("paper_lab", 1, 0.3, 0.03),
        _row("paper_lab", 2, "", "", reason="error", error="start pose in a wall"),
        _row("paper_lab", 0, 0.2, 0.02, profile="realistic"),
        _row("elsewhere", 0, 0.4, 0.04),
    ]
    lab, realistic, elsewhere = bench.summarize(rows)
    assert (lab.world, lab.profile, lab.runs, lab.failed) == ("paper_lab", "(config)", 2, 1)
    assert lab.eps_t == pytest.approx((0.2, math.sqrt(0.02)))
    assert lab.eps_r == pytest.approx((0.02, math.sqrt(0.0002)))
    assert lab.reasons == "error, no_frontiers"
    assert realistic.runs == 1 and realistic.eps_t[0] == 0.2 and math.isnan(realistic.eps_t[1])
    table = bench.markdown_table([lab, realistic, elsewhere]).splitlines()
    assert len(table) == 5 and table[0].count("|") == table[1].count("|") == table[2].count("|")
    assert "| III | paper_lab | (config) | 2 (+1 failed) | 0.200 +- 0.141 | 0.020 +- 0.014 |" in table[2]
    assert "0.086 +- 0.026 | 0.066 +- 0.010 | 0.101 +- 0.019 | 0.022 +- 0.004" in table[2]
    assert "| 0.200 | 0.020 |" in table[3]  # one run: no spread
    assert table[4].startswith("| - | elsewhere |") and "| - | - | - | - |" in table[4]


@pytest.mark.slow
def test_one_trial_runs_and_scores_a_replica():
    row = bench.one_trial(str(HALL), "paper_hall_furnished", None, 0)
    assert row["error"] == "" and row["profile"] == "realistic + 2 overrides"
    assert row["reason"] in ("map_converged", "no_frontiers") and row["mapped"] > 0.9
    assert 0.0 < float(row["eps_t"]) < 1.0 and 0.0 < float(row["eps_r"]) < 0.5


def test_set_option_changes_a_field_of_every_config():
    field, value = bench.parse_override("sim.odometry.bias_linear_range=[-0.005, 0.005]")
    assert (field, value) == ("sim.odometry.bias_linear_range", [-0.005, 0.005])
    config = bench.load_config(HALL, None, ((field, value), ("sim.laser.fov", 4.71238898038469)))
    assert config.sim.odometry.bias_linear_range == (-0.005, 0.005)
    assert config.sim.laser.num_beams == 271
    with pytest.raises(bench.argparse.ArgumentTypeError, match="FIELD=VALUE"):
        bench.parse_override("sim.laser.fov")
    with pytest.raises(ConfigError, match="fov"):
        bench.load_config(HALL, None, (("sim.laser.fov", -1.0),))
