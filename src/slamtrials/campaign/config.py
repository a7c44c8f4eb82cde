"""The campaign configuration: worlds, the trial's settings, the metric, the run-count rule, the seed.

A campaign config is a YAML mapping validated by :class:`CampaignConfig` (pydantic, frozen, unknown keys
rejected). Its ``sim``, ``slam``, ``explore``, ``termination`` and ``coverage_stride`` are those of
:class:`slamtrials.trial.TrialConfig`; ``metric`` sets the relation sampling that turns each run into
its two errors ``eps_t`` (m) and ``eps_r`` (rad); ``runs`` sets the paper's Section III-C rule that
decides how many runs each world needs. :meth:`CampaignConfig.from_yaml` and
:meth:`CampaignConfig.from_dict` raise one-line :class:`~slamtrials.errors.ConfigError` messages that
name the file, the field path and the bad value. ``slamtrials config dump`` prints the defaults
(:func:`slamtrials.campaign.dump.dump_default_yaml`).
"""

from __future__ import annotations

import copy
import hashlib
import json
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, ValidationInfo, field_validator, model_validator

from slamtrials.errors import ConfigError, FormatError, validation_problems
from slamtrials.explore import ExploreConfig, TerminationConfig
from slamtrials.explore.config import ROBOT_FIELDS
from slamtrials.metric.matching import RUN_TOLERANCE
from slamtrials.metric.rule import SamplingRule
from slamtrials.metric.runcount import DEFAULT_MIN_RUNS
from slamtrials.sim import SimConfig
from slamtrials.sim.overrides import warn_overrides
from slamtrials.sim.profiles import DEFAULT_PROFILE
from slamtrials.trial import SlamSettings, TrialConfig

__all__ = [
    "CampaignConfig",
    "MetricSettings",
    "RunSettings",
    "DEFAULT_MAX_RUNS",
    "RUN_TOLERANCE",
    "MAX_SEED",
    "CAMPAIGN_PROFILE",
]

_MODEL_CONFIG = ConfigDict(extra="forbid", frozen=True)

#: Smallest ``runs.initial`` of a new campaign (a stored one of an earlier version keeps its own).
MIN_INITIAL_RUNS = 5
#: Error profile of a campaign that names none: the simulator's one default
#: (:data:`slamtrials.sim.profiles.DEFAULT_PROFILE`). Campaigns stored by versions that had no profiles
#: were simulated with ``paper``, and :func:`upgrade_stored_config` says so.
CAMPAIGN_PROFILE = DEFAULT_PROFILE
#: Default cap on the runs of one world.
DEFAULT_MAX_RUNS = 60
#: Largest root seed (seeds are stored as SQLite 64-bit signed integers).
MAX_SEED = 2**63 - 1


class MetricSettings(SamplingRule):
    """Relation sampling of each run: the :class:`~slamtrials.metric.rule.SamplingRule` (``precise`` by
    default, or ``{rule: paper}``: pilot, then ``N = ceil(z^2 s^2 / d^2)`` relations) and the matching
    tolerance.

    A run's ``eps_t`` and ``eps_r`` are the mean translational (m) and rotational (rad) errors of its
    estimate over its relation set (:func:`slamtrials.metric.draw_relation_set`).
    """

    tolerance: float = Field(
        RUN_TOLERANCE, gt=0.0, le=10.0, description="matching tolerance of estimate to ground-truth timestamps (s)"
    )
    estimate: Literal["final", "online"] = Field(
        "final",
        description="which SLAM estimate eps_t and eps_r score: final (the trajectory after the last frame) or "
        "online (what SLAM returned at each frame, as the paper's system logged it)",
    )

    @classmethod
    def of_stored(cls, doc: dict[str, Any]) -> MetricSettings:
        """The ``metric`` section of a stored campaign config (an earlier version's means ``rule: paper``)."""
        return cls.model_validate(upgrade_stored_config({"metric": doc})["metric"], context={"stored": True})

    @property
    def sampling(self) -> SamplingRule:
        """The sampling rule alone (without the matching tolerance)."""
        return SamplingRule(**self.model_dump(exclude={"tolerance", "estimate"}))


