"""Configuration of one trial: simulator, SLAM algorithm, explorer and termination rule (pydantic).

``TrialConfig()`` is the paper's set-up with the default error profile: the paper's robot and laser with
the ``realistic`` profile's errors (:class:`~slamtrials.sim.SimConfig`; ``{"sim": {"profile": "paper"}}``
for the paper's noise-free Stage set-up), ``gmapping`` with the ``paper`` preset, frontier exploration and
the snapshot termination rule. The
explorer drives the simulated robot, so its motion limits, footprint and control period are those of
``sim`` (:meth:`TrialConfig.robot_limits`); the ``explore`` section holds the rest and refuses robot fields.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from slamtrials.errors import ConfigError, validation_problems
from slamtrials.explore import ExploreConfig, RobotLimits, TerminationConfig
from slamtrials.sim import SimConfig
from slamtrials.slam import get_algorithm, resolve_config
from slamtrials.slam.program import ProgramSpec

__all__ = ["SlamSettings", "TrialConfig"]

_MODEL_CONFIG = ConfigDict(extra="forbid", frozen=True)


class SlamSettings(BaseModel):
    """Which SLAM algorithm runs online, and with which parameters.

    Attributes
    ----------
    algorithm:
        Registry or entry-point name (``slamtrials.slam``).
    preset:
        One of the algorithm's presets, or ``None`` for its defaults; when left out, ``paper`` for an
        algorithm that has such a preset, else ``None``.
    params:
        Parameter overrides applied after the preset.
    program:
        An external SLAM program instead of a registered algorithm
        (:class:`~slamtrials.slam.program.ProgramSpec`). It runs offline, over recorded runs (``slam``,
        ``campaign replay``, ``validate``); ``algorithm`` is then its label and ``preset`` null.
    """

    model_config = _MODEL_CONFIG

    algorithm: str = Field("gmapping", min_length=1, description="SLAM algorithm name")
    preset: str | None = Field("paper", description="preset of the algorithm, or null for its defaults")
    params: dict[str, Any] = Field(default_factory=dict, description="parameter overrides")
    program: ProgramSpec | None = Field(None, description="an external SLAM program, run offline over recorded runs")

    @model_validator(mode="before")
    @classmethod
    def _paper_preset_if_any(cls, data: Any) -> Any:
        """Without a ``preset`` key: the algorithm's ``paper`` preset if it has one, else its defaults."""
        if isinstance(data, dict) and "preset" not in data and data.get("algorithm") not in (None, "gmapping"):
            try:
                presets = get_algorithm(str(data["algorithm"])).PRESETS
            except ConfigError:
                return data  # the unknown algorithm is named later, by resolved()
            if "paper" not in presets:
                data = {**data, "preset": None}
        return data

    @model_validator(mode="before")
    @classmethod
    def _program_named(cls, data: Any) -> Any:
        """With a program, the algorithm is the program's label and there is no preset."""
        if isinstance(data, dict) and data.get("program") is not None:
            spec = data["program"]
            if not isinstance(spec, ProgramSpec):
                spec = ProgramSpec.model_validate(spec)
            given = {k: data[k] for k in ("algorithm", "preset", "params") if data.get(k) not in (None, {})}
            if given.get("algorithm") == spec.label:  # as a stored config writes it back
                del given["algorithm"]
            if given:
                raise ValueError(f"slam.program replaces slam.{sorted(given)[0]}: give one or the other")
            data = {**data, "program": spec, "algorithm": spec.label, "preset": None, "params": {}}
        return data

    def resolved(self) -> BaseModel:
        """The algorithm's validated config, or the program (raises :class:`ConfigError` naming the bad parameter)."""
        if self.program is not None:
            return self.program
        cls = get_algorithm(self.algorithm)
        config = resolve_config(cls, preset=self.preset, overrides=self.params)
        check = getattr(cls, "check_config", None)  # an algorithm's own checks across its parameters
        if callable(check):
            check(config)
        return config

    def check_online(self) -> None:
        """Raise :class:`ConfigError` for a program: it runs over recorded runs only, not in a trial."""
        if self.program is not None:
            raise ConfigError(
                f"slam.program ({self.program.label}) runs offline, over recorded runs: use it with "
                "'slamtrials slam --program', 'campaign replay SOURCE --program' or 'validate --program'; "
                "a program that explores online is the algorithm 'program' (slam: {algorithm: program, "
                "params: {command: ...}})"
            )


class TrialConfig(BaseModel):
    """Everything a trial needs besides the world and the seed.

    Attributes
    ----------
    sim:
        Robot, laser, odometry and time step (error profile ``realistic`` unless named).
    slam:
        The online SLAM algorithm.
    explore:
        Frontier explorer settings (the robot it drives is ``sim``'s: :meth:`robot_limits`).
    termination:
        The paper's snapshot rule and the hard time cap.
    coverage_stride:
        Every how many frames a scan is traced at its true pose to measure what the laser observed (and
        a pose is a candidate for aligning the SLAM map locally to measure what it mapped).
    """

    model_config = _MODEL_CONFIG

    sim: SimConfig = Field(default_factory=SimConfig)
    slam: SlamSettings = Field(default_factory=SlamSettings)
    explore: ExploreConfig = Field(default_factory=ExploreConfig)
    termination: TerminationConfig = Field(default_factory=TerminationConfig)
    coverage_stride: int = Field(
        5,
        ge=1,
        le=1000,
        description="frames between scans traced for the observed area, and between poses aligning the mapped area",
    )

    def robot_limits(self) -> RobotLimits:
        """The explorer's robot: footprint and limits from ``sim.robot``, control period ``sim.dt``."""
        robot = self.sim.robot
        return RobotLimits(
            radius=robot.radius,
            max_linear_speed=robot.max_linear_speed,
            max_angular_speed=robot.max_angular_speed,
            max_linear_accel=robot.max_linear_accel,
            max_angular_accel=robot.max_angular_accel,
            control_period=self.sim.dt,
        )

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TrialConfig:
        """Validate a plain dict (e.g. from YAML), including the SLAM parameters; one-line ConfigError."""
        try:
            config = cls.model_validate(data)
        except ValidationError as exc:
            raise ConfigError("trial config: " + validation_problems(exc)) from None
        config.slam.resolved()
        config.slam.check_online()
        return config
