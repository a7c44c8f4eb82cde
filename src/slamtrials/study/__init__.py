"""Studies: campaigns over a grid of settings, compared cell by cell.

A study names a base campaign config and axes (any config key and its values) and named combinations
(:mod:`~slamtrials.study.config`); every cell is a campaign (:mod:`~slamtrials.study.cells`) in its own
folder under the study folder (:mod:`~slamtrials.study.folder`). The cells of a world share their seeds,
so cells are compared run by run. :func:`run_study` runs every cell together on one Dask client,
longest runs first (:mod:`~slamtrials.study.run`); :func:`study_status` reads the progress;
:func:`build_study_report` writes the study page (:mod:`~slamtrials.study.report`).
"""

from __future__ import annotations

from slamtrials.study.cells import Cell, expand_cells
from slamtrials.study.config import StudyConfig
from slamtrials.study.run import StudyResult, run_study
from slamtrials.study.status import StudyStatus, study_status

__all__ = ["StudyConfig", "Cell", "expand_cells", "run_study", "StudyResult", "study_status", "StudyStatus"]
