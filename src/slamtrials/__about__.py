"""The package version, and the source revision when the package runs from a git checkout."""

from __future__ import annotations

import functools
import subprocess
from pathlib import Path

__version__ = "0.1.0"


@functools.lru_cache(maxsize=1)
def source_revision() -> str | None:
    """The git commit of the source the package was imported from (12 hex digits, ``+dirty`` when the
    package's files differ from it), or ``None`` outside a git checkout or without git.

    The package version alone does not tell two development states apart; a run's provenance needs
    this. Asked once per process (a campaign's workers ask when they write their first run).
    """
    here = Path(__file__).resolve().parent
    try:

        def git(*args: str) -> str:
            return subprocess.run(
                ["git", "-C", str(here), *args], capture_output=True, text=True, timeout=10, check=True
            ).stdout.strip()

        commit = git("rev-parse", "--short=12", "HEAD")
        dirty = git("status", "--porcelain", "--untracked-files=no", "--", ".")
    except (OSError, subprocess.SubprocessError):
        return None
    return f"{commit}+dirty" if dirty else commit or None
