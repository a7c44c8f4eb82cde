"""``campaign replay --program``: an external program over a campaign's recorded runs. The reference
program (its estimate is the odometry) scores like the ``odometry`` algorithm on the same relation sets;
a run the program fails on is a failed run naming its exit status; a campaign (or trial) that would run
a program online is refused in one line."""

from __future__ import annotations

import json
import shlex
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from slamtrials.campaign import CampaignConfig, replay_campaign, run_campaign
from slamtrials.campaign.store import CampaignStore
from slamtrials.campaign.testing import FakeTrial
from slamtrials.errors import ConfigError
from slamtrials.record import RunRecord
from slamtrials.slam.program import program_spec

ODOMETRY_PROGRAM = Path(__file__).resolve().parents[2] / "docs" / "examples" / "odometry_program.py"
ODOMETRY_COMMAND = f"{shlex.quote(sys.executable)} {shlex.quote(str(ODOMETRY_PROGRAM))} {{input}} {{output}}"
#: Fails (status 5, with a line on stderr) on runs whose seed is odd; else the reference program.
FAILS_ON_ODD_SEEDS = "sh -c 'case $0 in *[13579]) echo odd seed $0 >&2; exit 5;; esac' {seed} && " + ODOMETRY_COMMAND


@dataclass(frozen=True)
class DriftTrial:
    """A short simulated drive (scans, a drifting odometry) whose SLAM estimate is the odometry, with
    :class:`FakeTrial`'s trial summary: a recorded run a program can be replayed over in well under a second."""

    def __call__(self, world, config, seed: int) -> RunRecord:
        from slamtrials.sim import SimConfig, simulate_waypoints

        sim = simulate_waypoints(world, [[3.0, 1.5], [3.0, 2.2], [1.5, 2.2]], SimConfig(), seed=seed, max_time=30)
        fake = FakeTrial()(world, config, seed)
        return RunRecord(
            t=sim.t,
            scans=sim.scans,
            odometry=sim.odometry,
            truth=sim.truth,
            stalled=sim.stalled,
            laser=sim.laser,
            metadata=fake.metadata,
            estimate=sim.odometry.copy(),
            map=fake.map,
        )


def source_config(rooms) -> CampaignConfig:
    return CampaignConfig.from_dict(
        {
            "worlds": rooms[:1],
            "seed": 5,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 5, "max_runs": 5},
        }
    )


@pytest.fixture(scope="module")
def source(tmp_path_factory, rooms, client):
    folder = tmp_path_factory.mktemp("source") / "c"
    result = run_campaign(source_config(rooms), folder, scheduler=client, trial_fn=DriftTrial())
    assert result.runs_done == 5 and result.runs_failed == 0
    return folder


@pytest.fixture(scope="module")
def odometry_replay(source, tmp_path_factory, client):
    folder = tmp_path_factory.mktemp("odometry") / "r"
    replay_campaign(source, folder, "odometry", None, scheduler=client)
    return folder


def runs_of(folder):
    with CampaignStore.open(folder) as store:
        return {(r.world, r.idx): r for r in store.runs()}


@pytest.mark.slow  # the source campaign and its odometry replay: ~5 s
def test_the_reference_program_scores_like_the_odometry_algorithm(source, odometry_replay, tmp_path, client):
    out = tmp_path / "program"
    result = replay_campaign(source, out, program=program_spec(command=ODOMETRY_COMMAND), scheduler=client)
    assert result.runs_done == 5 and result.runs_failed == 0
    with CampaignStore.open(out) as store:
        assert store.kind == "replay"
        slam = store.config().slam
    assert slam.program is not None and slam.program.command == ODOMETRY_COMMAND
    assert slam.algorithm == "program:odometry_program.py" and slam.preset is None
    program_runs, odometry_runs = runs_of(out), runs_of(odometry_replay)
    assert program_runs.keys() == odometry_runs.keys() == runs_of(source).keys()
    for key, run in program_runs.items():
        reference = odometry_runs[key]
        assert run.status == reference.status == "done"
        assert run.seed == reference.seed
        assert run.eps_t == pytest.approx(reference.eps_t, abs=1e-6) and run.eps_r == pytest.approx(
            reference.eps_r, abs=1e-6
        )
        assert run.eps_t > 1e-3  # the odometry drifts: the check is not 0 == 0
        # scored on the source run's own relation set
        assert (out / run.folder / "relations.npz").read_bytes() == (source / run.folder / "relations.npz").read_bytes()
        doc = json.loads((out / run.folder / "run.json").read_text())
        assert doc["replay"]["program"]["command"] == ODOMETRY_COMMAND
        assert doc["replay"]["source_run"] == str(source / run.folder)
        assert doc["program"]["poses_written"] == doc["program"]["frames_at_a_pose"] > 10
        assert doc["program"]["time_origin_s"] == 0.0 and "{" not in doc["program"]["command"]
        assert str(run.seed) not in doc["program"]["command"]  # the reference program takes no {seed}
    assert [r.runs for r in result.summary] == [5]
    # the same replay again: complete, nothing run (an unreachable scheduler would fail any work)
    again = replay_campaign(source, out, program=program_spec(command=ODOMETRY_COMMAND), scheduler="tcp://127.0.0.1:1")
    assert again.complete


