"""One trial: simulator + online SLAM + frontier explorer, until the map stops changing.

:func:`run_trial` returns the run as a :class:`~slamtrials.record.RunRecord` (writing it is the
caller's job, through :mod:`slamtrials.io`); :class:`TrialConfig` holds its settings.
"""

from __future__ import annotations

from slamtrials.trial.config import SlamSettings, TrialConfig
from slamtrials.trial.coverage import mapped_fraction, observed_fraction
from slamtrials.trial.run import TrialProgress, run_trial
from slamtrials.trial.summary import TRIAL_FORMAT, TrialSummary

__all__ = [
    "run_trial",
    "TrialConfig",
    "SlamSettings",
    "TrialProgress",
    "TrialSummary",
    "TRIAL_FORMAT",
    "mapped_fraction",
    "observed_fraction",
]
