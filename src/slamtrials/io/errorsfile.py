"""Per-relation error files: ``.npz`` arrays or a plain text table."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from slamtrials.atomicfile import atomic_write, atomic_write_text
from slamtrials.record import Relations

__all__ = ["write_errors"]


def write_errors(path: str | Path, relations: Relations, errors) -> Path:
    """Write per-relation errors: ``.npz`` arrays, or a text table ``t1 t2 translational rotational``.

    The ``.npz`` holds ``t1``, ``t2`` (s), ``translational``, ``rotational`` (m and rad, or their squares
    when ``squared``) of the matched relations, ``index`` (their positions among the relations),
    ``unmatched`` and ``corrected`` (positions) and ``squared`` (a boolean scalar). The text table has
    one matched relation per line; unmatched relations are listed in a trailing comment.
    """
    path = Path(path)
    t1, t2 = relations.t1[errors.index], relations.t2[errors.index]
    if path.suffix == ".npz":
        arrays = dict(
            t1=t1,
            t2=t2,
            translational=errors.translational,
            rotational=errors.rotational,
            index=errors.index,
            unmatched=errors.unmatched,
            corrected=errors.corrected,
            squared=np.array(errors.squared),
        )
        return atomic_write(path, lambda handle: np.savez(handle, **arrays))
    unit_t, unit_r = errors.units
    lines = [f"# t1 t2 translational_error[{unit_t}] rotational_error[{unit_r}]\n"]
    lines += [
        f"{a!r} {b!r} {e!r} {r!r}\n"
        for a, b, e, r in zip(t1.tolist(), t2.tolist(), errors.translational.tolist(), errors.rotational.tolist())
    ]
    if len(errors.unmatched):
        lines.append(f"# unmatched relations (0-based): {' '.join(str(i) for i in errors.unmatched.tolist())}\n")
    return atomic_write_text(path, "".join(lines))
