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
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from slamtrials.campaign.config import CampaignConfig
from slamtrials.campaign.runfiles import clean_partials, remove_unrecorded
from slamtrials.campaign.store import CONFIG_FILE, CampaignStore, WorldInfo, check_new_folder, is_campaign
from slamtrials.errors import ConfigError

__all__ = ["check_campaign_folder", "open_campaign", "campaign_lock", "prepare_resume", "LOCK_FILE"]

log = logging.getLogger(__name__)

LOCK_FILE = ".campaign.lock"


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
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise ConfigError(f"{folder}: another slamtrials process is running this campaign") from None
        yield
    finally:
        os.close(fd)


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
