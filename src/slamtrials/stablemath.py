"""Elementwise sin, cos, exp, log, power, arctan2 and hypot that give the same bits on every x86-64 machine.

A trial is chaotic: one last-bit difference in a heading moves every later scan, path and map, so
"the same seed gives the same trial" holds across machines only if every number on the way is computed
the same way everywhere. numpy does not promise that for its transcendental functions: where the CPU
has AVX-512 it computes sin, cos, exp, log, power, arctan2 and others with its own SIMD code (Intel's SVML), whose
results differ from the C library's by up to 4 ulp (numpy issue #23523), and which code it takes
depends on the machine a run lands on. numba's ``math`` functions call the C library's, and so do the
numba kernels of the simulator, GMapping and the explorer. The computing layers therefore take these
functions from here, never from numpy (``tests/test_architecture.py`` checks), so the whole trial
depends only on the C library (glibc's are the same on every x86-64 CPU with AVX2 and FMA).

On this project's development machine numpy's functions equal the C library's, so these give the same
bits as numpy's there (``tests/test_stablemath.py`` checks the C library's values themselves).

Each function takes floats or float64 arrays of any shape (broadcast like numpy) and returns a float
for scalar input, else a float64 array of the broadcast shape. (For type checkers, overloads say
"float in, float out" and "array in, array out"; a 0-d array, which also gives a float, is the one case
they do not describe.)
"""

from __future__ import annotations

import math
from typing import Any, overload

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

__all__ = ["arctan2", "cos", "exp", "hypot", "log", "power", "sin"]


@njit(cache=True, nogil=True)
def _sin(x, out):  # pragma: no cover - compiled
    for i in range(x.shape[0]):
        out[i] = math.sin(x[i])


@njit(cache=True, nogil=True)
def _cos(x, out):  # pragma: no cover - compiled
    for i in range(x.shape[0]):
        out[i] = math.cos(x[i])


@njit(cache=True, nogil=True)
def _exp(x, out):  # pragma: no cover - compiled
    for i in range(x.shape[0]):
        out[i] = math.exp(x[i])


@njit(cache=True, nogil=True)
def _log(x, out):  # pragma: no cover - compiled
    for i in range(x.shape[0]):
        out[i] = math.log(x[i])


@njit(cache=True, nogil=True)
def _power(x, y, out):  # pragma: no cover - compiled
    for i in range(x.shape[0]):
        out[i] = x[i] ** y[i]


@njit(cache=True, nogil=True)
def _arctan2(y, x, out):  # pragma: no cover - compiled
    for i in range(y.shape[0]):
        out[i] = math.atan2(y[i], x[i])


@njit(cache=True, nogil=True)
def _hypot(x, y, out):  # pragma: no cover - compiled
    for i in range(x.shape[0]):
        out[i] = math.hypot(x[i], y[i])


# Scalar versions. Python's math module calls the same C functions for sin, cos, exp and atan2 but
# raises where they return inf or nan, and its hypot is its own algorithm.
@njit(cache=True, nogil=True)
def _sin1(x):  # pragma: no cover - compiled
    return math.sin(x)


@njit(cache=True, nogil=True)
def _cos1(x):  # pragma: no cover - compiled
    return math.cos(x)


@njit(cache=True, nogil=True)
def _exp1(x):  # pragma: no cover - compiled
    return math.exp(x)


@njit(cache=True, nogil=True)
def _arctan21(y, x):  # pragma: no cover - compiled
    return math.atan2(y, x)


@njit(cache=True, nogil=True)
def _log1(x):  # pragma: no cover - compiled
    return math.log(x)


@njit(cache=True, nogil=True)
def _power1(x, y):  # pragma: no cover - compiled
    return x**y


@njit(cache=True, nogil=True)
def _hypot1(x, y):  # pragma: no cover - compiled
    return math.hypot(x, y)


def _unary(kernel, scalar, x: ArrayLike) -> float | NDArray[np.float64]:
    if isinstance(x, float) or np.ndim(x) == 0:  # float first: np.ndim costs a microsecond
        return scalar(float(x))
    values = np.asarray(x, dtype=np.float64)
    out = np.empty(values.shape)
    kernel(values.reshape(-1), out.reshape(-1))  # a fresh array's reshape is a view: written in place
    return out


