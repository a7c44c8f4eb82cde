"""The report's overview names the error profile the runs were simulated with, and says when the
campaign's config overrode it ("realistic + 2 overrides", which keys, which values)."""

from __future__ import annotations

from slamtrials.campaign import CampaignConfig
from slamtrials.report.overview import profile_text


def _stored_sim(sim: dict) -> dict:
    """The ``sim`` section as a campaign stores it (every value resolved)."""
    return CampaignConfig.from_dict({"worlds": ["w"], "sim": sim}).model_dump(mode="json")["sim"]


def test_the_default_profile_is_named_without_overrides():
    text = profile_text(_stored_sim({}))
    assert text.startswith("error profile realistic: the mean of the mit-csail and fr079 fits")
    assert "override" not in text


def test_overrides_are_counted_and_named_with_their_values():
    text = profile_text(
        _stored_sim({"laser": {"dropout_rate": 0.01}, "odometry": {"bias_linear_range": [-0.01, 0.01]}})
    )
    assert text.startswith("error profile realistic + 2 overrides (laser.dropout_rate 0.01 instead of 0.02")
    assert "odometry.bias_linear_range [-0.01, 0.01] instead of [-0.01" in text
    paper = profile_text(_stored_sim({"profile": "paper", "laser": {"short_rate": 0.1}}))
    assert paper.startswith("error profile paper + 1 override (laser.short_rate 0.1 instead of 0)")
    assert "IROS 2018 Stage set-up" in paper


def test_a_campaign_stored_before_profiles_is_paper_and_an_unknown_profile_keeps_its_name():
    assert profile_text({"dt": 0.1}).startswith("error profile paper: the IROS 2018 Stage set-up")
    assert profile_text({"profile": "from-a-later-version"}) == "error profile from-a-later-version"
