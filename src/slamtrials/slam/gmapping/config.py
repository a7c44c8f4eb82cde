"""GMapping's parameters under slam_gmapping's names, with its defaults, and the seed paper's preset.

Every parameter is named and defaulted as in the ROS wrapper ``slam_gmapping`` (spec/gmapping.md,
section 6); units are SI (metres, radians, seconds). Two parameters are slamtrials' own:
``free_cell_test`` (section 3 of the spec: whether the likelihood's free-cell test is done) and
``initial_pose``.
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

__all__ = ["GMappingConfig", "PRESETS", "default_max_range"]


class GMappingConfig(BaseModel):
    """Parameters of :class:`~slamtrials.slam.gmapping.GMapping` (slam_gmapping's names and defaults).

    Attributes
    ----------
    particles:
        Number of particles.
    linearUpdate, angularUpdate:
        Process a reading (scan-match, weigh, resample, register) once the odometry travelled this far
        (m) or turned this much (rad) since the last processed one.
    temporalUpdate:
        Also process a reading when more than this many seconds passed since the last processed one;
        negative: off.
    srr, srt, str, stt:
        Motion-model noise: translation from translation, rotation from translation, translation from
        rotation, rotation from rotation (standard deviations per metre or radian of odometry motion).
    sigma:
        Scan-matcher score variance (m^2): a beam scores ``exp(-|mu|^2 / sigma)``.
    kernelSize:
        Half-width (cells) of the window searched for the endpoint's nearest cell mean.
    lstep, astep:
        Initial hill-climbing steps (m, rad).
    iterations:
        Step halvings without improvement after which hill climbing stops.
    lsigma:
        Likelihood variance (m^2): a beam adds ``-|mu|^2 / lsigma`` to the log weight.
    ogain:
        Smoothing gain of the weights: log weights are divided by ``ogain * particles``.
    lskip:
        Use every ``(lskip + 1)``-th beam for matching and likelihood.
    minimumScore:
        A particle takes the matched pose only when the match score exceeds this.
    resampleThreshold:
        Resample when Neff < resampleThreshold * particles.
    delta:
        Map resolution (m).
    maxUrange:
        Usable range (m): longer beams are not used by the filter and, in the published map, are cut
        here and mark only free cells. ``None``: the laser's range_max.
    maxRange:
        Beams longer than this are ignored entirely. ``None``: the laser's ``range_max - 0.01``, as
        slam_gmapping sets it, so that a reading at the sensor's maximum (no return) is skipped.
    occ_thresh:
        Published map: occupied where hits / visits exceeds this.
    map_update_interval:
        Seconds (of reading time) between rebuilds of the published map.
    free_cell_test:
        ``False`` (default) behaves like the original code, whose free-cell test never rejects a cell
        (its test cell lies off the map); ``True`` does the test as intended: a cell's mean is used only
        when the cell one step back along the beam, shifted by the same window offset, holds no endpoint.
    initial_pose:
        Map-frame pose (x, y, theta) of the first reading. ``None`` (default): the first odometry pose,
        as slam_gmapping does (the map frame then starts aligned with the odometry frame).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    particles: int = Field(30, ge=1, le=10_000, description="number of particles")
    linearUpdate: float = Field(1.0, ge=0.0, le=1000.0, description="process after this much travel (m)")
    angularUpdate: float = Field(0.5, ge=0.0, le=2.0 * math.pi, description="process after this much turning (rad)")
    temporalUpdate: float = Field(-1.0, le=1.0e6, description="process after this much time (s); negative: off")
    srr: float = Field(0.1, ge=0.0, le=10.0, description="translation noise per metre of translation")
    srt: float = Field(0.2, ge=0.0, le=10.0, description="rotation noise per metre of translation")
    str: float = Field(0.1, ge=0.0, le=10.0, description="translation noise per radian of rotation")
    stt: float = Field(0.2, ge=0.0, le=10.0, description="rotation noise per radian of rotation")
    sigma: float = Field(0.05, gt=0.0, le=100.0, description="scan-matcher score variance (m^2)")
    kernelSize: int = Field(1, ge=0, le=10, description="window half-width for the nearest cell mean (cells)")
    lstep: float = Field(0.05, gt=0.0, le=10.0, description="initial linear hill-climbing step (m)")
    astep: float = Field(0.05, gt=0.0, le=math.pi, description="initial angular hill-climbing step (rad)")
    iterations: int = Field(5, ge=0, le=50, description="step halvings without improvement before stopping")
    lsigma: float = Field(0.075, gt=0.0, le=100.0, description="likelihood variance (m^2)")
    ogain: float = Field(3.0, gt=0.0, le=1.0e6, description="weight smoothing gain")
    lskip: int = Field(0, ge=0, le=1000, description="beams skipped between used beams")
    minimumScore: float = Field(0.0, ge=0.0, le=1.0e6, description="least score for taking the matched pose")
    resampleThreshold: float = Field(0.5, ge=0.0, le=1.0, description="resample when Neff < this x particles")
    delta: float = Field(0.05, ge=0.005, le=1.0, description="map resolution (m)")
    maxUrange: float | None = Field(
        None, gt=0.0, le=1000.0, description="usable range (m); None: the laser's range_max"
    )
    maxRange: float | None = Field(
        None, gt=0.0, le=1000.0, description="beams beyond are ignored (m); None: the laser's range_max - 0.01"
    )
    occ_thresh: float = Field(0.25, ge=0.0, lt=1.0, description="published map: occupied when hits/visits exceeds this")
    map_update_interval: float = Field(5.0, ge=0.0, le=1.0e6, description="seconds between published-map rebuilds")
    free_cell_test: bool = Field(False, description="do the likelihood's free-cell test (the original never rejects)")
    initial_pose: tuple[float, float, float] | None = Field(
        None, description="pose of the first reading; None: first odometry pose"
    )

    @field_validator("initial_pose")
    @classmethod
    def _finite(cls, value: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
        if value is not None and not all(math.isfinite(v) for v in value):
            raise ValueError(f"initial_pose must be finite numbers, got {value}")
        return value

    @model_validator(mode="after")
    def _ranges_consistent(self) -> GMappingConfig:
        if self.maxUrange is not None and self.maxRange is not None and self.maxUrange > self.maxRange:
            raise ValueError(f"maxUrange ({self.maxUrange} m) must not exceed maxRange ({self.maxRange} m)")
        return self


#: Named parameter sets. ``paper``: the seed paper's system (Amigoni, Castelli, Luperto, IROS 2018;
#: spec/gmapping.md section 6). Its temporalUpdate stays off: the launch file misspelt the parameter.
PRESETS: dict[str, dict[str, Any]] = {
    "paper": {
        "particles": 40,
        "linearUpdate": 1.0,
        "angularUpdate": 0.25,
        "srr": 0.01,
        "srt": 0.02,
        "str": 0.01,
        "stt": 0.02,
        "maxUrange": 30.0,
        "maxRange": 60.0,
    },
}


def default_max_range(range_min: float, range_max: float) -> float:
    """GMapping's ``maxRange`` (m) when the config leaves it unset: slam_gmapping's ``range_max - 0.01``,
    or ``range_max`` itself for a laser too short for that (``range_max - 0.01 <= range_min``)."""
    cut = range_max - 0.01
    return cut if cut > range_min else range_max
