"""``replay_campaign``: evaluate another SLAM algorithm (or configuration) on a campaign's recorded runs.

No simulation: for every done run of the source campaign, the recorded frames (laser, odometry, truth)
are fed offline to the new algorithm, seeded like the trial's own SLAM stream (the second child of
``SeedSequence(run seed)``, so replaying the original algorithm and parameters reproduces the original
estimate), and the estimate is scored on the source run's own relation set
(:func:`~slamtrials.campaign.score.run_relation_set`), so each replayed run and its source are compared
on the same relations. Each replayed run becomes a complete run folder of the new campaign:
``frames.npz`` (the new estimate; the recorded frames stay in the source run folder, which ``run.json``
names as ``frames_from``, so a replay costs no copy of them), ``estimate.tum``, the new map,
``relations.npz`` (the source's set) and a ``run.json`` whose ``replay`` entry names the source run
folder, the algorithm and its configuration, and whose ``cost`` is the replay's (the SLAM run over the
recorded frames: :class:`~slamtrials.cost.RunCost`), not the source trial's, and whose ``map_quality``
is the new map's against the world's floor plan (:mod:`slamtrials.campaign.mapscore`; where the world no
longer loads, none, and the ``replay`` entry says why).

The new campaign's config is the source's with ``slam`` changed (:func:`replay_slam_settings`: the
source's algorithm, preset and parameters, with the given overrides on top) and ``replay_of`` set to
the source folder; its catalog has the same worlds and run indices. The run-count rule cannot add runs in a
replay: a world whose errors under the new algorithm would need more runs than were recorded is
reported as ``short``. Note that the robot's paths are those it explored with the first algorithm's
maps (:data:`~slamtrials.campaign.events.REPLAY_NOTE`); the output says so.
"""

from __future__ import annotations

import enum
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

from slamtrials.campaign.cluster import check_workers, dask_client
from slamtrials.campaign.config import CampaignConfig, MetricSettings
from slamtrials.campaign.driver import Plan, drive
from slamtrials.campaign.events import REPLAY_NOTE, CampaignEvent, CampaignResult
from slamtrials.campaign.execute import result_notes
from slamtrials.campaign.folder import (
    campaign_lock,
    check_campaign_folder,
    completed_result,
    open_campaign,
    prepare_resume,
)
from slamtrials.campaign.loop import next_step
from slamtrials.campaign.mapscore import add_map_quality
from slamtrials.campaign.results import RunResult
from slamtrials.campaign.runfiles import publish_run
from slamtrials.campaign.score import run_relation_set, score_run
from slamtrials.campaign.store import CampaignStore, WorldInfo
from slamtrials.campaign.summary import summarize_store, write_summary_csv
from slamtrials.campaign.task import failure, outcome, write_scored_run
from slamtrials.campaign.worldset import load_world_cached
from slamtrials.cost import COST_KEY, RunCost
from slamtrials.errors import ConfigError, SlamtrialsError
from slamtrials.metric.mapquality import MAP_QUALITY_KEY
from slamtrials.record import RunRecord
from slamtrials.slam.offline import run_over_recording
from slamtrials.slam.program import ProgramSpec
from slamtrials.trial import SlamSettings

__all__ = [
    "replay_campaign",
    "replay_config",
    "replay_slam_settings",
    "SOURCE_PRESET",
    "ReplayTask",
    "replay_one",
    "replay_slam",
]


class _Source(enum.Enum):
    PRESET = "the source campaign's preset"


#: ``preset`` argument of :func:`replay_campaign`: keep the source campaign's preset (for the same
#: algorithm; another algorithm then runs with its defaults).
SOURCE_PRESET = _Source.PRESET

PresetChoice = str | None | Literal[_Source.PRESET]


