"""The one line the commands print about what a run, or a world's runs, cost."""

from __future__ import annotations

from slamtrials.campaign.costsummary import world_cost
from slamtrials.cli.costtext import run_cost_text, world_cost_line
from slamtrials.cost import CHILD_PROCESS, RunCost


class Row:
    def __init__(self, world, cost):
        self.world, self.cost = world, cost


def test_a_run_s_cost_line():
    cost = RunCost(6.43, 52.2, 8.61, 280.4, 25.04, 41.2, updates_timed=9)
    assert run_cost_text(cost) == (
        "cost: SLAM 6.4 s CPU, 52 MiB, 25 ms per update (p90 41 ms); whole run 8.6 s CPU, 280 MiB peak"
    )
    program = RunCost(1.5, 30.0, 2.0, 300.0, slam_process=CHILD_PROCESS)
    assert run_cost_text(program) == "cost: the program's process 1.5 s CPU, 30 MiB; whole run 2.0 s CPU, 300 MiB peak"
    assert run_cost_text(RunCost(0.5, None, 0.7, None)) == "cost: SLAM 0.5 s CPU, -; whole run 0.7 s CPU, - peak"
    assert run_cost_text(None) == "cost: not measured"
    cold = RunCost(11.46, 152.2, 14.7, 502.3, 74.7, 162.4, updates_timed=282, compile_cpu_s=48.53)
    assert run_cost_text(cold).endswith("whole run 15 s CPU, 502 MiB peak; 49 s CPU compiling kernels, left out")
    assert "compiling" not in run_cost_text(RunCost(0.5, None, 0.7, None, compile_cpu_s=0.0))


def test_the_worlds_cost_line_skips_worlds_without_one():
    rows = [
        Row(
            "office",
            world_cost([{"slam_cpu_s": 3.7, "slam_peak_mib": 52.4, "update_ms_median": 74.4, "update_ms_p90": 105}]),
        ),
        Row("old", None),
    ]
    assert world_cost_line(rows) == "SLAM cost per run (mean): office 3.7 s CPU, 74 ms per update (p90 105 ms), 52 MiB"
    assert world_cost_line([Row("old", None)]) is None
