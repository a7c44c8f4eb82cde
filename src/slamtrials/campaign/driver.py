"""The driver loop: keep every world's next runs submitted to Dask, record results as they arrive.

The driver is the only process that writes the catalog. For each world a *planner* says which runs are
needed now (:class:`Plan`); the driver submits those not yet in flight, with ``retries`` (a worker that
dies loses only its current run, which Dask runs again elsewhere), and records each result in SQLite as
it arrives (:func:`distributed.as_completed`, to which new futures are added as worlds advance). Worlds
proceed concurrently: while one waits for the last runs of its batch, the others keep the workers busy;
runs of larger worlds, which take longer, are started first.
A run that fails for good marks its world failed; the other worlds go on.
"""

from __future__ import annotations

import logging
import math
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from slamtrials.campaign.events import CampaignEvent
from slamtrials.campaign.results import RunDone, RunFailed, RunResult
from slamtrials.campaign.store import CampaignStore, WorldInfo
from slamtrials.metric.runcount import RunCount

__all__ = ["Plan", "Planner", "drive", "DriveCounts"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Plan:
    """What a world needs now.

    Attributes
    ----------
    target:
        Runs the world needs so far.
    to_run:
        Run indices to have done next (some may already be in flight).
    final_status:
        None while runs remain; else the world's final status (``done``, ``capped`` or ``short``).
    decision:
        The last decision of the run-count rule, or None.
    note:
        A remark stored with the world (e.g. why a replay is short of runs).
    """

    target: int
    to_run: tuple[int, ...]
    final_status: str | None
    decision: RunCount | None
    note: str | None = None


class Planner(Protocol):
    """Decides a world's runs and builds their tasks."""

    def plan(self, world: WorldInfo, results: dict[int, tuple[float, float]]) -> Plan:
        """The plan of ``world`` given its done runs ``{index: (eps_t, eps_r)}``."""
        ...

    def task(self, world: WorldInfo, index: int) -> tuple[Callable[[Any], RunResult], Any, int]:
        """``(function, argument, seed)`` of run ``index`` of ``world``; the function returns the run's result."""
        ...


@dataclass
class DriveCounts:
    """Runs finished and failed during one :func:`drive`."""

    done: int = 0
    failed: int = 0


def _priority(world: WorldInfo) -> int:
    """Dask priority of a world's runs (higher starts first): its reachable area in m^2, a proxy for how long
    a run takes. Longest runs first keeps the workers evenly busy to the end (the LPT rule for makespan):
    the short runs of small worlds fill the gaps instead of one long run finishing alone."""
    return int(world.reachable_area) if math.isfinite(world.reachable_area) else 0


def drive(
    store: CampaignStore,
    client: Any,
    worlds: Sequence[WorldInfo],
    planner: Planner,
    *,
    retries: int,
    on_event: Callable[[CampaignEvent], None] | None = None,
    prefix: str = "run",
) -> DriveCounts:
    """Run every world to its end (see the module docstring); return the counts of this call."""
    from distributed import as_completed

    emit = on_event or (lambda event: None)
    token = uuid.uuid4().hex[:8]
    by_name = {w.name: w for w in worlds}
    in_flight: dict[str, set[int]] = {w.name: set() for w in worlds}
    failed: dict[str, str] = {}
    targets: dict[str, int] = {}
    futures: dict[Any, tuple[str, int]] = {}
    queue = as_completed()
    counts = DriveCounts()

    def advance(world: WorldInfo, plan: Plan, results: dict) -> None:
        targets[world.name] = plan.target
        if plan.final_status is not None:
            store.record_world(
                world.name, status=plan.final_status, target=plan.target, decision=plan.decision, note=plan.note
            )
            emit(
                CampaignEvent(
                    "world_done",
                    world.name,
                    plan.target,
                    len(results),
                    status=plan.final_status,
                    message=plan.note or "",
                )
            )
            return
        new = [i for i in plan.to_run if i not in in_flight[world.name]]
        if not new:
            return
        tasks = [(i, *planner.task(world, i)) for i in new]
        store.mark_submitted(world.name, [(i, seed) for i, _, _, seed in tasks])
        store.record_world(world.name, status="running", target=plan.target, decision=plan.decision)
        for i, function, argument, _ in tasks:
            future = client.submit(
                function,
                argument,
                key=f"slamtrials-{prefix}-{world.name}-{i}-{token}",
                retries=retries,
                pure=False,
                priority=_priority(world),
            )
            futures[future] = (world.name, i)
            in_flight[world.name].add(i)
            queue.add(future)
        log.info("%s: submitted runs %s (needs %d)", world.name, new, plan.target)
        emit(CampaignEvent("batch", world.name, plan.target, len(results), message=f"runs {new[0]}..{new[-1]}"))

    for world in worlds:
        results = store.done_results(world.name)
        plan = planner.plan(world, results)
        emit(CampaignEvent("start", world.name, plan.target, len(results), status=plan.final_status or "pending"))
        advance(world, plan, results)

    for future in queue:
        name, index = futures.pop(future)
        in_flight[name].discard(index)
        try:
            result: RunResult = future.result()
        except Exception as exc:  # lost after its retries, or a bug: recorded, the other worlds go on
            result = RunFailed(world=name, index=index, error=f"{type(exc).__name__}: {exc}")
        finally:
            future.release()
        world = by_name[name]
        if isinstance(result, RunDone):
            store.record_done(name, index, result)
            counts.done += 1
            results = store.done_results(name)
            emit(
                CampaignEvent(
                    "run_done", name, targets[name], len(results), index=index, eps_t=result.eps_t, eps_r=result.eps_r
                )
            )
        else:
            error = result.error
            log.warning("%s run %d failed: %s", name, index, error)
            store.record_failed(name, index, error, worker=result.worker)
            counts.failed += 1
            failed.setdefault(name, f"run {index} failed: {error}")
            results = store.done_results(name)
            emit(CampaignEvent("run_failed", name, targets[name], len(results), index=index, message=error))
        if name in failed:
            if not in_flight[name]:
                emit(
                    CampaignEvent(
                        "world_done", name, targets[name], len(results), status="failed", message=failed[name]
                    )
                )
            continue
        advance(world, planner.plan(world, results), results)
    return counts