class RunSettings(BaseModel):
    """How many runs each world gets: the paper's Section III-C rule, with a cap.

    Start with ``initial`` runs; from the sample variances of the per-run ``eps_t`` and ``eps_r`` compute
    ``N = ceil(z^2 s^2 / d^2)`` for each (margins ``margin_t``, ``margin_r``), take the larger, run up to
    that many in total and estimate again, until the estimate is not larger than the runs done or
    ``max_runs`` is reached (the world is then reported as capped).
    """

    model_config = _MODEL_CONFIG

    initial: int = Field(
        DEFAULT_MIN_RUNS,
        ge=2,
        le=100_000,
        description=f"runs of the first variance estimate (10 in the paper; at least {MIN_INITIAL_RUNS})",
    )
    max_runs: int = Field(
        DEFAULT_MAX_RUNS,
        ge=2,
        le=100_000,
        description="cap on the runs of one world; a world that hits it is reported as capped",
    )
    confidence: float = Field(0.99, gt=0.0, lt=1.0, description="confidence level of a world's mean errors")
    margin_t: float = Field(
        0.02, gt=0.0, le=100.0, description="margin of error of a world's mean translational error (m)"
    )
    margin_r: float = Field(
        0.02, gt=0.0, le=3.2, description="margin of error of a world's mean rotational error (rad)"
    )
    distribution: Literal["normal", "t"] = Field(
        "t", description="quantile of the confidence level: t (R - 1 degrees of freedom) or normal (the paper's)"
    )
    retries: int = Field(
        2, ge=0, le=100, description="times a run is retried when its worker dies or it fails unexpectedly"
    )

    @field_validator("initial")
    @classmethod
    def _enough_initial_runs(cls, value: int, info: ValidationInfo) -> int:
        # a stored campaign of an earlier version keeps the value it ran with
        if value < MIN_INITIAL_RUNS and not (info.context or {}).get("stored"):
            raise ValueError(
                f"must be at least {MIN_INITIAL_RUNS}: with fewer runs the spread of the per-run errors is too "
                "uncertain for the run-count rule (the interval's true coverage drops far below its confidence)"
            )
        return value

    @model_validator(mode="after")
    def _cap_not_below_initial(self) -> RunSettings:
        if self.max_runs < self.initial:
            raise ValueError(f"max_runs ({self.max_runs}) must be at least initial ({self.initial})")
        return self


def _beside(folder: Path, entry: Any) -> Any:
    """``entry`` as an absolute path if it is a relative path to something in ``folder``, else unchanged."""
    if not isinstance(entry, str) or not entry.strip() or Path(entry).expanduser().is_absolute():
        return entry
    candidate = folder / entry
    return str(candidate.resolve()) if candidate.exists() else entry


def upgrade_stored_config(doc: dict[str, Any]) -> dict[str, Any]:
    """A stored campaign config's JSON form, as this version writes it (a copy; ``doc`` is not changed)."""
    doc = copy.deepcopy(doc)
    sim = doc.get("sim")
    if isinstance(sim, dict) and "profile" not in sim:
        sim["profile"] = "paper"  # earlier versions had only the paper's error models
    metric = doc.get("metric")
    if isinstance(metric, dict) and "rule" not in metric:
        metric["rule"] = "paper"  # earlier versions knew only the paper's absolute margins
    explore = doc.get("explore")
    if isinstance(explore, dict):
        for name in ROBOT_FIELDS:
            explore.pop(name, None)
    return doc


def stored_sim_config(sim: dict[str, Any]) -> SimConfig:
    """The simulation config of a stored campaign's ``sim`` section (one stored before error profiles
    existed names none and was simulated with ``paper``).

    Raises
    ------
    pydantic.ValidationError
        A section this version cannot read (e.g. a profile it does not know).
    """
    return SimConfig.model_validate(upgrade_stored_config({"sim": sim})["sim"])