def _binary(kernel, scalar, a: ArrayLike, b: ArrayLike) -> float | NDArray[np.float64]:
    if (isinstance(a, float) or np.ndim(a) == 0) and (isinstance(b, float) or np.ndim(b) == 0):
        return scalar(float(a), float(b))
    first = np.asarray(a, dtype=np.float64)
    second = np.asarray(b, dtype=np.float64)
    if first.shape != second.shape:
        shape = np.broadcast_shapes(first.shape, second.shape)
        first, second = np.broadcast_to(first, shape).copy(), np.broadcast_to(second, shape).copy()
    out = np.empty(first.shape)
    kernel(first.reshape(-1), second.reshape(-1), out.reshape(-1))
    return out


@overload
def sin(x: float) -> float: ...
@overload
def sin(x: NDArray[Any]) -> NDArray[np.float64]: ...
@overload
def sin(x: ArrayLike) -> float | NDArray[np.float64]: ...
def sin(x: ArrayLike) -> float | NDArray[np.float64]:
    """Sine of ``x`` (radians), elementwise, from the C library."""
    return _unary(_sin, _sin1, x)


@overload
def cos(x: float) -> float: ...
@overload
def cos(x: NDArray[Any]) -> NDArray[np.float64]: ...
@overload
def cos(x: ArrayLike) -> float | NDArray[np.float64]: ...
def cos(x: ArrayLike) -> float | NDArray[np.float64]:
    """Cosine of ``x`` (radians), elementwise, from the C library."""
    return _unary(_cos, _cos1, x)


@overload
def exp(x: float) -> float: ...
@overload
def exp(x: NDArray[Any]) -> NDArray[np.float64]: ...
@overload
def exp(x: ArrayLike) -> float | NDArray[np.float64]: ...
def exp(x: ArrayLike) -> float | NDArray[np.float64]:
    """``e ** x``, elementwise, from the C library."""
    return _unary(_exp, _exp1, x)


@overload
def log(x: float) -> float: ...
@overload
def log(x: NDArray[Any]) -> NDArray[np.float64]: ...
@overload
def log(x: ArrayLike) -> float | NDArray[np.float64]: ...
def log(x: ArrayLike) -> float | NDArray[np.float64]:
    """Natural logarithm of ``x``, elementwise, from the C library (-inf at 0, nan below 0)."""
    return _unary(_log, _log1, x)


@overload
def power(x: float, y: float) -> float: ...
@overload
def power(x: NDArray[Any], y: ArrayLike) -> NDArray[np.float64]: ...
@overload
def power(x: ArrayLike, y: NDArray[Any]) -> NDArray[np.float64]: ...
@overload
def power(x: ArrayLike, y: ArrayLike) -> float | NDArray[np.float64]: ...
def power(x: ArrayLike, y: ArrayLike) -> float | NDArray[np.float64]:
    """``x ** y``, elementwise, from the C library's ``pow``."""
    return _binary(_power, _power1, x, y)


@overload
def arctan2(y: float, x: float) -> float: ...
@overload
def arctan2(y: NDArray[Any], x: ArrayLike) -> NDArray[np.float64]: ...
@overload
def arctan2(y: ArrayLike, x: NDArray[Any]) -> NDArray[np.float64]: ...
@overload
def arctan2(y: ArrayLike, x: ArrayLike) -> float | NDArray[np.float64]: ...
def arctan2(y: ArrayLike, x: ArrayLike) -> float | NDArray[np.float64]:
    """Angle (radians, in [-pi, pi]) of the point (``x``, ``y``), elementwise, from the C library."""
    return _binary(_arctan2, _arctan21, y, x)


@overload
def hypot(x: float, y: float) -> float: ...
@overload
def hypot(x: NDArray[Any], y: ArrayLike) -> NDArray[np.float64]: ...
@overload
def hypot(x: ArrayLike, y: NDArray[Any]) -> NDArray[np.float64]: ...
@overload
def hypot(x: ArrayLike, y: ArrayLike) -> float | NDArray[np.float64]: ...
def hypot(x: ArrayLike, y: ArrayLike) -> float | NDArray[np.float64]:
    """``sqrt(x**2 + y**2)`` without overflow, elementwise, from the C library."""
    return _binary(_hypot, _hypot1, x, y)
