"""Run folders of a campaign, published atomically: ``runs/<world>/<index:03d>/``.

A worker writes a run into a fresh hidden sibling ``runs/<world>/.<index:03d>.partial-<random>/`` and
then renames it to its final name, so the final folder appears complete or not at all. The driver marks
the run ``done`` in the catalog only after that rename. On opening a campaign the driver deletes
leftover ``.partial-*`` folders (:func:`clean_partials`) and run folders without a ``done`` row
(:func:`remove_unrecorded`: a crash between the rename and the commit), which are then run again.
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

from slamtrials.campaign.store import RUNS_DIR

__all__ = ["run_folder", "relative_run_folder", "publish_run", "clean_partials", "remove_unrecorded", "PARTIAL_MARK"]

PARTIAL_MARK = ".partial-"


def relative_run_folder(world: str, index: int) -> str:
    """``runs/<world>/<index:03d>``, relative to the campaign folder (POSIX separators)."""
    return f"{RUNS_DIR}/{world}/{index:03d}"


def run_folder(campaign: str | Path, world: str, index: int) -> Path:
    """The final folder of run ``index`` of ``world``."""
    return Path(campaign) / RUNS_DIR / world / f"{index:03d}"


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def publish_run(campaign: str | Path, world: str, index: int, write: Callable[[Path], object]) -> Path:
    """Call ``write(tmp)`` on a fresh partial folder, then rename it to :func:`run_folder`.

    A final folder already there (from an earlier attempt that crashed before being recorded, or a
    twin task of a lost worker) is replaced: runs are reproducible, so both hold the same run.

    Returns
    -------
    Path
        The final run folder.
    """
    final = run_folder(campaign, world, index)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{index:03d}{PARTIAL_MARK}", dir=final.parent))
    try:
        write(tmp)
        for attempt in range(5):
            try:
                os.rename(tmp, final)
                break
            except OSError as exc:
                if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST, errno.EISDIR, errno.ENOTDIR) or attempt == 4:
                    raise
                shutil.rmtree(final, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    _fsync_dir(final.parent)
    return final


def clean_partials(campaign: str | Path) -> list[Path]:
    """Delete every leftover ``runs/<world>/.*.partial-*`` folder; return what was deleted."""
    runs = Path(campaign) / RUNS_DIR
    removed = sorted(runs.glob(f"*/.*{PARTIAL_MARK}*")) if runs.is_dir() else []
    for path in removed:
        shutil.rmtree(path, ignore_errors=True)
    return removed


def remove_unrecorded(campaign: str | Path, done: Iterable[tuple[str, int]]) -> list[Path]:
    """Delete run folders that have no ``done`` row (``done``: the ``(world, index)`` of done runs)."""
    keep = {run_folder(campaign, world, index) for world, index in done}
    runs = Path(campaign) / RUNS_DIR
    removed = []
    if runs.is_dir():
        for path in sorted(runs.glob("*/*")):
            if path.is_dir() and not path.name.startswith(".") and path not in keep:
                shutil.rmtree(path, ignore_errors=True)
                removed.append(path)
    return removed
