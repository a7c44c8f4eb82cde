"""Waypoint files for scripted drives.

A YAML file with a ``waypoints`` list of ``[x, y]`` pairs in metres in the world frame::

    # a drive through the corridor
    waypoints:
      - [1.0, 2.0]
      - [6.5, 2.0]
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml
from numpy.typing import NDArray

from slamtrials.errors import FormatError

__all__ = ["read_waypoints"]


def read_waypoints(path: str | Path) -> NDArray[np.float64]:
    """Read a waypoint file; returns float64 ``[N, 2]`` (m, world frame), N >= 1.

    Raises
    ------
    FormatError
        Not YAML, no ``waypoints`` list, or an entry that is not two finite numbers (names the line).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
        root = yaml.compose(text)
    except UnicodeDecodeError:
        raise FormatError(path, "not UTF-8 text") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise FormatError(
            path, f"not valid YAML ({getattr(exc, 'problem', exc)})", line=mark.line + 1 if mark else None
        ) from None
    if not isinstance(root, yaml.MappingNode):
        raise FormatError(path, "expected a mapping with a 'waypoints' list of [x, y] pairs (metres)", line=1)
    node = next((value for key, value in root.value if key.value == "waypoints"), None)
    if not isinstance(node, yaml.SequenceNode) or not node.value:
        raise FormatError(
            path, "expected a non-empty 'waypoints' list of [x, y] pairs (metres)", line=root.start_mark.line + 1
        )
    points = []
    for item in node.value:
        line = item.start_mark.line + 1
        if not isinstance(item, yaml.SequenceNode) or len(item.value) != 2:
            raise FormatError(path, "waypoint must be a pair [x, y] in metres", line=line)
        try:
            xy = [float(yaml.safe_load(yaml.serialize(v))) for v in item.value]
        except (TypeError, ValueError):
            raise FormatError(path, "waypoint coordinates must be numbers (metres)", line=line) from None
        if not np.all(np.isfinite(xy)):
            raise FormatError(path, "waypoint coordinates must be finite", line=line)
        points.append(xy)
    return np.asarray(points, dtype=np.float64)
