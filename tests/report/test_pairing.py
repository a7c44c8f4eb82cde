"""Which campaigns share their recorded data: replays of each other or of one source, with the same seeds."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from slamtrials.report.load import CampaignData
from slamtrials.report.pairing import detect_pairing


def _data(folder: str, replay_of: str | None = None, seeds: tuple[int, ...] = (11, 12, 13)) -> CampaignData:
    runs = pd.DataFrame({"world": ["w"] * len(seeds), "run": range(len(seeds)), "seed": list(seeds)})
    meta = {"kind": "replay" if replay_of else "campaign"}
    config = {"replay_of": replay_of} if replay_of else {}
    return CampaignData(Path(folder), runs, pd.DataFrame(), config, meta)


def test_a_replay_and_its_source_are_paired_either_way() -> None:
    source, replay = _data("/c/c1"), _data("/c/c1-p80", replay_of="/c/c1")
    assert detect_pairing(source, replay, ("c1", "c1-p80")).paired_by == "c1-p80 is a replay of c1"
    assert detect_pairing(replay, source, ("c1-p80", "c1")).paired_by == "c1-p80 is a replay of c1"
    other = _data("/c/c1-karto", replay_of="/c/c1")
    assert detect_pairing(replay, other).paired_by == "both are replays of /c/c1"
    assert detect_pairing(source, source).paired_by == "the same campaign"


def test_independent_campaigns_and_replays_of_something_else_are_not_paired() -> None:
    a, b = _data("/c/c1"), _data("/c/c2")
    found = detect_pairing(a, b)
    assert found.paired_by is None and found.note == ""
    elsewhere = detect_pairing(a, _data("/c/r", replay_of="/c/c2"), ("c1", "r"))
    assert elsewhere.paired_by is None
    assert (
        elsewhere.note
        == "r is a replay of /c/c2, not of the other campaign nor of its source: the runs are not paired (Welch's test)"
    )
    # a "campaign" whose config names a source but whose catalog says it is not a replay is not one
    not_a_replay = CampaignData(Path("/c/x"), a.runs, pd.DataFrame(), {"replay_of": "/c/c1"}, {"kind": "campaign"})
    assert detect_pairing(a, not_a_replay).paired_by is None


def test_a_source_made_again_with_other_seeds_is_not_paired() -> None:
    source = _data("/c/c1", seeds=(11, 99, 13))  # run 1 was made again with another root seed
    replay = _data("/c/r", replay_of="/c/c1")
    found = detect_pairing(source, replay, ("c1", "r"))
    assert found.paired_by is None
    assert "run w/1 (seed 99 in c1, 12 in r) has another seed" in found.note and "not paired" in found.note
