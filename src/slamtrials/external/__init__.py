"""External SLAM programs: run offline over a recording (:mod:`~slamtrials.external.offline`) or online,
frame by frame, in trials and campaigns (:mod:`~slamtrials.external.online`, the algorithm ``program``).

A layer of its own below ``io`` and ``slam`` (DESIGN.md): it writes files and starts processes;
``campaign`` and ``validation`` call it for runs whose SLAM is a program.
"""

from __future__ import annotations

from slamtrials.external.offline import (
    STDERR_LINES,
    ProgramRun,
    check_program,
    read_program_output,
    run_offline,
    run_program,
    time_origin_ns,
)

__all__ = [
    "ProgramRun",
    "run_program",
    "run_offline",
    "check_program",
    "read_program_output",
    "time_origin_ns",
    "STDERR_LINES",
]
