"""Fixtures and hooks shared across test folders: synthetic drives for tests that compare an estimate's
turns with a run's odometry, one click command per typer app for the CLI tests, and the fast lane's
time guard."""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable

import numpy as np
import pytest
from numba.core import event
from numba.core.caching import NullCache

from slamtrials.compilewatch import CompileTimer
from slamtrials.geometry import compose

# ----------------------------------------------------------------------------------- Dask


@pytest.fixture(scope="session")
def client():
    """Two single-threaded Dask workers in this process (fast to start; tasks share the test's imports),
    one cluster for the whole session."""
    from distributed import Client, LocalCluster

    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as c,
    ):
        yield c


# ----------------------------------------------------------------------------------- the fast lane's guard

#: The longest a test not marked slow may run, in seconds, on a machine with a core to spare (``make
#: test-fast`` runs over 3,000 tests in under 2 minutes; the slowest of them take about 3 s): its call,
#: and twice as long for its set-up (a module's or the session's fixtures, shared by several tests, are
#: made in the first one's). Above it the test fails and says so; mark it ``@pytest.mark.slow`` or make it
#: cheaper. ``SLAMTRIALS_TEST_TIME_LIMIT`` sets another limit for the call, 0 turns the guard off.
FAST_TEST_LIMIT_S = 5.0
SETUP_FACTOR = 2.0


def _limit() -> float:
    value = os.environ.get("SLAMTRIALS_TEST_TIME_LIMIT", "")
    return float(value) if value.strip() else FAST_TEST_LIMIT_S


def _load_scale() -> tuple[float, float]:
    """(factor, load): the 1-minute load average per core, at least 1. A test that needs one core for
    t seconds takes about factor * t when other work keeps more cores than there are busy."""
    load = os.getloadavg()[0]
    return max(1.0, load / (os.cpu_count() or 1)), load


class _CacheMisses(event.Listener):
    """Counts compiles of functions declared with ``cache=True``: each is a miss of numba's on-disk cache
    (a cache hit loads the machine code and fires no compile event)."""

    def __init__(self) -> None:
        self.count = 0

    def on_start(self, ev) -> None:
        if not isinstance(getattr(ev.data.get("dispatcher"), "_cache", NullCache()), NullCache):
            self.count += 1

    def on_end(self, ev) -> None:
        pass


class _TimeGuard:
    """Fails a test not marked slow whose set-up or call runs over the limit, after taking out the time
    numba spent compiling in it (a cold cache costs the first test of a kernel up to a minute) and
    scaling the limit by the machine's load. In a session where numba had to compile a kernel its
    on-disk cache should hold (a clean clone, an edited kernel), other processes a test starts may be
    compiling too: an overrun is then reported at the end instead of failing the test."""

    def __init__(self, limit: float) -> None:
        self.limit = limit
        self.compiling = CompileTimer(clock=time.perf_counter)
        self.misses = _CacheMisses()
        event.register("numba:compile", self.misses)
        self.excused: list[str] = []

    def close(self) -> None:
        self.compiling.stop()
        event.unregister("numba:compile", self.misses)

    def check(self, item: pytest.Item, phase: str, started: float, compiled_before: float) -> None:
        took = time.perf_counter() - started - (self.compiling.seconds - compiled_before)
        factor, load = _load_scale()
        base = self.limit * (SETUP_FACTOR if phase == "set-up" else 1.0)
        limit = base * factor
        if took <= limit:
            return
        message = (
            f"{item.nodeid}: its {phase} took {took:.1f} s, over the fast lane's {limit:.2f} s "
            f"({base:g} s at load {load:.1f} on {os.cpu_count()} cores, numba compiling left out); "
            "mark it @pytest.mark.slow or make it cheaper"
        )
        if self.misses.count:
            self.excused.append(message)
        else:
            pytest.fail(message, pytrace=False)


_GUARD_KEY = pytest.StashKey[_TimeGuard]()


def pytest_configure(config: pytest.Config) -> None:
    limit = _limit()
    if limit > 0 and sys.gettrace() is None:  # not under coverage or a debugger, which slow everything
        config.stash[_GUARD_KEY] = _TimeGuard(limit)


def pytest_unconfigure(config: pytest.Config) -> None:
    guard = config.stash.get(_GUARD_KEY, None)
    if guard is not None:
        guard.close()


def _guarded(item: pytest.Item):
    """The guard, if it watches this test: none for a test marked slow or when the guard is off."""
    guard = item.config.stash.get(_GUARD_KEY, None)
    if guard is None or item.get_closest_marker("slow") is not None:
        return None
    return guard


