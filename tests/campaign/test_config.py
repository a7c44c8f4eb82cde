"""The campaign config: defaults, one-line errors naming file, field and value, the commented dump."""

from __future__ import annotations

import pytest
import yaml

from slamtrials.campaign import CampaignConfig, dump_default_yaml, small_campaign_config
from slamtrials.campaign.dump import EXAMPLE_WORLDS, dump_config_yaml
from slamtrials.errors import ConfigError, FormatError
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
    # the simulated sensors: the realistic error profile (docs/realism.md), everything else the paper's
    assert config.sim.profile_name == "realistic" and config.sim.laser.short_rate > 0
    assert config.trial_config().model_copy(update={"sim": TrialConfig().sim}) == TrialConfig()
    paper = CampaignConfig.from_dict({"worlds": ["office_small_01"], "sim": {"profile": "paper"}})
    assert paper.trial_config() == TrialConfig()
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
