"""Notice when numba compiles one of slamtrials' kernels instead of loading it from its on-disk cache.

Every kernel is declared with ``cache=True``: the first process after an install (or after a kernel's
source changed) compiles it, which for a trial's kernels takes tens of seconds; later processes load
the machine code from the cache (``__pycache__`` next to the source, or ``NUMBA_CACHE_DIR``) in a
fraction of a second. numba announces a compile through its ``"numba:compile"`` event, which fires
only on a cache miss, so listening to it tells a compiling run from a cached one exactly.

:class:`CompileTimer` adds up the CPU time one thread spends compiling, so that what a run costs can be
told apart from what its first call in a fresh process paid to compile (:mod:`slamtrials.costmeter`).

Library code does not print: this module logs each compile (INFO for the kernels a caller asked for,
DEBUG for the kernels they call) and hands the first one to a callback; the CLI decides what to say.
"""

from __future__ import annotations

import logging
import threading
import time
import weakref
from collections.abc import Callable

from numba.core import event

__all__ = ["watch_compilation", "CompileTimer"]

log = logging.getLogger(__name__)

_PACKAGE = "slamtrials."


class _CompileListener(event.Listener):
    """Counts nested compiles per thread; calls ``on_first(kernel)`` for the first slamtrials kernel."""

    def __init__(self, on_first: Callable[[str], None] | None) -> None:
        self._on_first = on_first
        self._fired = False
        self._lock = threading.Lock()
        self._local = threading.local()

    def _stack(self) -> list[tuple[str | None, float]]:
        stack = getattr(self._local, "stack", None)
        if stack is None:
            stack = self._local.stack = []
        return stack

    def on_start(self, ev) -> None:
        function = ev.data["dispatcher"].py_func
        module = getattr(function, "__module__", None) or ""
        kernel = f"{module}.{function.__qualname__}" if module.startswith(_PACKAGE) else None
        stack = self._stack()
        stack.append((kernel, time.perf_counter()))
        if kernel is None:
            return
        with self._lock:
            first, self._fired = not self._fired, True
        if first and self._on_first is not None:
            self._on_first(kernel)

    def on_end(self, ev) -> None:
        stack = self._stack()
        if not stack:  # started before this listener was registered
            return
        kernel, started = stack.pop()
        if kernel is not None:
            outermost = not any(name is not None for name, _ in stack)
            log.log(
                logging.INFO if outermost else logging.DEBUG,
                "compiled %s in %.1f s (not in numba's on-disk cache)",
                kernel,
                time.perf_counter() - started,
            )


def watch_compilation(on_first_compile: Callable[[str], None] | None = None) -> Callable[[], None]:
    """Listen for numba compiling slamtrials kernels in this process, from now until the returned
    function is called.

    on_first_compile:
        Called once, with the kernel's qualified name (e.g. ``"slamtrials.sim.raycast._cast_scan"``),
        when the first kernel starts compiling; never if every kernel comes from the cache. It runs in
        the compiling thread, before the compile.

    Returns the function that stops listening. Each compile is logged on this module's logger.
    """
    listener = _CompileListener(on_first_compile)
    event.register("numba:compile", listener)
    return lambda: event.unregister("numba:compile", listener)


class _ThreadCompileListener(event.Listener):
    """Adds the time (by ``clock``) of one thread's outermost compiles to ``seconds``."""

    def __init__(self, thread: int, clock: Callable[[], float] = time.thread_time) -> None:
        self._thread = thread
        self._clock = clock
        self._depth = 0
        self._started = 0.0
        self.seconds = 0.0

    def on_start(self, ev) -> None:
        if threading.get_ident() != self._thread:
            return
        if self._depth == 0:
            self._started = self._clock()
        self._depth += 1

    def on_end(self, ev) -> None:
        if threading.get_ident() != self._thread or self._depth == 0:
            return
        self._depth -= 1
        if self._depth == 0:
            self.seconds += self._clock() - self._started


class CompileTimer:
    """The thread CPU seconds the thread that made it spends in numba compiles (cache misses) while it listens.

    Nested compiles (a kernel compiling the kernels it calls) count once, from the outermost one's start to
    its end; compiles in other threads are not counted. :attr:`seconds` is the total so far; :meth:`stop`
    stops listening (so does the timer's garbage collection). ``clock`` measures the time: the thread's CPU
    time by default, ``time.perf_counter`` for the wall-clock time the compiles took (what the test suite's
    time guard leaves out of a test's time).
    """

    def __init__(self, clock: Callable[[], float] = time.thread_time) -> None:
        self._listener = _ThreadCompileListener(threading.get_ident(), clock)
        event.register("numba:compile", self._listener)
        self._stop = weakref.finalize(self, event.unregister, "numba:compile", self._listener)

    @property
    def seconds(self) -> float:
        """Seconds spent compiling so far (thread CPU seconds, unless another clock was given)."""
        return self._listener.seconds

    def stop(self) -> None:
        """Stop listening; :attr:`seconds` keeps its total."""
        self._stop()
