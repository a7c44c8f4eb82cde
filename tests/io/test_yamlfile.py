"""YAML settings files: mappings read as dicts; everything else a FormatError naming file and line."""

from __future__ import annotations

import pytest

from slamtrials.errors import FormatError
from slamtrials.io.yamlfile import read_yaml_mapping


def test_reads_a_mapping_and_an_empty_file(tmp_path):
    (tmp_path / "a.yaml").write_text("laser:\n  max_range: 20\n")
    (tmp_path / "b.yaml").write_text("# nothing\n")
    assert read_yaml_mapping(tmp_path / "a.yaml") == {"laser": {"max_range": 20}}
    assert read_yaml_mapping(tmp_path / "b.yaml") == {}


@pytest.mark.parametrize(("text", "line"), [("a: [1, 2\nb: 3\n", None), ("- 1\n- 2\n", 1), ("a: 1\n  b: 2\n", 2)])
def test_bad_files_name_the_file(tmp_path, text, line):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(FormatError) as info:
        read_yaml_mapping(path)
    assert "bad.yaml" in str(info.value)
    if line is not None:
        assert info.value.line == line


def test_missing_file(tmp_path):
    with pytest.raises(FormatError, match="no such file"):
        read_yaml_mapping(tmp_path / "nope.yaml")
