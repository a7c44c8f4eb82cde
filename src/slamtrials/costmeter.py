"""Measuring what a run costs while it runs (:class:`CostMeter`), and a child's ``rusage`` as a
:class:`~slamtrials.cost.ProcessUsage` (:func:`usage_of`).

CPU time is the calling thread's (``time.thread_time``: right in a Dask worker thread, and blind to what
other threads of the process do). Memory is the kernel's count of the process's resident pages: Linux's
``VmHWM`` (the peak resident set size) and ``VmRSS`` from ``/proc/self/status``, the peak set back to the
current size by writing ``5`` to ``/proc/self/clear_refs`` before each SLAM call and at the run's start,
so each call's peak and the run's own peak are read apart from earlier runs of the same process. The
algorithm's memory is what its calls add to the resident set (:class:`CostMeter`), after the C heap gave
its free memory back at the run's start (:func:`release_free_heap`). Resident pages are not allocations
(the heap's fragments count, memory reused costs no new page), and the first run in a process also
counts loading the algorithm's compiled kernels: GMapping holding 51 MiB reads 63 to 76 MiB
(bench/RESULTS.md, "Cost of a run"). Where those files cannot be used (another OS, a sandbox) the memory
figures are None.

Resident memory is the process's, not one thread's: a process that runs two runs at once in two threads
(a Dask worker with ``--nthreads 2``) mixes their memory figures (slamtrials' local cluster runs one
thread per worker process). Nothing measured here reaches the simulation or the algorithm: the meter
only reads clocks and kernel counters around the calls, so results stay the same bit for bit.

CPU time spent compiling numba kernels in the run's thread (a cold on-disk cache: the first run of a fresh
install, or of a kernel whose source changed) is left out of both CPU figures and given apart
(:attr:`~slamtrials.cost.RunCost.compile_cpu_s`, :class:`~slamtrials.compilewatch.CompileTimer`): it is
what the install pays once, not what the run costs. Its memory cannot be told apart: a run that compiled
reads high in peak memory.

Cost: about 15 us per measured call (two reads of ``/proc/self/status``, one write), one call a frame in a
trial (``process`` and ``occupancy`` together): under 0.5 % of a trial (bench/bench_cost.py).
"""

from __future__ import annotations

import ctypes
import os
import sys
import time
import weakref
from dataclasses import dataclass
from typing import Any

from slamtrials.compilewatch import CompileTimer
from slamtrials.cost import CHILD_PROCESS, IN_PROCESS, MIB, ProcessUsage, RunCost, update_times_ms

__all__ = ["CostMeter", "CallMark", "usage_of", "ResidentMemory", "release_free_heap"]


class ResidentMemory:
    """The process's resident memory counters (Linux ``/proc/self``), kept open for cheap reads.

    Use :meth:`open`, which gives None where the counters cannot be read or the peak cannot be reset.
    """

    def __init__(self, status_fd: int, clear_fd: int):
        self._status = status_fd
        self._clear = clear_fd
        self._closer = weakref.finalize(self, _close_all, status_fd, clear_fd)

    @classmethod
    def open(cls) -> ResidentMemory | None:
        """The counters of this process, or None where ``/proc/self/status`` or ``clear_refs`` is unusable."""
        try:
            status = os.open("/proc/self/status", os.O_RDONLY)
        except OSError:
            return None
        try:
            clear = os.open("/proc/self/clear_refs", os.O_WRONLY)
        except OSError:
            os.close(status)
            return None
        meter = cls(status, clear)
        try:
            meter.reset()
            meter.read()
        except (OSError, ValueError):
            meter.close()
            return None
        return meter

    def read(self) -> tuple[int, int]:
        """``(peak, current)`` resident set size (KiB) since the last :meth:`reset`."""
        text = os.pread(self._status, 8192, 0)
        return _kib(text, b"VmHWM:"), _kib(text, b"VmRSS:")

    def reset(self) -> None:
        """Set the peak back to the current resident set size."""
        os.write(self._clear, b"5")

    def close(self) -> None:
        """Close the counters' files."""
        self._closer()


def release_free_heap() -> None:
    """Give the C heap's free memory back to the system (glibc's ``malloc_trim(0)``; nothing elsewhere).

    Done at a run's start, so that memory earlier runs of the process freed but kept resident is not
    silently reused by this run's algorithm (it would add no resident page, and the algorithm's memory
    would read low). Freeing memory changes no value any computation sees.
    """
    try:
        trim = ctypes.CDLL(None).malloc_trim
    except (AttributeError, OSError):
        return
    trim.argtypes = [ctypes.c_size_t]
    trim(0)


def _close_all(*fds: int) -> None:
    for fd in fds:
        try:
            os.close(fd)
        except OSError:
            pass


def _kib(text: bytes, key: bytes) -> int:
    start = text.index(key) + len(key)
    return int(text[start : text.index(b"kB", start)])


@dataclass(frozen=True)
class CallMark:
    """When a measured SLAM call began: the thread's CPU clock (s), the process's resident set size (KiB;
    None when memory is not measured) and the thread's compile time so far (s)."""

    cpu: float
    resident_kib: int | None = None
    compile_s: float = 0.0


