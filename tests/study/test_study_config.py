"""Study configs: axes, named combinations, the cells they expand to, and every bad input of issue 35."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from slamtrials.campaign import run_seed
from slamtrials.cli.main import app
from slamtrials.errors import ConfigError, FormatError
from slamtrials.study import StudyConfig, expand_cells

runner = CliRunner()


def study(rooms, **changes) -> StudyConfig:
    from slamtrials.study import StudyConfig

    mapping = {
        "worlds": list(rooms),
        "seed": 4,
        "slam": {"algorithm": "odometry", "preset": None},
        "runs": {"initial": 5, "max_runs": 5},
    }
    return StudyConfig.from_dict({"campaign": mapping, **changes})


def test_product_then_named_combinations_in_order(rooms):
    config = study(
        rooms,
        axes={"sim.laser.max_range": [30, 15], "sim.profile": ["paper", "realistic"]},
        combinations={"long_paper": {"sim.laser.max_range": 60, "sim.profile": "paper"}},
    )
    cells = expand_cells(config)
    assert [c.name for c in cells] == [
        "max_range=30,profile=paper",
        "max_range=30,profile=realistic",
        "max_range=15,profile=paper",
        "max_range=15,profile=realistic",
        "long_paper",
    ]
    assert [c.combination for c in cells] == [False] * 4 + [True]
    assert cells[2].config.sim.laser.max_range == 15.0 and cells[2].config.sim.profile_name == "paper"
    # another profile's cell takes every value of that profile (the base's realistic values do not stay)
    assert cells[0].config.sim.laser.range_noise_std != cells[1].config.sim.laser.range_noise_std
    # every cell keeps the root seed and the worlds: run i of a world has one seed in every cell
    assert {c.config.seed for c in cells} == {4} and {tuple(c.config.worlds) for c in cells} == {tuple(rooms)}
    seeds = {tuple(run_seed(c.config.seed, "room_a", i) for i in range(5)) for c in cells}
    assert len(seeds) == 1


def test_named_combinations_alone_and_slam_parameters(rooms, campaign_mapping, write_study):
    config = StudyConfig.from_dict(
        {
            "campaign": campaign_mapping(rooms, slam={"algorithm": "gmapping"}),
            "axes": {"slam.params.particles": [10, 30]},
            "product": False,
            "combinations": {"many": {"slam.params.particles": 80}},
        }
    )
    cells = expand_cells(config)
    assert [c.name for c in cells] == ["many"] and cells[0].config.slam.params == {"particles": 80}
    product = expand_cells(config.model_copy(update={"product": True, "combinations": {}}))
    assert [c.name for c in product] == ["particles=10", "particles=30"]


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"axes": {"sim.laser.max_rnge": [30]}}, "sim.laser.max_rnge is not a config key"),
        ({"axes": {"slam.params.particle": [3]}}, "slam.params.particle is not a config key"),
        ({"axes": {"sim.laser.max_range": []}}, "sim.laser.max_range: empty axis"),
        ({"axes": {"sim.laser.max_range": [30, 30]}}, "value 30 given twice"),
        ({"axes": {"sim.laser": [{}], "sim.laser.max_range": [30]}}, "two axes on overlapping keys"),
        ({"axes": {"seed": [1, 2]}}, "seed cannot vary between cells"),
        ({"axes": {"worlds": [["a"]]}}, "worlds cannot vary between cells"),
        ({"combinations": {"x": {"runs.margn_t": 0.1}}}, "runs.margn_t is not a config key"),
        ({"combinations": {"a/b": {"runs.margin_t": 0.1}}}, "is not a usable name"),
        ({"axes": {}}, "the study has no cells"),
        ({"axis": {}}, "axis: Extra inputs are not permitted"),
    ],
)
def test_bad_studies_are_one_line_config_errors(rooms, changes, expected):
    with pytest.raises(ConfigError) as info:
        study(rooms, **changes)
    assert expected in str(info.value) and "\n" not in str(info.value)


def test_a_value_out_of_range_names_the_cell(rooms):
    config = study(rooms, axes={"sim.laser.max_range": [30, -5]})
    with pytest.raises(ConfigError) as info:
        expand_cells(config)
    text = str(info.value)
    assert text.startswith("cell max_range=-5: sim.laser.max_range:") and "greater than 0" in text


def test_two_axes_on_one_key_in_yaml_are_refused(tmp_path, rooms, campaign_mapping, write_study):
    text = (
        "campaign:\n  worlds: [office_small_01]\naxes:\n  sim.laser.max_range: [30, 15]\n"
        "  slam.params.particles: [10]\n  sim.laser.max_range: [20]\n"
    )
    with pytest.raises(FormatError) as info:
        StudyConfig.from_yaml(write_study(tmp_path / "s.yaml", rooms, text))
    assert "key sim.laser.max_range given twice (lines 4 and 6)" in str(info.value)


def test_campaign_file_beside_the_study_and_set(tmp_path, rooms, campaign_mapping, write_study):
    import yaml

    (tmp_path / "base.yaml").write_text(yaml.safe_dump(campaign_mapping(rooms)))
    path = write_study(tmp_path / "s.yaml", rooms, "campaign: base.yaml\naxes:\n  sim.laser.max_range: [30, 15]\n")
    config = StudyConfig.from_yaml(path)
    assert config.base().worlds == list(rooms)
    capped = config.with_campaign_settings({"runs.max_runs": 6})
    assert capped.base().runs.max_runs == 6 and capped.digest() != config.digest()
    with pytest.raises(ConfigError, match="--set runs.max_rns: not a config key"):
        config.with_campaign_settings({"runs.max_rns": 6})


@pytest.mark.parametrize(
    ("study_text", "expected"),
    [
        ("axes:\n  sim.laser.max_rnge: [30]\n", "sim.laser.max_rnge is not a config key"),
        ("axes:\n  sim.laser.max_range: [30, 0]\n", "cell max_range=0: sim.laser.max_range"),
        ("axes:\n  sim.laser.max_range: []\n", "empty axis"),
        ("axes:\n  sim.laser.max_range: [30]\n  sim.laser.max_range: [15]\n", "given twice"),
    ],
)
def test_cli_bad_input_is_one_line_exit_2_and_writes_nothing(
    tmp_path, rooms, campaign_mapping, write_study, study_text, expected
):
    import yaml

    base = yaml.safe_dump({"campaign": campaign_mapping(rooms)}, sort_keys=False)
    path = write_study(tmp_path / "s.yaml", rooms, base + study_text)
    out = tmp_path / "out"
    result = runner.invoke(app, ["study", "run", path, "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert expected in result.output and result.output.strip().count("\n") == 0
    assert not out.exists()
