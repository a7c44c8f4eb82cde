"""The README's tour: every command it shows is a real command with real options, and its Python runs."""

from __future__ import annotations

import functools
import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app

README = Path(__file__).resolve().parents[1] / "README.md"


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README.read_text(), flags=re.S)


def _tour_commands() -> list[list[str]]:
    """The ``slamtrials ...`` lines of the README's shell blocks, continuation lines joined, comments cut."""
    commands = []
    for block in _blocks("sh"):
        text = block.replace("\\\n", " ")
        for line in text.splitlines():
            line = line.split("#", 1)[0].strip()
            if line.startswith("slamtrials "):
                commands.append(shlex.split(line.split(">", 1)[0])[1:])
    return commands


@functools.cache
def _cli():
    """The CLI's click command tree (built once: typer builds it anew on every call)."""
    import typer

    return typer.main.get_command(app)


def _command_words(words: list[str]) -> list[str]:
    """The leading words of ``words`` that name a (sub)command of the CLI."""
    command, named = _cli(), []
    for word in words:
        if not hasattr(command, "list_commands"):
            break
        ctx = command.context_class(command)
        if word not in command.list_commands(ctx):
            break
        command = command.get_command(ctx, word)
        named.append(word)
    return named


def test_the_tour_shows_real_commands_and_options():
    commands = _tour_commands()
    assert len(commands) >= 8
    runner = CliRunner()
    for words in commands:
        named = _command_words(words)
        assert named, words
        result = runner.invoke(app, [*named, "--help"], env={"COLUMNS": "200"})
        assert result.exit_code == 0, (words, result.output)
        for option in (w.split("=", 1)[0] for w in words if w.startswith("-")):
            assert re.search(rf"{re.escape(option)}(?![\w-])", result.output), (
                f"{' '.join(words)}: {option} is not an option of {' '.join(named)}"
            )


@pytest.mark.slow
def test_the_readme_python_runs():
    (code,) = _blocks("python")
    namespace: dict = {}
    exec(compile(code, str(README), "exec"), namespace)  # noqa: S102 - the README's own example
    assert namespace["record"].metadata["trial"]["termination_reason"] == "no_frontiers"
