"""Static checks of the source tree: mypy over the computing layers finds no error.

The files and settings are pyproject.toml's ``[tool.mypy]`` section (the computing layers, pydantic
plugin); mypy runs in this process through its API, from the repository root.
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_mypy_finds_no_error(monkeypatch: pytest.MonkeyPatch) -> None:
    api = pytest.importorskip("mypy.api", reason="mypy is not installed (pip install -e '.[test]')")
    monkeypatch.chdir(ROOT)  # the [tool.mypy] files are relative to the repository root
    stdout, stderr, status = api.run(["--config-file", str(ROOT / "pyproject.toml")])
    assert status == 0, f"mypy (exit status {status}) reports:\n{stdout}{stderr}"
    assert "Success: no issues found" in stdout, stdout
