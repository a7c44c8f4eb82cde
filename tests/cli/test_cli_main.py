"""The root command: --version, --help everywhere, errors as one line with exit status 2."""

from __future__ import annotations

import typer
from typer.testing import CliRunner

from slamtrials.__about__ import __version__
from slamtrials.cli.main import app

runner = CliRunner()


def _all_command_paths(command, prefix=()):
    yield prefix
    for name, sub in getattr(command, "commands", {}).items():
        yield from _all_command_paths(sub, (*prefix, name))


def test_version():
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.output.strip() == f"slamtrials {__version__}"


def test_every_command_has_help():
    paths = list(_all_command_paths(typer.main.get_command(app)))
    assert ("simulate",) in paths and ("demo",) in paths and ("worlds", "list") in paths
    for path in paths:
        result = runner.invoke(app, [*path, "--help"])
        assert result.exit_code == 0, (path, result.output)
        assert "Usage" in result.output and "--help" in result.output


def test_unknown_world_is_one_line_and_exit_2(tmp_path):
    result = runner.invoke(app, ["simulate", "--world", "no_such_building", "--tour", "--out", str(tmp_path / "r")])
    assert result.exit_code == 2
    assert "no_such_building" in result.output
    assert "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_simulate_needs_exactly_one_path_source(tmp_path):
    result = runner.invoke(app, ["simulate", "--world", "office_small_01", "--out", str(tmp_path / "r")])
    assert result.exit_code == 2
    assert "--path" in result.output and "--tour" in result.output
