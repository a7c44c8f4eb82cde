"""The driver loop: keep every world's next runs submitted to Dask, record results as they arrive.

The driver is the only process that writes the catalog. For each world a *planner* says which runs are
needed now (:class:`Plan`); the driver submits those not yet in flight, with ``retries`` (a worker that
dies loses only its current run, which Dask runs again elsewhere), and records each result in SQLite as
it arrives (:func:`distributed.as_completed`, to which new futures are added as worlds advance). Worlds
proceed concurrently: while one waits for the last runs of its batch, the others keep the workers busy;
runs of larger worlds, which take longer, are started first.
:func:`drive_lanes` does the same for several campaigns at once on one client (a study's cells), their runs
in one queue and one priority order.
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

__all__ = ["Plan", "Planner", "drive", "drive_lanes", "Lane", "DriveCounts"]

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


@dataclass(frozen=True)
class Lane:
    """One campaign among several driven together on one Dask client (:func:`drive_lanes`).

    Attributes
    ----------
    store:
        The campaign's catalog (open, locked by the caller).
    worlds:
        Its worlds, in campaign order.
    planner:
        Decides its runs and builds their tasks.
    retries:
        Dask retries of each of its runs.
    on_event:
        Called with its :class:`CampaignEvent` objects.
    prefix:
        Part of its task keys (``slamtrials-<prefix>-<world>-<index>-<token>``); unique per lane.
    priority:
        ``world -> Dask priority`` of the world's runs (higher starts first); default :func:`_priority`.
    """

    store: CampaignStore
    worlds: Sequence[WorldInfo]
    planner: Planner
    retries: int
    on_event: Callable[[CampaignEvent], None] | None = None
    prefix: str = "run"
    priority: Callable[[WorldInfo], int] | None = None


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
    return drive_lanes(client, [Lane(store, worlds, planner, retries, on_event, prefix)])[0]


def drive_lanes(client: Any, lanes: Sequence[Lane]) -> list[DriveCounts]:
    """Run every world of every lane to its end on one client, their runs interleaved (one queue of
    results, one Dask priority order over all lanes); return each lane's counts of this call."""
    from distributed import as_completed

    token = uuid.uuid4().hex[:8]
    # state per (lane, world name)
    in_flight: dict[tuple[int, str], set[int]] = {
        (k, w.name): set() for k, lane in enumerate(lanes) for w in lane.worlds
    }
    failed: dict[tuple[int, str], str] = {}
    targets: dict[tuple[int, str], int] = {}
    futures: dict[Any, tuple[int, str, int]] = {}
    by_name = [{w.name: w for w in lane.worlds} for lane in lanes]
    queue = as_completed()
    counts = [DriveCounts() for _ in lanes]

    def emit(k: int, event: CampaignEvent) -> None:
        if lanes[k].on_event is not None:
            lanes[k].on_event(event)  # type: ignore[misc]

    def advance(k: int, world: WorldInfo, plan: Plan, results: dict) -> None:
        lane, key = lanes[k], (k, world.name)
        targets[key] = plan.target
        if plan.final_status is not None:
            lane.store.record_world(
                world.name, status=plan.final_status, target=plan.target, decision=plan.decision, note=plan.note
            )
            emit(
                k,
                CampaignEvent(
                    "world_done",
                    world.name,
                    plan.target,
                    len(results),
                    status=plan.final_status,
                    message=plan.note or "",
                ),
            )
            return
        new = [i for i in plan.to_run if i not in in_flight[key]]
        if not new:
            return
        tasks = [(i, *lane.planner.task(world, i)) for i in new]
        lane.store.mark_submitted(world.name, [(i, seed) for i, _, _, seed in tasks])
        lane.store.record_world(world.name, status="running", target=plan.target, decision=plan.decision)
        priority = (lane.priority or _priority)(world)
        for i, function, argument, _ in tasks:
            future = client.submit(
                function,
                argument,
                key=f"slamtrials-{lane.prefix}-{world.name}-{i}-{token}",
                retries=lane.retries,
                pure=False,
                priority=priority,
            )
            futures[future] = (k, world.name, i)
            in_flight[key].add(i)
            queue.add(future)
        log.info("%s: submitted runs %s (needs %d)", world.name, new, plan.target)
        emit(k, CampaignEvent("batch", world.name, plan.target, len(results), message=f"runs {new[0]}..{new[-1]}"))

    for k, lane in enumerate(lanes):
        for world in lane.worlds:
            results = lane.store.done_results(world.name)
            plan = lane.planner.plan(world, results)
            emit(
                k, CampaignEvent("start", world.name, plan.target, len(results), status=plan.final_status or "pending")
            )
            advance(k, world, plan, results)

    for future in queue:
        k, name, index = futures.pop(future)
        lane, key = lanes[k], (k, name)
        in_flight[key].discard(index)
        try:
            result: RunResult = future.result()
        except Exception as exc:  # lost after its retries, or a bug: recorded, the other worlds go on
            result = RunFailed(world=name, index=index, error=f"{type(exc).__name__}: {exc}")
        finally:
            future.release()
        world = by_name[k][name]
        if isinstance(result, RunDone):
            lane.store.record_done(name, index, result)
            counts[k].done += 1
            results = lane.store.done_results(name)
            emit(
                k,
                CampaignEvent(
                    "run_done", name, targets[key], len(results), index=index, eps_t=result.eps_t, eps_r=result.eps_r
                ),
            )
        else:
            error = result.error
            log.warning("%s run %d failed: %s", name, index, error)
            lane.store.record_failed(name, index, error, worker=result.worker)
            counts[k].failed += 1
            failed.setdefault(key, f"run {index} failed: {error}")
            results = lane.store.done_results(name)
            emit(k, CampaignEvent("run_failed", name, targets[key], len(results), index=index, message=error))
        if key in failed:
            if not in_flight[key]:
                emit(
                    k,
                    CampaignEvent("world_done", name, targets[key], len(results), status="failed", message=failed[key]),
                )
            continue
        advance(k, world, lane.planner.plan(world, results), results)
    return counts
