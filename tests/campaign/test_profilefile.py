"""Error-profile files: written and read back, inlined into configs that name them by path."""

from __future__ import annotations

import pytest
import yaml

from slamtrials.campaign import CampaignConfig
from slamtrials.campaign.profilefile import read_profile, write_profile
from slamtrials.errors import ConfigError
from slamtrials.sim.profiles import ErrorProfile


def test_profile_file_round_trip_and_config_by_path(tmp_path):
    profile = ErrorProfile(
        name="lab-fit",
        description="fitted on a test",
        laser={"range_noise_std": 0.03, "short_rate": 0.1},
        odometry={"noise_linear_per_m": 0.02, "bias_angular_range": (-0.1, 0.05)},
    )
    path = write_profile(tmp_path / "profiles" / "lab.yaml", profile, header="written by a test")
    assert path.read_text().startswith("# written by a test\n")
    assert read_profile(path) == profile
    config_path = tmp_path / "campaign.yaml"
    config_path.write_text(yaml.safe_dump({"worlds": ["office_small_01"], "sim": {"profile": "profiles/lab.yaml"}}))
    config = CampaignConfig.from_yaml(config_path)
    assert config.sim.profile_name == "lab-fit" and config.sim.laser.short_rate == 0.1
    assert config.sim.odometry.bias_angular_range == (-0.1, 0.05)
    # stored inline: the stored config reads back without the file
    (tmp_path / "profiles" / "lab.yaml").unlink()
    assert CampaignConfig.from_dict(config.model_dump(mode="json")) == config


def test_bad_profile_files_name_the_file_and_field(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump({"laser": {"dropout_rate": 2.0}}))
    with pytest.raises(ConfigError, match=r"bad.yaml: laser.*dropout_rate"):
        read_profile(bad)
    config_path = tmp_path / "campaign.yaml"
    config_path.write_text(yaml.safe_dump({"worlds": ["office_small_01"], "sim": {"profile": "missing.yaml"}}))
    with pytest.raises(Exception, match="missing.yaml"):
        CampaignConfig.from_yaml(config_path)
