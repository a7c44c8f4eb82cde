"""The root command: --version, --help everywhere, errors as one line with exit status 2."""

from __future__ import annotations

import pytest
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


@pytest.fixture(scope="module")
def helps():
    """``{columns: [(words, result), ...]}``: the help of every command at 60, 100 and 120 columns, rendered
    once for the tests below (a render takes some 30 ms; the CLI has about 30 commands)."""
    paths = list(_command_paths(typer.main.get_command(app)))
    return {
        columns: [(words, runner.invoke(app, [*words, "--help"], env={"COLUMNS": columns})) for words in paths]
        for columns in ("60", "100", "120")
    }


def test_every_command_has_help(helps):
    paths = list(_all_command_paths(typer.main.get_command(app)))
    assert ("simulate",) in paths and ("demo",) in paths and ("worlds", "list") in paths
    assert sorted(paths) == sorted(words for words, _ in helps["120"])
    for path, result in helps["120"]:
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


def _help_texts(command, path=()):
    """(where, text) for the help text of every command and every option and argument under ``command``."""
    if command.help:
        yield " ".join(path) or "slamtrials", command.help
    for param in command.params:
        if getattr(param, "help", None):
            yield f"{' '.join(path)} {param.name}", param.help
    for name, sub in getattr(command, "commands", {}).items():
        yield from _help_texts(sub, (*path, name))


def test_no_help_text_loses_brackets_to_rich_markup():
    # typer renders help as rich markup: an unescaped "[x, y]" or "[default: ...]" is a style tag and vanishes
    from rich.text import Text

    texts = list(_help_texts(typer.main.get_command(app)))
    assert len(texts) > 50
    for where, text in texts:
        assert Text.from_markup(text).plain == text.replace("\\[", "["), where


def test_simulate_help_shows_the_waypoints_example():
    result = runner.invoke(app, ["simulate", "--help"], env={"COLUMNS": "200"})
    assert result.exit_code == 0
    assert "'waypoints: [[x, y], ...]'" in result.output


def test_import_help_shows_the_default_topics():
    result = runner.invoke(app, ["import", "--help"], env={"COLUMNS": "200"})
    assert (
        "[default: /base_scan]" in result.output
        and "[default: /base_pose_ground_truth when the bag has it" in result.output
    )


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (
            ["export", "RUN", "--to", "xyz", "--out", "x.bag"],
            "error: --to: 'xyz' is not one of 'bag', 'bag2', 'carmen', 'tum'",
        ),
        (
            ["export", "RUN", "--to", "tum", "--what", "gps", "--out", "x.tum"],
            "error: --what: 'gps' is not one of 'truth', 'odometry'",
        ),
        (
            ["import", "x.bag", "--out", "r", "--format", "csv"],
            "error: --format: 'csv' is not one of 'auto', 'bag', 'carmen'",
        ),
        (["export-table", "CAMPAIGN", "--format", "xls"], "error: --format: 'xls' is not one of 'csv', 'parquet'"),
        (
            ["simulate", "--world", "office_small_01", "--tour", "--seed", "three", "--out", "r"],
            "error: --seed: Input should be a valid integer",
        ),
    ],
)
def test_a_bad_option_value_is_one_line_and_exit_2(args, expected):
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(expected), result.output


def test_a_missing_option_keeps_the_usage_panel():
    result = runner.invoke(app, ["export", "RUN", "--to", "tum"])
    assert result.exit_code == 2
    assert "Missing option '--out'" in result.output and "Usage" in result.output


def _command_paths(group, prefix=()):
    """Every command of the CLI as the words that name it, groups included."""
    yield prefix
    if hasattr(group, "list_commands"):  # a group (typer vendors its own click)
        ctx = group.context_class(group)
        for name in group.list_commands(ctx):
            yield from _command_paths(group.get_command(ctx, name), (*prefix, name))


def test_boolean_flags_are_shown_as_flags_in_every_help(helps):
    """typer's rich help prints a type after every option; a flag must not read as taking a value."""
    assert len(helps["120"]) > 15
    for words, result in helps["120"]:
        assert result.exit_code == 0, (words, result.output)
        assert "<bool>" not in result.output, words
    shown = runner.invoke(app, ["trial", "--help"], env={"COLUMNS": "120"}).output
    assert "--overwrite" in shown and "<int>" in shown


def test_every_help_is_reflowed_to_the_terminal_and_cuts_no_word(helps):
    """A docstring's line breaks are not kept inside a paragraph (they left ragged lines), and a word
    too long for its column (an option name, a path) is folded, never cut with an ellipsis."""
    from slamtrials.cli.common import reflow

    assert reflow("One two\nthree.\n\nA list:\n\n- a\n- b\n\n    indented\n    block") == (
        "One two three.\n\nA list:\n\n- a\n- b\n\n    indented\n    block"
    )
    for columns in ("60", "100"):
        for words, result in helps[columns]:
            assert result.exit_code == 0, (words, result.output)
            assert "…" not in result.output, (words, columns, result.output)
    # the validate docstring's second paragraph wraps as one paragraph: no line ends mid-sentence early
    result = runner.invoke(app, ["validate", "--help"], env={"COLUMNS": "100"})
    text_lines = [line.strip() for line in result.output.splitlines() if line.strip() and "│" not in line]
    long_enough = [line for line in text_lines[2:8] if not line.endswith((".", ":"))]
    assert all(len(line) > 70 for line in long_enough), text_lines[:8]
