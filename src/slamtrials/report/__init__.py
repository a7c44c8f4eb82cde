"""The report: a campaign's tables, the paper's figures, map galleries, and comparisons of campaigns.

* :func:`load_campaign` reads a campaign folder (read-only) into pandas DataFrames ``runs`` and ``worlds``
  (:class:`CampaignData`); :func:`export_table` writes them as CSV or Parquet.
* :func:`build_report` writes ``<campaign>/report/index.html`` with the paper's Table I and Figs. 1, 3, 4,
  5, 6, trajectories, termination reasons, explored fraction and provenance.
* :func:`compare_report` compares two campaigns world by world (paired tests for a replay and its source,
  Welch's otherwise; corrected p-values and intervals; Stouffer's overall verdict; the Fig. 6 trap) and
  writes ``compare.html``; :func:`compare_campaigns` is the statistics alone, :func:`detect_pairing` says
  whether two campaigns share their recorded data.
* :func:`world_summary` is Table I as a DataFrame; the ``draw_*`` functions of
  :mod:`slamtrials.report.campaign_figures` draw on a given matplotlib Axes.

Names are imported lazily, so importing one module of the package stays cheap.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

_PUBLIC = {
    "CampaignData": "slamtrials.report.load",
    "load_campaign": "slamtrials.report.load",
    "export_table": "slamtrials.report.load",
    "build_report": "slamtrials.report.build",
    "compare_report": "slamtrials.report.compare_page",
    "CompareReport": "slamtrials.report.compare_page",
    "compare_campaigns": "slamtrials.report.compare",
    "Comparison": "slamtrials.report.compare",
    "world_pair_traps": "slamtrials.report.compare",
    "detect_pairing": "slamtrials.report.pairing",
    "world_summary": "slamtrials.report.tables",
    "paper_table": "slamtrials.report.tables",
    "save_figure": "slamtrials.report.campaign_figures",
}

__all__ = list(_PUBLIC)


def __getattr__(name: str) -> Any:
    if name in _PUBLIC:
        return getattr(import_module(_PUBLIC[name]), name)
    raise AttributeError(f"module 'slamtrials.report' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_PUBLIC])
