"""The study configuration: a campaign config and a grid of settings to vary over it.

A study config is a YAML mapping validated by :class:`StudyConfig` (pydantic, frozen, unknown keys
rejected)::

    campaign: laser-base.yaml          # the campaign every cell starts from: a file (relative to this
                                       # one) or an inline mapping of a campaign config
    axes:                              # each axis: a dotted campaign config key and its values, in order
      sim.laser.max_range: [30, 15]
      slam.params.particles: [10, 30, 80]
    product: true                      # the cells of the full product of the axes (default true)
    combinations:                      # named cells besides (or, with product: false, instead of) it
      paper: {sim.laser.max_range: 30, slam.params.particles: 40}
    output: studies/laser              # study folder; --out overrides it

Every cell is a campaign (:mod:`slamtrials.study.cells`); the cells of a world share their seeds, as
they share the campaign's root seed and world names, so ``seed``, ``worlds``, ``output`` and
``replay_of`` cannot vary. An axis key must be a key of the campaign config (``slamtrials config
dump`` lists them; under ``slam.params`` the algorithm's parameters); two axes may not name the same
key, nor one key and a key inside it (``sim.laser`` and ``sim.laser.max_range``); an axis has at least
one value and no value twice. Whether each value is in its range is checked when the cells are
expanded (:func:`slamtrials.study.cells.expand_cells`), naming the cell. Every problem is a one-line
:class:`~slamtrials.errors.ConfigError`.
"""

from __future__ import annotations

import copy
import hashlib
import json
import re
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from slamtrials.campaign.config import CampaignConfig
from slamtrials.errors import ConfigError, FormatError, validation_problems

__all__ = ["StudyConfig", "FIXED_KEYS", "NAME_PATTERN", "known_key", "value_text", "written_campaign", "set_key"]

#: Campaign config keys that no axis or combination may set: the cells of a world must share their seeds
#: and worlds (paired comparisons), and where a cell is stored is the study's business.
FIXED_KEYS = ("seed", "worlds", "output", "replay_of")
#: What a combination's name may hold (it names the cell's folder).
NAME_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._=,+-]{0,99}$")


def value_text(value: Any) -> str:
    """A setting's value as it appears in cell names and tables (strings bare, others as JSON)."""
    return value if isinstance(value, str) else json.dumps(value, sort_keys=True)


def written_campaign(config: CampaignConfig) -> dict[str, Any]:
    """A campaign config's JSON form as a file would write it: ``sim`` with only the error-model values
    that override its profile (:func:`slamtrials.sim.overrides.written_form`), so that a cell that names
    another profile gets that profile's values; ``output`` left out."""
    from slamtrials.sim.overrides import written_form

    data = config.model_dump(mode="json", exclude={"output"})
    data["sim"] = written_form(config.sim)
    return data


def set_key(data: dict[str, Any], key: str, value: Any) -> None:
    """Set the dotted ``key`` of the nested mapping ``data`` to ``value`` (intermediate mappings created)."""
    parts = key.split(".")
    node = data
    for part in parts[:-1]:
        child = node.get(part)
        if not isinstance(child, dict):
            child = node[part] = {}
        node = child
    node[parts[-1]] = copy.deepcopy(value)


def _settings_tree(config: CampaignConfig) -> dict[str, Any]:
    """The campaign config's JSON form with the SLAM parameters resolved (preset + overrides)."""
    data = config.model_dump(mode="json")
    try:
        data["slam"]["params"] = config.slam.resolved().model_dump(mode="json")
    except ConfigError:
        pass
    return data


def known_key(config: CampaignConfig, key: str) -> bool:
    """Whether the dotted ``key`` names a setting of ``config`` (a leaf or a section)."""
    node: Any = _settings_tree(config)
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return False
        node = node[part]
    return True


def _check_key(base: CampaignConfig, key: str, where: str) -> None:
    """Raise ConfigError unless ``key`` may vary between cells."""
    if not key or any(not part for part in key.split(".")):
        raise ConfigError(f"{where}: {key!r} is not a dotted config key (e.g. sim.laser.max_range)")
    if key.split(".")[0] in FIXED_KEYS:
        raise ConfigError(
            f"{where}: {key} cannot vary between cells (the cells of a world share seed and worlds; "
            "the study places their folders); set it in the campaign config"
        )
    if key.startswith("slam.params.") and not known_key(base, "slam.params"):
        return  # an algorithm that does not resolve here: its parameters are checked per cell
    if not known_key(base, key):
        raise ConfigError(
            f"{where}: {key} is not a config key of the campaign ('slamtrials config dump' lists them; "
            "under slam.params the algorithm's parameters)"
        )


def _overlap(keys: list[str]) -> tuple[str, str] | None:
    """Two keys of which one is the other or contains it (``sim.laser``, ``sim.laser.max_range``)."""
    for i, first in enumerate(keys):
        for second in keys[i + 1 :]:
            if first == second or second.startswith(first + ".") or first.startswith(second + "."):
                return first, second
    return None