class CostMeter:
    """The cost of one run, measured in the thread that runs it.

    Made at the run's start; every call into the SLAM algorithm goes between :meth:`enter` and
    :meth:`leave`; :meth:`finish` gives the :class:`~slamtrials.cost.RunCost`::

        meter = CostMeter()
        mark = meter.enter()
        tick = time.perf_counter()
        pose = slam.process(reading)
        spent = time.perf_counter() - tick
        meter.leave(mark, update_seconds=spent if slam.updates > before else None)
        cost = meter.finish()

    Consecutive calls (``process`` then ``occupancy``) may go between one ``enter`` and ``leave``.

    The algorithm's memory is what its calls added to the process's resident set: each call's change of
    the resident set size (pages touched, less pages given back) summed over the calls so far, and at its
    largest the sum before a call plus that call's own peak above where it began. Memory the rest of the
    run touches between the calls counts for the run only.

    Parameters
    ----------
    memory:
        Measure resident memory (when the platform allows it); False leaves the memory figures None.
    """

    def __init__(self, *, memory: bool = True):
        if memory:
            release_free_heap()
        self._memory = ResidentMemory.open() if memory else None
        self._run_peak_kib = 0
        self._slam_held_kib = 0
        self._slam_peak_kib = 0
        self._slam_cpu = 0.0
        self._calls = 0
        self._updates: list[float] = []
        self._compile = CompileTimer()
        self._started_cpu = time.thread_time()

    def _observe(self) -> tuple[int, int]:
        """Read ``(peak since the last reset, current)`` resident set size (KiB); the peak goes into the run's."""
        assert self._memory is not None
        peak, current = self._memory.read()
        self._run_peak_kib = max(self._run_peak_kib, peak)
        return peak, current

    def enter(self) -> CallMark:
        """Start measuring one call into the SLAM algorithm."""
        resident = None
        if self._memory is not None:
            _, resident = self._observe()  # the peak of the stretch since the last call belongs to the run
            self._memory.reset()
        return CallMark(time.thread_time(), resident, self._compile.seconds)

    def leave(self, mark: CallMark, *, update_seconds: float | None = None) -> None:
        """End measuring the call begun at ``mark``. ``update_seconds``: the wall time (s) of the SLAM update
        the call made (the caller times ``process`` itself), counted towards
        :attr:`~slamtrials.cost.RunCost.update_ms_median`; None: the call made no update."""
        compiling = self._compile.seconds - mark.compile_s
        self._slam_cpu += time.thread_time() - mark.cpu - compiling
        self._calls += 1
        if update_seconds is not None:
            self._updates.append(update_seconds)
        if self._memory is not None and mark.resident_kib is not None:
            peak, current = self._observe()
            self._slam_peak_kib = max(self._slam_peak_kib, self._slam_held_kib + peak - mark.resident_kib)
            self._slam_held_kib += current - mark.resident_kib

    def finish(self, child: ProcessUsage | None = None, *, in_child: bool = False) -> RunCost:
        """The run's cost; the meter's files are closed.

        ``child``: what an external SLAM program's process used; the SLAM figures are then the child's
        and the run's include it. ``in_child``: the SLAM algorithm ran in a child process whose usage is
        unknown (``child`` None): the SLAM figures are None rather than those of the calls.
        """
        self._compile.stop()
        compile_cpu = self._compile.seconds
        run_cpu = time.thread_time() - self._started_cpu - compile_cpu
        run_peak = slam_peak = None
        if self._memory is not None:
            self._observe()
            self._memory.close()
            self._memory = None
            run_peak = self._run_peak_kib / 1024.0
            if self._calls:
                slam_peak = max(self._slam_peak_kib, 0) / 1024.0
        median, p90 = update_times_ms(self._updates)
        common: dict[str, Any] = {
            "update_ms_median": median,
            "update_ms_p90": p90,
            "updates_timed": len(self._updates),
            "compile_cpu_s": compile_cpu,
        }
        if child is None and not in_child:
            return RunCost(self._slam_cpu, slam_peak, run_cpu, run_peak, **common, slam_process=IN_PROCESS)
        if child is None:
            return RunCost(None, None, None, None, **common, slam_process=CHILD_PROCESS)
        return RunCost(
            slam_cpu_s=child.cpu_s,
            slam_peak_mib=child.peak_mib,
            run_cpu_s=run_cpu + child.cpu_s,
            run_peak_mib=None if run_peak is None else run_peak + child.peak_mib,
            **common,
            slam_process=CHILD_PROCESS,
        )


def usage_of(rusage: Any) -> ProcessUsage:
    """A waited-for child's ``resource.struct_rusage`` (``os.wait4``) as a :class:`ProcessUsage`."""
    peak_bytes = rusage.ru_maxrss if sys.platform == "darwin" else rusage.ru_maxrss * 1024
    return ProcessUsage(cpu_s=float(rusage.ru_utime + rusage.ru_stime), peak_mib=peak_bytes / MIB)