def _timed(item: pytest.Item, phase: str):
    """The body of a hook wrapper around one phase of a test: the guard times it (if it watches the test)."""
    guard = _guarded(item)
    if guard is None:
        return (yield)
    started, compiled = time.perf_counter(), guard.compiling.seconds
    result = yield  # a phase that fails raises here and is reported as it is
    guard.check(item, phase, started, compiled)
    return result


@pytest.hookimpl(wrapper=True)
def pytest_runtest_setup(item: pytest.Item):
    return (yield from _timed(item, "set-up"))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item):
    return (yield from _timed(item, "call"))


def pytest_terminal_summary(terminalreporter, exitstatus, config: pytest.Config) -> None:
    guard = config.stash.get(_GUARD_KEY, None)
    if guard is not None and guard.excused:
        terminalreporter.section("fast lane: tests over the time limit")
        count = guard.misses.count
        terminalreporter.write_line(
            f"not failed, because numba compiled {count} function{'s' * (count != 1)} its on-disk cache should "
            "hold in this session (processes the tests start may have compiled too); run again to check:"
        )
        for message in guard.excused:
            terminalreporter.write_line(f"  {message}")


# ------------------------------------------------------------------------ hypothesis in the fast lane

#: In the fast lane (``-m "not slow"``, ``make test-fast``) a property test tries a fifth of its examples
#: (at least 10); ``make test`` tries them all.
FAST_LANE_EXAMPLES = 0.2


def _fast_lane(config: pytest.Config) -> bool:
    return "not slow" in (config.option.markexpr or "")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if not _fast_lane(config):
        return
    from hypothesis import settings

    for item in items:
        test = getattr(item, "obj", None)
        # the settings a @given test runs with (hypothesis reads them when the test is called)
        chosen = getattr(test, "_hypothesis_internal_use_settings", None)
        if isinstance(chosen, settings) and chosen.max_examples > 10:
            fewer = max(10, int(chosen.max_examples * FAST_LANE_EXAMPLES))
            test._hypothesis_internal_use_settings = settings(chosen, max_examples=fewer)


# ------------------------------------------------------------------------------------- the CLI tests' app


@pytest.fixture(scope="session", autouse=True)
def _one_click_command_per_app():
    """typer's CliRunner builds the click command tree from the typer app on every invoke (about 45 ms for
    slamtrials' app, some 20 s over the suite); build it once per app and set of commands instead. The
    tree holds no state of an invocation: each invoke makes its own context."""
    import typer.testing

    build = typer.testing._get_command
    built: dict[int, tuple[object, tuple[int, int, int], object]] = {}

    def get_command(app):
        shape = (len(app.registered_commands), len(app.registered_groups), id(app.registered_callback))
        kept = built.get(id(app))
        if kept is None or kept[1] != shape:
            kept = built[id(app)] = (app, shape, build(app))  # the app kept: its id stays its own
        return kept[2]

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(typer.testing, "_get_command", get_command)
        yield


# -------------------------------------------------------------------------------------- synthetic drives


def _drive(seed: int, seconds: float = 300.0, dt: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Times and poses of a robot at 0.4 m/s that picks a new turn rate in [-0.6, 0.6] rad/s every 3 s."""
    rng = np.random.default_rng(seed)
    n = int(seconds / dt)
    rates = np.repeat(rng.uniform(-0.6, 0.6, n // 30 + 1), 30)[: n - 1]
    poses = np.zeros((n, 3))
    for k in range(n - 1):
        poses[k + 1] = compose(poses[k], [0.4 * dt, 0.0, rates[k] * dt])
    return np.arange(n) * dt, poses


def _odometry_of(poses: np.ndarray, seed: int, turn_scale: float = 1.06) -> np.ndarray:
    """Odometry that drifts from ``poses``: 6 % over-counted turns and noise on every step."""
    rng = np.random.default_rng(seed)
    out = np.zeros_like(poses)
    out[0] = [5.0, -2.0, 1.0]  # its own frame
    for k in range(len(poses) - 1):
        dx, dy, dth = poses[k + 1] - poses[k]
        c, s = np.cos(poses[k, 2]), np.sin(poses[k, 2])
        step = np.array([c * dx + s * dy, -s * dx + c * dy, np.arctan2(np.sin(dth), np.cos(dth))])
        step = step * [1.0, 1.0, turn_scale] + rng.normal(0.0, [0.002, 0.002, 0.004])
        out[k + 1] = compose(out[k], step)
    return out


@pytest.fixture
def drive() -> Callable[..., tuple[np.ndarray, np.ndarray]]:
    """``drive(seed, seconds=300, dt=0.1)``: times (s) and poses ``[T, 3]`` of a turning robot."""
    return _drive


@pytest.fixture
def odometry_of() -> Callable[..., np.ndarray]:
    """``odometry_of(poses, seed, turn_scale=1.06)``: a drifting odometry of ``poses`` in its own frame."""
    return _odometry_of
