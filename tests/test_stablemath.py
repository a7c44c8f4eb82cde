"""slamtrials.stablemath: the C library's sin, cos, exp, log, pow, arctan2 and hypot, elementwise, in numpy's shapes."""

from __future__ import annotations

import ctypes
import ctypes.util
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from slamtrials import stablemath

_LIBM = ctypes.CDLL(ctypes.util.find_library("m"))
for _name, _arity in (("sin", 1), ("cos", 1), ("exp", 1), ("log", 1), ("atan2", 2), ("hypot", 2), ("pow", 2)):
    getattr(_LIBM, _name).restype = ctypes.c_double
    getattr(_LIBM, _name).argtypes = [ctypes.c_double] * _arity

UNARY = [
    (stablemath.sin, _LIBM.sin),
    (stablemath.cos, _LIBM.cos),
    (stablemath.exp, _LIBM.exp),
    (stablemath.log, _LIBM.log),
]
BINARY = [(stablemath.arctan2, _LIBM.atan2), (stablemath.hypot, _LIBM.hypot), (stablemath.power, _LIBM.pow)]
SPECIAL = [0.0, -0.0, 1e-310, -1e-310, 1e-8, math.pi, -math.pi / 2, 710.0, -746.0, 1e6, 1e22, math.inf, -math.inf]


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """The same bits, except that a NaN is a NaN whatever its sign and payload (log of a negative number)."""
    a, b = np.atleast_1d(np.asarray(a, dtype=np.float64)), np.atleast_1d(np.asarray(b, dtype=np.float64))
    nan = np.isnan(a)
    return bool(np.array_equal(nan, np.isnan(b)) and np.array_equal(a[~nan].view(np.int64), b[~nan].view(np.int64)))


@pytest.mark.parametrize(("ours", "libm"), UNARY, ids=["sin", "cos", "exp", "log"])
def test_unary_functions_give_the_c_librarys_bits(ours, libm) -> None:
    x = np.concatenate([np.random.default_rng(3).uniform(-40.0, 40.0, 5000), SPECIAL])
    expected = np.array([libm(v) for v in x])
    assert _same_bits(ours(x), expected)
    assert _same_bits(ours(x[::-3]), expected[::-3])  # strided input
    assert np.isnan(ours(np.array([np.nan])))[0]


@pytest.mark.parametrize(("ours", "libm"), BINARY, ids=["arctan2", "hypot", "power"])
def test_binary_functions_give_the_c_librarys_bits(ours, libm) -> None:
    rng = np.random.default_rng(4)
    a = np.concatenate([rng.uniform(-5.0, 5.0, 3000), np.array(SPECIAL), np.array(SPECIAL)])
    b = np.concatenate([rng.uniform(-5.0, 5.0, 3000), np.array(SPECIAL), np.array(SPECIAL[::-1])])
    assert _same_bits(ours(a, b), np.array([libm(u, v) for u, v in zip(a, b)]))


@settings(max_examples=200, deadline=None)
@given(
    st.floats(allow_nan=False, allow_infinity=False, min_value=-1e9, max_value=1e9),
    st.floats(allow_nan=False, allow_infinity=False, min_value=-1e9, max_value=1e9),
)
def test_every_function_agrees_with_the_c_library_on_any_finite_input(x: float, y: float) -> None:
    for ours, libm in UNARY:
        assert _same_bits(np.float64(ours(x)), np.float64(libm(x)))
    for ours, libm in BINARY:
        assert _same_bits(np.float64(ours(x, y)), np.float64(libm(x, y)))


def test_hypot_is_the_c_librarys_not_pythons() -> None:
    # Python's math.hypot is its own algorithm: with glibc 2.36 and Python 3.11 the two disagree in the
    # last bit for about 0.6 % of these pairs; ours must be the C library's, scalars included
    x, y = np.random.default_rng(5).uniform(-5.0, 5.0, (2, 20000))
    libm = np.array([_LIBM.hypot(u, v) for u, v in zip(x, y)])
    assert _same_bits(stablemath.hypot(x, y), libm)
    python = np.array([math.hypot(u, v) for u, v in zip(x, y)])
    differ = np.flatnonzero(python != libm)
    for i in differ[:20]:
        assert stablemath.hypot(float(x[i]), float(y[i])) == libm[i] != python[i]
    assert stablemath.hypot(float(x[0]), float(y[0])) == libm[0]


def test_shapes_follow_numpy() -> None:
    angles = np.linspace(-3.0, 3.0, 12).reshape(3, 4)
    assert stablemath.cos(angles).shape == (3, 4)
    assert stablemath.sin(angles.T).shape == (4, 3)
    assert isinstance(stablemath.sin(0.5), float) and isinstance(stablemath.exp(np.float64(1.0)), float)
    assert isinstance(stablemath.cos(np.array(0.25)), float)
    assert isinstance(stablemath.hypot(3, 4), float) and stablemath.hypot(3, 4) == 5.0
    assert stablemath.cos([0.0, 0.0]).tolist() == [1.0, 1.0]
    assert stablemath.cos(np.zeros(0)).shape == (0,)
    # broadcasting: a column against a row, an array against a scalar
    column, row = np.arange(3.0)[:, None], np.arange(1.0, 5.0)[None, :]
    assert _same_bits(
        stablemath.arctan2(column, row), np.array([[_LIBM.atan2(c, r) for r in range(1, 5)] for c in range(3)])
    )
    assert _same_bits(stablemath.hypot(np.arange(4.0), 2.0), np.array([_LIBM.hypot(v, 2.0) for v in range(4)]))


def test_importing_slamtrials_keeps_numba_off_svml() -> None:
    """With Intel's SVML installed, numba would vectorize math calls into SVML's (other) results."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_INTEL_SVML"}
    code = "import slamtrials.geometry, numba; print(numba.config.DISABLE_INTEL_SVML, numba.config.USING_SVML)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    assert out.split() == ["1", "False"]
