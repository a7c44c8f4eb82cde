"""File formats: run folders, CARMEN logs, TUM trajectories, relations files, ROS bags and map files."""

from slamtrials.io.carmen import read_carmen, write_carmen
from slamtrials.io.relations import read_relations, write_relations
from slamtrials.io.runfolder import read_run, write_run
from slamtrials.io.tum import read_tum, write_tum

__all__ = [
    "read_run",
    "write_run",
    "read_carmen",
    "write_carmen",
    "read_tum",
    "write_tum",
    "read_relations",
    "write_relations",
]
