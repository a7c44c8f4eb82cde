"""A run recorded along a given true path: the simulator's sensors without its controller.

:func:`simulate_path` puts the robot at given poses at given times (a path that came from elsewhere: a
SLAM algorithm's estimate of a real run, a recorded tour) and records what the simulated laser and
odometry would have measured there, with the config's error models. Nothing moves the robot, so there
is no collision check and no velocity limit: the path is the truth, whatever its speed. This is how a
real run is replicated in the simulator (:mod:`slamtrials.validation`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from slamtrials.errors import SimulationError
from slamtrials.geometry import ominus1
from slamtrials.record import RunRecord
from slamtrials.sim.config import SimConfig
from slamtrials.sim.odometry import Odometry, draw_bias
from slamtrials.sim.raycast import LaserModel
from slamtrials.sim.simulator import as_generator
from slamtrials.worlds.world import World

__all__ = ["simulate_path"]


def simulate_path(
    world: World,
    t: ArrayLike,
    poses: ArrayLike,
    config: SimConfig | None,
    rng: np.random.Generator | int | np.random.SeedSequence,
) -> RunRecord:
    """Record one frame at each of ``poses`` (the truth) at times ``t``.

    Parameters
    ----------
    world:
        The world the laser scans.
    t:
        float64 ``[T]`` frame times (s), strictly increasing, ``T >= 1``.
    poses:
        float64 ``[T, 3]`` true poses of the robot base (x, y, theta; world frame, m and rad).
    config:
        Laser and odometry settings with their error models (``config.dt`` and ``config.robot`` are not
        used); ``None`` means ``SimConfig()`` (the default profile, :data:`~slamtrials.sim.profiles.DEFAULT_PROFILE`).
    rng:
        The run's simulator stream (a Generator, or a seed turned into one).

    Returns
    -------
    RunRecord
        ``t``, the scans float32 ``[T, B]``, the odometry ``[T, 3]`` (odometry frame, (0, 0, 0) at the
        first frame), ``truth = poses``, ``stalled`` all False; ``metadata`` holds the drawn ``bias``,
        ``controller: "path"``, the world's name and the full simulation config.

    Notes
    -----
    Draw order, the same as :class:`~slamtrials.sim.Simulator`'s, so a path a Simulator drove, replayed
    here with the same world, config and seed, gives the same frames bit for bit: the odometry bias
    (two uniforms, :func:`~slamtrials.sim.odometry.draw_bias`); the first frame's laser draws; then for
    each later frame ``k`` the odometry's draws for the true step ``ominus(poses[k-1], poses[k])``
    (:meth:`~slamtrials.sim.odometry.Odometry.update`), then frame ``k``'s laser draws
    (:meth:`~slamtrials.sim.raycast.LaserModel.scan`). With every error model off only the bias is drawn.

    The odometry's random noise is a random walk per metre driven and per radian turned
    (:mod:`slamtrials.sim.odometry`): each frame-to-frame step draws it from its motion alone, never
    from its duration, so the noise accumulated along the path is what the simulator, stepping every
    ``config.dt``, would give, whatever the frames' stamps (a real log's frames come every 0.2 s or so,
    and a log whose stamps were out of order has gaps of a millisecond across a normal step).

    Raises
    ------
    SimulationError
        ``t`` and ``poses`` of other shapes, not finite, or times not strictly increasing.
    """
    times = np.asarray(t, dtype=np.float64)
    path = np.asarray(poses, dtype=np.float64)
    if times.ndim != 1 or len(times) == 0 or path.shape != (len(times), 3):
        raise SimulationError(
            f"simulate_path needs t [T] and poses [T, 3] with T >= 1, got shapes {times.shape} and {path.shape}"
        )
    if not (np.all(np.isfinite(times)) and np.all(np.isfinite(path))):
        raise SimulationError("simulate_path: times and poses must be finite")
    if np.any(np.diff(times) <= 0.0):
        raise SimulationError("simulate_path: times must be strictly increasing")
    config = SimConfig() if config is None else config
    generator = as_generator(rng)
    bias = draw_bias(config.odometry, generator)
    laser = LaserModel(world, config.laser)
    odometry = Odometry(config.odometry, bias, generator)
    scans = np.empty((len(times), laser.num_beams), dtype=np.float32)
    measured = np.empty((len(times), 3), dtype=np.float64)
    scans[0] = laser.scan(path[0], generator, float(times[0]))
    measured[0] = odometry.pose
    for k in range(1, len(times)):
        measured[k] = odometry.update(ominus1(path[k - 1], path[k]))
        scans[k] = laser.scan(path[k], generator, float(times[k]))
    metadata = {
        "world": world.name,
        "controller": "path",
        "bias": dict(bias),
        "sim_config": config.model_dump(mode="json"),
    }
    return RunRecord(
        t=times.copy(),
        scans=scans,
        odometry=measured,
        truth=path.copy(),
        stalled=np.zeros(len(times), dtype=bool),
        laser=laser.geometry(),
        metadata=metadata,
    )