def replay_slam_settings(
    source: SlamSettings,
    algorithm: str | None = None,
    preset: PresetChoice = SOURCE_PRESET,
    params: dict[str, Any] | None = None,
    program: ProgramSpec | None = None,
) -> SlamSettings:
    """The SLAM settings of a replay of a campaign that ran with ``source``.

    Parameters
    ----------
    source:
        The source campaign's SLAM settings.
    algorithm:
        The replay's algorithm; None: the source's.
    preset:
        :data:`SOURCE_PRESET`: the source's preset when the algorithm is the source's, the algorithm's
        defaults (no preset) for another algorithm; else the named preset, or None for the defaults.
    params:
        Parameter overrides. For the source's algorithm they go on top of the source's own overrides
        (which are kept, whatever the preset); another algorithm gets only these.
    program:
        An external program to replay with instead of an algorithm (then ``algorithm``, ``preset``
        and ``params`` must be left out).

    Raises
    ------
    ConfigError
        A program together with an algorithm, preset or parameters.
    """
    if program is not None:
        if algorithm is not None or params or preset is not SOURCE_PRESET:
            raise ConfigError("a replay runs either --program or --algorithm (with --preset, --set), not both")
        return SlamSettings(program=program)
    if source.program is not None and algorithm is None and not params and preset in (SOURCE_PRESET, None):
        return source  # a replay of a program's campaign with the same program
    algorithm = source.algorithm if algorithm is None else algorithm
    same = algorithm == source.algorithm
    if preset is SOURCE_PRESET:
        preset = source.preset if same else None
    merged = {**source.params, **(params or {})} if same else dict(params or {})
    return SlamSettings(algorithm=algorithm, preset=preset, params=merged)


def replay_config(
    source_config: CampaignConfig,
    source: str | Path,
    folder: str | Path,
    algorithm: str | None = None,
    preset: PresetChoice = SOURCE_PRESET,
    params: dict[str, Any] | None = None,
    program: ProgramSpec | None = None,
) -> CampaignConfig:
    """The config of the replay in ``folder`` of the campaign in ``source`` (config ``source_config``).

    ``slam`` is :func:`replay_slam_settings` of the source's; ``replay_of`` is ``source``, ``output``
    is ``folder`` (both absolute).

    Raises
    ------
    ConfigError
        An unknown algorithm or preset, or a bad parameter (named).
    """
    slam = replay_slam_settings(source_config.slam, algorithm, preset, params, program)
    data = source_config.model_dump(mode="json")
    data.update(
        slam=slam.model_dump(mode="json"), replay_of=str(Path(source).absolute()), output=str(Path(folder).absolute())
    )
    return CampaignConfig.from_dict(data, source="replay")


@dataclass(frozen=True)
class ReplayTask:
    """One recorded run to re-evaluate: where it is, where it goes, and with what.

    Attributes
    ----------
    campaign:
        Absolute path of the new campaign folder.
    world, index, seed:
        The run's world name, index and seed (as in the source campaign).
    source:
        Absolute path of the source run folder.
    slam:
        The new SLAM algorithm and parameters.
    metric:
        The relation sampling (the source campaign's).
    extra:
        Facts added to ``run.json`` under ``campaign``.
    ref:
        What loads the run's world (as the source campaign recorded it), for scoring the new map; None:
        the map is not scored.
    """

    campaign: str
    world: str
    index: int
    seed: int
    source: str
    slam: SlamSettings
    metric: MetricSettings
    extra: dict[str, Any] = field(default_factory=dict)
    ref: str | None = None


def replay_slam(record: RunRecord, slam: SlamSettings, seed: int) -> RunRecord:
    """``record`` with the estimate and map of ``slam`` run over its frames with the run's ``seed``, and
    the cost of that run in its metadata (:data:`~slamtrials.cost.COST_KEY`, replacing the source's).

        The algorithm runs through :func:`slamtrials.slam.offline.run_over_recording`, seeded as in
        :func:`slamtrials.trial.run_trial` (:mod:`slamtrials.seeding`); a program through
        :func:`slamtrials.external.run_program` (given the seed as ``{seed}``).

        Raises
        ------
        ConfigError
            A bad configuration, or an algorithm whose trajectory does not hold one pose per frame.
        ProgramError
            The program failed on the run.
    """
    if slam.program is not None:
        return _replay_program(record, slam.program, seed)
    result = run_over_recording(record, slam.algorithm, preset=slam.preset, overrides=slam.params, seed=seed)
    estimate = result.estimate_per_frame(record)
    metadata = _with_cost(record.metadata, result.cost)
    metadata["slam_config"] = result.config.model_dump(mode="json")
    return replace(record, metadata=metadata, estimate=estimate, map=result.occupancy, online=result.online)


