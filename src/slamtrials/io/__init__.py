"""File formats for runs and trajectories: the run folder (and, later, ROS bags, CARMEN logs, TUM, relations)."""

from slamtrials.io.runfolder import read_run, write_run

__all__ = ["read_run", "write_run"]
