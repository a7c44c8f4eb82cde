"""Validation: a real run replicated in the simulator, the paper's Section IV (Tables II and III).

It composes sim, slam and metric like a trial does, and sits at the trial's level of the layers: it
takes a real log and its relations as values (reading them is the caller's job) and returns a typed
:class:`ValidationResult` that the CLI prints and writes.

- :mod:`~slamtrials.validation.replica`: the replica's world (the reference map, unknown cells as walls),
  path, times and laser geometry.
- :mod:`~slamtrials.validation.validate`: :func:`validate`: the reference run, the real errors, the
  replica runs and their errors on the real relations' time pairs.
"""

from __future__ import annotations

from slamtrials.validation.replica import UNKNOWN_AS_WALL, Replica, blocked_frames, laser_config_for, world_from_map
from slamtrials.validation.validate import (
    KINDS,
    SOURCES,
    ReplicaResult,
    RunErrors,
    Runner,
    Spread,
    ValidationPlan,
    ValidationResult,
    ValidationSettings,
    check_belong,
    frame_pairs,
    plan_validation,
    replica_config,
    replica_from_reference,
    run_replica,
    validate,
)

__all__ = [
    "UNKNOWN_AS_WALL",
    "Replica",
    "blocked_frames",
    "laser_config_for",
    "world_from_map",
    "KINDS",
    "SOURCES",
    "ReplicaResult",
    "RunErrors",
    "Runner",
    "Spread",
    "ValidationPlan",
    "ValidationResult",
    "ValidationSettings",
    "check_belong",
    "frame_pairs",
    "plan_validation",
    "replica_config",
    "replica_from_reference",
    "run_replica",
    "validate",
]
