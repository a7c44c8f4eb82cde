"""wait_with_usage: one child's own rusage (CPU time, peak memory), its exit code, and the timeout."""

from __future__ import annotations

import subprocess
import sys

import pytest

from slamtrials.external.childwait import wait_with_usage

#: A child that spins for 0.3 s of CPU time and touches 64 MiB, then exits with status 3.
BUSY = """
import sys, time
block = bytearray(64 * 2**20)
for i in range(0, len(block), 4096):
    block[i] = 1
end = time.process_time() + 0.3
while time.process_time() < end:
    pass
sys.exit(3)
"""


def test_the_child_s_own_cpu_time_and_peak_memory_are_read():
    process = subprocess.Popen([sys.executable, "-c", BUSY])
    code, usage = wait_with_usage(process, timeout=60.0)
    assert code == 3 and process.returncode == 3
    assert usage is not None
    assert 0.3 <= usage.cpu_s < 5.0
    assert 64.0 <= usage.peak_mib < 1024.0
    # reaped: a second wait gives the code and no usage (it was read once)
    assert wait_with_usage(process) == (3, None)


def test_a_shell_s_usage_holds_the_program_it_waited_for():
    process = subprocess.Popen(["/bin/sh", "-c", f"{sys.executable} -c '{BUSY}'; exit 0"])
    code, usage = wait_with_usage(process)
    assert code == 0 and usage is not None and usage.cpu_s >= 0.3 and usage.peak_mib >= 64.0


def test_a_child_that_runs_past_the_timeout_keeps_running():
    process = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        with pytest.raises(subprocess.TimeoutExpired):
            wait_with_usage(process, timeout=0.2)
        assert process.poll() is None
    finally:
        process.kill()
    code, usage = wait_with_usage(process, timeout=10.0)
    assert code == -9 and usage is not None
