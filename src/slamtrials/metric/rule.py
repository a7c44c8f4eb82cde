"""The relation-sampling rule: how many relations a run's error is measured on, as one typed value.

Every place that samples relations from a ground truth (``slamtrials evaluate RUN``, a campaign's
scoring, the report's sampling check) takes a :class:`SamplingRule`. Two named rules:

``precise`` (the default)
    A 500-pair pilot, then ``N = ceil(z^2 s^2 / d^2)`` with a margin **relative to the error**,
    ``d = 1 %`` of the pilot's mean error (for translation and rotation, the larger ``N`` wins), at 99 %
    confidence; at least 5,000 and at most 200,000 relations. A run's mean error is then known to about
    1 % of itself, so the metric's own noise is a small part of the spread between runs.
``paper``
    The IROS 2018 rule: the same pilot, then ``N = ceil(z^2 s^2 / d^2)`` with **absolute** margins
    ``d = 0.02 m`` and ``0.02 rad`` at 99 % confidence (normal quantile, two-sided), at least 2 relations.
    Made for errors of 0.3 to 0.6 m; on errors of a few centimetres it gives 10 to 30 relations per run.

A rule is written ``{rule: paper}``; any other field given overrides the named rule's value. The two
kinds of margin do not mix: ``margin_t``/``margin_r`` belong to ``paper``, ``relative_margin`` to
``precise``.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from slamtrials.metric.quantiles import Distribution

__all__ = [
    "SamplingRule",
    "RuleName",
    "RULE_PRESETS",
    "DEFAULT_PILOT",
    "DEFAULT_CONFIDENCE",
    "DEFAULT_MARGIN_T",
    "DEFAULT_MARGIN_R",
    "DEFAULT_RELATIVE_MARGIN",
    "DEFAULT_MIN_RELATIONS",
    "DEFAULT_MAX_RELATIONS",
    "PAPER_MAX_RELATIONS",
]

RuleName = Literal["precise", "paper"]

DEFAULT_PILOT = 500
DEFAULT_CONFIDENCE = 0.99
#: The paper's absolute margins.
DEFAULT_MARGIN_T = 0.02  # m
DEFAULT_MARGIN_R = 0.02  # rad
#: The precise rule's margin, a fraction of the pilot's mean error.
DEFAULT_RELATIVE_MARGIN = 0.01
#: The precise rule's floor and cap. Per-relation errors of a simulated run have a coefficient of
#: variation of about 0.6-1.2, so 1 % at 99 % needs 25,000-100,000 relations (evaluated in well under a
#: second); the cap bounds a run whose errors are far more skewed.
DEFAULT_MIN_RELATIONS = 5_000
DEFAULT_MAX_RELATIONS = 200_000
#: The paper rule's cap, so that a diverging estimate (huge error spread) cannot exhaust memory.
PAPER_MAX_RELATIONS = 1_000_000

#: The values each named rule gives to the fields it is not told.
RULE_PRESETS: dict[str, dict[str, Any]] = {
    "precise": {
        "relative_margin": DEFAULT_RELATIVE_MARGIN,
        "margin_t": None,
        "margin_r": None,
        "min_relations": DEFAULT_MIN_RELATIONS,
        "max_relations": DEFAULT_MAX_RELATIONS,
    },
    "paper": {
        "relative_margin": None,
        "margin_t": DEFAULT_MARGIN_T,
        "margin_r": DEFAULT_MARGIN_R,
        "min_relations": 2,
        "max_relations": PAPER_MAX_RELATIONS,
    },
}


class SamplingRule(BaseModel):
    """How relations are sampled from a run's ground truth (see :func:`slamtrials.metric.sample_relations`).

    Attributes
    ----------
    rule:
        ``precise`` (relative margin, the default) or ``paper`` (the IROS 2018 absolute margins); it sets
        every field below that is not given.
    pilot:
        Pairs of the pilot sample that estimates the error spread (``n0``).
    confidence:
        Confidence level ``1 - alpha`` of the margins.
    relative_margin:
        ``precise``: the margin of error as a fraction of the pilot's mean error (translation and
        rotation each). None under ``paper``.
    margin_t, margin_r:
        ``paper``: margins of error of a run's mean translational (m) and rotational (rad) error; in
        squared units when ``squared``. None under ``precise``.
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

    rule: RuleName = Field(
        "precise", description="precise (margin relative to the error) or paper (the IROS 2018 absolute margins)"
    )
    pilot: int = Field(
        DEFAULT_PILOT, ge=2, le=1_000_000, description="pairs of the pilot sample that estimates the error spread"
    )
    confidence: float = Field(
        DEFAULT_CONFIDENCE, gt=0.0, lt=1.0, description="confidence level of a run's relation sampling"
    )
    relative_margin: float | None = Field(
        DEFAULT_RELATIVE_MARGIN,
        gt=0.0,
        le=1.0,
        description="precise rule: margin of error as a fraction of the pilot's mean error",
    )
    margin_t: float | None = Field(
        None,
        gt=0.0,
        le=100.0,
        description="paper rule: margin of error of a run's mean translational error (m)",
    )
    margin_r: float | None = Field(
        None,
        gt=0.0,
        le=10.0,
        description="paper rule: margin of error of a run's mean rotational error (rad; rad^2 when squared)",
    )
    distribution: Distribution = Field(
        "normal", description="quantile of the confidence level: normal or t (pilot - 1 degrees of freedom)"
    )
    sides: Literal[1, 2] = Field(2, description="two-sided (2) or one-sided (1) margins")
    min_relations: int = Field(
        DEFAULT_MIN_RELATIONS, ge=1, le=100_000_000, description="floor on a run's relation count"
    )
    max_relations: int = Field(DEFAULT_MAX_RELATIONS, ge=1, le=100_000_000, description="cap on a run's relation count")
    squared: bool = Field(False, description="sample on squared errors (m^2, rad^2)")

    @model_validator(mode="before")
    @classmethod
    def _named_rule_fills_the_rest(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        name = data.get("rule", "precise")
        preset = RULE_PRESETS.get(name) if isinstance(name, str) else None
        if preset is None:
            return data  # the field's own validation names the bad value
        return {**preset, **data}

    @model_validator(mode="after")
    def _margins_of_the_rule(self) -> SamplingRule:
        if self.rule == "precise":
            absolute = [name for name in ("margin_t", "margin_r") if getattr(self, name) is not None]
            if absolute:
                raise ValueError(
                    f"{' and '.join(absolute)} is an absolute margin of the paper rule; with rule: precise the margin is "
                    "relative_margin (a fraction of the error), or set rule: paper"
                )
            if self.relative_margin is None:
                raise ValueError("rule: precise needs relative_margin (a fraction of the error, e.g. 0.01)")
        else:
            if self.relative_margin is not None:
                raise ValueError(
                    "relative_margin belongs to rule: precise; the paper rule's margins are margin_t (m) and margin_r (rad)"
                )
            missing = [name for name in ("margin_t", "margin_r") if getattr(self, name) is None]
            if missing:
                raise ValueError(f"rule: paper needs {' and '.join(missing)}")
        if self.min_relations > self.max_relations:
            raise ValueError(
                f"min_relations ({self.min_relations}) must not exceed max_relations ({self.max_relations})"
            )
        return self

    def margins(self, mean_t: float, mean_r: float) -> tuple[float, float]:
        """The margins of error ``(d_t, d_r)`` for a pilot with mean errors ``mean_t``, ``mean_r``.

        Absolute under ``paper``; ``relative_margin`` times the means under ``precise`` (0 for a zero mean).
        """
        if self.relative_margin is None:
            assert self.margin_t is not None and self.margin_r is not None
            return self.margin_t, self.margin_r
        return self.relative_margin * mean_t, self.relative_margin * mean_r

    def describe(self) -> str:
        """One line: the rule, its margins, confidence and bounds (for printed output and the report)."""
        if self.relative_margin is not None:
            margins = f"margin {self.relative_margin:.3g} of the mean error"
        else:
            margins = f"margins {self.margin_t:g}, {self.margin_r:g}"
        return (
            f"{self.rule} rule: pilot {self.pilot}, {margins} at {self.confidence:g} confidence "
            f"({self.distribution}), {self.min_relations}-{self.max_relations} relations"
        )
