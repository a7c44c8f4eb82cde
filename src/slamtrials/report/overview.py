"""The report's first section, the overview: what the campaign ran (SLAM algorithm, simulated sensors,
relations, worlds, run-count rule, times, seed) and notes on what is missing (unfinished, capped or failed
worlds, failed runs)."""

from __future__ import annotations

from typing import Any

import pandas as pd

from slamtrials.campaign.config import MetricSettings
from slamtrials.campaign.events import REPLAY_NOTE
from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.load import CampaignData

__all__ = ["overview_section", "campaign_notes", "slam_text", "profile_text", "relations_text", "run_times_text"]

#: The section's anchor.
SECTION_ID = "overview"


def overview_section(view: CampaignView) -> str:
    """The section (HTML, ``id="overview"``): a definition list of the campaign's settings, then its notes
    (``id="notes"``)."""
    data, done = view.data, view.done
    config = data.config
    runs = config.get("runs", {})
    counts = data.runs["status"].value_counts()
    items = [
        ("campaign folder", str(data.folder)),
        ("kind", data.kind + (f" of {config.get('replay_of')}" if config.get("replay_of") else "")),
        ("SLAM algorithm", slam_text(config.get("slam", {}))),
        ("simulated sensors", profile_text(config.get("sim", {}))),
        ("relations per run", relations_text(config.get("metric", {}))),
        (
            "worlds",
            f"{len(data.worlds)}: "
            + ", ".join(f"{w} {s}" for w, s in zip(data.worlds["world"], data.worlds["status"])),
        ),
        ("runs", ", ".join(f"{int(counts.get(s, 0))} {s}" for s in ("done", "running", "pending", "failed"))),
        (
            "run-count rule",
            f"first {runs.get('initial')} runs, cap {runs.get('max_runs')}, margins \u00b1{runs.get('margin_t')} m "
            f"and \u00b1{runs.get('margin_r')} rad at {h.fmt_percent(runs.get('confidence'))} confidence "
            f"({runs.get('distribution')} quantile)",
        ),
        *([("run times", run_times_text(done))] if len(done) else []),
        ("root seed", str(config.get("seed"))),
        ("created", str(data.meta.get("created"))),
    ]
    return h.section(
        "Overview", h.definition_list(items), h.notes(campaign_notes(data, done), id="notes"), id=SECTION_ID
    )


def campaign_notes(data: CampaignData, done: pd.DataFrame) -> list[str]:
    """One sentence per thing a reader of the page should know is missing or special: a replay, no finished
    run (``done`` is empty), a capped, failed, short or unfinished world, failed runs."""
    notes = []
    if data.kind == "replay":
        notes.append(f"This campaign is a replay of {data.config.get('replay_of')}: {REPLAY_NOTE}.")
    if done.empty:
        notes.append("No run has finished yet: the tables and figures appear as runs finish (rebuild the report).")
    for _, w in data.worlds.iterrows():
        note = f" ({w['note']})" if isinstance(w["note"], str) and w["note"] else ""
        if w["status"] == "capped":
            notes.append(
                f"{w['world']}: stopped at the cap of {w['runs_done']} runs; the run-count rule asked for "
                f"{w['runs_needed']}, so its margins of error are not reached."
            )
        elif w["status"] == "failed":
            notes.append(f"{w['world']}: failed{note}; resume the campaign to retry.")
        elif w["status"] == "short":
            notes.append(f"{w['world']}: short of runs{note}.")
        elif w["status"] in ("running", "pending"):
            notes.append(f"{w['world']}: {w['status']} ({w['runs_done']} runs done so far); this report is a snapshot.")
        elif note:
            notes.append(f"{w['world']}: {w['note']}.")
    failed = data.runs[data.runs["status"] == "failed"]
    if len(failed):
        notes.append(f"{len(failed)} run(s) failed; their errors are listed in the runs table.")
    return notes


def slam_text(slam: dict[str, Any]) -> str:
    """The provenance line of the stored SLAM settings: an algorithm with its preset and parameters, or a program."""
    program = slam.get("program")
    if program:
        return (
            f"{slam.get('algorithm')}: external program, offline (command {program.get('command')!r}, input "
            f"{program.get('input')}, output {program.get('output')}, timeout {program.get('timeout')} s)"
        )
    return f"{slam.get('algorithm')} (preset {slam.get('preset')}, params {slam.get('params') or {}})"


def profile_text(sim: dict[str, Any]) -> str:
    """The error profile the runs were simulated with, and whether the config overrode it: ``error profile
    realistic + 2 overrides (laser.dropout_rate 0.01 instead of 0.02526, ...)``, then where the profile's
    values come from. A stored config that names none is ``paper`` (versions before profiles)."""
    from pydantic import ValidationError

    from slamtrials.campaign.config import stored_sim_config

    sim = sim if isinstance(sim, dict) else {}
    profile = sim.get("profile", "paper")
    name = profile.get("name", "?") if isinstance(profile, dict) else str(profile)
    try:
        config = stored_sim_config(sim)
    except ValidationError:  # a profile this version does not know: its name as stored
        return f"error profile {name}"
    label, overrides = config.profile_label, config.profile_overrides
    changed = ", ".join(f"{o.key} {_value_text(o.value)} instead of {_value_text(o.profile_value)}" for o in overrides)
    text = f"error profile {label}" + (f" ({changed})" if changed else "")
    if name == "paper":
        return text + ": the IROS 2018 Stage set-up (noise-free laser, per-run odometry scale bias)"
    description = config.error_profile.description
    return text + (f": {description}" if description else "")


def _value_text(value: Any) -> str:
    """A field's value, short: ``0.01``, ``[-0.01, 0.01]``."""
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_value_text(v) for v in value) + "]"
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def relations_text(metric: dict[str, Any]) -> str:
    """The stored relation rule and which SLAM estimate (final or online) the run errors score."""
    settings = MetricSettings.of_stored(metric)
    which = "the final SLAM estimate" if settings.estimate == "final" else "the online SLAM estimate"
    return f"{settings.sampling.describe()}; the run errors score {which}"


def run_times_text(done: pd.DataFrame) -> str:
    """The finished runs' simulated time (``duration_s``) and worker time (``wall_s``), in all and per run,
    rounded; ``-`` when neither is recorded."""
    simulated, wall = done["duration_s"].dropna(), done["wall_s"].dropna()
    parts = []
    if len(simulated):
        parts.append(f"{h.fmt_duration(simulated.sum())} simulated (mean {h.fmt_duration(simulated.mean())} per run)")
    if len(wall):
        parts.append(f"{h.fmt_duration(wall.sum())} of worker time (mean {h.fmt_duration(wall.mean())} per run)")
    return "; ".join(parts) or "-"
