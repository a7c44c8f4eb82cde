"""A campaign folder as pandas DataFrames, for notebooks and the report: :func:`load_campaign`.

The catalog (``campaign.sqlite``) is opened read-only (SQLite ``mode=ro``), so loading never writes to
the campaign and works while its driver is still running (the DataFrames are a snapshot).

``runs``: one row per run in the catalog (every status), in campaign order of worlds, then run index:

============== ======================================================================================
column         meaning
============== ======================================================================================
world          the world's campaign name (its run folder name)
run            run index within the world (0-based)
seed           the run's seed (int64)
status         ``done``, ``running``, ``failed`` or ``pending``
attempts       submissions by a driver
eps_t, eps_r   the run's mean translational (m) and rotational (rad) error; NaN unless done
relations      relations sampled to compute them
termination    why the run ended (``map_converged``, ``no_frontiers``, ``time_cap``, ...)
mapped         fraction of the free space the robot can reach that the final map knows (0..1)
duration_s     simulated duration of the run (s)
wall_s         wall-clock time of the run on its worker (s)
worker         ``host:pid`` of the worker
error          why the run failed
folder         run folder, relative to the campaign folder (``runs/<world>/<idx:03d>``)
submitted,     ISO times (UTC)
finished
outlier_t,     the run is an outlier of its world (Tukey's fences, :func:`slamtrials.report.tables.outlier_mask`,
outlier_r      among the world's done runs); False unless done
frames, ...    the entries of the catalog's ``details`` (frames, distance_m, observed_fraction,
               slam_updates, relation_std_t, relation_std_r, relations_capped, and se_t, se_r: the standard
               errors of eps_t, eps_r, and the run's cost: slam_cpu_s, slam_peak_mib, run_cpu_s,
               run_peak_mib, update_ms_median, update_ms_p90, :class:`slamtrials.cost.RunCost`, and the
               map's quality: occupied_precision_1, occupied_recall_1, occupied_precision_2,
               occupied_recall_2, free_iou, ghost_free_m2, :class:`slamtrials.metric.mapquality.MapQuality`,
               from this version on)
============== ======================================================================================

``worlds``: one row per world in campaign order: the catalog's ``worlds`` columns (``name`` as ``world``,
``ref``, ``position``, ``reachable_area`` m^2, ``status``, the last decision of the run-count rule
``runs_target``, ``runs_needed``, ``needed_t``, ``needed_r``, ``std_t``, ``std_r``, ``capped``, ``note``,
``updated``), the run counts ``runs_done``, ``runs_failed``, ``runs_running``, ``runs_pending``, and the
paper's Table I over the done runs (the columns of :func:`slamtrials.report.tables.world_summary`:
``eps_t_mean``, ``eps_t_std``, ``eps_t_std_population``, ``eps_t_ci_low``, ``eps_t_ci_high``,
``eps_t_half_width``, ``eps_t_min``, ``eps_t_max``, ``eps_t_outliers``, the same for ``eps_r``, and
``confidence``), NaN for a world without done runs; and ``eps_t_metric_share``, ``eps_r_metric_share``:
the metric's share of the variance between the done runs (:func:`slamtrials.report.tables.metric_shares`,
mean ``se^2`` over the variance of the run errors), NaN when a run has no standard error recorded
(``se_t``, ``se_r``: runs of earlier versions) or for fewer than 2 runs. The intervals use the campaign's confidence and
quantile (``runs.confidence``, ``runs.distribution``), as ``slamtrials campaign status`` prints them. Last, the mean
cost per done run (:mod:`slamtrials.campaign.costsummary`, as summary.csv): ``slam_cpu_s_mean``, ``slam_peak_mib_mean``,
``run_cpu_s_mean``, ``run_peak_mib_mean``, ``update_ms_median_mean``, ``update_ms_p90_mean``, NaN where no run
recorded that figure (runs of earlier versions), and the mean map quality per done run
(:mod:`slamtrials.campaign.mapsummary`): ``occupied_precision_1_mean``, ``occupied_recall_1_mean``,
``occupied_precision_2_mean``, ``occupied_recall_2_mean``, ``free_iou_mean``, ``ghost_free_m2_mean``, NaN
where no run recorded it; and how fast the done runs explored, as summary.csv has it
(:mod:`slamtrials.campaign.explorationsummary`): ``exploration_runs``, ``coverage_final_mean``,
``reached_90``, ``time_to_90_s_mean``, ``distance_to_90_m_mean``, ``reached_99``, ``time_to_99_s_mean``,
``distance_to_99_m_mean`` (the counts nullable integers), missing where no run recorded them.

:func:`export_table` writes either table as CSV or Parquet.
"""