def _replay_program(record: RunRecord, program: ProgramSpec, seed: int) -> RunRecord:
    from slamtrials.external import run_program

    ran = run_program(record, program, seed)
    a = ran.alignment
    metadata = _with_cost(record.metadata, ran.cost)
    metadata["slam_config"] = program.model_dump(mode="json")
    metadata["program"] = {
        "command": ran.command,
        "seconds": ran.seconds,
        "time_origin_s": ran.time_origin_s,
        "poses_written": a.poses_read,
        "frames_at_a_pose": a.frames_at_pose,
        "frames_carried_by_odometry": a.frames_carried,
        "stderr_tail": list(ran.stderr_tail),
    }
    return replace(record, metadata=metadata, estimate=ran.estimate, map=ran.occupancy, online=ran.estimate)


def _with_cost(metadata: dict[str, Any], cost: RunCost | None) -> dict[str, Any]:
    """A copy of ``metadata`` whose cost is ``cost`` (none when None: never the source trial's)."""
    copy = {k: v for k, v in metadata.items() if k != COST_KEY}
    if cost is not None:
        copy[COST_KEY] = cost.to_dict()
    return copy


def _score_replayed_map(record: RunRecord, ref: str | None) -> str | None:
    """Score the replayed map against its world (run.json's ``map_quality``); the reason it was not, or None."""
    record.metadata.pop(MAP_QUALITY_KEY, None)  # the source run's was of another map
    if ref is None:
        return "not scored: the source campaign does not say which world the run was in"
    try:
        add_map_quality(record, load_world_cached(ref))
    except SlamtrialsError as exc:
        return f"not scored: the world {ref!r} does not load here ({exc})"
    return None


def replay_one(task: ReplayTask) -> RunResult:
    """Re-evaluate one recorded run (see the module docstring); return what the driver records."""
    from slamtrials.io.runfolder import read_run

    started = time.perf_counter()
    try:
        source = read_run(task.source)
        relation_set = run_relation_set(task.source, source, task.seed, task.metric)
        record = replay_slam(source, task.slam, task.seed)
        score = score_run(record, task.seed, task.metric, relation_set)
    except SlamtrialsError as exc:
        return failure(task.world, task.index, exc)
    unscored = _score_replayed_map(record, task.ref)
    record.metadata["replay"] = {
        "source_run": task.source,
        "algorithm": task.slam.algorithm,
        "preset": task.slam.preset,
        "params": dict(task.slam.params),
        "program": task.slam.program.model_dump(mode="json") if task.slam.program else None,
        "wall_time_s": time.perf_counter() - started,
        "note": REPLAY_NOTE,
        **({"map_quality": unscored} if unscored else {}),
    }
    record.metadata["campaign"] = {
        "world": task.world,
        "index": task.index,
        "seed": task.seed,
        **score.to_dict(),
        "metric": task.metric.model_dump(mode="json"),
        **task.extra,
    }
    publish_run(
        task.campaign,
        task.world,
        task.index,
        lambda folder: write_scored_run(folder, record, score, frames_from=task.source),
    )
    return outcome(task.world, task.index, record, score, started)


class ReplayPlanner:
    """Every recorded run once; then the run-count rule's verdict on the new errors (no runs added)."""

    def __init__(
        self, config: CampaignConfig, folder: Path, source: Path, recorded: dict[str, dict[int, tuple[int, str]]]
    ):
        self.config = config
        self.folder = folder
        self.source = source
        self.recorded = recorded

    def plan(self, world: WorldInfo, results: dict[int, tuple[float, float]]) -> Plan:
        recorded = self.recorded.get(world.name, {})
        missing = tuple(i for i in sorted(recorded) if i not in results)
        if missing:
            return Plan(len(recorded), missing, None, None)
        step = next_step(results, self.config.runs)
        if step.finished:
            return Plan(step.target, (), "capped" if step.capped else "done", step.decision)
        note = (
            f"short of runs: the rule asks for {step.target} runs (runs {', '.join(map(str, step.missing[:5]))}"
            f"{'...' if len(step.missing) > 5 else ''} missing) but the source campaign recorded {len(recorded)}"
        )
        return Plan(step.target, (), "short", step.decision, note)

    def task(self, world: WorldInfo, index: int) -> tuple[Callable[[Any], RunResult], ReplayTask, int]:
        seed, folder = self.recorded[world.name][index]
        task = ReplayTask(
            str(self.folder),
            world.name,
            index,
            seed,
            str(self.source / folder),
            self.config.slam,
            self.config.metric,
            extra={"root_seed": self.config.seed, "replay_of": str(self.source)},
            ref=world.ref,
        )
        return replay_one, task, seed


