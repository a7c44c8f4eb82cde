"""Helpers shared by the line-oriented text readers (CARMEN logs, TUM trajectories, relations files).

Every helper raises :class:`~slamtrials.errors.FormatError` naming the file and the 1-based line, so the
readers built on them let no other exception escape on bad input.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import FormatError
from slamtrials.io.compressed import read_maybe_compressed

__all__ = [
    "read_lines",
    "data_lines",
    "parse_floats",
    "parse_int",
    "last_line",
    "first_bad_row",
    "float_text",
    "read_number_table",
]


def read_lines(path: Path) -> list[str]:
    """Read ``path`` as UTF-8 text and split it at ``\\n`` (a trailing ``\\r`` is left to ``str.split``).

    A gzip- or bzip2-compressed file is decompressed first (recognised by its first bytes; see
    :mod:`slamtrials.io.compressed`); line numbers in messages are those of the decompressed text.

    Raises
    ------
    FormatError
        The file is missing or unreadable, its compressed stream is corrupt, or it is not UTF-8 (the
        message gives the line and byte offset).
    """
    data = read_maybe_compressed(path)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise FormatError(
            path, f"not UTF-8 text (byte {exc.start}: {data[exc.start : exc.start + 1]!r})", line=line
        ) from None
    return text.split("\n")


def last_line(lines: Sequence[str]) -> int:
    """1-based number of the last line of a file split by :func:`read_lines` (1 for an empty file)."""
    n = len(lines) - (1 if lines and lines[-1] == "" else 0)
    return max(n, 1)


def data_lines(lines: Sequence[str]) -> Iterator[tuple[int, list[str]]]:
    """Yield ``(line number, whitespace-separated tokens)`` of every line that is neither blank nor a
    ``#`` comment (a line whose first token starts with ``#``)."""
    for number, line in enumerate(lines, 1):
        tokens = line.split()
        if tokens and not tokens[0].startswith("#"):
            yield number, tokens


def _bad_token(tokens: Sequence[str]) -> int:
    for i, token in enumerate(tokens):
        try:
            float(token)
        except ValueError:
            return i
    return -1


def parse_floats(
    path: Path, line: int, tokens: Sequence[str], first_field: int, what: str | Sequence[str]
) -> list[float]:
    """Convert ``tokens`` to floats; ``first_field`` is the 1-based field number of ``tokens[0]`` on the line
    and ``what`` describes the tokens for error messages (one description, or one name per token).

    NaN and infinities are returned as they are (callers check finiteness on the stacked arrays).

    Raises
    ------
    FormatError
        A token is not a number; the message names the field and the token.
    """
    try:
        return list(map(float, tokens))
    except ValueError:
        i = _bad_token(tokens)
        name = what if isinstance(what, str) else what[i]
        raise FormatError(
            path, f"field {first_field + i} ({name}) is not a number: {tokens[i][:40]!r}", line=line
        ) from None


def parse_int(path: Path, line: int, token: str, field: int, what: str, minimum: int = 0) -> int:
    """Parse one integer field, at least ``minimum``; FormatError naming the field otherwise."""
    try:
        value = int(token)
    except ValueError:
        raise FormatError(path, f"field {field} ({what}) must be an integer, got {token[:40]!r}", line=line) from None
    if value < minimum:
        raise FormatError(path, f"field {field} ({what}) must be >= {minimum}, got {value}", line=line)
    return value


def first_bad_row(bad: NDArray[np.bool_]) -> tuple[int, int] | None:
    """Row and column of the first True in a 2-D mask (row-major order), or None if there is none."""
    rows = np.flatnonzero(bad.any(axis=1))
    if rows.size == 0:
        return None
    row = int(rows[0])
    return row, int(np.flatnonzero(bad[row])[0])


def float_text(value: float) -> str:
    """The shortest text that reads back as exactly ``value`` (Python's ``repr`` of a float)."""
    return repr(float(value))


def read_number_table(path: Path, fields: Sequence[str], nothing: str) -> tuple[NDArray[np.float64], list[int]]:
    """Read a text file of rows of ``len(fields)`` finite numbers (comments and blank lines skipped).

    Parameters
    ----------
    path:
        The file.
    fields:
        Names of the columns, for messages (e.g. ``("t", "x", ...)``).
    nothing:
        What the file holds, for the message when it has no rows (e.g. ``"poses"``).

    Returns
    -------
    values:
        float64 ``[N, len(fields)]``.
    line_numbers:
        1-based line of each row, for messages about rows found bad later.

    Raises
    ------
    FormatError
        Naming the file and line: a row with another number of fields, a field that is not a finite
        number, or no rows at all.
    """
    layout = " ".join(fields)
    lines = read_lines(path)
    rows: list[list[float]] = []
    numbers: list[int] = []
    for number, tokens in data_lines(lines):
        if len(tokens) != len(fields):
            raise FormatError(path, f"expected {len(fields)} fields '{layout}', got {len(tokens)}", line=number)
        rows.append(parse_floats(path, number, tokens, 1, fields))
        numbers.append(number)
    if not rows:
        raise FormatError(path, f"no {nothing}: expected lines '{layout}'", line=last_line(lines))
    values = np.array(rows, dtype=np.float64)
    bad = first_bad_row(~np.isfinite(values))
    if bad is not None:
        row, col = bad
        raise FormatError(path, f"field {col + 1} ({fields[col]}) is not finite: {values[row, col]}", line=numbers[row])
    return values, numbers