from __future__ import annotations

import io
import json
import sqlite3
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd

from slamtrials.atomicfile import atomic_write, atomic_write_text
from slamtrials.campaign.costsummary import COST_CSV_COLUMNS
from slamtrials.campaign.explorationsummary import EXPLORATION_CSV_COLUMNS, EXPLORATION_FIGURES, world_exploration
from slamtrials.campaign.mapsummary import MAP_QUALITY_CSV_COLUMNS
from slamtrials.campaign.store import DB_FILE, RUNS_DIR, STORE_FORMAT
from slamtrials.cost import COST_FIGURES
from slamtrials.errors import ConfigError, FormatError
from slamtrials.metric.mapquality import MAP_QUALITY_FIGURES
from slamtrials.metric.quantiles import Distribution
from slamtrials.report.tables import METRICS, metric_shares, outlier_mask, world_summary

__all__ = ["CampaignData", "load_campaign", "export_table", "RUN_COLUMNS", "WORLD_COLUMNS", "TABLES", "FORMATS"]

#: Columns of ``runs`` always present, in order (``details`` entries follow).
RUN_COLUMNS = (
    "world",
    "run",
    "seed",
    "status",
    "attempts",
    "eps_t",
    "eps_r",
    "relations",
    "termination",
    "mapped",
    "duration_s",
    "wall_s",
    "worker",
    "error",
    "folder",
    "submitted",
    "finished",
    "outlier_t",
    "outlier_r",
)
_STORE_WORLD_COLUMNS = (
    "world",
    "ref",
    "position",
    "reachable_area",
    "status",
    "runs_target",
    "runs_needed",
    "needed_t",
    "needed_r",
    "std_t",
    "std_r",
    "capped",
    "note",
    "updated",
)
_STATS = ("mean", "std", "std_population", "ci_low", "ci_high", "half_width", "min", "max", "outliers")
#: Columns of ``worlds``, in order.
WORLD_COLUMNS = (
    *_STORE_WORLD_COLUMNS,
    "runs_done",
    "runs_failed",
    "runs_running",
    "runs_pending",
    *(f"{m}_{s}" for m in METRICS for s in _STATS),
    "confidence",
    *(f"{m}_metric_share" for m in METRICS),
    *COST_CSV_COLUMNS,
    *MAP_QUALITY_CSV_COLUMNS,
    *EXPLORATION_CSV_COLUMNS,
)
#: The exploration columns of ``worlds`` that count runs (nullable integers; the others are float64).
_EXPLORATION_COUNTS = ("exploration_runs", "reached_90", "reached_99")
#: The tables :func:`export_table` writes.
TABLES = ("runs", "worlds")
#: The file formats :func:`export_table` writes.
FORMATS = ("csv", "parquet")

_RUN_SQL = (
    "SELECT r.world, r.idx, r.seed, r.status, r.attempts, r.eps_t, r.eps_r, r.relations, r.termination, "
    "r.mapped_fraction, r.sim_duration, r.wall_time, r.worker, r.error, r.folder, r.submitted, r.finished, r.details "
    "FROM runs r JOIN worlds w ON w.name = r.world ORDER BY w.position, r.idx"
)
_WORLD_SQL = (
    "SELECT name, ref, position, reachable_area, status, runs_target, runs_needed, needed_t, needed_r, std_t, "
    "std_r, capped, note, updated FROM worlds ORDER BY position"
)


