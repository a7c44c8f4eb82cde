"""What a run cost: CPU time and peak memory of the SLAM algorithm and of the whole run, and the time of
each SLAM update (:class:`RunCost`), and what an external program's process used (:class:`ProcessUsage`).

These are measurements of the machine, not results: the same run costs a little more or less each time,
so a cost never enters a digest, a determinism check or a comparison of results. They are taken by
:mod:`slamtrials.costmeter` (in-process algorithms) and from the child's ``rusage`` (external programs),
stored in run.json under ``cost`` (:data:`COST_KEY`) and read back with :meth:`RunCost.of`; a run.json of
an earlier version has none, and every reader shows it as missing.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

__all__ = [
    "RunCost",
    "ProcessUsage",
    "COST_KEY",
    "COST_FORMAT",
    "COST_FIGURES",
    "IN_PROCESS",
    "CHILD_PROCESS",
    "update_times_ms",
]

#: run.json key (and metadata key of a record) of a run's cost.
COST_KEY = "cost"
#: Format tag of the ``cost`` object.
COST_FORMAT = "slamtrials-cost/1"
#: :attr:`RunCost.slam_process` of an algorithm that ran in the run's own process.
IN_PROCESS = "in_process"
#: :attr:`RunCost.slam_process` of an external program (a child process).
CHILD_PROCESS = "child"

#: The figures of a :class:`RunCost`, as its attributes, run.json keys and catalog ``details`` keys are named.
COST_FIGURES = ("slam_cpu_s", "slam_peak_mib", "run_cpu_s", "run_peak_mib", "update_ms_median", "update_ms_p90")

#: Bytes per MiB.
MIB = float(1 << 20)


@dataclass(frozen=True)
class ProcessUsage:
    """What a finished child process used, from its ``rusage`` (``os.wait4``).

    Attributes
    ----------
    cpu_s:
        User plus system CPU time (s) of the process and of the descendants it waited for.
    peak_mib:
        Its peak resident set size (MiB): ``ru_maxrss``, the largest of the process and of the
        descendants it waited for.
    """

    cpu_s: float
    peak_mib: float


@dataclass(frozen=True)
class RunCost:
    """CPU time and memory of one run (a trial, or SLAM replayed over a recording).

    Every figure is None where it was not measured (a platform without ``/proc``, an external program
    timed as a whole, a run.json of an earlier version).

    Attributes
    ----------
    slam_cpu_s:
        CPU seconds (user + system) of the SLAM algorithm. In-process: the thread's CPU time inside the
        algorithm's calls (building it, ``reset``, ``process``, ``occupancy``, ``trajectory``), less the time
        they spent compiling numba kernels (``compile_cpu_s``); an external
        program: the child process's CPU time (its ``rusage``, with the descendants it waited for).
    slam_peak_mib:
        Peak memory of the SLAM algorithm (MiB). In-process: the most resident memory the algorithm's
        calls had added to the process (the pages they touched less those they gave back, summed over the
        calls, plus the scratch of the call at its peak): its maps, particles or graph. Approximate:
        resident pages are not allocations (the heap's fragments count), and a process's first run also
        counts loading the algorithm's compiled kernels (:mod:`slamtrials.costmeter`). An external program: the child's
        peak resident set size (``ru_maxrss``), its interpreter and libraries included.
    run_cpu_s:
        CPU seconds of the whole run: the thread that ran it (simulator, SLAM, explorer, coverage; compiles
        left out) plus, for an external program, the child's.
    run_peak_mib:
        Peak resident set size of the process that ran the run, during the run (MiB; the Python runtime
        and the loaded libraries included), plus an external program's own peak.
    update_ms_median, update_ms_p90:
        Median and 90th percentile of the wall time (ms) of the ``process`` calls that made a SLAM update
        (the algorithm's ``updates`` count went up); None where no call did, or for a program run offline
        (timed as a whole).
    updates_timed:
        How many calls those two figures are taken over.
    slam_process:
        Where the SLAM algorithm ran: :data:`IN_PROCESS` or :data:`CHILD_PROCESS` (an external program),
        which says what ``slam_cpu_s`` and ``slam_peak_mib`` measure.
    compile_cpu_s:
        CPU seconds the run's thread spent compiling numba kernels that were not in numba's on-disk cache
        (0 on a warm cache; None where not measured). They are left out of ``slam_cpu_s`` and ``run_cpu_s``;
        a run that compiled has its peak memory figures raised by the compiler's memory.
    """

    slam_cpu_s: float | None
    slam_peak_mib: float | None
    run_cpu_s: float | None
    run_peak_mib: float | None
    update_ms_median: float | None = None
    update_ms_p90: float | None = None
    updates_timed: int = 0
    slam_process: str = IN_PROCESS
    compile_cpu_s: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON form stored in run.json under :data:`COST_KEY` (``format`` first)."""
        return {"format": COST_FORMAT, **asdict(self)}

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> RunCost:
        """Read the JSON form; a missing or non-numeric figure reads as None."""
        values: dict[str, Any] = {}
        for item in fields(cls):
            value = doc.get(item.name)
            if item.name == "slam_process":
                values[item.name] = str(value) if isinstance(value, str) else IN_PROCESS
            elif item.name == "updates_timed":
                values[item.name] = int(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else 0
            else:
                values[item.name] = _figure(value)
        return cls(**values)

    def figures(self) -> dict[str, float | None]:
        """The :data:`COST_FIGURES` by name (None where not measured)."""
        return {name: getattr(self, name) for name in COST_FIGURES}

    @classmethod
    def of(cls, metadata: Mapping[str, Any]) -> RunCost | None:
        """The cost stored in a record's metadata (or a run.json document), or None for a run without one."""
        doc = metadata.get(COST_KEY)
        return cls.from_dict(doc) if isinstance(doc, Mapping) else None


def _figure(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def update_times_ms(seconds: Sequence[float] | np.ndarray) -> tuple[float | None, float | None]:
    """Median and 90th percentile (ms, linear interpolation) of wall times in seconds; None, None for none."""
    values = np.asarray(seconds, dtype=np.float64)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return None, None
    median, p90 = np.percentile(values, [50.0, 90.0])
    return 1000.0 * float(median), 1000.0 * float(p90)
