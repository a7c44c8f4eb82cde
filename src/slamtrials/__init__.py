"""slamtrials: repeatable SLAM evaluation.

Simulate a robot that explores a floor plan on its own, many times; run a SLAM algorithm on every run;
measure the localization error against ground truth; add runs until each building's mean error is
known to a stated confidence (Amigoni, Castelli and Luperto, IROS 2018).

The public API is imported lazily so that ``import slamtrials`` stays fast.
"""

from __future__ import annotations

import os
from importlib import import_module
from typing import Any

from slamtrials.__about__ import __version__

# Before numba is first imported: with Intel's SVML library installed, numba would let LLVM turn its
# loops over math.sin, exp, ... into SVML calls, whose results differ from the C library's; every run
# must compute the same bits on every machine (slamtrials.stablemath).
os.environ.setdefault("NUMBA_DISABLE_INTEL_SVML", "1")

_PUBLIC = {
    "load_world": "slamtrials.worlds",
    "World": "slamtrials.worlds",
    "generate_world": "slamtrials.worlds.generate",
    "Simulator": "slamtrials.sim",
    "SimConfig": "slamtrials.sim",
    "simulate_waypoints": "slamtrials.sim",
    "Frame": "slamtrials.record",
    "Reading": "slamtrials.record",
    "RunRecord": "slamtrials.record",
    "evaluate_run": "slamtrials.evaluation",
    "evaluate_files": "slamtrials.evaluation",
    "score_map": "slamtrials.campaign.mapscore",
    "MapQuality": "slamtrials.metric.mapquality",
    "write_run": "slamtrials.io.runfolder",
    "read_run": "slamtrials.io.runfolder",
    "SlamtrialsError": "slamtrials.errors",
    "make_algorithm": "slamtrials.slam",
    "run_trial": "slamtrials.trial",
    "TrialConfig": "slamtrials.trial",
    "CampaignConfig": "slamtrials.campaign",
    "run_campaign": "slamtrials.campaign",
    "replay_campaign": "slamtrials.campaign",
    "campaign_status": "slamtrials.campaign",
    "load_campaign": "slamtrials.report",
    "build_report": "slamtrials.report",
}

__all__ = ["__version__", *_PUBLIC]


def __getattr__(name: str) -> Any:
    if name in _PUBLIC:
        return getattr(import_module(_PUBLIC[name]), name)
    raise AttributeError(f"module 'slamtrials' has no attribute {name!r}")
