"""The exploration line of ``slamtrials trial``."""

from __future__ import annotations

from slamtrials.cli.explorationtext import exploration_text
from slamtrials.trial.exploration import exploration_measures


def test_the_line_names_both_thresholds_and_the_end():
    found = exploration_measures([0.0, 139.8, 191.3], [0.2, 0.95, 0.9995], [0.0, 51.2, 72.8], "no_frontiers")
    assert exploration_text(found) == (
        "exploration: 90 % after 140 s and 51 m, 99 % after 191 s and 73 m; 100.0 % mapped at the end"
    )


def test_a_threshold_never_reached_and_a_run_without_measures():
    found = exploration_measures([0.0, 10.0], [0.2, 0.93], [0.0, 4.0], "time_cap")
    assert exploration_text(found) == "exploration: 90 % after 10 s and 4 m, 99 % never; 93.0 % mapped at the end"
    assert exploration_text(None) == "exploration: not recorded"
