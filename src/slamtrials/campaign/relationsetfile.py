"""A run's relation set on disk: ``relations.npz`` in the run folder (campaign, trial and evaluate write it;
it sits in the campaign layer because it stores a metric type).

Arrays: ``first``, ``second`` (uint32 ``[N]``, frame indices into the run's ``frames.npz``, ``first <
second``) and ``info`` (a 0-d string: JSON with ``format``, ``frames``, ``seed``, ``rule`` (the sampling
rule's fields), ``sized_on`` and the pilot's ``mean_t``, ``mean_r``, ``std_t``, ``std_r``, ``needed_t``,
``needed_r``, ``capped``). Written compressed and atomically; read back exactly.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from slamtrials.atomicfile import atomic_write
from slamtrials.errors import FormatError, MetricError, validation_problems
from slamtrials.metric.relationset import RelationSet
from slamtrials.metric.rule import SamplingRule

__all__ = ["read_relation_set", "write_relation_set", "RELATION_SET_FORMAT"]

RELATION_SET_FORMAT = "slamtrials-relation-set/1"

_FIGURES = ("mean_t", "mean_r", "std_t", "std_r")


def write_relation_set(path: str | Path, relation_set: RelationSet) -> Path:
    """Write ``relation_set`` to ``path`` (``.npz``)."""
    if relation_set.frames > np.iinfo(np.uint32).max:
        raise MetricError(f"relation set of {relation_set.frames} frames: too many for uint32 indices")
    info = {
        "format": RELATION_SET_FORMAT,
        "frames": relation_set.frames,
        "seed": relation_set.seed,
        "rule": relation_set.rule.model_dump(mode="json"),
        "sized_on": relation_set.sized_on,
        **{name: getattr(relation_set, name) for name in _FIGURES},
        "needed_t": relation_set.needed_t,
        "needed_r": relation_set.needed_r,
        "capped": relation_set.capped,
    }
    first = relation_set.first.astype(np.uint32)
    second = relation_set.second.astype(np.uint32)
    text = np.array(json.dumps(info, sort_keys=True))
    return atomic_write(path, lambda handle: np.savez_compressed(handle, first=first, second=second, info=text))


def read_relation_set(path: str | Path) -> RelationSet:
    """Read a ``relations.npz`` written by :func:`write_relation_set`.

    Raises
    ------
    FormatError
        Not such a file (missing arrays, bad info, indices out of range or out of order).
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as npz:
            missing = [name for name in ("first", "second", "info") if name not in npz.files]
            if missing:
                raise FormatError(path, f"not a relation set: no array {', '.join(missing)}")
            first, second, text = npz["first"], npz["second"], npz["info"]
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise FormatError(path, f"not a readable .npz file ({exc})") from None
    if first.dtype.kind not in "ui" or second.dtype.kind not in "ui" or text.dtype.kind != "U" or text.ndim:
        raise FormatError(path, "not a relation set: first/second must be integer arrays and info a string")
    try:
        info = json.loads(str(text))
    except json.JSONDecodeError as exc:
        raise FormatError(path, f"info is not JSON ({exc})") from None
    if not isinstance(info, dict) or info.get("format") != RELATION_SET_FORMAT:
        raise FormatError(path, f"info: format must be {RELATION_SET_FORMAT!r}")
    try:
        rule = SamplingRule.model_validate(info["rule"])
        figures = {name: float(info[name]) for name in _FIGURES}
        relation_set = RelationSet(
            first=first.astype(np.int64),
            second=second.astype(np.int64),
            frames=int(info["frames"]),
            seed=int(info["seed"]),
            rule=rule,
            sized_on=str(info["sized_on"]),
            needed_t=int(info["needed_t"]),
            needed_r=int(info["needed_r"]),
            capped=bool(info["capped"]),
            **figures,
        )
    except KeyError as exc:
        raise FormatError(path, f"info: no field {exc.args[0]!r}") from None
    except ValidationError as exc:
        raise FormatError(path, f"info.rule: {validation_problems(exc)}") from None
    except (TypeError, ValueError) as exc:
        raise FormatError(path, f"info: {exc}") from None
    except MetricError as exc:
        raise FormatError(path, exc.problem) from None
    return relation_set