@pytest.mark.slow  # the source campaign and its odometry replay: ~5 s
def test_a_run_the_program_fails_on_is_a_failed_run_naming_its_status(source, tmp_path, client):
    seeds = {key: run.seed for key, run in runs_of(source).items()}
    odd = {key for key, seed in seeds.items() if str(seed)[-1] in "13579"}
    if not odd or len(odd) == len(seeds):
        pytest.skip("the source's seeds do not mix odd and even")  # fixed seed 5: they do
    out = tmp_path / "failing"
    result = replay_campaign(source, out, program=program_spec(command=FAILS_ON_ODD_SEEDS), scheduler=client)
    assert result.runs_failed == len(odd) and result.runs_done == len(seeds) - len(odd)
    for key, run in runs_of(out).items():
        if key in odd:
            assert run.status == "failed", key
            assert run.error.startswith("ProgramError: ") and "exited with status 5" in run.error, run.error
            assert f"its stderr ends: odd seed {seeds[key]}" in run.error and "\n" not in run.error
        else:
            assert run.status == "done" and run.error is None, (key, run.error)


@pytest.mark.slow  # the source campaign and its odometry replay: ~5 s
def test_the_cli_replays_with_a_program(source, odometry_replay, tmp_path, client):
    from typer.testing import CliRunner

    from slamtrials.cli.main import app

    out = tmp_path / "cli"
    args = ["campaign", "replay", str(source), "--out", str(out), "--program", ODOMETRY_COMMAND]
    result = CliRunner().invoke(app, [*args, "--scheduler", client.scheduler.address])
    assert result.exit_code == 0, result.output
    assert "slam.program" in result.output and "program:odometry_program.py" in result.output
    program_runs, odometry_runs = runs_of(out), runs_of(odometry_replay)
    for key, run in program_runs.items():
        assert run.eps_t == pytest.approx(odometry_runs[key].eps_t, abs=1e-6)
    both = CliRunner().invoke(
        app, [*args[:-2], "--out", str(tmp_path / "x"), "--program", ODOMETRY_COMMAND, "-a", "karto"]
    )
    assert both.exit_code == 2 and "either --program or --algorithm" in both.output
    assert len(both.output.strip().splitlines()) == 1 and not (tmp_path / "x").exists()


@pytest.mark.slow  # the source campaign and its odometry replay: ~5 s
def test_a_program_with_an_algorithm_preset_or_parameters_is_refused(source, tmp_path):
    spec = program_spec(command=ODOMETRY_COMMAND)
    for extra in ({"algorithm": "karto"}, {"params": {"resolution": 0.1}}, {"preset": None}):
        with pytest.raises(ConfigError, match="either --program or --algorithm"):
            replay_campaign(source, tmp_path / "r", program=spec, **extra)
    with pytest.raises(ConfigError, match="not found on PATH"):
        replay_campaign(source, tmp_path / "r", program=program_spec(command="no-such-slam-xyz {input} {output}"))
    assert not (tmp_path / "r").exists()


# --- a program does not run online ------------------------------------------------------------------------


def test_a_campaign_or_trial_config_with_a_program_is_refused_in_one_line(rooms):
    from slamtrials.trial import TrialConfig

    slam = {"program": {"command": "my_slam {input} {output}", "input": "bag"}}
    with pytest.raises(ConfigError) as info:
        CampaignConfig.from_dict({"worlds": rooms, "slam": slam})
    message = str(info.value)
    assert message.startswith("campaign config: slam: slam.program (program:my_slam) runs offline"), message
    assert "campaign replay SOURCE --program" in message and "\n" not in message
    with pytest.raises(ConfigError, match=r"slam.program \(program:my_slam\) runs offline") as info:
        TrialConfig.from_dict({"slam": slam})
    assert "\n" not in str(info.value)
    with pytest.raises(ConfigError, match="slam.program replaces slam.algorithm") as info:
        CampaignConfig.from_dict({"worlds": rooms, "slam": {**slam, "algorithm": "karto"}})
    assert "\n" not in str(info.value)
    with pytest.raises(ConfigError, match="must hold {output}"):
        CampaignConfig.from_dict({"worlds": rooms, "slam": {"program": {"command": "my_slam {input}"}}})