class CampaignConfig(BaseModel):
    """Everything a campaign needs: worlds, trial settings, metric, run-count rule, root seed, output.

    Attributes
    ----------
    worlds:
        World entries: bundled catalog names, floor-plan files (map_server ``.yaml``, Stage ``.world``,
        HouseExpo ``.json``), or folders, which expand to the floor plans inside them (sorted).
    sim, slam, explore, termination, coverage_stride:
        The trial's settings (:class:`slamtrials.trial.TrialConfig`).
    metric:
        Relation sampling of each run.
    runs:
        The run-count rule.
    seed:
        Root seed; each (world, run index) gets its own stream (:mod:`slamtrials.campaign.seeds`).
    output:
        Campaign folder (``--out`` on the command line overrides it).
    replay_of:
        Set by ``slamtrials campaign replay``: the campaign whose recorded runs were re-evaluated.
    """

    model_config = _MODEL_CONFIG

    worlds: list[str] = Field(min_length=1, description="bundled world names, floor-plan files or folders of them")
    sim: SimConfig = Field(
        default_factory=SimConfig,
        description=f"simulated robot, laser and odometry (error profile {DEFAULT_PROFILE} unless named)",
    )
    slam: SlamSettings = Field(default_factory=SlamSettings, description="the SLAM algorithm under test")
    explore: ExploreConfig = Field(
        default_factory=ExploreConfig, description="frontier explorer (its robot limits come from sim)"
    )
    termination: TerminationConfig = Field(
        default_factory=TerminationConfig, description="when a run ends: the paper's map snapshot rule and a time cap"
    )
    coverage_stride: int = Field(5, ge=1, le=1000, description="frames between scans traced for the observed area")
    metric: MetricSettings = Field(default_factory=MetricSettings, description="relation sampling of each run")
    runs: RunSettings = Field(
        default_factory=RunSettings, description="how many runs each world gets (paper Section III-C)"
    )
    seed: int = Field(0, ge=0, le=MAX_SEED, description="root seed of every random draw of the campaign")
    output: str | None = Field(None, description="campaign folder; --out overrides it")
    replay_of: str | None = Field(
        None, description="set by 'campaign replay': the campaign whose recorded runs are re-evaluated"
    )

    @model_validator(mode="after")
    def _worlds_not_blank(self) -> CampaignConfig:
        for i, entry in enumerate(self.worlds):
            if not entry.strip():
                raise ValueError(f"worlds[{i}] is empty")
        return self

    def trial_config(self) -> TrialConfig:
        """The :class:`~slamtrials.trial.TrialConfig` of every run of the campaign."""
        return TrialConfig(
            sim=self.sim,
            slam=self.slam,
            explore=self.explore,
            termination=self.termination,
            coverage_stride=self.coverage_stride,
        )

    def identity(self) -> dict[str, Any]:
        """The JSON form that decides whether two configs describe the same campaign (``output`` left out)."""
        return self.model_dump(mode="json", exclude={"output"})

    def digest(self) -> str:
        """SHA-256 (hex) of :meth:`identity`, canonical JSON: a stored campaign only resumes with an equal one."""
        text = json.dumps(self.identity(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode("utf-8")).hexdigest()

    @classmethod
    def from_stored(cls, doc: dict[str, Any]) -> CampaignConfig:
        """The config of a stored campaign (its JSON form), written by this or an earlier version.

        Campaigns stored before the explore section lost its robot fields (:data:`ROBOT_FIELDS`) carry
        them; those versions replaced them by ``sim.robot``'s values anyway, so they are dropped.
        """
        return cls.model_validate(upgrade_stored_config(doc), context={"stored": True})

    @classmethod
    def from_dict(cls, data: Any, *, source: str = "campaign config") -> CampaignConfig:
        """Validate a plain mapping (e.g. parsed YAML), including the SLAM algorithm's parameters.

        Parameters
        ----------
        data:
            The mapping.
        source:
            What to call it in error messages (e.g. the file name).

        Raises
        ------
        ConfigError
            One line: ``<source>: <field.path>: <problem> (got <value>)``, every problem joined by ``; ``.
        """
        if not isinstance(data, dict):
            raise ConfigError(f"{source}: expected a mapping of settings, got {type(data).__name__}")
        try:
            config = cls.model_validate(data)
        except ValidationError as exc:
            raise ConfigError(f"{source}: " + validation_problems(exc)) from None
        try:
            config.slam.resolved()
            if config.replay_of is None:
                config.slam.check_online()
        except ConfigError as exc:
            raise ConfigError(f"{source}: slam: {exc}") from None
        return config

    @classmethod
    def from_yaml(cls, path: str | Path) -> CampaignConfig:
        """Read and validate a YAML campaign config.

        A relative ``worlds`` entry that names a file or folder next to the config file is taken
        relative to the config file's folder (and stored as an absolute path), so a config and its
        floor plans can move together; other entries (catalog names, paths relative to the working
        directory) are kept as written. A ``sim.profile`` that is a YAML file's path (relative to the
        config's folder) is read and held inline (:mod:`slamtrials.campaign.profilefile`). Error-model
        values in ``sim.laser`` / ``sim.odometry`` that differ from the profile's override it; they are
        accepted, with one logged warning naming them (:func:`slamtrials.sim.overrides.warn_overrides`).

        Raises
        ------
        FormatError
            Missing file or not YAML (naming the line).
        ConfigError
            A bad setting (naming the file, the field and the value).
        """
        from slamtrials.io.yamlfile import read_yaml_mapping

        path = Path(path)
        if path.is_dir():
            raise FormatError(path, "is a folder; give a campaign config YAML file")
        from slamtrials.campaign.profilefile import inline_profile_file

        data = read_yaml_mapping(path)
        worlds = data.get("worlds")
        if isinstance(worlds, list):
            data["worlds"] = [_beside(path.parent, entry) for entry in worlds]
        data = inline_profile_file(data, path.parent)
        config = cls.from_dict(data, source=str(path))
        warn_overrides(config.sim, str(path))
        return config
