"""The study's paired comparisons without a cluster: identical comparisons stay out of the correction's
family, and the adjusted intervals are labelled by comparisons, not worlds."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from slamtrials.report.compare import NO_DIFFERENCE, adjust_pvalues
from slamtrials.study.cells import expand_cells
from slamtrials.study.comparisons import IDENTICAL_RULE, compare_neighbours
from slamtrials.study.config import StudyConfig
from slamtrials.study.report import _comparisons_section

WORLDS = ["office_small_01", "lab_small_01", "house_small_01"]


def _runs(shift: dict[str, float]) -> pd.DataFrame:
    """Seven runs per world with fixed errors, ``eps_t`` shifted per world by ``shift`` (m) and a little noise
    where the shift is not 0, so that the paired differences vary."""
    rows = []
    for w, world in enumerate(WORLDS):
        base = np.linspace(0.20, 0.26, 7) + 0.01 * w
        noise = np.zeros(7) if shift[world] == 0.0 else 0.004 * np.sin(np.arange(7) + w)
        for k in range(7):
            t = float(base[k] + shift[world] + noise[k])
            r = 0.04 + 0.001 * k + (0.0 if shift[world] == 0.0 else 0.0005 * np.cos(k + w))
            rows.append({"world": world, "run": k, "seed": 100 * w + k, "eps_t": t, "eps_r": r})
    return pd.DataFrame(rows)


@pytest.fixture(scope="module")
def compared():
    config = StudyConfig.from_dict({"campaign": {"worlds": WORLDS}, "axes": {"sim.laser.max_range": [30, 15]}})
    cells = expand_cells(config)
    runs = {
        cells[0].name: _runs(dict.fromkeys(WORLDS, 0.0)),
        # office: every run the same in both cells (identical); lab and house differ
        cells[1].name: _runs({"office_small_01": 0.0, "lab_small_01": 0.012, "house_small_01": 0.004}),
    }
    # the identical world's runs are those of cell A, bit for bit
    office = runs[cells[1].name]["world"] == "office_small_01"
    runs[cells[1].name].loc[office, ["eps_t", "eps_r"]] = runs[cells[0].name].loc[office, ["eps_t", "eps_r"]].values
    return compare_neighbours(cells, config.axes, runs)


def test_identical_comparisons_are_left_out_of_the_holm_family(compared):
    table, levels = compared
    rows = table[table["metric"] == "eps_t"].set_index("world")
    assert list(rows["identical"]) == [True, False, False]
    office = rows.loc["office_small_01"]
    assert (office["p"], office["p_adjusted"], office["wilcoxon_p_adjusted"]) == (1.0, 1.0, 1.0)
    assert office["verdict"] == NO_DIFFERENCE and office["ci_adj_low"] == office["ci_adj_high"] == 0.0
    # Holm over the two comparisons that differ, not three
    others = rows.loc[["lab_small_01", "house_small_01"]]
    expected = adjust_pvalues(others["p"].to_numpy(), "holm")
    assert others["p_adjusted"].to_numpy() == pytest.approx(expected, rel=0, abs=0)
    assert min(others["p_adjusted"]) == pytest.approx(2 * min(others["p"]))
    assert levels["eps_t"].confidence == pytest.approx(1 - 0.05 / 2)


def test_the_adjusted_intervals_are_labelled_by_comparisons_and_the_rule_is_stated(compared):
    table, levels = compared
    assert "2 comparisons" in levels["eps_t"].label and "world" not in levels["eps_t"].label
    html = _comparisons_section(table, levels, 0.05, "holm")
    assert "Bonferroni, 2 comparisons: each at 97.5%" in html
    assert "worlds:" not in html
    assert "identical runs" in html and "(1 comparison of identical runs left out)" in html
    assert IDENTICAL_RULE.split(" (")[0] in html  # the rule, in the page
