"""What every section of a campaign's report reads: :class:`CampaignView`, the campaign loaded once, its
finished runs and the worlds in the order of Table I."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from slamtrials.record import RunRecord
from slamtrials.report.load import CampaignData

__all__ = ["CampaignView", "finished_runs"]


def finished_runs(data: CampaignData) -> pd.DataFrame:
    """The done runs of ``data`` whose ``eps_t`` (m) and ``eps_r`` (rad) are both finite, one row per run in
    the catalog's order, indexed from 0."""
    done = data.done
    return done[np.isfinite(done["eps_t"]) & np.isfinite(done["eps_r"])].reset_index(drop=True)


@dataclass(frozen=True, eq=False)
class CampaignView:
    """A campaign as the sections of its report read it.

    Attributes
    ----------
    data:
        The campaign folder's catalog (:func:`slamtrials.report.load.load_campaign`).
    done:
        Its finished runs (:func:`finished_runs`): one row per run, the columns of ``data.runs``.
    worlds:
        The worlds that have finished runs, in the order of Table I (the campaign's order); every figure
        and table of the page keeps it.
    """

    data: CampaignData
    done: pd.DataFrame
    worlds: list[str]

    @classmethod
    def of(cls, data: CampaignData) -> CampaignView:
        """The view of ``data``: its finished runs and their worlds in the campaign's order."""
        done = finished_runs(data)
        present = set(done["world"].astype(str))
        return cls(data, done, [str(w) for w in data.worlds["world"] if str(w) in present])

    def read_record(self, world: str, run: int) -> RunRecord:
        """The recorded run ``run`` of ``world`` (its run folder: frames, estimate, map).

        Raises
        ------
        SlamtrialsError
            The catalog has no such run, or its folder cannot be read.
        """
        from slamtrials.io.runfolder import read_run

        return read_run(self.data.run_folder(world, run))
