"""The CLI's console prints text as given: brackets in paths and values are not taken for style tags."""

import pytest

from slamtrials.cli.common import make_console


def test_brackets_survive(capsys):
    console = make_console()
    console.print("folder /tmp/runs[2]/x, range [0.1, 0.2], [bold]tag[/bold]")
    out = capsys.readouterr().out
    assert "runs[2]/x" in out and "[0.1, 0.2]" in out and "[bold]tag[/bold]" in out


@pytest.mark.slow  # a new Python process (about 2.5 s of imports)
def test_python_dash_m_runs_the_command():
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "slamtrials", "--help"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and "Usage" in done.stdout and "campaign" in done.stdout
