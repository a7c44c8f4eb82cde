"""Reading YAML configuration files into plain dicts, with errors that name the file and line."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from slamtrials.errors import FormatError

__all__ = ["read_yaml_mapping"]


def read_yaml_mapping(path: str | Path) -> dict[str, Any]:
    """Parse ``path`` as YAML whose top level is a mapping (an empty file gives ``{}``).

    Raises
    ------
    FormatError
        The file is missing, not UTF-8, not YAML (names the line), or its top level is not a mapping.
    """
    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FormatError(path, "no such file") from None
    except UnicodeDecodeError:
        raise FormatError(path, "not UTF-8 text") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise FormatError(
            path, f"not valid YAML ({getattr(exc, 'problem', exc)})", line=mark.line + 1 if mark else None
        ) from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise FormatError(path, f"expected a mapping of settings at the top level, got {type(data).__name__}", line=1)
    return data