@dataclass(frozen=True)
class CampaignData:
    """A snapshot of a campaign folder (see the module docstring for the columns).

    Attributes
    ----------
    folder:
        The campaign folder (absolute).
    runs:
        One row per run of the catalog.
    worlds:
        One row per world, with its status and the paper's Table I over its done runs.
    config:
        The stored campaign config (plain JSON values, as :class:`~slamtrials.campaign.CampaignConfig` dumps it).
    meta:
        The catalog's other ``meta`` entries: ``format``, ``kind`` (``campaign`` or ``replay``),
        ``config_hash``, ``slamtrials_version``, ``created``.
    """

    folder: Path
    runs: pd.DataFrame
    worlds: pd.DataFrame
    config: dict[str, Any] = field(default_factory=dict)
    meta: dict[str, str] = field(default_factory=dict)

    @property
    def kind(self) -> str:
        """``campaign`` or ``replay``."""
        return self.meta.get("kind", "campaign")

    @property
    def done(self) -> pd.DataFrame:
        """The rows of ``runs`` of done runs (index kept)."""
        return self.runs[self.runs["status"] == "done"]

    @property
    def confidence(self) -> float:
        """The confidence level of the worlds' intervals (``runs.confidence`` of the config)."""
        return float(self.config.get("runs", {}).get("confidence", 0.99))

    @property
    def distribution(self) -> Distribution:
        """The quantile of the worlds' intervals (``runs.distribution`` of the config)."""
        return "normal" if self.config.get("runs", {}).get("distribution") == "normal" else "t"

    def run_folder(self, world: str, run: int) -> Path:
        """The absolute folder of run ``run`` of ``world`` (as recorded in the catalog)."""
        rows = self.runs[(self.runs["world"] == world) & (self.runs["run"] == int(run))]
        if rows.empty:
            raise ConfigError(f"{self.folder}: has no run {world}/{int(run)}")
        folder = rows["folder"].iloc[0]
        return self.folder / (folder if isinstance(folder, str) and folder else f"{RUNS_DIR}/{world}/{int(run):03d}")


def _read_only(path: Path) -> sqlite3.Connection:
    """A read-only connection: never creates, never writes (WAL readers may create the shared-memory file)."""
    uri = path.absolute().as_uri()
    try:
        conn = sqlite3.connect(f"{uri}?mode=ro", uri=True, timeout=30.0)
        conn.execute("SELECT 1 FROM sqlite_master LIMIT 1").fetchall()
        return conn
    except sqlite3.OperationalError:
        # a read-only folder where the WAL index cannot be created: nobody can be writing, read it as immutable
        return sqlite3.connect(f"{uri}?immutable=1", uri=True, timeout=30.0)


def _query(path: Path) -> tuple[dict[str, str], list[tuple], list[tuple]]:
    try:
        conn = _read_only(path)
    except sqlite3.Error as exc:
        raise FormatError(path, f"not a readable campaign catalog ({exc})") from None
    try:
        conn.execute("BEGIN")  # one snapshot for the three reads, even while the driver writes
        meta = dict(conn.execute("SELECT key, value FROM meta").fetchall())
        if meta.get("format") != STORE_FORMAT:
            raise FormatError(path, f"expected a campaign catalog of format {STORE_FORMAT}, got {meta.get('format')!r}")
        worlds = conn.execute(_WORLD_SQL).fetchall()
        runs = conn.execute(_RUN_SQL).fetchall()
        conn.execute("COMMIT")
    except sqlite3.Error as exc:
        raise FormatError(path, f"not a readable campaign catalog ({exc})") from None
    finally:
        conn.close()
    return meta, worlds, runs


def _details(text: str | None) -> dict[str, Any]:
    try:
        value = json.loads(text) if text else {}
    except json.JSONDecodeError:
        return {}
    return {str(k): v for k, v in value.items() if not isinstance(v, (dict, list))} if isinstance(value, dict) else {}


def _typed(column: pd.Series) -> pd.Series:
    """A ``details`` column with a nullable dtype when its values are all booleans, integers or numbers."""
    cells = [None if v is None or (isinstance(v, float) and v != v) else v for v in column.tolist()]
    values = [v for v in cells if v is not None]
    if values and all(isinstance(v, bool) for v in values):
        return pd.Series(pd.array(cells, dtype="boolean"), index=column.index)
    if values and all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return pd.Series(pd.array(cells, dtype="Int64"), index=column.index)
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return pd.to_numeric(column, errors="coerce").astype("float64")
    return column


