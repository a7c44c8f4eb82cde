"""Waiting for an external program's process and reading what it used: :func:`wait_with_usage`.

``os.wait4`` reaps one child and returns its own ``rusage`` (CPU time and peak resident set size, with
those of the descendants it waited for), exact for that child whatever else the process runs at the
same time. ``resource.getrusage(RUSAGE_CHILDREN)`` differences would mix in every other child reaped
meanwhile (another thread's program, a shell of ``check_program``).
"""

from __future__ import annotations

import os
import subprocess
import time

from slamtrials.cost import ProcessUsage
from slamtrials.costmeter import usage_of

__all__ = ["wait_with_usage"]

#: Longest pause (s) between two looks at a child that has not exited (as ``Popen.wait`` does).
_LONGEST_PAUSE = 0.05


def wait_with_usage(process: subprocess.Popen, timeout: float | None = None) -> tuple[int, ProcessUsage | None]:
    """Wait for ``process`` to exit; return its exit code (negative: killed by that signal) and its usage.

    The usage is None when the process had been reaped already (its ``returncode`` set by an earlier
    wait). ``process.returncode`` is set, as ``Popen.wait`` sets it.

    Raises
    ------
    subprocess.TimeoutExpired
        It has not exited within ``timeout`` seconds (it keeps running).
    """
    if process.returncode is not None:
        return process.returncode, None
    deadline = None if timeout is None else time.monotonic() + timeout
    pause = 0.0005
    while True:
        try:
            pid, status, rusage = os.wait4(process.pid, 0 if deadline is None else os.WNOHANG)
        except ChildProcessError:  # reaped by someone else meanwhile
            return process.wait(), None
        if pid == process.pid:
            process.returncode = os.waitstatus_to_exitcode(status)
            return process.returncode, usage_of(rusage)
        assert deadline is not None and timeout is not None
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise subprocess.TimeoutExpired(process.args, timeout)
        pause = min(pause * 2, remaining, _LONGEST_PAUSE)
        time.sleep(pause)
