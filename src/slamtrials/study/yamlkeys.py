"""Reading a study config's YAML with every key once per mapping.

PyYAML keeps the last of two equal keys of a mapping without a word, which would turn two axes on the
same key (``sim.laser.max_range`` written twice under ``axes``) into one axis silently;
:func:`read_unique_yaml` refuses the file instead, naming the key and both lines.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from slamtrials.errors import FormatError
from slamtrials.io.yamlfile import read_yaml_mapping

__all__ = ["read_unique_yaml", "DuplicateKeyError"]


class DuplicateKeyError(yaml.YAMLError):
    """A key written twice in one YAML mapping (``key``, 1-based ``lines``)."""

    def __init__(self, key: Any, lines: tuple[int, int]):
        super().__init__(f"key {key} given twice (lines {lines[0]} and {lines[1]})")
        self.key = key
        self.lines = lines


class _UniqueKeyLoader(yaml.SafeLoader):
    """A safe loader whose mappings refuse a key given twice."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            try:
                if key in seen:
                    raise DuplicateKeyError(key, (seen[key], line))
            except TypeError:  # an unhashable key: the base loader says so
                break
            seen[key] = line
        return super().construct_mapping(node, deep=deep)


def read_unique_yaml(path: str | Path) -> dict[str, Any]:
    """The YAML mapping of ``path`` (as :func:`slamtrials.io.yamlfile.read_yaml_mapping` reads it), with
    no key twice in any mapping.

    Raises
    ------
    FormatError
        What ``read_yaml_mapping`` raises, or a key given twice (naming it and its two lines).
    """
    path = Path(path)
    data = read_yaml_mapping(path)  # missing file, not UTF-8, not YAML, not a mapping
    try:
        yaml.load(path.read_text(encoding="utf-8"), Loader=_UniqueKeyLoader)  # noqa: S506 (a safe loader)
    except DuplicateKeyError as exc:
        raise FormatError(path, f"{exc}: two axes or settings on the same key", line=exc.lines[1]) from None
    return data