def _runs_frame(rows: list[tuple]) -> pd.DataFrame:
    base = RUN_COLUMNS[:17]
    records, extra_keys = [], []
    for row in rows:
        record = dict(zip(base, row[:17]))
        details = _details(row[17])
        for key in details:
            if key not in extra_keys and key not in RUN_COLUMNS:
                extra_keys.append(key)
        record.update({k: v for k, v in details.items() if k not in RUN_COLUMNS})
        records.append(record)
    runs = pd.DataFrame(records, columns=[*base, *extra_keys])
    for key in extra_keys:
        runs[key] = _typed(runs[key])
    runs["run"] = runs["run"].astype("int64")
    runs["seed"] = runs["seed"].astype("int64")
    runs["attempts"] = runs["attempts"].astype("int64")
    for column in ("eps_t", "eps_r", "mapped", "duration_s", "wall_s"):
        runs[column] = pd.to_numeric(runs[column], errors="coerce").astype("float64")
    runs["relations"] = pd.array(runs["relations"].tolist(), dtype="Int64")
    for column in ("status", "world"):
        runs[column] = runs[column].astype(str)
    for metric, column in (("eps_t", "outlier_t"), ("eps_r", "outlier_r")):
        mask = np.zeros(len(runs), dtype=bool)
        usable = ((runs["status"] == "done") & np.isfinite(runs[metric])).to_numpy()
        for world in runs.loc[usable, "world"].unique():
            here = np.flatnonzero(usable & (runs["world"] == world).to_numpy())
            mask[here] = outlier_mask(runs[metric].to_numpy()[here])
        runs[column] = mask
    return runs[[*RUN_COLUMNS, *extra_keys]].reset_index(drop=True)


def _worlds_frame(rows: list[tuple], runs: pd.DataFrame, config: dict[str, Any]) -> pd.DataFrame:
    worlds = pd.DataFrame(rows, columns=list(_STORE_WORLD_COLUMNS))
    worlds["position"] = worlds["position"].astype("int64")
    worlds["capped"] = worlds["capped"].astype(bool)
    for column in ("runs_target", "runs_needed", "needed_t", "needed_r"):
        worlds[column] = pd.array(worlds[column].tolist(), dtype="Int64")
    # the rule's own figure where the cap cut it (catalogs of earlier versions stored the capped one)
    asked = worlds[["runs_needed", "needed_t", "needed_r"]].max(axis=1, skipna=True).astype("Int64")
    worlds["runs_needed"] = worlds["runs_needed"].where(~worlds["capped"] | worlds["runs_needed"].isna(), asked)
    for column in ("reachable_area", "std_t", "std_r"):
        worlds[column] = pd.to_numeric(worlds[column], errors="coerce").astype("float64")
    for status in ("done", "failed", "running", "pending"):
        counts = runs[runs["status"] == status].groupby("world").size()
        worlds[f"runs_{status}"] = worlds["world"].map(counts).fillna(0).astype("int64")
    settings = config.get("runs", {}) if isinstance(config.get("runs"), dict) else {}
    confidence = float(settings.get("confidence", 0.99))
    distribution = settings.get("distribution", "t")
    done = runs[(runs["status"] == "done") & np.isfinite(runs["eps_t"]) & np.isfinite(runs["eps_r"])]
    table = (
        world_summary(done, confidence=confidence, distribution=distribution)
        if len(done)
        else pd.DataFrame(columns=["world"])
    )
    table = table.drop(columns=["runs", "confidence"], errors="ignore")
    worlds = worlds.merge(table, on="world", how="left")
    for metric in METRICS:
        for stat in _STATS:
            column = f"{metric}_{stat}"
            if column not in worlds:
                worlds[column] = np.nan
            if stat == "outliers":
                worlds[column] = worlds[column].fillna(0).astype("int64")
            else:
                worlds[column] = worlds[column].astype("float64")
    worlds["confidence"] = confidence
    for metric in METRICS:
        shares = metric_shares(done, metric) if len(done) else pd.Series(dtype="float64")
        worlds[f"{metric}_metric_share"] = worlds["world"].map(shares).astype("float64")
    means = (*zip(COST_FIGURES, COST_CSV_COLUMNS), *zip(MAP_QUALITY_FIGURES, MAP_QUALITY_CSV_COLUMNS))
    for name, column in means:
        done_runs = runs[runs["status"] == "done"]
        if name in done_runs.columns:
            figures = pd.to_numeric(done_runs[name], errors="coerce").astype("float64")
            worlds[column] = worlds["world"].map(figures.groupby(done_runs["world"]).mean()).astype("float64")
        else:
            worlds[column] = np.nan
    _add_exploration(worlds, runs)
    return worlds[list(WORLD_COLUMNS)]


