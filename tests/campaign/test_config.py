"""The campaign config: defaults, one-line errors naming file, field and value, the commented dump."""

from __future__ import annotations

import logging

import pytest
import yaml

from slamtrials.campaign import CampaignConfig, dump_default_yaml, small_campaign_config
from slamtrials.campaign.dump import EXAMPLE_WORLDS, dump_config_yaml
from slamtrials.errors import ConfigError, FormatError
from slamtrials.sim import SimConfig
from slamtrials.sim.config import LASER_ERROR_FIELDS, ODOMETRY_ERROR_FIELDS
from slamtrials.sim.profiles import BUNDLED_PROFILES, DEFAULT_PROFILE
from slamtrials.trial import TrialConfig


def test_defaults_are_the_papers_but_the_error_profile():
    config = CampaignConfig(worlds=["office_small_01"])
    assert config.runs.initial == 10 and config.runs.max_runs >= 10
    assert config.metric.pilot == 500 and config.metric.confidence == 0.99
    # per-run relations: the precise rule by default, the paper's absolute margins as a named rule
    assert config.metric.rule == "precise" and config.metric.relative_margin == 0.01
    assert config.metric.min_relations == 5000 and config.metric.margin_t is None
    paper = CampaignConfig.from_dict({"worlds": ["office_small_01"], "metric": {"rule": "paper"}}).metric
    assert paper.margin_t == 0.02 and paper.margin_r == 0.02 and paper.relative_margin is None
    assert config.runs.margin_t == 0.02 and config.runs.margin_r == 0.02
    # the simulated sensors: the one default error profile (realistic, docs/realism.md) of every command,
    # the trial's own; everything else the paper's
    assert config.sim.profile_name == DEFAULT_PROFILE == "realistic" and config.sim.laser.short_rate > 0
    assert config.trial_config() == TrialConfig() and config.sim == SimConfig()
    paper = CampaignConfig.from_dict({"worlds": ["office_small_01"], "sim": {"profile": "paper"}})
    assert paper.trial_config() == TrialConfig(sim=SimConfig.paper())
    # a campaign stored before profiles existed was simulated with paper, and is read so
    assert CampaignConfig.from_stored({"worlds": ["w"], "sim": {"dt": 0.1}}).sim == SimConfig.paper()
    assert config.seed == 0 and config.output is None


def test_dump_is_complete_commented_and_loads_back_equal():
    text = dump_default_yaml()
    config = CampaignConfig.from_dict(yaml.safe_load(text))
    assert config == CampaignConfig(worlds=list(EXAMPLE_WORLDS))
    lines = text.splitlines()
    # every key line is preceded by a comment
    for i, line in enumerate(lines):
        if line.strip() and not line.lstrip().startswith(("#", "- ")):
            assert lines[i - 1].lstrip().startswith("#"), line
    for key in (
        "sim:",
        "laser:",
        "odometry:",
        "slam:",
        "termination:",
        "metric:",
        "runs:",
        "max_runs:",
        "seed:",
        "pilot:",
    ):
        assert any(line.strip() == key or line.strip().startswith(key + " ") for line in lines), key


def test_a_changed_config_dumps_and_loads_back_equal():
    config = CampaignConfig.from_dict(
        {
            "worlds": ["a.yaml", "b"],
            "seed": 12,
            "runs": {"initial": 5, "max_runs": 7},
            "slam": {"algorithm": "gmapping", "params": {"particles": 5}},
            "sim": {"laser": {"mount": [0.1, 0.0, 0.2]}},
        }
    )
    assert CampaignConfig.from_dict(yaml.safe_load(dump_config_yaml(config))) == config


def test_dump_names_the_profile_and_no_error_value_so_editing_the_name_changes_every_value():
    text = dump_default_yaml()
    sim = yaml.safe_load(text)["sim"]
    assert sim["profile"] == DEFAULT_PROFILE
    error_fields = {*LASER_ERROR_FIELDS, *ODOMETRY_ERROR_FIELDS}
    assert not error_fields & set(sim["laser"]) and not error_fields & set(sim["odometry"])
    edited = CampaignConfig.from_dict(yaml.safe_load(text.replace(f"profile: {DEFAULT_PROFILE}", "profile: paper")))
    assert edited.sim == SimConfig.paper() and not edited.sim.laser.has_errors
    assert edited.model_copy(update={"sim": SimConfig()}) == CampaignConfig(worlds=list(EXAMPLE_WORLDS))


def test_dump_of_a_changed_config_writes_only_the_overrides():
    config = CampaignConfig.from_dict({"worlds": ["w"], "sim": {"profile": "paper", "laser": {"short_rate": 0.1}}})
    sim = yaml.safe_load(dump_config_yaml(config))["sim"]
    assert sim["profile"] == "paper" and sim["laser"]["short_rate"] == 0.1
    assert "dropout_rate" not in sim["laser"] and "bias_linear_range" not in sim["odometry"]
    # a campaign folder's config.yaml holds every value, as the campaign ran it
    resolved = yaml.safe_load(dump_config_yaml(config, resolved=True))["sim"]
    assert resolved["laser"]["dropout_rate"] == 0.0 and resolved["odometry"]["bias_linear_range"] == [-0.005, 0.005]
    assert CampaignConfig.from_dict(yaml.safe_load(dump_config_yaml(config, resolved=True))) == config


