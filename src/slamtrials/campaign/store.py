"""The campaign store: ``<folder>/campaign.sqlite`` (catalog of worlds and runs) and ``config.yaml``.

Tables (SQLite, WAL journal, ``synchronous=FULL``, one transaction per state change):

``meta(key, value)``
    ``format``, ``kind`` (``campaign`` or ``replay``), ``config`` (JSON of the :class:`CampaignConfig`),
    ``config_hash`` (:meth:`CampaignConfig.digest`, ``output`` left out), ``slamtrials_version``,
    ``created`` (ISO time, UTC).
``worlds``
    one row per world: ``name`` (campaign name, the run folder name), ``ref`` (catalog name or absolute
    file), ``position``, ``reachable_area`` (m^2), ``status`` (pending, running, done, capped, failed,
    short), the last decision of the run-count rule (``runs_target``; ``runs_needed``, the runs the rule
    asked for before the cap; ``needed_t``, ``needed_r``, ``std_t`` m, ``std_r`` rad, ``capped``: the cap,
    ``runs_target``, cut ``runs_needed``), ``note``, ``updated``.
``runs``
    one row per submitted run, primary key ``(world, idx)``: ``seed``, ``status`` (running, done,
    failed, or pending: to be submitted again after a resume), ``attempts`` (submissions by a driver),
    ``eps_t`` (m), ``eps_r`` (rad), ``relations``, ``termination``, ``mapped_fraction``,
    ``sim_duration`` (s), ``wall_time`` (s), ``worker``, ``error``, ``folder`` (relative to the campaign
    folder), ``details`` (JSON), ``submitted``, ``finished``.

The database is created complete under a temporary name and renamed into place, so a folder either
holds a whole catalog or none. Only the driver process writes it. A run is ``done`` only after its run
folder was renamed into place (:mod:`slamtrials.campaign.runfiles`), so a crash at any moment leaves at
worst a run folder without a ``done`` row, which the next driver deletes and runs again
(:func:`slamtrials.campaign.runfiles.remove_unrecorded`).
"""

from __future__ import annotations

import json
import os
import sqlite3
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from slamtrials.__about__ import __version__
from slamtrials.atomicfile import atomic_write_text
from slamtrials.campaign.config import CampaignConfig
from slamtrials.campaign.results import RunDone
from slamtrials.errors import ConfigError, FormatError

__all__ = [
    "CampaignStore",
    "WorldInfo",
    "WorldRow",
    "RunRow",
    "STORE_FORMAT",
    "DB_FILE",
    "CONFIG_FILE",
    "RUNS_DIR",
    "is_campaign",
    "check_new_folder",
    "config_differences",
    "differing_fields",
    "ABSENT",
]

STORE_FORMAT = "slamtrials-campaign/1"
DB_FILE = "campaign.sqlite"
CONFIG_FILE = "config.yaml"
RUNS_DIR = "runs"

_SCHEMA = """
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE worlds (
    name TEXT PRIMARY KEY, ref TEXT NOT NULL, position INTEGER NOT NULL, reachable_area REAL,
    status TEXT NOT NULL DEFAULT 'pending', runs_target INTEGER, runs_needed INTEGER, needed_t INTEGER,
    needed_r INTEGER, std_t REAL, std_r REAL, capped INTEGER NOT NULL DEFAULT 0, note TEXT, updated TEXT);
CREATE TABLE runs (
    world TEXT NOT NULL REFERENCES worlds(name), idx INTEGER NOT NULL, seed INTEGER NOT NULL,
    status TEXT NOT NULL, attempts INTEGER NOT NULL DEFAULT 0, eps_t REAL, eps_r REAL, relations INTEGER,
    termination TEXT, mapped_fraction REAL, sim_duration REAL, wall_time REAL, worker TEXT, error TEXT,
    folder TEXT, details TEXT, submitted TEXT, finished TEXT, PRIMARY KEY (world, idx));
"""


def _now() -> str:
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())


@dataclass(frozen=True)
class WorldInfo:
    """A world of a campaign as the driver resolved it: ``name`` (unique), ``ref`` (what loads it), area (m^2)."""

    name: str
    ref: str
    position: int
    reachable_area: float


@dataclass(frozen=True)
class WorldRow:
    """A row of the ``worlds`` table (see the module docstring for the columns)."""

    name: str
    ref: str
    position: int
    reachable_area: float | None
    status: str
    runs_target: int | None
    runs_needed: int | None
    needed_t: int | None
    needed_r: int | None
    std_t: float | None
    std_r: float | None
    capped: int
    note: str | None
    updated: str | None


