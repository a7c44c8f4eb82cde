"""``slamtrials config dump``: a complete campaign config of the defaults, every key commented.

The YAML is written by walking the pydantic models recursively: each field gets a comment line with its
``Field(description=...)`` (or its model's docstring summary for a nested section) and its default value
in flow style. The text loads back (:meth:`CampaignConfig.from_dict`) as a config equal to the defaults.

The ``sim`` section is its error profile plus overrides (:mod:`slamtrials.sim.overrides`): it names the
profile and writes only the error-model fields whose values differ from the profile's (none for the
defaults), so that editing the profile's name changes every value the profile sets. A campaign folder's
``config.yaml`` (``resolved=True``) writes every value instead, as the campaign ran it.
"""

from __future__ import annotations

from typing import Any

import yaml
from pydantic import BaseModel

from slamtrials.campaign.config import CampaignConfig
from slamtrials.sim import SimConfig
from slamtrials.sim.overrides import ERROR_SECTIONS

__all__ = ["dump_default_yaml", "dump_config_yaml", "EXAMPLE_WORLDS"]

#: World entries shown in the dumped default (``worlds`` has no default).
EXAMPLE_WORLDS = ("office_small_01", "lab_small_01", "house_small_01")

_HEADER = """\
# slamtrials campaign config: every setting with its default value (SI units: m, rad, s).
# Run it with:  slamtrials campaign run THIS.yaml --out CAMPAIGN_FOLDER
# Delete what you do not change; unknown keys are an error. The sim section names an error profile, which
# sets the laser's and the odometry's error models; their values written under sim override the profile's.
"""


def _scalar(value: Any) -> str:
    """A value in YAML flow style on one line (floats as their shortest round-tripping repr)."""
    text = yaml.safe_dump(value, default_flow_style=True, width=10_000, sort_keys=False).strip()
    return text.removesuffix("\n...").removesuffix("...").strip()


def _summary(model: type[BaseModel]) -> str:
    doc = (model.__doc__ or "").strip().splitlines()
    return doc[0].strip().rstrip(".") if doc else model.__name__


def _profile_note(sim: SimConfig, section: str, pad: str) -> str:
    """The comment that says which fields of ``section`` the profile sets."""
    what = "noise, short readings, dropouts, edges" if section == "laser" else "bias ranges, noise, slips"
    return f"{pad}# its error-model fields ({what}) come from profile {sim.profile_name}; a value written here overrides it"


def _lines(model: BaseModel, indent: int, *, resolved: bool = True, skip: frozenset[str] = frozenset()) -> list[str]:
    pad = "  " * indent
    out: list[str] = []
    overridden = set() if resolved or not isinstance(model, SimConfig) else {o.key for o in model.profile_overrides}
    fields = list(type(model).model_fields.items())
    if isinstance(model, SimConfig):  # the profile first: the values below are its overrides
        fields.sort(key=lambda item: item[0] != "profile")
    for name, field in fields:
        if name in skip:
            continue
        value = getattr(model, name)
        if isinstance(value, BaseModel):
            comment = field.description or _summary(type(value))
            out.append(f"{pad}# {comment}")
            out.append(f"{pad}{name}:")
            inner: frozenset[str] = frozenset()
            if isinstance(model, SimConfig) and name in ERROR_SECTIONS and not resolved:
                inner = frozenset(f for f in ERROR_SECTIONS[name] if f"{name}.{f}" not in overridden)
                out.append(_profile_note(model, name, "  " * (indent + 1)))
            out.extend(_lines(value, indent + 1, resolved=resolved, skip=inner))
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


def dump_config_yaml(config: CampaignConfig, *, header: str = "", resolved: bool = False) -> str:
    """``config`` as commented YAML that loads back as an equal config.

    Parameters
    ----------
    config:
        The config.
    header:
        Comment lines to put first.
    resolved:
        Write every error-model value of ``sim``; by default only those that override the profile's.
    """
    return header + "\n".join(_lines(config, 0, resolved=resolved)) + "\n"


def dump_default_yaml() -> str:
    """The default campaign config as commented YAML (``worlds`` holds :data:`EXAMPLE_WORLDS`)."""
    return dump_config_yaml(CampaignConfig(worlds=list(EXAMPLE_WORLDS)), header=_HEADER)
