"""The :class:`Simulator`: a differential-drive robot with a laser and biased odometry in a :class:`World`.

One step of ``dt`` seconds: the velocity command is limited and integrated as an arc, checked for
collisions (:mod:`slamtrials.sim.robot`), the true motion is measured by the odometry
(:mod:`slamtrials.sim.odometry`), and the laser scans from the new true pose
(:mod:`slamtrials.sim.raycast`). All randomness comes from the one ``rng`` given at construction, in a
fixed order: the odometry bias (two uniform deviates) at construction, then per frame the odometry
noise (only if enabled) and the laser noise (only if enabled). A run is therefore reproduced bit for
bit from its seed, its config and its sequence of commands.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from slamtrials.errors import SimulationError
from slamtrials.geometry import Pose1Like, ominus1
from slamtrials.record import Frame, LaserGeometry
from slamtrials.sim.config import SimConfig
from slamtrials.sim.odometry import Odometry, draw_bias
from slamtrials.sim.raycast import LaserModel
from slamtrials.sim.robot import Robot
from slamtrials.worlds.world import World

__all__ = ["Simulator", "as_generator"]


def as_generator(seed: int | np.random.SeedSequence | np.random.Generator) -> np.random.Generator:
    """A ``numpy.random.Generator`` from a seed, a SeedSequence or a Generator (returned as is)."""
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, (int, np.integer, np.random.SeedSequence)) and not isinstance(seed, bool):
        return np.random.default_rng(seed)
    raise TypeError(f"expected an int seed, a SeedSequence or a numpy Generator, got {type(seed).__name__}")


class Simulator:
    """Simulate the robot in ``world``, one ``config.dt`` step at a time.

    Parameters
    ----------
    world:
        The world to drive in. The robot starts at ``world.start`` (or ``start``).
    config:
        Robot, laser, odometry and step settings; ``None`` means ``SimConfig()`` (the default error
        profile, ``realistic``; :meth:`SimConfig.paper` for the paper's set-up).
    rng:
        The run's random stream (a Generator, or a seed turned into one; required, there is no default
        seed). The odometry bias is drawn from it here.
    start:
        Optional float64 ``[3]`` start pose (world frame) instead of ``world.start``.

    Raises
    ------
    SimulationError
        If the robot's footprint at the start pose overlaps an occupied cell.

    Examples
    --------
    >>> sim = Simulator(world, SimConfig(), np.random.default_rng(1))   # doctest: +SKIP
    >>> frames = [sim.observe()] + [sim.step((0.5, 0.1)) for _ in range(100)]   # doctest: +SKIP
    """

    def __init__(
        self,
        world: World,
        config: SimConfig | None,
        rng: np.random.Generator | int | np.random.SeedSequence,
        *,
        start: ArrayLike | None = None,
    ):
        self.world = world
        self.config = SimConfig() if config is None else config
        self.rng = as_generator(rng)
        self._bias = draw_bias(self.config.odometry, self.rng)
        pose = np.asarray(world.start if start is None else start, dtype=np.float64).reshape(-1)
        if pose.shape != (3,) or not np.all(np.isfinite(pose)):
            raise SimulationError(f"start pose must be three finite numbers (x, y, theta), got {start!r}")
        self._initial = pose.copy()
        self._robot = Robot(world, self.config.robot, self.config.dt, pose)
        if not self._robot.pose_free():
            raise SimulationError(
                f"world {world.name!r}: the robot (radius {self.config.robot.radius:g} m) at the start pose "
                f"({pose[0]:.3f}, {pose[1]:.3f}) overlaps a wall"
            )
        self._laser = LaserModel(world, self.config.laser)
        self._odometry = Odometry(self.config.odometry, self._bias, self.rng)
        self._steps = 0
        self._stalled = False
        self._frame: Frame | None = None

    # --- state -------------------------------------------------------------------------------------------

    @property
    def t(self) -> float:
        """Time (s) since the start: ``steps * dt``."""
        return self._steps * self.config.dt

    @property
    def steps(self) -> int:
        """Number of steps taken."""
        return self._steps

    @property
    def truth(self) -> NDArray[np.float64]:
        """float64 ``[3]`` true pose of the robot base (world frame), a copy."""
        return self._robot.pose.copy()

    @property
    def odometry(self) -> NDArray[np.float64]:
        """float64 ``[3]`` odometry pose (odometry frame, (0, 0, 0) at t = 0), a copy."""
        return self._odometry.pose.copy()

    @property
    def velocity(self) -> tuple[float, float]:
        """Current true velocity (v m/s, w rad/s) after the limits."""
        return self._robot.velocity

    @property
    def stalled(self) -> bool:
        """Whether the last step was blocked by a wall."""
        return self._stalled

    @property
    def bias(self) -> dict[str, float]:
        """The run's odometry bias ``{"linear": e_lin (m/m), "angular": e_ang (rad/rad)}``."""
        return dict(self._bias)

    @property
    def laser(self) -> LaserGeometry:
        """The laser's geometry, for :meth:`slamtrials.record.RunRecord.from_frames`."""
        return self._laser.geometry()

    @property
    def metadata(self) -> dict[str, Any]:
        """JSON-serialisable facts of the run: world name, bias, start pose, the error profile (its name,
        label and overrides, :func:`~slamtrials.sim.overrides.profile_summary`) and the full config."""
        from slamtrials.sim.overrides import profile_summary

        return {
            "world": self.world.name,
            "bias": self.bias,
            "start": [float(v) for v in self._initial],
            "profile": profile_summary(self.config),
            "sim_config": self.config.model_dump(mode="json"),
        }

    # --- stepping ----------------------------------------------------------------------------------------

    def observe(self) -> Frame:
        """The frame at the current time, without moving (the same object if called again)."""
        if self._frame is None:
            ranges = self._laser.scan(self._robot.pose, self.rng, self.t)
            self._frame = Frame(
                t=self.t,
                ranges=ranges,
                odometry=self._odometry.pose.copy(),
                truth=self._robot.pose.copy(),
                stalled=self._stalled,
            )
        return self._frame

    def step(self, command: Pose1Like) -> Frame:
        """Drive for one ``dt`` towards velocity ``command`` = (v m/s, w rad/s), then sense.

        Raises
        ------
        SimulationError
            If the command is not two finite numbers.
        """
        try:
            v, w = (float(c) for c in command)
        except (TypeError, ValueError):
            raise SimulationError(f"velocity command must be two numbers (v m/s, w rad/s), got {command!r}") from None
        if not (math.isfinite(v) and math.isfinite(w)):
            raise SimulationError(f"velocity command must be finite, got ({v}, {w})")
        before = self._robot.pose.copy()
        self._stalled = self._robot.step((v, w))
        self._odometry.update(ominus1(before, self._robot.pose))
        self._steps += 1
        self._frame = None
        return self.observe()
