"""``slamtrials worlds``: list, show, info, generate; bad input is one line and exit status 2."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.worlds import load_world
from slamtrials.worlds.catalog import catalog_names
from slamtrials.worlds.generate import generate_world

runner = CliRunner()


def run(*args: str):
    return runner.invoke(app, ["worlds", *args])


def assert_one_line_error(result, *words: str) -> None:
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1, result.output
    for word in words:
        assert word in lines[0]


@pytest.mark.parametrize("command", [[], ["list"], ["show"], ["info"], ["generate"]])
def test_every_worlds_command_has_help(command):
    result = run(*command, "--help")
    assert result.exit_code == 0
    assert "Usage" in result.output


def test_list_shows_every_bundled_world():
    result = runner.invoke(app, ["worlds", "list"], env={"COLUMNS": "200"})
    assert result.exit_code == 0
    for name in catalog_names():
        assert name in result.output
    assert "office" in result.output and "multiwing" in result.output


def test_show_draws_a_catalog_world(tmp_path):
    out = tmp_path / "office.png"
    result = run("show", "office_small_01", "-o", str(out))
    assert result.exit_code == 0, result.output
    assert str(out) in result.output
    with Image.open(out) as image:
        assert image.format == "PNG" and image.size[0] > 300


def test_show_draws_a_bare_image_with_a_resolution(tmp_path):
    world = generate_world("house", 80, seed=1)
    png = tmp_path / "plan.png"
    Image.fromarray(np.where(world.occupied, 0, 255).astype(np.uint8)).save(png)
    out = tmp_path / "picture.svg"
    result = run("show", str(png), "--resolution", "0.05", "-o", str(out))
    assert result.exit_code == 0, result.output
    assert out.read_text().lstrip().startswith("<?xml")


def test_info_describes_a_world():
    result = run("info", "lab_small_01")
    assert result.exit_code == 0, result.output
    for word in ("lab_small_01", "resolution", "free area", "reachable free area", "start pose", "1 connected region"):
        assert word in result.output


def test_generate_writes_a_rosmap_and_one_summary_line(tmp_path):
    out = tmp_path / "maps" / "office.yaml"
    result = run("generate", "--kind", "office", "--area", "150", "--seed", "3", "--out", str(out), "--name", "mine")
    assert result.exit_code == 0, result.output
    assert len(result.output.strip().splitlines()) == 1
    assert "office" in result.output and "m^2" in result.output
    loaded = load_world(out)
    expected = generate_world("office", 150, seed=3)
    assert loaded.name == "mine"
    assert np.array_equal(loaded.occupied, expected.occupied)
    assert loaded.metadata["kind"] == "office" and loaded.metadata["seed"] == 3


@pytest.mark.parametrize(
    "args, words",
    [
        (["generate", "--kind", "castle", "--area", "300", "--out", "x.yaml"], ["--kind", "castle", "office"]),
        (["generate", "--kind", "office", "--area", "5", "--out", "x.yaml"], ["--area", "5", "80"]),
        (["generate", "--kind", "office", "--area", "300", "--seed", "-2", "--out", "x.yaml"], ["--seed"]),
        (["generate", "--kind", "office", "--area", "300", "--out", "x.txt"], ["--out", ".yaml"]),
        (["show", "no_such_building", "-o", "x.png"], ["no_such_building"]),
        (["show", "office_small_01", "-o", "x.bmp3"], ["--out"]),
        (["info", "no_such_building"], ["no_such_building"]),
        (["info", "office_small_01", "--resolution", "-1"], ["--resolution"]),
    ],
)
def test_bad_input_is_one_line_and_exit_2(args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert_one_line_error(run(*args), *words)


def test_show_refuses_to_draw_over_the_floor_plan_it_reads(tmp_path):
    """A generated ROS map is office.yaml + office.png: drawing the picture to office.png would destroy it."""
    plan = tmp_path / "office.yaml"
    assert (
        runner.invoke(
            app, ["worlds", "generate", "--kind", "office", "--area", "150", "--seed", "3", "--out", str(plan)]
        ).exit_code
        == 0
    )
    image = tmp_path / "office.png"
    before = image.read_bytes()
    result = runner.invoke(app, ["worlds", "show", str(plan), "-o", str(image)])
    assert result.exit_code == 2 and "is the floor plan itself" in result.output
    assert image.read_bytes() == before
    assert runner.invoke(app, ["worlds", "show", str(plan), "-o", str(tmp_path / "picture.png")]).exit_code == 0
