"""The odometry error model: a constant per-run scale bias on distance and rotation, plus optional noise.

As in the paper (and Stage's odometry error), odometry multiplies the distance travelled by
``1 + e_lin`` and the rotation by ``1 + e_ang``, with ``e_lin`` and ``e_ang`` drawn once per run.

How a step is scaled
--------------------
Each step, the true motion is the relative pose ``delta = ominus(truth_prev, truth_new) = (dx, dy, phi)``
in the robot frame at the start of the step. The simulator's steps are circular arcs (or turns in
place), so ``delta`` is read as an arc: heading change ``phi`` and arc length
``L = c / sinc(phi / 2)``, where ``c = |(dx, dy)|`` is the chord and ``sinc(x) = sin(x) / x``; the chord
points at ``phi / 2`` from the start heading (``phi / 2 + pi`` when driving backwards).

The odometry measures the arc length ``L' = (1 + e_lin) L (+ noise)`` and the heading change
``phi' = (1 + e_ang) phi (+ noise)``, as a differential drive whose encoders over-read distance and
rotation would, and integrates them exactly as an arc: the measured chord has length
``c' = L' sinc(phi' / 2)`` and points at ``phi' / 2`` (the true chord rotated by ``(phi' - phi) / 2``).
The measured increment is composed onto the odometry pose, which starts at (0, 0, 0).

Consequences: driving straight, the odometry distance is exactly ``(1 + e_lin)`` times the true one;
turning in place, the odometry rotation is exactly ``(1 + e_ang)`` times the true one (with
``e_ang = -1 deg/rad``, 360 deg of true rotation read 353.72 deg).

Random noise: a random walk per metre and per radian
----------------------------------------------------
The optional noise is a random walk in distance travelled and angle turned, not in time or in steps: a
step of arc length ``L`` and heading change ``phi`` adds zero-mean Gaussian errors with variances

    var(arc length)    = a^2 |L| + b^2 |phi|      a = noise_linear_per_m (m/sqrt(m)), b = noise_linear_per_rad (m/sqrt(rad))
    var(heading change) = c^2 |phi| + d^2 |L|      c = noise_angular_per_rad (rad/sqrt(rad)), d = noise_angular_per_m (rad/sqrt(m))

Variances of independent steps add, and ``|L|`` and ``|phi|`` add along a path, so the error accumulated
over a stretch of path is the same however the stretch is cut into steps: 0.1 s steps, irregular steps,
sub-millisecond steps or steps of zero length (a duplicated stamp) alike. Over ``D`` metres driven and
``R`` radians turned the arc-length error has variance ``a^2 D + b^2 R`` and the heading error ``c^2 R +
d^2 D``. (The model this replaced had standard deviations proportional to the step, ``k L``, whose
accumulated variance ``k^2 sum L^2`` shrinks as the steps do; it needed a rescaling by the step's duration,
which blew up across the near-zero gaps of a log whose stamps were out of order.)

Slips are a Poisson process in distance: a step of arc length ``L`` holds ``k`` slips, ``k`` Poisson of
mean ``slip_per_m |L|`` (so it slips at all with probability ``1 - exp(-slip_per_m |L|)``), and each slip
adds ``N(0, slip_linear_std)`` to the arc length and ``N(0, slip_angular_std)`` to the heading change.
The number of slips along a path, and their summed errors, therefore do not depend on how it is cut.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials.geometry import compose1
from slamtrials.sim.config import OdometryConfig
from slamtrials.sim.robot import sinc

__all__ = ["draw_bias", "measured_increment", "step_noise_std", "slip_count", "Odometry"]


def draw_bias(config: OdometryConfig, rng: np.random.Generator) -> dict[str, float]:
    """Draw the per-run bias: ``{"linear": e_lin (m/m), "angular": e_ang (rad/rad)}``.

    Two uniform deviates are always drawn from ``rng`` (linear first), even when the config fixes a
    value, so fixing the bias leaves the rest of the random stream unchanged.
    """
    lin = float(rng.uniform(*config.bias_linear_range))
    ang = float(rng.uniform(*config.bias_angular_range))
    if config.bias_linear is not None:
        lin = float(config.bias_linear)
    if config.bias_angular is not None:
        ang = float(config.bias_angular)
    return {"linear": lin, "angular": ang}


def measured_increment(
    delta: ArrayLike, bias_linear: float, bias_angular: float, noise_linear: float = 0.0, noise_angular: float = 0.0
) -> NDArray[np.float64]:
    """The odometry increment measured for the true step ``delta``.

    Parameters
    ----------
    delta:
        float64 ``[3]`` true relative pose (dx, dy, phi) of the step, in the robot frame at its start
        (m, m, rad; ``|phi| < pi``).
    bias_linear, bias_angular:
        Scale errors ``e_lin`` (m/m) and ``e_ang`` (rad/rad).
    noise_linear:
        Additive error (m) on the measured arc length (in the direction of travel).
    noise_angular:
        Additive error (rad) on the measured heading change.

    Returns
    -------
    float64 ``[3]`` measured relative pose (dx', dy', phi'), see the module docstring.
    """
    dx, dy, phi = (float(v) for v in np.asarray(delta, dtype=np.float64))
    phi_m = (1.0 + bias_angular) * phi + noise_angular
    chord = math.hypot(dx, dy)
    if chord == 0.0:  # a turn in place: an arc-length error moves along the mean heading of the step
        if noise_linear == 0.0:
            return np.array([0.0, 0.0, phi_m])
        half = 0.5 * phi_m
        return np.array([noise_linear * math.cos(half), noise_linear * math.sin(half), phi_m])
    length = chord / sinc(0.5 * phi)  # arc length, >= 0 (the direction sits in the chord)
    length_m = (1.0 + bias_linear) * length + noise_linear
    scale = length_m * sinc(0.5 * phi_m) / chord
    turn = 0.5 * (phi_m - phi)
    c, s = math.cos(turn), math.sin(turn)
    return np.array([scale * (c * dx - s * dy), scale * (s * dx + c * dy), phi_m])


def step_noise_std(coef_main: float, motion_main: float, coef_cross: float, motion_cross: float) -> float:
    """Standard deviation of one step's random-walk error: ``sqrt(coef_main^2 |motion_main| +
    coef_cross^2 |motion_cross|)``.

    For the arc length ``coef_main`` is ``noise_linear_per_m`` (m/sqrt(m)) with ``motion_main`` the
    step's arc length (m), and ``coef_cross`` ``noise_linear_per_rad`` (m/sqrt(rad)) with its heading
    change (rad); for the heading change the roles swap (``noise_angular_per_rad`` with the heading
    change, ``noise_angular_per_m`` with the arc length). Scalars in, a scalar out (``math.sqrt`` is
    correctly rounded, so the result does not depend on the CPU).
    """
    return math.sqrt(coef_main * coef_main * abs(motion_main) + coef_cross * coef_cross * abs(motion_cross))


def slip_count(slip_per_m: float, length: float, u: float) -> int:
    """Slips in a step of arc length ``length`` (m): the Poisson count of mean ``slip_per_m |length|``
    whose CDF first reaches the uniform ``u`` in [0, 1) (inverse-CDF sampling, so one uniform decides it).

    ``k = 0`` exactly when ``u < exp(-slip_per_m |length|)``: the step slips with chance ``1 -
    exp(-slip_per_m |length|)``. Scalars through ``math`` (the C library's), so the count does not depend
    on the CPU.
    """
    mean = slip_per_m * abs(length)
    term = math.exp(-mean)
    cdf = term
    k = 0
    while u >= cdf and k < 10_000:
        k += 1
        term *= mean / k
        if term == 0.0 and cdf > 0.0:
            break
        cdf += term
    return k


class Odometry:
    """The robot's odometry for one run.

    Parameters
    ----------
    config:
        Error model.
    bias:
        ``{"linear": e_lin, "angular": e_ang}``, usually from :func:`draw_bias`.
    rng:
        Random stream for the optional per-step noise; not used when the noise coefficients are 0.

    Attributes
    ----------
    pose:
        float64 ``[3]`` current odometry pose (odometry frame, starts at (0, 0, 0)).
    """

    def __init__(self, config: OdometryConfig, bias: dict[str, float], rng: np.random.Generator):
        self.config = config
        self.bias = dict(bias)
        self.rng = rng
        self.pose: NDArray[np.float64] = np.zeros(3)

    def update(self, delta: ArrayLike) -> NDArray[np.float64]:
        """Add the measurement of the true step ``delta`` (``[3]``, robot frame) and return the new pose.

        The step may be of any length, zero included: its noise depends on its motion only (arc length
        ``L`` and heading change ``phi``, see the module docstring), never on its duration.

        Draws, in this order and only for the models that are on: one normal deviate for the arc length
        (``noise_linear_per_m`` or ``noise_linear_per_rad`` > 0; std ``sqrt(a^2 |L| + b^2 |phi|)``), one
        for the heading change (``noise_angular_per_rad`` or ``noise_angular_per_m`` > 0; std
        ``sqrt(c^2 |phi| + d^2 |L|)``), then, with ``slip_per_m > 0``, one uniform (how many slips ``k``:
        :func:`slip_count`, none with chance ``exp(-slip_per_m |L|)``) and two standard normals (the slips'
        summed arc-length and heading errors, times ``sqrt(k)`` and the slip stds), drawn whether or not
        it slips.
        """
        delta = np.asarray(delta, dtype=np.float64)
        cfg = self.config
        n_lin = n_ang = 0.0
        phi = abs(float(delta[2]))
        length = math.hypot(delta[0], delta[1]) / sinc(0.5 * float(delta[2]))
        if cfg.noise_linear_per_m > 0.0 or cfg.noise_linear_per_rad > 0.0:
            std = step_noise_std(cfg.noise_linear_per_m, length, cfg.noise_linear_per_rad, phi)
            n_lin = float(self.rng.normal(0.0, std))
        if cfg.noise_angular_per_rad > 0.0 or cfg.noise_angular_per_m > 0.0:
            std = step_noise_std(cfg.noise_angular_per_rad, phi, cfg.noise_angular_per_m, length)
            n_ang = float(self.rng.normal(0.0, std))
        if cfg.slip_per_m > 0.0:
            slips = slip_count(cfg.slip_per_m, length, float(self.rng.random()))
            slip_lin = float(self.rng.normal(0.0, cfg.slip_linear_std))
            slip_ang = float(self.rng.normal(0.0, cfg.slip_angular_std))
            if slips:
                root = math.sqrt(slips)  # the sum of k independent slips' errors
                n_lin += slip_lin * root
                n_ang += slip_ang * root
        inc = measured_increment(delta, self.bias["linear"], self.bias["angular"], n_lin, n_ang)
        self.pose = compose1(self.pose, inc)
        return self.pose
