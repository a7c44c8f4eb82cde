"""Whether two campaigns share their recorded data, so that :func:`compare_campaigns` may pair their runs.

A replay (:mod:`slamtrials.campaign.replay`) stores its source campaign's folder as ``replay_of`` and
keeps the source's worlds, run indices and seeds: its run ``i`` of world ``w`` was computed from the
recorded laser and odometry of the source's run ``i`` of ``w``. Two campaigns are paired when one is a
replay of the other, or both are replays of the same source (the same folder). As a guard against a
source folder that was made again since (same path, other runs), every run index present in both must
have the same seed in both; otherwise the comparison falls back to Welch and says why.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from slamtrials.report.load import CampaignData

__all__ = ["Pairing", "detect_pairing"]


@dataclass(frozen=True)
class Pairing:
    """What :func:`detect_pairing` found.

    Attributes
    ----------
    paired_by:
        None: unpaired. Otherwise what the two campaigns share, in words, e.g. ``"B is a replay of A"``
        or ``"both are replays of /data/c1"`` (``compare_campaigns(paired_by=...)``).
    note:
        Why not, when one of the campaigns is a replay but the pairing was refused; else empty.
    """

    paired_by: str | None
    note: str = ""


def _source(data: CampaignData) -> Path | None:
    replay_of = data.config.get("replay_of")
    if data.kind != "replay" or not replay_of:
        return None
    return Path(str(replay_of)).absolute()


def _seed_mismatch(a: CampaignData, b: CampaignData, labels: tuple[str, str]) -> str:
    """The first run present in both whose seeds differ, as ``"world/run (seed x in A, y in B)"``; else ``""``."""
    keys = ["world", "run"]
    both = pd.merge(a.runs[[*keys, "seed"]], b.runs[[*keys, "seed"]], on=keys, suffixes=("_a", "_b"))
    differ = both[both["seed_a"] != both["seed_b"]]
    if differ.empty:
        return ""
    row = differ.sort_values(keys, kind="stable").iloc[0]
    return f"{row['world']}/{int(row['run'])} (seed {int(row['seed_a'])} in {labels[0]}, {int(row['seed_b'])} in {labels[1]})"


def detect_pairing(a: CampaignData, b: CampaignData, labels: tuple[str, str] = ("A", "B")) -> Pairing:
    """Whether the runs of ``a`` and ``b`` come from the same recorded data (see the module docstring).

    ``labels`` name A and B in the words of the result.
    """
    name_a, name_b = labels
    folder_a, folder_b = a.folder.absolute(), b.folder.absolute()
    source_a, source_b = _source(a), _source(b)
    if folder_a == folder_b:
        paired_by = "the same campaign"
    elif source_b is not None and source_b == folder_a:
        paired_by = f"{name_b} is a replay of {name_a}"
    elif source_a is not None and source_a == folder_b:
        paired_by = f"{name_a} is a replay of {name_b}"
    elif source_a is not None and source_a == source_b:
        paired_by = f"both are replays of {source_a}"
    else:
        replays = [(n, s) for n, s in ((name_a, source_a), (name_b, source_b)) if s is not None]
        note = "; ".join(f"{n} is a replay of {s}" for n, s in replays)
        if note:
            note += ", not of the other campaign nor of its source: the runs are not paired (Welch's test)"
        return Pairing(None, note)
    mismatch = _seed_mismatch(a, b, labels)
    if mismatch:
        return Pairing(
            None,
            f"{paired_by}, but run {mismatch} has another seed: the source was made again since, "
            "so the runs are not paired (Welch's test)",
        )
    return Pairing(paired_by)
