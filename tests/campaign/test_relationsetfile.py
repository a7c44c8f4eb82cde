"""relations.npz: a run's relation set written and read back exactly; broken files are one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from slamtrials.campaign.relationsetfile import read_relation_set, write_relation_set
from slamtrials.errors import FormatError
from slamtrials.metric import SamplingRule, draw_relation_set
from slamtrials.record import Trajectory


def _set(rule=None):
    t = np.arange(400) * 0.1
    truth = np.column_stack([0.05 * np.arange(400), np.zeros(400), np.zeros(400)])
    noisy = truth + np.random.default_rng(1).normal(0.0, 0.02, truth.shape)
    relation_set, _ = draw_relation_set(
        Trajectory(t=t, poses=truth), Trajectory(t=t, poses=noisy), seed=9, rule=rule or SamplingRule()
    )
    return relation_set


@pytest.mark.parametrize("rule", [SamplingRule(), SamplingRule(rule="paper", margin_t=0.005)])
def test_round_trip_is_exact(tmp_path, rule):
    relation_set = _set(rule)
    path = write_relation_set(tmp_path / "relations.npz", relation_set)
    back = read_relation_set(path)
    np.testing.assert_array_equal(back.first, relation_set.first)
    np.testing.assert_array_equal(back.second, relation_set.second)
    assert back.first.dtype == np.int64
    for name in ("frames", "seed", "rule", "sized_on", "mean_t", "mean_r", "std_t", "std_r", "needed_t", "capped"):
        assert getattr(back, name) == getattr(relation_set, name), name


def test_broken_files_name_the_file_and_the_problem(tmp_path):
    relation_set = _set()
    good = write_relation_set(tmp_path / "good.npz", relation_set)
    with np.load(good) as npz:
        arrays = {name: npz[name] for name in npz.files}
    info = json.loads(str(arrays["info"]))

    def broken(name, **changes):
        path = tmp_path / name
        np.savez(path, **{**arrays, **changes})
        return path

    with pytest.raises(FormatError, match="no array second"):
        np.savez(tmp_path / "short.npz", first=arrays["first"], info=arrays["info"])
        read_relation_set(tmp_path / "short.npz")
    with pytest.raises(FormatError, match="0 <= first < second < 400"):
        read_relation_set(broken("order.npz", first=arrays["second"], second=arrays["first"]))
    with pytest.raises(FormatError, match="info: no field 'seed'"):
        read_relation_set(broken("seed.npz", info=np.array(json.dumps({k: v for k, v in info.items() if k != "seed"}))))
    with pytest.raises(FormatError, match="info.rule"):
        read_relation_set(broken("rule.npz", info=np.array(json.dumps({**info, "rule": {"rule": "loose"}}))))
    (tmp_path / "text.npz").write_text("not a zip")
    with pytest.raises(FormatError, match="text.npz: not a readable"):
        read_relation_set(tmp_path / "text.npz")
