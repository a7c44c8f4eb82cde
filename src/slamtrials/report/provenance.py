"""The report's last section, provenance: the campaign catalog's metadata and seeds, the versions the runs
were made with (from each run.json), the versions that wrote the page, and the campaign's config as YAML."""

from __future__ import annotations

import json
import platform
from collections import Counter

import numpy as np
import pandas as pd

from slamtrials.__about__ import __version__, source_revision
from slamtrials.io.layout import RunFolder
from slamtrials.report import html as h
from slamtrials.report.load import CampaignData

__all__ = ["provenance_section", "report_versions", "SECTION_ID"]

#: The section's anchor.
SECTION_ID = "provenance"


def provenance_section(data: CampaignData) -> str:
    """The section (HTML, ``id="provenance"``): catalog, ``<table id="versions-table">`` of the runs' versions
    (most runs first), this report's versions and ``<pre id="config">``."""
    import yaml

    config_text = yaml.safe_dump(data.config, sort_keys=False, default_flow_style=None, width=110)
    run_versions = [[", ".join(f"{k} {v}" for k, v in json.loads(key).items()), n] for key, n in _run_versions(data)]
    meta = [(k, v) for k, v in sorted(data.meta.items())]
    return h.section(
        "Provenance",
        "<h3>Campaign catalog</h3>",
        h.definition_list(
            [
                *meta,
                ("root seed", data.config.get("seed")),
                (
                    "run seeds",
                    "each (world, run index) has its own stream from numpy.random.SeedSequence of "
                    "the root seed (listed per run in the runs table)",
                ),
            ]
        ),
        "<h3>Versions of the runs (from run.json)</h3>",
        h.table(["versions", "runs"], run_versions, id="versions-table")
        if run_versions
        else "<p>No run folder read.</p>",
        "<h3>This report</h3>",
        h.definition_list(sorted(report_versions().items())),
        "<h3>Configuration</h3>",
        h.pre(config_text, id="config"),
        id=SECTION_ID,
    )


def _run_versions(data: CampaignData) -> list[tuple[str, int]]:
    """``(versions as sorted JSON, runs)`` of the done runs' run.json files, most runs first; a run.json that
    is missing, unreadable or has no versions is left out."""
    seen: Counter = Counter()
    for folder in data.done["folder"]:
        path = RunFolder(data.folder / str(folder)).run_json
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        versions = doc.get("versions")
        if isinstance(versions, dict):
            seen[json.dumps(versions, sort_keys=True)] += 1
    return seen.most_common()


def report_versions() -> dict[str, str]:
    """The versions of slamtrials (and its source revision when known), Python and the libraries that drew
    the page."""
    import matplotlib
    import scipy

    revision = source_revision()
    source = {"source": revision} if revision else {}
    return {
        "slamtrials": __version__,
        **source,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pandas": pd.__version__,
        "matplotlib": matplotlib.__version__,
    }
