"""A run that has to compile numba kernels says so once; a run that finds them in the cache says nothing."""

from __future__ import annotations

import logging
import os
import pty
import subprocess
import sys
import time

import numba
import pytest

from slamtrials import stablemath
from slamtrials.cli.main import COMPILING_NOTICE
from slamtrials.compilewatch import CompileTimer, watch_compilation


def _twice(x):
    return 2.0 * x


def test_the_first_slamtrials_compile_is_announced_once_and_each_is_logged(caplog):
    seen = []
    stop = watch_compilation(seen.append)
    try:
        with caplog.at_level(logging.DEBUG, logger="slamtrials.compilewatch"):
            numba.njit(_twice)(1.0)  # not a slamtrials kernel: no announcement
            assert seen == []
            # fresh dispatchers (no cache) of a slamtrials kernel's Python function: they must compile
            numba.njit(stablemath._cos1.py_func)(0.5)
            numba.njit(stablemath._sin1.py_func)(0.5)
    finally:
        stop()
    assert seen == ["slamtrials.stablemath._cos1"]
    logged = [r.getMessage() for r in caplog.records if r.name == "slamtrials.compilewatch"]
    assert (
        len(logged) == 2 and "slamtrials.stablemath._cos1" in logged[0] and "slamtrials.stablemath._sin1" in logged[1]
    )
    numba.njit(stablemath._cos1.py_func)(0.5)  # after stop(): not heard
    assert seen == ["slamtrials.stablemath._cos1"]


def _cli(*args: str, cache) -> tuple[int, str, str]:
    """Exit status, stdout and stderr of ``slamtrials ARGS`` in a new process whose stderr is a terminal
    (a pseudo-terminal), with numba's cache in ``cache``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    code = "import sys; from slamtrials.cli.main import main; sys.argv[0] = 'slamtrials'; main()"
    leader, follower = pty.openpty()
    try:
        done = subprocess.run(
            [sys.executable, "-c", code, *args],
            env=env,
            stdout=subprocess.PIPE,
            stderr=follower,
            text=True,
            timeout=300,
            check=False,
        )
    finally:
        os.close(follower)
    stderr = b""
    while True:
        try:
            chunk = os.read(leader, 4096)
        except OSError:  # EIO: the terminal has no writer left and nothing more to read
            break
        if not chunk:
            break
        stderr += chunk
    os.close(leader)
    return done.returncode, done.stdout, stderr.decode().replace("\r\n", "\n")


@pytest.mark.slow
def test_a_command_says_once_that_it_compiles_and_not_when_the_cache_has_the_kernels(tmp_path):
    cache = tmp_path / "numba-cache"  # empty: every kernel the command needs is compiled
    status, stdout, stderr = _cli("worlds", "info", "office_small_01", cache=cache)
    assert status == 0, stderr
    assert stderr.splitlines().count(COMPILING_NOTICE) == 1, stderr
    assert COMPILING_NOTICE not in stdout and "office_small_01" in stdout
    status, again, stderr = _cli("worlds", "info", "office_small_01", cache=cache)
    assert status == 0, stderr
    assert COMPILING_NOTICE not in stderr
    assert again == stdout


@pytest.mark.slow  # compiles again in a new process (seconds); the test above covers the notice itself
def test_no_notice_when_stderr_is_not_a_terminal(tmp_path):
    # scripts, logs and tests get a clean stderr (with --verbose, the log names each kernel compiled)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")}
    code = "import sys; from slamtrials.cli.main import main; sys.argv[0] = 'slamtrials'; main()"
    done = subprocess.run(
        [sys.executable, "-c", code, "-v", "worlds", "info", "office_small_01"],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert COMPILING_NOTICE not in done.stderr
    assert "compiled slamtrials.stablemath." in done.stderr


def test_the_compile_timer_measures_by_the_clock_it_is_given():
    # the typing of ``late`` sleeps: wall-clock time inside the compile, no CPU time
    from numba.extending import overload

    def late():
        pass

    @overload(late)
    def _late():
        time.sleep(0.2)
        return lambda: None

    def kernel():
        late()
        return 1

    cpu, wall = CompileTimer(), CompileTimer(clock=time.perf_counter)
    try:
        assert numba.njit(kernel)() == 1
    finally:
        cpu.stop()
        wall.stop()
    assert wall.seconds >= 0.2 > cpu.seconds > 0.0
