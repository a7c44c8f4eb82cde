"""An external program's cost is its process's rusage: offline (run_program, run_offline), online (the
algorithm ``program`` over a recording and in a trial)."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import numpy as np
import pytest

from slamtrials.cost import CHILD_PROCESS, RunCost
from slamtrials.external import run_offline, run_program
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.slam.offline import run_over_recording
from slamtrials.slam.program import program_spec
from slamtrials.trial import TrialConfig, run_trial
from slamtrials.worlds import World

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"
PYTHON = shlex.quote(sys.executable)

#: Lines a program runs before its work: 0.3 s of CPU time and 64 MiB touched.
BURN = """
import time
_block = bytearray(64 * 2**20)
for _i in range(0, len(_block), 4096):
    _block[_i] = 1
_end = time.process_time() + 0.3
while time.process_time() < _end:
    pass
"""

#: An online client that answers the odometry, and burns at the end.
ONLINE = (
    """
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m["type"] == "frame":
        print(json.dumps({"pose": m["odometry"], "updates": m["index"] + 1}), flush=True)
    elif m["type"] == "end":
"""
    + "\n".join("        " + line for line in BURN.strip().splitlines())
    + """
        print("{}", flush=True)
        break
"""
)


def _box() -> World:
    occupied = np.ones((60, 100), bool)
    occupied[10:50, 10:90] = False
    return World(occupied, 0.05, name="box", start=np.array([1.0, 1.0, 0.0]))


@pytest.fixture(scope="module")
def record():
    return simulate_waypoints(_box(), [[3.5, 1.0], [3.5, 1.9]], SimConfig.paper(), seed=1, max_time=30)


def _assert_child_cost(cost: RunCost | None) -> None:
    assert cost is not None and cost.slam_process == CHILD_PROCESS
    assert 0.3 <= cost.slam_cpu_s < 10.0 and cost.slam_peak_mib >= 64.0
    assert cost.run_cpu_s >= cost.slam_cpu_s
    if cost.run_peak_mib is not None:
        assert cost.run_peak_mib > cost.slam_peak_mib


def test_an_offline_program_s_cost_is_its_process_s(record, tmp_path):
    script = tmp_path / "burn_then_odometry.py"
    script.write_text(BURN + (EXAMPLES / "odometry_program.py").read_text())
    spec = program_spec(command=f"{PYTHON} {shlex.quote(str(script))} {{input}} {{output}}")
    ran = run_program(record, spec, seed=1)
    _assert_child_cost(ran.cost)
    assert ran.cost.update_ms_median is None and ran.cost.updates_timed == 0  # a program is timed as a whole
    assert run_offline(record, "", program=spec, seed=1).cost.slam_process == CHILD_PROCESS


def test_an_online_program_s_cost_is_its_process_s(record, tmp_path):
    client = tmp_path / "client.py"
    client.write_text(ONLINE)
    result = run_over_recording(record, "program", overrides={"command": f"{PYTHON} {shlex.quote(str(client))}"})
    _assert_child_cost(result.cost)
    assert result.cost.updates_timed == len(record)  # it reports an update per frame: each call is timed
    assert 0.0 < result.cost.update_ms_median <= result.cost.update_ms_p90


def test_a_trial_with_an_online_program_records_the_program_s_cost(tmp_path):
    client = tmp_path / "client.py"
    client.write_text(ONLINE)
    config = TrialConfig.from_dict(
        {
            "sim": {"profile": "paper"},
            "termination": {"max_time": 5.0},
            "slam": {"algorithm": "program", "params": {"command": f"{PYTHON} {shlex.quote(str(client))}"}},
        }
    )
    record = run_trial(_box(), config, seed=2)
    _assert_child_cost(RunCost.of(record.metadata))