def _asked_before_cap(row: WorldRow) -> WorldRow:
    """``row`` with ``runs_needed`` the rule's own figure: catalogs written before it was stored held the
    capped figure, which ``needed_t`` and ``needed_r`` still tell apart."""
    if row.capped and row.runs_needed is not None:
        asked = max(row.runs_needed, row.needed_t or 0, row.needed_r or 0)
        if asked != row.runs_needed:
            return replace(row, runs_needed=asked)
    return row


@dataclass(frozen=True)
class RunRow:
    """A row of the ``runs`` table (see the module docstring for the columns)."""

    world: str
    idx: int
    seed: int
    status: str
    attempts: int
    eps_t: float | None
    eps_r: float | None
    relations: int | None
    termination: str | None
    mapped_fraction: float | None
    sim_duration: float | None
    wall_time: float | None
    worker: str | None
    error: str | None
    folder: str | None
    details: str | None
    submitted: str | None
    finished: str | None


_WORLD_COLUMNS = ", ".join(f.name for f in fields(WorldRow))
_RUN_COLUMNS = ", ".join(f.name for f in fields(RunRow))


def is_campaign(folder: str | Path) -> bool:
    """Whether ``folder`` holds a campaign catalog."""
    return (Path(folder) / DB_FILE).is_file()


