"""Per-world means of figures the catalog keeps in each run's details (cost, map quality, exploration).

A figure is read from a run's details only when it is a finite number (a run stored by an earlier version,
or one that could not measure it, has none); a mean is taken over the runs that have it, with
``math.fsum`` (the same on every machine).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

__all__ = ["figure", "mean_of", "figure_means", "csv_cells"]


def figure(value: Any) -> float | None:
    """``value`` as a float when it is a finite number (not a bool), else None."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def mean_of(values: Iterable[float | None]) -> float | None:
    """The mean of the values that are not None; None when none is."""
    kept = [v for v in values if v is not None]
    return math.fsum(kept) / len(kept) if kept else None


def figure_means(
    details: Iterable[Mapping[str, Any]], names: Sequence[str]
) -> tuple[int, dict[str, float | None]] | None:
    """Over the runs whose details hold at least one of ``names``: how many they are, and each figure's
    mean over the runs that hold it; None when no run holds any."""
    rows = [d for d in details if any(figure(d.get(name)) is not None for name in names)]
    if not rows:
        return None
    return len(rows), {name: mean_of(figure(d.get(name)) for d in rows) for name in names}


def csv_cells(values: Sequence[float | int | None] | None, width: int) -> list[str]:
    """summary.csv cells of ``values`` (``width`` empty cells when None): empty for None, an int as
    written, a float by ``repr`` (every digit kept)."""
    if values is None:
        return [""] * width
    return ["" if v is None else str(v) if isinstance(v, int) else repr(v) for v in values]
