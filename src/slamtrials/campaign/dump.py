"""``slamtrials config dump``: a complete campaign config of the defaults, every key commented.

The YAML is written by walking the pydantic models recursively: each field gets a comment line with its
``Field(description=...)`` (or its model's docstring summary for a nested section) and its default value
in flow style. The text loads back (:meth:`CampaignConfig.from_dict`) as a config equal to the defaults.
"""

from __future__ import annotations

from typing import Any

import yaml
from pydantic import BaseModel

from slamtrials.campaign.config import CampaignConfig

__all__ = ["dump_default_yaml", "dump_config_yaml", "EXAMPLE_WORLDS"]

#: World entries shown in the dumped default (``worlds`` has no default).
EXAMPLE_WORLDS = ("office_small_01", "lab_small_01", "house_small_01")

_HEADER = """\
# slamtrials campaign config: every setting with its default value (SI units: m, rad, s).
# Run it with:  slamtrials campaign run THIS.yaml --out CAMPAIGN_FOLDER
# Delete what you do not change; unknown keys are an error.
"""


def _scalar(value: Any) -> str:
    """A value in YAML flow style on one line (floats as their shortest round-tripping repr)."""
    text = yaml.safe_dump(value, default_flow_style=True, width=10_000, sort_keys=False).strip()
    return text.removesuffix("\n...").removesuffix("...").strip()


def _summary(model: type[BaseModel]) -> str:
    doc = (model.__doc__ or "").strip().splitlines()
    return doc[0].strip().rstrip(".") if doc else model.__name__


def _lines(model: BaseModel, indent: int) -> list[str]:
    pad = "  " * indent
    out: list[str] = []
    for name, field in type(model).model_fields.items():
        value = getattr(model, name)
        if isinstance(value, BaseModel):
            comment = field.description or _summary(type(value))
            out.append(f"{pad}# {comment}")
            out.append(f"{pad}{name}:")
            out.extend(_lines(value, indent + 1))
            continue
        if field.description:
            out.append(f"{pad}# {field.description}")
        plain = model.model_dump(mode="json", include={name})[name]
        if isinstance(plain, list) and plain and name == "worlds":
            out.append(f"{pad}{name}:")
            out.extend(f"{pad}  - {_scalar(item)}" for item in plain)
        else:
            out.append(f"{pad}{name}: {_scalar(plain)}")
    return out


def dump_config_yaml(config: CampaignConfig, *, header: str = "") -> str:
    """``config`` as commented YAML that loads back as an equal config."""
    return header + "\n".join(_lines(config, 0)) + "\n"


def dump_default_yaml() -> str:
    """The default campaign config as commented YAML (``worlds`` holds :data:`EXAMPLE_WORLDS`)."""
    return dump_config_yaml(CampaignConfig(worlds=list(EXAMPLE_WORLDS)), header=_HEADER)
