"""The exception hierarchy of slamtrials.

Every error the library raises on purpose is a :class:`SlamtrialsError`. Messages are one line and name
the file, line or field at fault and what was expected, so the CLI can print them as they are and exit
with status 2.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = [
    "validation_problems",
    "SlamtrialsError",
    "ConfigError",
    "FormatError",
    "WorldError",
    "SimulationError",
    "MetricError",
    "CalibrationError",
    "ProgramError",
]


class SlamtrialsError(Exception):
    """Base class of every error slamtrials raises on purpose."""


class ConfigError(SlamtrialsError):
    """A configuration value is missing, malformed or out of its allowed range."""


class FormatError(SlamtrialsError):
    """A file does not follow the format it claims to be in.

    Parameters
    ----------
    path:
        The file at fault.
    problem:
        What is wrong and what was expected.
    line:
        1-based line number, for text formats.
    offset:
        Byte offset, for binary formats.
    """

    def __init__(self, path: str | Path, problem: str, *, line: int | None = None, offset: int | None = None):
        self.path = Path(path)
        self.problem = problem
        self.line = line
        self.offset = offset
        where = str(self.path)
        if line is not None:
            where += f":{line}"
        elif offset is not None:
            where += f" (byte {offset})"
        super().__init__(f"{where}: {problem}")


class WorldError(SlamtrialsError):
    """A floor plan cannot be used as a world (no free space, bad resolution, unknown name, ...)."""


class SimulationError(SlamtrialsError):
    """The simulator was asked for something it cannot do (e.g. a start pose inside a wall)."""


class CalibrationError(SlamtrialsError):
    """A log cannot be calibrated from (too short, no odometry, too few usable beams or windows)."""


class ProgramError(SlamtrialsError):
    """An external SLAM program failed on a recording: it exited with an error, ran out of time, wrote
    nothing, or wrote a trajectory that cannot be read or mapped onto the run.

    Parameters
    ----------
    problem:
        What went wrong, one line (with the last lines of the program's stderr, when it wrote any).
    exit_code:
        The program's exit status (None when it was killed at its timeout or did not fail by status).
    stderr_tail:
        The last lines of its stderr.
    """

    def __init__(self, problem: str, *, exit_code: int | None = None, stderr_tail: tuple[str, ...] = ()):
        self.problem = problem
        self.exit_code = exit_code
        self.stderr_tail = tuple(stderr_tail)
        super().__init__(problem)


class MetricError(SlamtrialsError):
    """Data handed to the metric cannot be evaluated (empty or unordered trajectory, unmatched relation, ...).

    The metric is pure and knows no files, so it names the item at fault by position; the caller that
    read the data maps that position to a file and line.

    Parameters
    ----------
    problem:
        What is wrong and what was expected.
    what:
        Which input is at fault: ``"relations"``, ``"estimate"``, ``"odometry"``, ``"truth"``, ... .
    index:
        0-based index of the relation or pose at fault within that input.
    """

    def __init__(self, problem: str, *, what: str | None = None, index: int | None = None):
        self.problem = problem
        self.what = what
        self.index = index
        super().__init__(problem)


def validation_problems(exc: Any) -> str:
    """A pydantic ``ValidationError`` as one line: ``field.path: message (got value)``, joined by ``; ``."""
    problems = []
    for err in exc.errors():
        field = ".".join(str(p) for p in err["loc"]) or "<root>"
        if err.get("type") == "missing":
            problems.append(f"{field}: required setting is missing")
            continue
        shown = repr(err.get("input"))
        if len(shown) > 80:
            shown = shown[:77] + "..."
        problems.append(f"{field}: {err['msg'].removeprefix('Value error, ')} (got {shown})")
    return "; ".join(problems)