def check_new_folder(folder: str | Path) -> None:
    """Raise :class:`ConfigError` unless a new campaign can be created in ``folder`` (absent or empty)."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ConfigError(f"{folder}: exists and is not a folder; choose another campaign folder")
    if folder.is_dir():
        others = [p.name for p in folder.iterdir() if not p.name.startswith(f".{DB_FILE}")]
        if others:
            raise ConfigError(
                f"{folder}: is not empty and holds no campaign ({DB_FILE} missing; found {', '.join(sorted(others)[:3])}); "
                "choose a new or empty folder"
            )


def _flatten(value: Any, prefix: str = "") -> dict[str, Any]:
    if isinstance(value, dict):
        out: dict[str, Any] = {}
        for key, item in value.items():
            out.update(_flatten(item, f"{prefix}.{key}" if prefix else str(key)))
        return out
    return {prefix: value}


#: What :func:`differing_fields` gives for a field that one of the two dicts lacks.
ABSENT = "<absent>"


def differing_fields(first: dict[str, Any], second: dict[str, Any]) -> list[tuple[str, Any, Any]]:
    """``(dotted.field, first value, second value)`` for every leaf that differs, sorted by field name.

    Nested dicts are walked (``slam.params.particles``); any other value (lists included) is a leaf. A
    field that only one side has gives :data:`ABSENT` for the other.
    """
    a, b = _flatten(first), _flatten(second)
    keys = [k for k in sorted(set(a) | set(b)) if a.get(k, ABSENT) != b.get(k, ABSENT)]
    return [(k, a.get(k, ABSENT), b.get(k, ABSENT)) for k in keys]


def config_differences(stored: dict[str, Any], given: dict[str, Any], limit: int = 3) -> str:
    """``field: stored X, given Y`` for the first ``limit`` differing fields of two config dicts."""
    keys = differing_fields(stored, given)
    parts = [f"{k}: stored {a!r}, given {b!r}" for k, a, b in keys[:limit]]
    if len(keys) > limit:
        parts.append(f"and {len(keys) - limit} more")
    return "; ".join(parts)


def _connect(path: Path) -> sqlite3.Connection:
    conn = sqlite3.connect(path, isolation_level=None, timeout=30.0)
    conn.execute("PRAGMA journal_mode=WAL")
    conn.execute("PRAGMA synchronous=FULL")
    conn.execute("PRAGMA foreign_keys=ON")
    return conn


class CampaignStore:
    """The SQLite catalog of one campaign folder. Create with :meth:`create`, open with :meth:`open`."""

    def __init__(self, folder: Path, conn: sqlite3.Connection):
        self.folder = folder
        self._conn = conn

    # ------------------------------------------------------------------ creating and opening

    @classmethod
    def create(
        cls, folder: str | Path, config: CampaignConfig, worlds: Sequence[WorldInfo], *, kind: str = "campaign"
    ) -> CampaignStore:
        """Create the catalog of a new campaign in ``folder`` (created if needed; must hold no other files).

        Raises
        ------
        ConfigError
            ``folder`` exists and holds something other than a campaign (nothing is touched).
        """
        folder = Path(folder)
        check_new_folder(folder)
        if folder.is_dir():
            for leftover in folder.iterdir():  # a creation interrupted before the rename
                leftover.unlink()
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f".{DB_FILE}.{os.getpid()}.tmp"
        conn = sqlite3.connect(tmp, isolation_level=None)
        try:
            conn.executescript(_SCHEMA)
            conn.execute("BEGIN")
            meta = {
                "format": STORE_FORMAT,
                "kind": kind,
                "config": json.dumps(config.model_dump(mode="json"), sort_keys=True),
                "config_hash": config.digest(),
                "slamtrials_version": __version__,
                "created": _now(),
            }
            conn.executemany("INSERT INTO meta VALUES (?, ?)", list(meta.items()))
            conn.executemany(
                "INSERT INTO worlds (name, ref, position, reachable_area, updated) VALUES (?, ?, ?, ?, ?)",
                [(w.name, w.ref, w.position, w.reachable_area, _now()) for w in worlds],
            )
            conn.execute("COMMIT")
            conn.execute("PRAGMA journal_mode=WAL")
        finally:
            conn.close()
        with open(tmp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.replace(tmp, folder / DB_FILE)
        store = cls(folder, _connect(folder / DB_FILE))
        store.write_config_file()
        return store

    @classmethod
    def open(cls, folder: str | Path) -> CampaignStore:
        """Open the catalog of an existing campaign.

        Raises
        ------
        ConfigError
            ``folder`` holds no campaign.
        FormatError
            The catalog is not a slamtrials campaign of a known format.
        """
        folder = Path(folder)
        path = folder / DB_FILE
        if not path.is_file():
            raise ConfigError(f"{folder}: not a campaign folder ({DB_FILE} missing)")
        try:
            conn = _connect(path)
            row = conn.execute("SELECT value FROM meta WHERE key = 'format'").fetchone()
        except sqlite3.DatabaseError as exc:
            raise FormatError(path, f"not a readable campaign catalog ({exc})") from None
        if row is None or row[0] != STORE_FORMAT:
            conn.close()
            raise FormatError(
                path, f"expected a campaign catalog of format {STORE_FORMAT}, got {row[0] if row else None!r}"
            )
        return cls(folder, conn)

    def close(self) -> None:
        """Close the database connection."""
        self._conn.close()

    def __enter__(self) -> CampaignStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        self._conn.execute("BEGIN IMMEDIATE")
        try:
            yield self._conn
        except BaseException:
            self._conn.execute("ROLLBACK")
            raise
        self._conn.execute("COMMIT")

    # ------------------------------------------------------------------ reading

    def meta(self, key: str) -> str | None:
        """A value of the ``meta`` table, or None."""
        row = self._conn.execute("SELECT value FROM meta WHERE key = ?", (key,)).fetchone()
        return None if row is None else row[0]

    @property
    def kind(self) -> str:
        """``campaign`` or ``replay``."""
        return self.meta("kind") or "campaign"

    def config(self) -> CampaignConfig:
        """The stored campaign config."""
        return CampaignConfig.from_stored(json.loads(self.meta("config") or "{}"))

    def check_config(self, config: CampaignConfig) -> None:
        """Raise :class:`ConfigError` (touching nothing) when ``config`` is not the stored campaign's."""
        if self.meta("config_hash") == config.digest():
            return
        stored = json.loads(self.meta("config") or "{}")
        stored.pop("output", None)
        if self._stored_by_earlier_version_as(stored, config):
            return
        diff = config_differences(stored, config.identity())
        raise ConfigError(
            f"{self.folder}: holds a campaign with a different config ({diff}); "
            "resume it with its own config or choose another folder"
        )

    @staticmethod
    def _stored_by_earlier_version_as(stored: dict[str, Any], config: CampaignConfig) -> bool:
        """Whether a config stored by an earlier version (other fields, other digest) is ``config``."""
        try:
            return CampaignConfig.from_stored(stored).identity() == config.identity()
        except ValidationError:
            return False

    def worlds(self) -> list[WorldRow]:
        """The worlds, in campaign order."""
        rows = self._conn.execute(f"SELECT {_WORLD_COLUMNS} FROM worlds ORDER BY position").fetchall()
        return [_asked_before_cap(WorldRow(*row)) for row in rows]

    def world_infos(self) -> list[WorldInfo]:
        """The worlds as :class:`WorldInfo`, in campaign order."""
        return [WorldInfo(w.name, w.ref, w.position, w.reachable_area or 0.0) for w in self.worlds()]

    def runs(self, world: str | None = None) -> list[RunRow]:
        """The run rows (of one world), ordered by world position and index."""
        sql = f"SELECT {', '.join('r.' + c.strip() for c in _RUN_COLUMNS.split(','))} FROM runs r JOIN worlds w ON w.name = r.world"
        args: tuple = ()
        if world is not None:
            sql += " WHERE r.world = ?"
            args = (world,)
        rows = self._conn.execute(sql + " ORDER BY w.position, r.idx", args).fetchall()
        return [RunRow(*row) for row in rows]

    def done_results(self, world: str) -> dict[int, tuple[float, float]]:
        """``{index: (eps_t, eps_r)}`` of the world's done runs (m, rad)."""
        rows = self._conn.execute("SELECT idx, eps_t, eps_r FROM runs WHERE world = ? AND status = 'done'", (world,))
        return {int(i): (float(t), float(r)) for i, t, r in rows}

    def done_runs(self) -> set[tuple[str, int]]:
        """``(world, index)`` of every done run."""
        return {(w, int(i)) for w, i in self._conn.execute("SELECT world, idx FROM runs WHERE status = 'done'")}

    # ------------------------------------------------------------------ writing

    def write_config_file(self) -> Path:
        """Write ``config.yaml`` (the stored config, commented) atomically."""
        from slamtrials.campaign.dump import dump_config_yaml

        header = (
            f"# slamtrials {self.kind}: the resolved config of this campaign folder (also in {DB_FILE}).\n"
            f"# Resume with: slamtrials campaign {'run' if self.kind == 'campaign' else 'replay'} ... --out {self.folder}\n"
        )
        return atomic_write_text(
            self.folder / CONFIG_FILE, dump_config_yaml(self.config(), header=header, resolved=True)
        )

    def prepare_resume(self) -> int:
        """Put back what an interrupted driver left unfinished: runs ``running`` or ``failed`` become
        ``pending`` (to be submitted again) and failed worlds ``pending``. Returns the runs put back."""
        with self._transaction() as conn:
            count = conn.execute("UPDATE runs SET status = 'pending' WHERE status IN ('running', 'failed')").rowcount
            conn.execute(
                "UPDATE worlds SET status = 'pending', note = NULL, updated = ? WHERE status IN ('running', 'failed')",
                (_now(),),
            )
        return count

    def mark_submitted(self, world: str, runs: Sequence[tuple[int, int]]) -> None:
        """Record runs ``(index, seed)`` of ``world`` as submitted (status ``running``)."""
        now = _now()
        with self._transaction() as conn:
            for index, seed in runs:
                conn.execute(
                    "INSERT INTO runs (world, idx, seed, status, attempts, submitted) VALUES (?, ?, ?, 'running', 1, ?) "
                    "ON CONFLICT (world, idx) DO UPDATE SET status = 'running', attempts = attempts + 1, submitted = excluded.submitted, "
                    "error = NULL",
                    (world, index, seed, now),
                )
            conn.execute(
                "UPDATE worlds SET status = 'running', updated = ? WHERE name = ? AND status = 'pending'", (now, world)
            )

    def record_done(self, world: str, index: int, result: RunDone) -> None:
        """Mark a run done with its outcome (what :func:`slamtrials.campaign.task.run_one` returned)."""
        with self._transaction() as conn:
            conn.execute(
                "UPDATE runs SET status = 'done', eps_t = ?, eps_r = ?, relations = ?, termination = ?, mapped_fraction = ?, "
                "sim_duration = ?, wall_time = ?, worker = ?, error = NULL, folder = ?, details = ?, finished = ? WHERE world = ? AND idx = ?",
                (
                    result.eps_t,
                    result.eps_r,
                    result.relations,
                    result.termination,
                    result.mapped_fraction,
                    result.sim_duration,
                    result.wall_time,
                    result.worker,
                    result.folder,
                    json.dumps(asdict(result.details), sort_keys=True),
                    _now(),
                    world,
                    index,
                ),
            )

    def record_failed(self, world: str, index: int, error: str, *, worker: str | None = None) -> None:
        """Mark a run failed (with its error text) and its world failed."""
        now = _now()
        with self._transaction() as conn:
            conn.execute(
                "UPDATE runs SET status = 'failed', error = ?, worker = ?, finished = ? WHERE world = ? AND idx = ?",
                (error, worker, now, world, index),
            )
            conn.execute(
                "UPDATE worlds SET status = 'failed', note = ?, updated = ? WHERE name = ?",
                (f"run {index} failed: {error}", now, world),
            )

    def record_world(
        self, world: str, *, status: str, target: int | None, decision: Any = None, note: str | None = None
    ) -> None:
        """Store a world's status and the last decision of the run-count rule (a :class:`RunCount`)."""
        d = decision
        values = (
            status,
            target,
            getattr(d, "asked", getattr(d, "needed", None)),
            getattr(d, "needed_t", None),
            getattr(d, "needed_r", None),
            _finite(getattr(d, "std_t", None)),
            _finite(getattr(d, "std_r", None)),
            int(bool(getattr(d, "capped", False))),
            note,
            _now(),
            world,
        )
        with self._transaction() as conn:
            conn.execute(
                "UPDATE worlds SET status = ?, runs_target = ?, runs_needed = ?, needed_t = ?, needed_r = ?, std_t = ?, "
                "std_r = ?, capped = ?, note = ?, updated = ? WHERE name = ?",
                values,
            )


def _finite(value: float | None) -> float | None:
    if value is None or value != value:  # NaN
        return None
    return float(value)
