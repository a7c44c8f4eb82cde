"""Error-profile YAML files (:class:`~slamtrials.sim.profiles.ErrorProfile`): read, written, and inlined
into configs whose ``sim.profile`` is a path.

A profile file is a mapping ``{name, description, laser: {...}, odometry: {...}}`` (what ``slamtrials
calibrate`` writes); ``name`` defaults to the file's stem. Configs hold a profile by bundled name or
inline, so the config loaders replace a ``sim.profile`` that ends in ``.yaml``/``.yml`` by the file's
content (a relative path is taken from the config file's folder) before validation; the run folders
then record the profile itself, not a path that may move.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from slamtrials.atomicfile import atomic_write_text
from slamtrials.errors import ConfigError, validation_problems
from slamtrials.sim.profiles import ErrorProfile

__all__ = ["read_profile", "write_profile", "inline_profile_file", "is_profile_path"]


def is_profile_path(value: Any) -> bool:
    """Whether a ``sim.profile`` value names a YAML file rather than a bundled profile."""
    return isinstance(value, str) and value.lower().endswith((".yaml", ".yml"))


def read_profile(path: str | Path) -> ErrorProfile:
    """Read and validate a profile file.

    Raises
    ------
    FormatError
        Missing file or not YAML.
    ConfigError
        A bad profile (naming the file and the field).
    """
    from slamtrials.io.yamlfile import read_yaml_mapping

    path = Path(path)
    data = read_yaml_mapping(path)
    data.setdefault("name", path.stem)
    try:
        return ErrorProfile.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(f"{path}: {validation_problems(exc)}") from None


def write_profile(path: str | Path, profile: ErrorProfile, header: str = "") -> Path:
    """Write ``profile`` as YAML (atomically), after ``header`` comment lines."""
    doc = profile.model_dump(mode="json")
    comments = "".join(f"# {line}\n" for line in header.splitlines())
    return atomic_write_text(path, comments + yaml.safe_dump(doc, sort_keys=False))


def inline_profile_file(data: dict[str, Any], base: Path) -> dict[str, Any]:
    """``data`` (a config mapping with a ``sim`` section) with a ``sim.profile`` file path replaced by the
    file's profile; ``base`` is the folder a relative path is taken from. Other values are left as they are."""
    sim = data.get("sim")
    if not isinstance(sim, dict) or not is_profile_path(sim.get("profile")):
        return data
    path = Path(sim["profile"]).expanduser()
    if not path.is_absolute():
        path = base / path
    profile = read_profile(path)
    return {**data, "sim": {**sim, "profile": profile.model_dump(mode="json")}}
