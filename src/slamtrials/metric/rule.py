"""The relation-sampling rule: how many relations a run's error is measured on, as one typed value.

Every place that samples relations from a ground truth (``slamtrials evaluate RUN``, a campaign's
scoring, replays, the report's sampling check) takes a :class:`SamplingRule`; the defaults are those
of the IROS 2018 method (a 500-pair pilot, then ``N = ceil(z^2 s^2 / d^2)`` at 99 % confidence and
+-0.02 m / +-0.02 rad margins, normal quantile, two-sided).
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from slamtrials.metric.quantiles import Distribution

__all__ = [
    "SamplingRule",
    "DEFAULT_PILOT",
    "DEFAULT_CONFIDENCE",
    "DEFAULT_MARGIN_T",
    "DEFAULT_MARGIN_R",
    "DEFAULT_MAX_RELATIONS",
]

DEFAULT_PILOT = 500
DEFAULT_CONFIDENCE = 0.99
DEFAULT_MARGIN_T = 0.02  # m
DEFAULT_MARGIN_R = 0.02  # rad
#: Cap on the relation count, so that a diverging estimate (huge error spread) cannot exhaust memory.
DEFAULT_MAX_RELATIONS = 1_000_000


class SamplingRule(BaseModel):
    """How relations are sampled from a run's ground truth (see :func:`slamtrials.metric.sample_relations`).

    Attributes
    ----------
    pilot:
        Pairs of the pilot sample that estimates the error spread (``n0``).
    confidence:
        Confidence level ``1 - alpha`` of the margins.
    margin_t, margin_r:
        Margins of error of a run's mean translational (m) and rotational (rad) error; in squared units
        when ``squared``.
    distribution:
        Quantile of the confidence level: ``normal``, or Student ``t`` with ``pilot - 1`` degrees of freedom.
    sides:
        Two-sided (2, default) or one-sided (1) margins.
    min_relations:
        Floor on the relation count (a perfect estimate has ``s = 0`` and would need none).
    max_relations:
        Cap on the relation count (a diverged estimate's huge spread cannot exhaust memory).
    squared:
        Work with squared errors (m^2, rad^2).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    pilot: int = Field(
        DEFAULT_PILOT, ge=2, le=1_000_000, description="pairs of the pilot sample that estimates the error spread"
    )
    confidence: float = Field(
        DEFAULT_CONFIDENCE, gt=0.0, lt=1.0, description="confidence level of a run's relation sampling"
    )
    margin_t: float = Field(
        DEFAULT_MARGIN_T, gt=0.0, le=100.0, description="margin of error of a run's mean translational error (m)"
    )
    margin_r: float = Field(
        DEFAULT_MARGIN_R,
        gt=0.0,
        le=10.0,
        description="margin of error of a run's mean rotational error (rad; rad^2 when squared)",
    )
    distribution: Distribution = Field(
        "normal", description="quantile of the confidence level: normal or t (pilot - 1 degrees of freedom)"
    )
    sides: Literal[1, 2] = Field(2, description="two-sided (2) or one-sided (1) margins")
    min_relations: int = Field(2, ge=1, le=100_000_000, description="floor on a run's relation count")
    max_relations: int = Field(DEFAULT_MAX_RELATIONS, ge=1, le=100_000_000, description="cap on a run's relation count")
    squared: bool = Field(False, description="sample on squared errors (m^2, rad^2)")

    @model_validator(mode="after")
    def _floor_not_above_cap(self) -> SamplingRule:
        if self.min_relations > self.max_relations:
            raise ValueError(
                f"min_relations ({self.min_relations}) must not exceed max_relations ({self.max_relations})"
            )
        return self
