"""CostMeter: CPU time inside and outside the measured calls, the memory a call allocates, update times."""

from __future__ import annotations

import json
import subprocess
import sys
import time

import numpy as np
import pytest

from slamtrials.cost import CHILD_PROCESS, IN_PROCESS, ProcessUsage
from slamtrials.costmeter import CostMeter, ResidentMemory, usage_of

needs_proc = pytest.mark.skipif(ResidentMemory.open() is None, reason="no usable /proc/self/status and clear_refs")


def _busy(seconds: float) -> None:
    end = time.thread_time() + seconds
    while time.thread_time() < end:
        pass


def test_cpu_time_of_the_calls_and_of_the_run_and_the_update_times():
    meter = CostMeter(memory=False)
    _busy(0.05)  # the run's own work, outside SLAM
    for k in range(5):
        mark = meter.enter()
        tick = time.perf_counter()
        _busy(0.004 if k % 2 else 0.001)
        spent = time.perf_counter() - tick
        meter.leave(mark, update_seconds=spent if k % 2 == 1 else None)  # two calls made an update
    cost = meter.finish()
    assert cost.slam_process == IN_PROCESS and cost.updates_timed == 2
    assert 0.010 <= cost.slam_cpu_s < 0.05
    assert cost.run_cpu_s >= cost.slam_cpu_s + 0.05
    assert cost.update_ms_p90 >= cost.update_ms_median >= 3.5  # wall time of the calls that updated
    assert cost.slam_peak_mib is None and cost.run_peak_mib is None  # memory not asked for


# The memory tests run in a fresh interpreter: the meter reads the whole process's resident set, so in
# the test session another thread's frees, or a garbage collection freeing earlier tests' arrays while a
# measured call allocates, can hide that call's growth.
_MEMORY_SCENARIOS = """
import json, mmap, sys
import numpy as np
from slamtrials.costmeter import CostMeter


def touched(mib):
    buffer = mmap.mmap(-1, mib * 2**20)  # a new mapping, every page written
    np.frombuffer(buffer, dtype=np.uint8)[:: mmap.PAGESIZE] = 1
    return buffer


meter = CostMeter()
if sys.argv[1] == "inside":
    held = []
    mark = meter.enter()
    held.append(touched(80))  # 80 MiB, kept
    meter.leave(mark)
    mark = meter.enter()
    touched(40).close()  # 40 MiB more, freed within the call
    meter.leave(mark)
else:
    mark = meter.enter()
    meter.leave(mark)
    touched(60).close()  # 60 MiB outside the calls
cost = meter.finish()
print(json.dumps([cost.slam_peak_mib, cost.run_peak_mib]))
"""


def _memory_scenario(name: str) -> tuple[float, float]:
    """``(slam_peak_mib, run_peak_mib)`` of a scenario of ``_MEMORY_SCENARIOS`` run in a new interpreter."""
    done = subprocess.run(
        [sys.executable, "-c", _MEMORY_SCENARIOS, name], capture_output=True, text=True, timeout=120, check=True
    )
    slam, run = json.loads(done.stdout.strip().splitlines()[-1])
    return slam, run


@needs_proc
def test_the_memory_a_call_holds_at_its_peak_counts_for_slam_and_the_run():
    slam_peak, run_peak = _memory_scenario("inside")
    assert 110 <= slam_peak <= 140
    assert run_peak >= slam_peak
    assert run_peak >= 120  # the process's whole resident memory at that peak


@needs_proc
def test_memory_touched_outside_the_calls_is_the_run_s_not_slam_s():
    slam_peak, run_peak = _memory_scenario("outside")
    assert slam_peak < 20
    assert run_peak > 60


def test_a_child_s_usage_makes_the_slam_figures_and_adds_to_the_run_s():
    meter = CostMeter()
    mark = meter.enter()
    meter.leave(mark, update_seconds=0.01)
    cost = meter.finish(ProcessUsage(cpu_s=2.5, peak_mib=30.0), in_child=True)
    assert cost.slam_process == CHILD_PROCESS and cost.slam_cpu_s == 2.5 and cost.slam_peak_mib == 30.0
    assert cost.run_cpu_s >= 2.5 and cost.updates_timed == 1
    if cost.run_peak_mib is not None:
        assert cost.run_peak_mib > 30.0
    unknown = CostMeter().finish(None, in_child=True)
    assert unknown.slam_cpu_s is None and unknown.slam_peak_mib is None and unknown.slam_process == CHILD_PROCESS


def test_usage_of_a_rusage_is_seconds_and_mib():
    class Rusage:
        ru_utime, ru_stime = 1.25, 0.25
        ru_maxrss = 2048 * 1024 if sys.platform == "darwin" else 2048  # 2 MiB

    assert usage_of(Rusage()) == ProcessUsage(cpu_s=1.5, peak_mib=2.0)


def _fresh_kernel():
    """A numba kernel made anew (never in the on-disk cache), so its first call compiles."""
    import numba

    source = "def kernel(x):\n    total = 0.0\n    for v in x:\n        total += v * v\n    return total\n"
    namespace: dict = {}
    exec(compile(source, f"<kernel {time.perf_counter_ns()}>", "exec"), namespace)
    return numba.njit(cache=False)(namespace["kernel"])


def test_compiling_in_a_call_is_left_out_of_the_cpu_figures_and_given_apart():
    kernel = _fresh_kernel()
    meter = CostMeter(memory=False)
    mark = meter.enter()
    started = time.thread_time()
    kernel(np.ones(10))  # compiles: tens to hundreds of ms
    _busy(0.02)
    inside = time.thread_time() - started
    meter.leave(mark)
    cost = meter.finish()
    assert cost.compile_cpu_s > 0.02  # numba's compile of even a tiny kernel takes longer than that
    assert cost.slam_cpu_s == pytest.approx(inside - cost.compile_cpu_s, abs=0.005)
    assert 0.02 <= cost.slam_cpu_s < 0.02 + 0.01
    assert cost.run_cpu_s < cost.slam_cpu_s + 0.02  # the compile is out of the run's figure too
    warm = CostMeter(memory=False)
    mark = warm.enter()
    kernel(np.ones(10))  # compiled already
    warm.leave(mark)
    assert warm.finish().compile_cpu_s == 0.0


def test_a_compile_in_another_thread_is_not_this_run_s():
    import threading

    kernel = _fresh_kernel()
    meter = CostMeter(memory=False)
    other = threading.Thread(target=kernel, args=(np.ones(10),))
    other.start()
    other.join()
    assert meter.finish().compile_cpu_s == 0.0
