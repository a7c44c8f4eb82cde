"""The tutorial "Evaluate your own SLAM" (docs/programs.md) runs as written: every ``slamtrials`` command
of its shell blocks, in order, from a folder where ``docs/`` is the repository's."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app

REPO = Path(__file__).resolve().parents[1]
PAGE = REPO / "docs" / "programs.md"


def _commands() -> list[tuple[list[str], str]]:
    """(arguments, the comment after ``# error:`` or '') of each ``slamtrials`` line of the sh blocks."""
    commands = []
    for block in re.findall(r"```sh\n(.*?)```", PAGE.read_text(encoding="utf-8"), flags=re.S):
        for line in block.replace("\\\n", " ").splitlines():
            code, _, comment = line.partition("    #")
            if code.strip().startswith("slamtrials "):
                expected = comment.strip().removeprefix("error:").strip() if "error:" in comment else ""
                commands.append((shlex.split(code)[1:], expected))
    return commands


@pytest.mark.slow
def test_the_tutorial_runs_as_written(tmp_path, monkeypatch):
    (tmp_path / "docs").symlink_to(REPO / "docs", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    commands = _commands()
    assert len(commands) >= 5
    runner = CliRunner()
    for words, error in commands:
        result = runner.invoke(app, words, env={"COLUMNS": "200"})
        if error:
            assert result.exit_code == 2, (words, result.output)
            first, _, last = error.partition("...")
            assert first.strip() in result.output and last.strip() in result.output, result.output
            out = Path(words[words.index("--out") + 1])
            assert not out.exists()  # a failed program leaves nothing
        else:
            assert result.exit_code == 0, (words, result.output)
    # the three ways produced what the page says
    assert (tmp_path / "slam" / "dr" / "slam.json").is_file()
    summary = json.loads((tmp_path / "slam" / "program" / "slam.json").read_text())
    assert summary["algorithm"] == "program:odometry_program.py"
    online = json.loads((tmp_path / "runs" / "online" / "run.json").read_text())
    assert online["config"]["slam"]["algorithm"] == "program"


def test_the_readme_shows_the_tutorials_commands():
    """The README's "Evaluate your own SLAM" commands are the tutorial's, so the test above runs them."""
    readme = (REPO / "README.md").read_text(encoding="utf-8").split("## Evaluate your own SLAM", 1)[1]
    block = re.findall(r"```sh\n(.*?)```", readme, flags=re.S)[0].replace("\\\n", " ")
    shown = [shlex.split(line.split("#", 1)[0]) for line in block.splitlines() if line.startswith("slamtrials ")]
    assert len(shown) == 4
    run = [["slamtrials", *words] for words, _ in _commands()]
    for words in shown:
        assert words in run, words