def _recorded_runs(store: CampaignStore) -> dict[str, dict[int, tuple[int, str]]]:
    """``{world: {index: (seed, folder)}}`` of the source's done runs, each checked to be complete."""
    from slamtrials.io.layout import RunFolder

    recorded: dict[str, dict[int, tuple[int, str]]] = {w.name: {} for w in store.worlds()}
    for run in store.runs():
        if run.status != "done":
            continue
        folder = run.folder or f"runs/{run.world}/{run.idx:03d}"
        if not RunFolder(store.folder / folder).is_complete():
            raise ConfigError(f"{store.folder / folder}: recorded run {run.world} #{run.idx} is missing its run folder")
        recorded[run.world][run.idx] = (run.seed, folder)
    return recorded


def replay_campaign(
    source: str | Path,
    folder: str | Path,
    algorithm: str | None = None,
    preset: PresetChoice = SOURCE_PRESET,
    params: dict[str, Any] | None = None,
    *,
    program: ProgramSpec | None = None,
    scheduler: Any = None,
    workers: int | None = None,
    on_event: Callable[[CampaignEvent], None] | None = None,
) -> CampaignResult:
    """Re-evaluate the recorded runs of campaign ``source`` with ``algorithm`` into a new campaign ``folder``.

    Calling it again with the same arguments resumes an interrupted replay.

    Parameters
    ----------
    source:
        Folder of the campaign whose runs are replayed.
    folder:
        Folder of the new (replay) campaign.
    algorithm, preset, params:
        The SLAM algorithm (None: the source's), its preset (:data:`SOURCE_PRESET`: the source's for
        the same algorithm, the defaults for another; None: the defaults) and parameter overrides, on
        top of the source's own for the same algorithm (:func:`replay_slam_settings`).
    program:
        An external SLAM program to evaluate instead (:class:`~slamtrials.slam.program.ProgramSpec`);
        its failure on a run makes that run failed, with the program's exit code and stderr.
    scheduler, workers, on_event:
        As for :func:`slamtrials.campaign.run_campaign`.

    Returns
    -------
    CampaignResult
        Its ``notes`` start with :data:`~slamtrials.campaign.events.REPLAY_NOTE`; ``complete`` is set
        (nothing run) if the replay in ``folder`` was already complete.

    Raises
    ------
    ConfigError
        ``source`` is not a campaign, a recorded run folder is missing, a bad algorithm or parameter, or
        ``folder`` holds something else; before any work starts.
    """
    started = time.perf_counter()
    if scheduler is None:
        check_workers(workers)
    source = Path(source).absolute()
    folder = Path(folder).absolute()
    if folder == source:
        raise ConfigError(f"{folder}: the replay needs its own folder, not the source campaign's")
    with CampaignStore.open(source) as src:
        base = src.config()
        worlds = src.world_infos()
        recorded = _recorded_runs(src)
    config = replay_config(base, source, folder, algorithm, preset, params, program)
    if program is not None:
        from slamtrials.external import check_program

        check_program(program)

    check_campaign_folder(folder, config, worlds, kind="replay")  # before starting a cluster; touches nothing
    complete = completed_result(folder, ("done", "capped", "short"))
    if complete is not None:
        return replace(complete, notes=(REPLAY_NOTE, *result_notes(list(complete.summary))))
    planner = ReplayPlanner(config, folder, source, recorded)
    with dask_client(scheduler, workers, allowed_failures=config.runs.retries) as client:
        store = open_campaign(folder, config, worlds, kind="replay")
        with store, campaign_lock(folder):
            prepare_resume(store)
            counts = drive(
                store, client, worlds, planner, retries=config.runs.retries, on_event=on_event, prefix="replay"
            )
            summary = summarize_store(store)
            csv_path = write_summary_csv(folder, summary, config.runs.confidence)
    return CampaignResult(
        folder,
        tuple(summary),
        csv_path,
        counts.done,
        counts.failed,
        time.perf_counter() - started,
        (REPLAY_NOTE, *result_notes(summary)),
    )
