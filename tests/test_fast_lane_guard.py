"""The fast lane's time guard (tests/conftest.py), run on small test files of its own: a test not marked
slow whose call or set-up runs over the limit fails, naming itself, its time and the fix; a test marked
slow does not; the time numba spends compiling is left out; and in a session whose kernels had to compile
(a cold cache) an overrun is reported at the end instead of failing."""

from __future__ import annotations

from pathlib import Path

import numba
import numba.extending  # noqa: F401  (the inner tests' import: loaded before pytester's snapshot)
import pytest

pytest_plugins = ["pytester"]

CONFTEST = Path(__file__).with_name("conftest.py")
#: The inner sessions' limit (s) and what their slow tests sleep: 10 times the limit, so the guard, which
#: scales its limit by the load, still catches them on a machine loaded 10 times over.
LIMIT, NAP = 0.05, 0.5

SLOW_AND_FAST = f"""
import time

import pytest


def test_quick():
    pass


def test_naps():
    time.sleep({NAP})


@pytest.mark.slow
def test_naps_but_is_marked_slow():
    time.sleep({NAP})


@pytest.fixture
def slow_to_make():
    time.sleep({NAP})


def test_with_a_slow_fixture(slow_to_make):
    pass
"""


@pytest.fixture
def numba_loaded():
    """numba imports modules at its first compile in a process: done here, before pytester takes its
    snapshot of sys.modules, or pytester would drop them after an inner session and the next compile in
    this process would register numba's types a second time (a KeyError)."""
    numba.njit(lambda x: x + 1)(1)


@pytest.fixture
def guarded(numba_loaded, pytester, monkeypatch):
    """A pytester folder with the suite's conftest.py and the slow marker, the guard's limit at LIMIT."""
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makeini("[pytest]\nmarkers =\n    slow: slow\n")
    monkeypatch.setenv("SLAMTRIALS_TEST_TIME_LIMIT", str(LIMIT))
    return pytester


def test_an_unmarked_test_over_the_limit_fails_and_a_marked_one_passes(guarded):
    guarded.makepyfile(test_lane=SLOW_AND_FAST)
    result = guarded.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(passed=2, failed=1, errors=1)
    result.stdout.fnmatch_lines(
        [
            "*test_lane.py::test_naps: its call took * s, over the fast lane's * s (0.05 s at load * on * "
            "cores, numba compiling left out); mark it @pytest.mark.slow or make it cheaper"
        ]
    )
    result.stdout.fnmatch_lines(["*test_lane.py::test_with_a_slow_fixture: its set-up took * s, *(0.1 s at*"])
    assert "test_naps_but_is_marked_slow:" not in result.stdout.str()


def test_the_guard_is_off_at_a_limit_of_zero(guarded, monkeypatch):
    guarded.makepyfile(test_lane=SLOW_AND_FAST)
    monkeypatch.setenv("SLAMTRIALS_TEST_TIME_LIMIT", "0")
    guarded.runpytest("-p", "no:cacheprovider").assert_outcomes(passed=4)


def test_time_spent_compiling_is_left_out(guarded):
    # the kernel's compile includes its typing, which here sleeps: numba's compile event covers it
    guarded.makepyfile(
        test_kernel=f"""
import time

import numba
from numba.extending import overload


def typed_slowly():
    pass


@overload(typed_slowly)
def _typed_slowly():
    time.sleep({NAP})
    return lambda: None


@numba.njit
def kernel():
    typed_slowly()
    return 1


def test_compiles_a_kernel():
    assert kernel() == 1
"""
    )
    guarded.runpytest("-p", "no:cacheprovider").assert_outcomes(passed=1)


@pytest.mark.slow  # a new Python process that compiles a kernel into an empty numba cache: seconds
def test_after_a_cache_miss_an_overrun_is_reported_not_failed(guarded, monkeypatch, tmp_path):
    guarded.makepyfile(
        test_cold=f"""
import time

import numba

from slamtrials import stablemath


def test_a_kernel_compiles():  # as a kernel does when the cache is cold: a cache=True function compiled
    assert numba.njit(cache=True)(stablemath._cos1.py_func)(0.0) == 1.0


def test_naps():
    time.sleep({NAP})
"""
    )
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba-cache"))  # empty: the kernel compiles
    result = guarded.runpytest_subprocess("-p", "no:cacheprovider")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(
        [
            "*fast lane: tests over the time limit*",
            "not failed, because numba compiled 1 function its on-disk cache should hold in this session*",
            "*test_cold.py::test_naps: its call took * s, over the fast lane's*",
        ]
    )