def test_a_file_that_contradicts_its_profile_is_accepted_with_one_warning(tmp_path, caplog):
    same = BUNDLED_PROFILES["realistic"].laser_values()["short_rate"]
    path = tmp_path / "c.yaml"
    path.write_text(
        "worlds: [office_small_01]\nsim:\n  profile: realistic\n"
        f"  laser:\n    short_rate: {same!r}\n    dropout_rate: 0.0\n"
        "  odometry:\n    bias_linear_range: [-0.01, 0.01]\n"
    )
    with caplog.at_level(logging.WARNING):
        config = CampaignConfig.from_yaml(path)
    assert config.sim.laser.dropout_rate == 0.0 and config.sim.profile_label == "realistic + 2 overrides"
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert warnings == [
        f"{path}: keys that override profile realistic: sim.laser.dropout_rate, sim.odometry.bias_linear_range"
    ]
    caplog.clear()
    path.write_text("worlds: [office_small_01]\nsim:\n  profile: realistic\n")
    with caplog.at_level(logging.WARNING):
        CampaignConfig.from_yaml(path)
    assert not [r for r in caplog.records if r.levelno == logging.WARNING]


@pytest.mark.parametrize(
    ("sim", "expected"),
    [
        ({"profile": {"name": "x", "laser": {"shrt": 0.1}}}, "unknown laser error field 'shrt'"),
        ({"profile": {"name": "x", "laser": {"dropout_rate": -0.1}}}, "dropout_rate"),
        ({"profile": {"name": "x", "odometry": {"noise_linear_per_m": -1}}}, "noise_linear_per_m"),
        ({"profile": {"name": "x", "lazer": {}}}, "lazer"),
        ({"profile": "realstic"}, "unknown error profile 'realstic'"),
        ({"laser": {"dropout_rate": -0.5}}, "sim.laser.dropout_rate"),
    ],
)
def test_a_bad_profile_is_one_line_naming_the_key(sim, expected):
    with pytest.raises(ConfigError) as info:
        CampaignConfig.from_dict({"worlds": ["w"], "sim": sim}, source="c.yaml")
    message = str(info.value)
    assert message.startswith("c.yaml: ") and expected in message and "\n" not in message


@pytest.mark.parametrize(
    ("data", "expected"),
    [
        ({"worlds": ["w"], "runz": {}}, "runz: Extra inputs are not permitted"),
        ({"worlds": ["w"], "runs": {"initial": 1}}, "runs.initial: Input should be greater than or equal to 2 (got 1)"),
        ({"worlds": ["w"], "runs": {"initial": 10, "max_runs": 5}}, "max_runs (5) must be at least initial (10)"),
        ({"worlds": ["w"], "metric": {"confidence": 1.5}}, "metric.confidence: Input should be less than 1 (got 1.5)"),
        ({"worlds": ["w"], "sim": {"laser": {"max_range": -1}}}, "sim.laser.max_range"),
        ({"worlds": ["w"], "seed": -3}, "seed: Input should be greater than or equal to 0 (got -3)"),
        ({"worlds": []}, "worlds: List should have at least 1 item"),
        ({"seed": 1}, "worlds: required setting is missing"),
        (
            {"worlds": ["w"], "slam": {"params": {"particlez": 3}}},
            "slam: SLAM algorithm 'gmapping' has no parameter particlez",
        ),
        ({"worlds": ["w"], "slam": {"algorithm": "nope"}}, "unknown SLAM algorithm 'nope'"),
    ],
)
def test_bad_values_are_one_line_errors_naming_the_field(data, expected):
    with pytest.raises(ConfigError) as info:
        CampaignConfig.from_dict(data, source="c.yaml")
    message = str(info.value)
    assert message.startswith("c.yaml: ") and expected in message and "\n" not in message


def test_from_yaml_names_the_file(tmp_path):
    path = tmp_path / "campaign.yaml"
    path.write_text("worlds: [office_small_01]\nruns:\n  retries: -1\n")
    with pytest.raises(
        ConfigError, match=r"campaign.yaml: runs.retries: Input should be greater than or equal to 0 \(got -1\)"
    ):
        CampaignConfig.from_yaml(path)
    path.write_text("worlds: [office_small_01\n")
    with pytest.raises(FormatError, match="campaign.yaml"):
        CampaignConfig.from_yaml(path)
    with pytest.raises(FormatError, match="no such file"):
        CampaignConfig.from_yaml(tmp_path / "missing.yaml")


def test_the_digest_ignores_the_output_folder_only():
    a = CampaignConfig(worlds=["w"], output="x")
    assert a.digest() == CampaignConfig(worlds=["w"], output="y").digest()
    assert a.digest() != CampaignConfig(worlds=["w"], seed=1).digest()


def test_small_campaign_config():
    config = small_campaign_config(seed=4)
    assert config.worlds == ["office_small_01", "lab_small_01", "house_small_01"]
    assert (config.runs.initial, config.runs.max_runs, config.seed) == (5, 10, 4)
    assert config.slam.algorithm == "gmapping" and config.slam.preset == "paper"
    odometry = small_campaign_config(["room"], initial=5, max_runs=6, slam={"algorithm": "odometry", "preset": None})
    assert odometry.slam.algorithm == "odometry" and odometry.runs.max_runs == 6
    with pytest.raises(ConfigError, match="max_runs"):
        small_campaign_config(initial=5, max_runs=3)


def test_world_paths_in_a_config_file_are_relative_to_that_file(tmp_path, monkeypatch):
    """A floor plan next to the config resolves from any working directory; catalog names and paths
    that are not beside the config stay as written."""
    folder = tmp_path / "study"
    (folder / "maps").mkdir(parents=True)
    (folder / "maps" / "a.yaml").write_text("placeholder: the loader is not called here\n")
    config_file = folder / "campaign.yaml"
    config_file.write_text("worlds: [maps/a.yaml, office_small_01, elsewhere/b.yaml]\n")
    monkeypatch.chdir(tmp_path)
    config = CampaignConfig.from_yaml(config_file)
    assert config.worlds == [str((folder / "maps" / "a.yaml").resolve()), "office_small_01", "elsewhere/b.yaml"]
