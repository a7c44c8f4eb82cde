"""The user guide's "Plugging in a SLAM algorithm" example runs as written: Python API and command line."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.io.runfolder import write_run
from slamtrials.io.tum import read_tum
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.slam import ALGORITHMS, OdometrySlam
from slamtrials.worlds import World

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide.md"
EXAMPLE = GUIDE.parent / "examples" / "dead_reckoning.py"


def _section_blocks(language: str) -> list[str]:
    text = GUIDE.read_text(encoding="utf-8")
    section = text.split("## Plugging in a SLAM algorithm", 1)[1].split("\n## ", 1)[0]
    return re.findall(rf"```{language}\n(.*?)```", section, flags=re.S)


@pytest.fixture
def readme_algorithm():
    namespace: dict = {"__name__": "readme_example"}
    assert _section_blocks("python")[0].strip() == f'--8<-- "docs/examples/{EXAMPLE.name}"'  # the guide shows it
    exec(compile(EXAMPLE.read_text(encoding="utf-8"), str(EXAMPLE), "exec"), namespace)  # noqa: S102 - our own example
    yield namespace["DeadReckoning"]
    ALGORITHMS.pop("dead-reckoning", None)


def _run(tmp_path: Path):
    occ = np.ones((60, 100), bool)
    occ[10:50, 10:90] = False
    world = World(occ, 0.05, name="box", start=np.array([1.0, 1.0, 0.0]))
    record = simulate_waypoints(world, [[3.5, 1.0], [3.5, 1.9]], SimConfig.paper(), seed=1, max_time=30)
    return write_run(tmp_path / "run", record), record


def test_readme_algorithm_through_python_and_cli(readme_algorithm, tmp_path):
    from slamtrials.slamrun import load_recording, run_slam, write_slam_outputs

    assert ALGORITHMS["dead-reckoning"] is readme_algorithm
    folder, record = _run(tmp_path)
    result = run_slam(load_recording(folder), "dead-reckoning", preset="coarse", seed=0)
    write_slam_outputs(result, tmp_path / "py")
    np.testing.assert_allclose(result.trajectory.poses, record.odometry)
    assert result.occupancy.resolution == 0.2 and (result.occupancy.grid == 100).any()
    # the same map as the built-in baseline at that resolution
    baseline = run_slam(record, "odometry", overrides={"resolution": 0.2})
    np.testing.assert_array_equal(result.occupancy.grid, baseline.occupancy.grid)
    out = tmp_path / "cli"
    slam = runner_invoke(
        ["slam", "--algorithm", "dead-reckoning", "--preset", "coarse", "--input", str(folder), "--out", str(out)]
    )
    assert slam.exit_code == 0, slam.output
    np.testing.assert_allclose(read_tum(out / "trajectory.tum").poses[:, :2], record.odometry[:, :2], atol=1e-6)
    evaluated = runner_invoke(["evaluate", str(folder), "--estimate", str(out / "trajectory.tum")])
    assert evaluated.exit_code == 0 and "Translational error" in evaluated.output
    assert OdometrySlam.name == "odometry"


def test_readme_commands_name_real_options():
    commands = "\n".join(_section_blocks("sh"))
    for option in re.findall(r"(--[a-z-]+)", commands):
        assert option in {"--algorithm", "--input", "--out", "--set", "--preset", "--estimate"}, option


def runner_invoke(args):
    return CliRunner().invoke(app, args)
