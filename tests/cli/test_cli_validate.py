"""``slamtrials validate`` end to end on a small simulated "real" run: the table, --json, the figure, and
one-line errors (exit 2, nothing written) for inputs that do not belong together and bad profiles."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.io.relations import write_relations
from slamtrials.io.runfolder import write_run
from slamtrials.metric.sampling import relations_between
from slamtrials.record import Relations, Trajectory
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.sim.profiles import DEFAULT_PROFILE
from slamtrials.worlds import World

runner = CliRunner()


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    occ = np.ones((80, 140), bool)
    occ[10:70, 10:130] = False
    occ[10:35, 60:63] = True
    world = World(occ, 0.05, name="room", start=np.array([1.0, 1.0, 0.0]))
    record = simulate_waypoints(world, [[5.5, 1.0], [5.5, 2.6], [1.0, 2.6]], SimConfig.paper(), seed=1, max_time=60)
    base = tmp_path_factory.mktemp("validate")
    write_run(base / "run", record)
    i = np.arange(0, len(record) - 15, 7)
    relations = relations_between(Trajectory(t=record.t, poses=record.truth), i, i + 10)
    write_relations(base / "run.relations", relations)
    shifted = Relations(t1=relations.t1 + 5000.0, t2=relations.t2 + 5000.0, delta=relations.delta)
    write_relations(base / "other.relations", shifted)
    (base / "bad_profile.yaml").write_text("name: bad\nlaser:\n  range_noise_std: -0.1\n", encoding="utf-8")
    (base / "unknown_key.yaml").write_text("name: bad\nlaser:\n  dropout_chance: 0.1\n", encoding="utf-8")
    (base / "unknown_section.yaml").write_text("name: bad\nlazer:\n  dropout_rate: 0.1\n", encoding="utf-8")
    return base, record, len(relations)


def _args(base, *extra):
    return [
        "validate",
        str(base / "run"),
        "--relations",
        str(base / "run.relations"),
        "--algorithm",
        "odometry",
        *extra,
    ]


def test_validate_prints_the_table_and_writes_json_and_figure(inputs, tmp_path):
    base, record, count = inputs
    out, fig = tmp_path / "v.json", tmp_path / "v.png"
    result = runner.invoke(app, _args(base, "--runs", "3", "--json", str(out), "--figure", str(fig)))
    assert result.exit_code == 0, result.output
    # no --profile: the one default of every command, said first on stderr and named in the table and the JSON
    assert result.stderr.splitlines()[0] == f"profile: {DEFAULT_PROFILE}"
    assert "real log" in result.output and "simulation" in result.output
    assert f"profile {DEFAULT_PROFILE}" in result.stdout
    doc = json.loads(out.read_text())
    assert doc["runs"] == 3 and doc["seeds"] == [0, 1, 2] and doc["frames"] == len(record)
    assert doc["profile"]["name"] == DEFAULT_PROFILE == "realistic" and doc["algorithm"] == "odometry"
    assert doc["relations"] == {"given": count, "replica": count}
    assert doc["replica_world"]["unknown_cells"] == "walls"
    for source in ("slam", "odometry"):
        for kind in ("translational_m", "rotational_rad"):
            entry = doc[source][kind]
            assert len(entry["per_replica"]) == 3
            assert entry["simulated_mean"] == pytest.approx(np.mean(entry["per_replica"]))
            assert entry["simulated_std"] == pytest.approx(np.std(entry["per_replica"], ddof=1))
            assert entry["real"] >= 0.0
    # the "real" run's odometry is the paper's biased odometry, and the odometry algorithm's estimate is it
    assert doc["slam"]["translational_m"]["real"] == pytest.approx(doc["odometry"]["translational_m"]["real"])
    assert [r["odometry_translational_m"] for r in doc["replicas"]] == doc["odometry"]["translational_m"]["per_replica"]
    assert f"{doc['slam']['translational_m']['real']:.4f}" in result.output
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_relations_of_another_log_are_one_line_and_nothing_is_written(inputs, tmp_path):
    base, _, _ = inputs
    out = tmp_path / "v.json"
    args = ["validate", str(base / "run"), "--relations", str(base / "other.relations"), "--algorithm", "odometry"]
    result = runner.invoke(app, [*args, "--json", str(out), "--figure", str(tmp_path / "v.png")])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "does not belong to" in lines[0] and "other.relations" in lines[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("profile", "expected"),
    [
        ("no_such_profile", "unknown profile 'no_such_profile'"),
        ("bad_profile.yaml", "range_noise_std"),
        ("unknown_key.yaml", "unknown laser error field 'dropout_chance'"),
        ("unknown_section.yaml", "lazer"),
    ],
)
def test_a_bad_profile_is_one_line_and_nothing_is_written(inputs, tmp_path, profile, expected):
    base, _, _ = inputs
    value = str(base / profile) if profile.endswith(".yaml") else profile
    result = runner.invoke(app, _args(base, "--profile", value, "--json", str(tmp_path / "v.json")))
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and expected in lines[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_replicas_on_dask_give_the_sequential_numbers(inputs, tmp_path):
    base, _, _ = inputs
    docs = []
    for name, extra in (("seq", []), ("dask", ["--workers", "2"])):
        out = tmp_path / f"{name}.json"
        result = runner.invoke(app, _args(base, "--runs", "2", "--json", str(out), *extra))
        assert result.exit_code == 0, result.output
        doc = json.loads(out.read_text())
        for replica in doc["replicas"]:
            replica.pop("seconds")
        docs.append(doc)
    assert docs[0] == docs[1]