class StudyConfig(BaseModel):
    """A study: a base campaign config and the settings its cells vary (see the module docstring).

    Attributes
    ----------
    campaign:
        The base campaign config, as a plain mapping (a file named in the YAML is read into it).
    axes:
        ``{dotted key: [values]}`` in order; the order of the keys and values is that of the tables and
        figures.
    product:
        Whether the cells of the full product of the axes are part of the study.
    combinations:
        ``{name: {dotted key: value}}``: named cells, each the base config with those settings.
    output:
        Study folder (``--out`` overrides it).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    campaign: dict[str, Any] = Field(description="the campaign config every cell starts from")
    axes: dict[str, list[Any]] = Field(default_factory=dict, description="dotted config key -> its values")
    product: bool = Field(True, description="whether the full product of the axes is part of the study")
    combinations: dict[str, dict[str, Any]] = Field(
        default_factory=dict, description="named cells: name -> {dotted config key: value}"
    )
    output: str | None = Field(None, description="study folder; --out overrides it")

    def base(self) -> CampaignConfig:
        """The validated base campaign config (raises :class:`ConfigError` naming the field)."""
        return CampaignConfig.from_dict(copy.deepcopy(self.campaign), source="campaign")

    def identity(self) -> dict[str, Any]:
        """The JSON form that decides whether two configs describe the same study (``output`` left out;
        the campaign as its validated config, so that equal settings written differently are equal)."""
        data = self.model_dump(mode="json", exclude={"output"})
        data["campaign"] = self.base().identity()
        return data

    def digest(self) -> str:
        """SHA-256 (hex) of :meth:`identity` as canonical JSON."""
        text = json.dumps(self.identity(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode("utf-8")).hexdigest()

    def check(self) -> CampaignConfig:
        """Check the axes and combinations against the base config (see the module docstring); return it.

        Raises
        ------
        ConfigError
            One line naming the axis or combination and what is wrong.
        """
        base = self.base()
        keys = list(self.axes)
        for key, values in self.axes.items():
            _check_key(base, key, f"axes: {key}")
            if not values:
                raise ConfigError(f"axes: {key}: empty axis; give at least one value")
            shown = [value_text(v) for v in values]
            twice = sorted({v for v in shown if shown.count(v) > 1})
            if twice:
                raise ConfigError(f"axes: {key}: value {twice[0]} given twice")
        overlap = _overlap(keys)
        if overlap is not None:
            first, second = overlap
            what = "the same key" if first == second else "overlapping keys"
            raise ConfigError(f"axes: two axes on {what}: {first} and {second}")
        for name, settings in self.combinations.items():
            if not NAME_PATTERN.match(name):
                raise ConfigError(
                    f"combinations: {name!r} is not a usable name (letters, digits and . _ = , + -, "
                    "starting with a letter or digit)"
                )
            if not settings:
                raise ConfigError(f"combinations: {name}: empty; give the settings of the cell")
            for key in settings:
                _check_key(base, key, f"combinations: {name}: {key}")
            overlap = _overlap(list(settings))
            if overlap is not None:
                raise ConfigError(f"combinations: {name}: overlapping keys {overlap[0]} and {overlap[1]}")
        if not (self.product and self.axes) and not self.combinations:
            raise ConfigError("the study has no cells: give axes (with product: true) or combinations")
        return base

    def with_campaign_settings(self, settings: dict[str, Any]) -> StudyConfig:
        """This study with ``{dotted key: value}`` set in its base campaign (``study run --set``), checked.

        Raises
        ------
        ConfigError
            A key that is not a config key, or a bad value (one line).
        """
        if not settings:
            return self
        base = self.base()
        campaign = copy.deepcopy(self.campaign)
        for key, value in settings.items():
            if not known_key(base, key):
                raise ConfigError(
                    f"--set {key}: not a config key of the campaign ('slamtrials config dump' lists them)"
                )
            set_key(campaign, key, value)
        return StudyConfig.from_dict({**self.model_dump(mode="json"), "campaign": campaign}, source="--set")

    @classmethod
    def from_dict(cls, data: Any, *, source: str = "study config") -> StudyConfig:
        """Validate a plain mapping (the base campaign inline) and :meth:`check` it.

        Raises
        ------
        ConfigError
            ``<source>: <problem>``, one line.
        """
        if not isinstance(data, dict):
            raise ConfigError(f"{source}: expected a mapping of settings, got {type(data).__name__}")
        try:
            config = cls.model_validate(data)
        except ValidationError as exc:
            raise ConfigError(f"{source}: " + validation_problems(exc)) from None
        try:
            config.check()
        except ConfigError as exc:
            raise ConfigError(f"{source}: {exc}") from None
        return config

    @classmethod
    def from_yaml(cls, path: str | Path) -> StudyConfig:
        """Read a study config YAML (duplicate keys refused, naming the line); a ``campaign`` given as a
        file name is read relative to the study config's folder (its own relative world files relative to
        its folder, as ``campaign run`` reads it).

        Raises
        ------
        FormatError
            Missing file, not YAML, a key twice in one mapping.
        ConfigError
            A bad setting (one line, naming the file).
        """
        from slamtrials.study.yamlkeys import read_unique_yaml

        path = Path(path)
        if path.is_dir():
            raise FormatError(path, "is a folder; give a study config YAML file")
        data = read_unique_yaml(path)
        campaign = data.get("campaign")
        if isinstance(campaign, str):
            campaign_path = Path(campaign).expanduser()
            if not campaign_path.is_absolute():
                campaign_path = path.parent / campaign_path
            try:
                base = CampaignConfig.from_yaml(campaign_path)
            except ConfigError as exc:
                raise ConfigError(f"{path}: campaign: {exc}") from None
            data = {**data, "campaign": written_campaign(base)}
        elif isinstance(campaign, dict):
            data = {**data, "campaign": _absolute_worlds(campaign, path.parent)}
        return cls.from_dict(data, source=str(path))


def _absolute_worlds(campaign: dict[str, Any], folder: Path) -> dict[str, Any]:
    """An inline campaign whose relative world files next to the study config are made absolute."""
    worlds = campaign.get("worlds")
    if not isinstance(worlds, list):
        return campaign
    resolved = []
    for entry in worlds:
        if isinstance(entry, str) and entry.strip() and not Path(entry).expanduser().is_absolute():
            candidate = folder / entry
            resolved.append(str(candidate.resolve()) if candidate.exists() else entry)
        else:
            resolved.append(entry)
    return {**campaign, "worlds": resolved}
