"""Opening a campaign folder safely: new or resumed, checked before any work, locked while running.

:func:`check_campaign_folder` checks all that without touching anything (so that a campaign fails
before it starts a cluster); :func:`open_campaign` creates the catalog of a new campaign, or opens an existing one after checking
that it was made by an equal config (same hash, ``output`` aside) and the same worlds; any mismatch is
a :class:`~slamtrials.errors.ConfigError` and nothing in the folder is touched. :func:`campaign_lock`
keeps a second driver off a running campaign (an advisory ``flock``, released by the OS even after
``kill -9``). :func:`prepare_resume` then puts back what an interrupted driver left: unfinished runs
are queued again, leftover partial run folders and run folders without a ``done`` row are deleted.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from slamtrials.campaign.config import CampaignConfig
from slamtrials.campaign.events import CampaignResult
from slamtrials.campaign.runfiles import clean_partials, remove_unrecorded
from slamtrials.campaign.store import CONFIG_FILE, CampaignStore, WorldInfo, check_new_folder, is_campaign
from slamtrials.campaign.summary import SUMMARY_FILE, summarize_store, write_summary_csv
from slamtrials.errors import ConfigError

__all__ = [
    "check_campaign_folder",
    "open_campaign",
    "campaign_lock",
    "driver_alive",
    "completed_result",
    "prepare_resume",
    "LOCK_FILE",
]

log = logging.getLogger(__name__)

LOCK_FILE = ".campaign.lock"

#: Tries (50 ms apart) to take the lock before concluding that another driver holds it.
_LOCK_ATTEMPTS = 5


def open_campaign(folder: Path, config: CampaignConfig, worlds: Sequence[WorldInfo], *, kind: str) -> CampaignStore:
    """Create or open the campaign in ``folder`` (see the module docstring).

    Raises
    ------
    ConfigError
        The folder holds another kind of campaign, a campaign of a different config or different
        worlds, or something that is not a campaign.
    """
    if not is_campaign(folder):
        return CampaignStore.create(folder, config, worlds, kind=kind)
    store = CampaignStore.open(folder)
    try:
        if store.kind != kind:
            verb = "campaign run" if store.kind == "campaign" else "campaign replay"
            raise ConfigError(f"{folder}: holds a {store.kind}, not a {kind}; continue it with 'slamtrials {verb}'")
        store.check_config(config)
        stored = [w.name for w in store.worlds()]
        given = [w.name for w in worlds]
        if stored != given:
            raise ConfigError(
                f"{folder}: the campaign's worlds are {', '.join(stored)} but the config gives {', '.join(given)}; "
                "choose another folder"
            )
    except BaseException:
        store.close()
        raise
    return store


def check_campaign_folder(folder: Path, config: CampaignConfig, worlds: Sequence[WorldInfo], *, kind: str) -> None:
    """Raise what :func:`open_campaign` would raise, without creating or changing anything."""
    if is_campaign(folder):
        open_campaign(folder, config, worlds, kind=kind).close()
    else:
        check_new_folder(folder)


@contextmanager
def campaign_lock(folder: Path) -> Iterator[None]:
    """Hold an exclusive advisory lock on ``folder`` (ConfigError if another process holds it)."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no locking
        yield
        return
    fd = os.open(Path(folder) / LOCK_FILE, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        for attempt in range(_LOCK_ATTEMPTS):  # a few tries: driver_alive may be probing it this instant
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError:
                if attempt == _LOCK_ATTEMPTS - 1:
                    raise ConfigError(f"{folder}: another slamtrials process is running this campaign") from None
                time.sleep(0.05)
        yield
    finally:
        os.close(fd)


def driver_alive(folder: Path) -> bool | None:
    """Whether a driver holds ``folder``'s :func:`campaign_lock` now (None: cannot tell, not POSIX).

    The lock is probed, not waited for: taken and released at once if free (its file is not created
    if missing: a folder never run has no driver). A driver killed in any way, ``kill -9`` included,
    released it, so a free lock means that the runs its catalog says are running were interrupted.
    A driver starting during the probe's microseconds tries again (:func:`campaign_lock`).
    """
    try:
        import fcntl
    except ImportError:
        return None
    try:
        fd = os.open(Path(folder) / LOCK_FILE, os.O_RDONLY)
    except FileNotFoundError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return True
    finally:
        os.close(fd)  # releases the lock if it was taken
    return False


def completed_result(folder: Path, finished: tuple[str, ...], notes: tuple[str, ...] = ()) -> CampaignResult | None:
    """The result of the campaign in ``folder`` if it is complete, else None.

    Complete: every world's status is in ``finished`` and no run is left ``running`` (a driver stopped
    between a run's folder and its commit leaves one, which a resume must redo). Nothing is run and no
    cluster is started for a complete campaign; ``summary.csv`` is written only if it is missing. Call
    it after :func:`check_campaign_folder` (it does not compare configs).
    """
    started = time.perf_counter()
    if not is_campaign(folder):
        return None
    with CampaignStore.open(folder) as store:
        worlds = store.worlds()
        if not worlds or any(w.status not in finished for w in worlds):
            return None
        if any(run.status == "running" for run in store.runs()):
            return None
        summary = summarize_store(store)
        csv_path = Path(folder) / SUMMARY_FILE
        if not csv_path.is_file():
            csv_path = write_summary_csv(folder, summary, store.config().runs.confidence)
    return CampaignResult(
        Path(folder), tuple(summary), csv_path, 0, 0, time.perf_counter() - started, notes, complete=True
    )


def prepare_resume(store: CampaignStore) -> None:
    """Queue unfinished runs again and delete partial or unrecorded run folders (driver-side, locked)."""
    requeued = store.prepare_resume()
    partials = clean_partials(store.folder)
    unrecorded = remove_unrecorded(store.folder, store.done_runs())
    if not (store.folder / CONFIG_FILE).is_file():
        store.write_config_file()
    if requeued or partials or unrecorded:
        log.info(
            "%s: resuming: %d runs queued again, %d partial and %d unrecorded run folders removed",
            store.folder,
            requeued,
            len(partials),
            len(unrecorded),
        )