def _add_exploration(worlds: pd.DataFrame, runs: pd.DataFrame) -> None:
    """The exploration columns of ``worlds``: each world's done runs through
    :func:`~slamtrials.campaign.explorationsummary.world_exploration`, as summary.csv computes them."""
    done = runs[runs["status"] == "done"]
    names = [name for name in EXPLORATION_FIGURES if name in done.columns]
    found = {}
    if names:
        for world, group in done.groupby("world", sort=False):
            details = [dict(zip(names, values)) for values in group[names].itertuples(index=False, name=None)]
            exploration = world_exploration(details)
            if exploration is not None:
                found[world] = exploration.cells()
    for k, column in enumerate(EXPLORATION_CSV_COLUMNS):
        values = [found[w][k] if w in found else None for w in worlds["world"]]
        if column in _EXPLORATION_COUNTS:
            worlds[column] = pd.array(values, dtype="Int64")
        else:
            worlds[column] = pd.array([np.nan if v is None else v for v in values], dtype="float64")


def load_campaign(path: str | Path) -> CampaignData:
    """Load the campaign in folder ``path`` as DataFrames (see the module docstring), read-only.

    Parameters
    ----------
    path:
        A campaign folder (made by ``slamtrials campaign run`` or ``replay``), finished or still running.

    Returns
    -------
    CampaignData

    Raises
    ------
    FormatError
        ``path`` is not a campaign folder, or its catalog is not a readable campaign catalog.
    """
    folder = Path(path).absolute()
    db = folder / DB_FILE
    if not folder.is_dir():
        raise FormatError(folder, "not a campaign folder (no such directory)")
    if not db.is_file():
        raise FormatError(folder, f"not a campaign folder ({DB_FILE} missing)")
    meta, world_rows, run_rows = _query(db)
    try:
        config = json.loads(meta.pop("config", "") or "{}")
    except json.JSONDecodeError as exc:
        raise FormatError(db, f"the stored config is not valid JSON ({exc.msg})") from None
    runs = _runs_frame(run_rows)
    worlds = _worlds_frame(world_rows, runs, config if isinstance(config, dict) else {})
    return CampaignData(folder, runs, worlds, config if isinstance(config, dict) else {}, meta)


def export_table(
    path: str | Path,
    fmt: Literal["csv", "parquet"] = "csv",
    out: str | Path | None = None,
    *,
    table: Literal["runs", "worlds"] = "runs",
) -> Path:
    """Write a table of the campaign in ``path`` as CSV or Parquet (pyarrow), atomically.

    Parameters
    ----------
    path:
        The campaign folder.
    fmt:
        ``"csv"`` or ``"parquet"``.
    out:
        The file to write; default ``<campaign>/<table>.<fmt>``.
    table:
        ``"runs"`` (one row per run) or ``"worlds"`` (one row per world, with Table I).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ConfigError
        An unknown format or table.
    FormatError
        ``path`` is not a campaign folder.
    """
    if fmt not in FORMATS:
        raise ConfigError(f"format must be one of {', '.join(FORMATS)}, got {fmt!r}")
    if table not in TABLES:
        raise ConfigError(f"table must be one of {', '.join(TABLES)}, got {table!r}")
    data = load_campaign(path)
    frame = data.runs if table == "runs" else data.worlds
    target = Path(out) if out is not None else data.folder / f"{table}.{fmt}"
    if target.is_dir():
        raise ConfigError(f"{target}: is a folder; give the file to write")
    if fmt == "csv":
        text = io.StringIO()
        frame.to_csv(text, index=False, lineterminator="\n")
        return atomic_write_text(target, text.getvalue())
    return atomic_write(target, lambda handle: frame.to_parquet(handle, engine="pyarrow", index=False))
