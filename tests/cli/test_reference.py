"""The reference pages written from the code: every command, every configuration key, the public API."""

from __future__ import annotations

import re

import slamtrials
from slamtrials.cli.reference import api_reference, cli_reference, config_reference
from slamtrials.sim.config import LaserConfig


def test_the_cli_reference_has_every_command_with_its_options():
    text = cli_reference()
    headings = re.findall(r"^#+ `(slamtrials[^`]*)`", text, re.M)
    for command in ("slamtrials", "slamtrials trial", "slamtrials campaign run", "slamtrials worlds show"):
        assert command in headings
    assert len(headings) == len(set(headings))
    trial = text.split("`slamtrials trial`", 1)[1].split("\n#", 1)[0]
    assert "--seed" in trial and "Usage: slamtrials trial" in trial


def test_the_config_reference_gives_defaults_and_ranges_from_the_models():
    text = config_reference()
    row = next(line for line in text.splitlines() if line.startswith("| `sim.laser.max_range` |"))
    assert f"`{LaserConfig().max_range:.6g}`" in row and "> 0, <= 1000" in row
    assert "| `sim.odometry.noise_linear_per_m` |" in text
    assert text.count("## ") == 2  # the campaign's and the trial's


def test_the_api_reference_documents_every_public_name_where_it_is_defined():
    text = api_reference()
    blocks = re.findall(r"^::: (\S+)$", text, re.M)
    assert len(blocks) == len(slamtrials.__all__) - 1  # all but __version__
    assert "slamtrials.trial.run.run_trial" in blocks
