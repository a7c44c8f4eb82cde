"""Static checks of the source tree: mypy over the computing layers and campaign and ruff (lint, format) over src, tests and bench find nothing.

The files and settings are pyproject.toml's ``[tool.mypy]`` section (the computing layers, pydantic
plugin); mypy runs in this process through its API, from the repository root.
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow  # about 16 s with a cold mypy cache (a clean clone, many files changed), 2 s warm
def test_mypy_finds_no_error(monkeypatch: pytest.MonkeyPatch) -> None:
    api = pytest.importorskip("mypy.api", reason="mypy is not installed (pip install -e '.[test]')")
    monkeypatch.chdir(ROOT)  # the [tool.mypy] files are relative to the repository root
    stdout, stderr, status = api.run(["--config-file", str(ROOT / "pyproject.toml")])
    assert status == 0, f"mypy (exit status {status}) reports:\n{stdout}{stderr}"
    assert "Success: no issues found" in stdout, stdout


def _ruff(*args: str) -> tuple[int, str]:
    import shutil
    import subprocess
    import sys

    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed (pip install -e '.[test]')")
    done = subprocess.run([ruff, *args, "src", "tests", "bench"], cwd=ROOT, capture_output=True, text=True, check=False)
    return done.returncode, done.stdout + done.stderr


def test_ruff_lint_finds_nothing() -> None:
    status, report = _ruff("check", "--no-cache")
    assert status == 0, f"ruff check reports:\n{report}"


def test_ruff_format_leaves_every_file_as_it_is() -> None:
    status, report = _ruff("format", "--check", "--no-cache")
    assert status == 0, (
        f"ruff format --check: these files are not formatted (run ruff format src tests bench):\n{report}"
    )
