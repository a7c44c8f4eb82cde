"""The layout of a run folder (DESIGN.md, "Run folder"): every file name in one place.

``RunFolder(path).frames`` is ``path / "frames.npz"``, and so on; nothing else in slamtrials spells
these names.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

__all__ = ["RunFolder"]


@dataclass(frozen=True)
class RunFolder:
    """The files of the run folder at ``path``.

    Attributes
    ----------
    path:
        The folder.
    """

    path: Path

    #: ``run.json``: what produced the run (config, seed, versions, outcome); written last.
    RUN = "run.json"
    #: ``frames.npz``: t, scans, odometry, truth, stalled (and the estimate) arrays.
    FRAMES = "frames.npz"
    #: ``estimate.tum``: the SLAM estimate (TUM format).
    ESTIMATE = "estimate.tum"
    #: ``map.yaml`` + ``map.pgm``: the final SLAM map in ROS map_server form; ``map.png``: its picture.
    MAP = "map.yaml"
    MAP_IMAGE = "map.pgm"
    MAP_PICTURE = "map.png"
    #: ``relations.npz``: the run's relation set (pairs of frames), drawn once; every estimate of the run
    #: is scored on it (:mod:`slamtrials.campaign.relationsetfile`).
    RELATION_SET = "relations.npz"
    #: ``relations.txt`` (Kuemmerle format) and ``errors.npz`` (per-relation errors): what a later
    #: evaluation writes into its ``evaluations/<name>/`` folder.
    RELATIONS = "relations.txt"
    ERRORS = "errors.npz"
    #: ``run.png``: the true and estimated paths on the floor plan.
    PICTURE = "run.png"
    #: ``evaluations/``: one folder per later evaluation (``slamtrials evaluate RUN``), never over the above.
    EVALUATIONS = "evaluations"

    def __init__(self, path: str | Path) -> None:
        object.__setattr__(self, "path", Path(path))

    @property
    def run_json(self) -> Path:
        """``run.json``."""
        return self.path / self.RUN

    @property
    def frames(self) -> Path:
        """``frames.npz``."""
        return self.path / self.FRAMES

    @property
    def estimate(self) -> Path:
        """``estimate.tum``."""
        return self.path / self.ESTIMATE

    @property
    def map(self) -> Path:
        """``map.yaml`` (its image ``map.pgm`` beside it)."""
        return self.path / self.MAP

    @property
    def map_files(self) -> tuple[Path, Path, Path]:
        """``map.yaml``, ``map.pgm`` and ``map.png``."""
        return self.path / self.MAP, self.path / self.MAP_IMAGE, self.path / self.MAP_PICTURE

    @property
    def map_picture(self) -> Path:
        """``map.png``."""
        return self.path / self.MAP_PICTURE

    @property
    def relation_set(self) -> Path:
        """``relations.npz``."""
        return self.path / self.RELATION_SET

    @property
    def relations(self) -> Path:
        """``relations.txt``."""
        return self.path / self.RELATIONS

    @property
    def errors(self) -> Path:
        """``errors.npz``."""
        return self.path / self.ERRORS

    @property
    def picture(self) -> Path:
        """``run.png``."""
        return self.path / self.PICTURE

    @property
    def evaluations(self) -> Path:
        """``evaluations/``, where later evaluations of the run write their relations and errors."""
        return self.path / self.EVALUATIONS

    def new_evaluation(self, name: str) -> Path:
        """A folder ``evaluations/<name>`` that does not exist yet (``<name>-2``, ``-3``, ... if taken); not created."""
        folder = self.evaluations / name
        k = 2
        while folder.exists():
            folder = self.evaluations / f"{name}-{k}"
            k += 1
        return folder

    def is_complete(self) -> bool:
        """Whether ``run.json`` is there (it is written last)."""
        return self.run_json.is_file()
