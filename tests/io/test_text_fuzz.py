"""Fuzzing the text readers (CARMEN, TUM, relations): whatever the bytes, the only exception that escapes
is a FormatError naming the file and a line (or byte offset) inside it; whatever reads is sane."""

from __future__ import annotations

import bz2
import gzip
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from slamtrials.errors import FormatError
from slamtrials.io.carmen import CarmenLog, read_carmen
from slamtrials.io.carmen_read import TOLERATED
from slamtrials.io.compressed import read_maybe_compressed
from slamtrials.io.relations import read_relations
from slamtrials.io.tum import read_tum
from slamtrials.record import Relations, Trajectory

# Fuzzing runs hundreds of generated files per test: the whole suite runs it, the fast lane does not.
pytestmark = pytest.mark.slow

FLASER_LOG = (
    "# CARMEN Logfile\n"
    "PARAM robot_front_laser_max 50.0 100.0 b21 0.1\n"
    "PARAM laser_front_laser_fov 180 100.0 b21 0.1\n"
    "ODOM 1.0 2.0 0.1 0.5 0.0 0.0 100.05 b21 0.15\n"
    "FLASER 4 1.40 1.39 81.91 0.50 576.536523 0.106594 -2.255213 576.536523 0.106594 -2.255213 100.1 b21 0.2\n"
    "RLASER 2 1.0 1.0 0 0 0 0 0 0 100.15 b21 0.25\n"
    "FLASER 4 1.41 1.38 81.91 0.51 576.6 0.1 -2.25 576.6 0.1 -2.25 100.2 b21 0.3\n"
)
ROBOTLASER_LOG = (
    "PARAM robot_frontlaser_offset 0.1\n"
    "ROBOTLASER1 0 -1.5708 3.1416 1.0472 30.0 0.01 0 4 1.0 2.0 3.0 4.0 1 0.5 1 2 0.1 1 2 0.1 0 0 0 0 0 5.0 host 0.1\n"
    "ODOM 1 2 0.1 0 0 0 5.05 host 0.15\n"
    "ROBOTLASER1 0 -1.5708 3.1416 1.0472 30.0 0.01 0 4 1.5 2.5 3.5 4.5 0 1.1 2 0.2 1.1 2 0.2 0.1 0 0 0 0 5.1 host 0.2\n"
)
POSE_ONLY_LOG = (  # a Freiburg-evaluator test log: laser lines without readings, odd PARAMs, nan, time going back
    "PARAM robot_frontlaser_offset 0.0 nohost 0\n"
    "FLASER 0 1.0 2.0 0.1 1.0 2.0 0.1 100.1 h 0.1\n"
    "FLASER 0 1.1 2.0 0.1 1.1 2.0 0.1 100.3 h 0.3\n"
    "FLASER 0 1.05 2.0 0.1 1.05 2.0 0.1 100.2 h 0.2\n"
    "FLASER 0 nan 2.0 0.1 1.1 2.0 0.1 100.4 h 0.4\n"
    "FLASER 0 1.2 2.0 0.1 1.2 2.0 0.1 100.5 h"
)
CHANGING_LOG = (  # ROBOTLASER1 beam counts changing on one grid, ODOM lines between
    "ROBOTLASER1 0 -0.5 1.0 0.25 30.0 0.01 0 5 1 2 3 4 5 0 1 2 0.1 1 2 0.1 0 0 0 0 0 5.0 host 0.1\n"
    "ODOM 1 2 0.1 0 0 0 5.05 host 0.15\n"
    "ROBOTLASER1 0 -0.25 0.5 0.25 40.0 0.01 0 3 7 8 9 0 1.1 2 0.2 1.1 2 0.2 0.1 0 0 0 0 5.1 host 0.2\n"
    "ODOM 1 2 0.1 0 0 0 5.02 host 0.15\n"
    "ROBOTLASER1 0 -0.5 1.25 0.25 30.0 0.01 0 6 1 2 3 4 5 6 0 1.2 2 0.2 1.2 2 0.2 0.1 0 0 0 0 5.2 host 0.3\n"
)
TRUEPOS_LOG = (  # an exported simulated run: ground truth in TRUEPOS lines, one written late
    "PARAM robot_frontlaser_offset 0.1\n"
    "ODOM 0 0 0 0 0 0 5.0 host 0.0\n"
    "TRUEPOS 3.5 -2.0 0.5 0 0 0 5.0 host 0.0\n"
    "ROBOTLASER1 0 -1.5708 3.1416 1.0472 30.0 0.01 0 4 1.0 2.0 3.0 4.0 0 0.1 0 0 0 0 0 0 0 0 0 0 5.0 host 0.0\n"
    "ODOM 0.1 0 0 1 0 0 5.1 host 0.1\n"
    "ROBOTLASER1 0 -1.5708 3.1416 1.0472 30.0 0.01 0 4 1.5 2.5 3.5 4.5 0 0.2 0 0 0.1 0 0 1 0 0 0 0 5.1 host 0.1\n"
    "TRUEPOS 3.59 -1.95 0.5 0.1 0 0 5.1 host 0.1\n"
)
TUM_FILE = "# t x y z qx qy qz qw\n1.0 0.5 -0.5 0.0 0.0 0.0 0.3826834323650898 0.9238795325112867\n1.1 0.6 -0.4 0.0 0.0 0.0 0.0 1.0\n"
RELATIONS_FILE = (
    "1134864645.90321 1134864646.32420 0.31293 0.02935 0.00000  0.00000 0.00000 0.24198\n1 2 0.1 0.2 0 0 0 -0.1\n"
)

TOKENS = [
    "nan",
    "NaN",
    "inf",
    "-inf",
    "Infinity",
    "1e308",
    "-1e308",
    "1e400",
    "-1e400",
    "1e-400",
    "0",
    "-0",
    "1",
    "-1",
    "4",
    "361",
    "0.5",
    "abc",
    "1.2.3",
    "1_000",
    "0x1F",
    "+",
    "-",
    ".",
    "e5",
    "FLASER",
    "ROBOTLASER1",
    "ODOM",
    "PARAM",
    "TRUEPOS",
    "RLASER",
    "#",
    "b21",
    "\x00",
    "\u00e9",
    "\u2028",
    "\x0b",
    "9" * 40,
    "laser_front_laser_fov",
    "robot_front_laser_max",
    "laser_front_laser_resolution",
    "robot_frontlaser_offset",
    "slamtrials_laser_range_min",
]
token = st.one_of(
    st.sampled_from(TOKENS),
    st.floats().map(repr),
    st.integers(min_value=-(10**20), max_value=10**20).map(str),
    st.text(max_size=6),
)


@st.composite
def mutated(draw, seed: str) -> bytes:
    """The seed file after one to four random edits: of bytes, of tokens or of whole lines."""
    data = seed.encode("utf-8")
    for _ in range(draw(st.integers(min_value=1, max_value=4))):
        op = draw(st.sampled_from(["truncate", "byte", "insert", "token", "delete_token", "line"]))
        if op == "truncate":
            data = data[: draw(st.integers(min_value=0, max_value=len(data)))]
        elif op in ("byte", "insert") and data:
            at = draw(st.integers(min_value=0, max_value=len(data) - 1))
            new = bytes([draw(st.integers(min_value=0, max_value=255))])
            data = data[:at] + new + data[at + (op == "byte") :]
        elif op in ("token", "delete_token"):
            lines = data.decode("utf-8", errors="replace").split("\n")
            row = draw(st.integers(min_value=0, max_value=len(lines) - 1))
            tokens = lines[row].split(" ")
            at = draw(st.integers(min_value=0, max_value=len(tokens) - 1))
            tokens[at : at + 1] = [] if op == "delete_token" else [draw(token)]
            lines[row] = " ".join(tokens)
            data = "\n".join(lines).encode("utf-8")
        elif op == "line":
            lines = data.split(b"\n")
            row = draw(st.integers(min_value=0, max_value=len(lines) - 1))
            action = draw(st.sampled_from(["duplicate", "delete", "swap"]))
            if action == "duplicate":
                lines.insert(row, lines[row])
            elif action == "delete":
                del lines[row]
            else:
                other = draw(st.integers(min_value=0, max_value=len(lines) - 1))
                lines[row], lines[other] = lines[other], lines[row]
            data = b"\n".join(lines)
    return data


def _sane_carmen(log: CarmenLog) -> None:
    laser = log.laser
    assert laser.ranges.dtype == np.float32 and np.isfinite(laser.ranges).all() and (laser.ranges >= 0).all()
    assert np.all(np.diff(laser.t) > 0) and np.isfinite(laser.pose).all() and np.isfinite(laser.odometry).all()
    assert math.isfinite(laser.angle_min) and math.isfinite(laser.angle_increment) and laser.range_max >= 0
    assert np.all(np.diff(log.odom.t) >= 0) and np.isfinite(log.odom.pose).all()
    assert set(log.tolerated) <= set(TOLERATED) and all(count > 0 for count in log.tolerated.values())
    assert laser.line_readings is not None and laser.line_readings.shape == (len(laser),)
    truepos = log.truepos
    assert np.all(np.diff(truepos.t) >= 0) and np.isfinite(truepos.pose).all() and np.isfinite(truepos.odometry).all()


def _sane_tum(trajectory: Trajectory) -> None:
    assert np.all(np.diff(trajectory.t) > 0) and np.isfinite(trajectory.poses).all()
    assert np.abs(trajectory.poses[:, 2]).max() <= math.pi


def _sane_relations(relations: Relations) -> None:
    assert len(relations) > 0 and np.isfinite(relations.delta).all() and np.isfinite(relations.t1).all()


def _read_carmen_poses(path: Path) -> CarmenLog:
    return read_carmen(path, ranges=False)


def _sane_carmen_poses(log: CarmenLog) -> None:
    assert log.laser.ranges.shape == (len(log.laser), 0)
    _sane_carmen(log)


CARMEN_SEEDS = [FLASER_LOG, ROBOTLASER_LOG, POSE_ONLY_LOG, CHANGING_LOG, TRUEPOS_LOG]
READERS: dict[str, tuple[Callable, Callable, list[str]]] = {
    "carmen": (read_carmen, _sane_carmen, CARMEN_SEEDS),
    "carmen_poses": (_read_carmen_poses, _sane_carmen_poses, CARMEN_SEEDS),
    "tum": (read_tum, _sane_tum, [TUM_FILE]),
    "relations": (read_relations, _sane_relations, [RELATIONS_FILE]),
}


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


def _only_format_errors(name: str, path: Path, data: bytes) -> None:
    reader, sane, _ = READERS[name]
    path.write_bytes(data)
    try:
        result = reader(path)
    except FormatError as exc:
        assert exc.path == path and str(path) in str(exc)
        assert exc.line is not None or exc.offset is not None, str(exc)
        if exc.line is not None:
            text = read_maybe_compressed(path)  # line numbers count the decompressed text's lines
            assert 1 <= exc.line <= text.count(b"\n") + 1, str(exc)
            assert f"{path}:{exc.line}:" in str(exc)
    else:
        sane(result)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("name", READERS)
def test_seed_files_read(folder, name):
    reader, sane, seeds = READERS[name]
    for i, seed in enumerate(seeds):
        path = folder / f"seed-{name}-{i}"
        path.write_text(seed)
        sane(reader(path))


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize(
    ("name", "seed"), [(name, i) for name, (_, _, seeds) in READERS.items() for i in range(len(seeds))]
)
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_mutated_files_raise_only_format_errors(folder, name, seed, data):
    source = READERS[name][2][seed]
    _only_format_errors(name, folder / f"mutated-{name}-{seed}", data.draw(mutated(source)))


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("name", READERS)
@settings(max_examples=200, deadline=None)
@given(
    lines=st.lists(st.lists(token, max_size=14), max_size=6),
    first=st.sampled_from(["", "FLASER", "ROBOTLASER1", "ODOM", "PARAM", "TRUEPOS", "1.0"]),
)
def test_random_token_lines_raise_only_format_errors(folder, name, lines, first):
    text = "\n".join(" ".join([first, *tokens]) for tokens in lines)
    _only_format_errors(name, folder / f"tokens-{name}", text.encode("utf-8", errors="surrogatepass"))


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("name", READERS)
@settings(max_examples=150, deadline=None)
@given(data=st.binary(max_size=400))
def test_random_bytes_raise_only_format_errors(folder, name, data):
    _only_format_errors(name, folder / f"bytes-{name}", data)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("name", READERS)
@pytest.mark.parametrize(
    "value", ["1e308", "-1e308", "1e400", "-1e400", "nan", "-nan", "inf", "1e-320", "4e38", "3.4e38"]
)
def test_extreme_numbers_in_every_field(folder, name, value):
    """Every number of every seed file replaced in turn by an extreme value."""
    for s, seed in enumerate(READERS[name][2]):
        lines = seed.split("\n")
        for row, line in enumerate(lines):
            tokens = line.split()
            for at in range(1 if name.startswith("carmen") else 0, len(tokens)):
                edited = list(lines)
                edited[row] = " ".join(tokens[:at] + [value] + tokens[at + 1 :])
                _only_format_errors(name, folder / f"extreme-{name}-{s}", "\n".join(edited).encode())


@pytest.mark.parametrize("name", READERS)
def test_empty_file(folder, name):
    path = folder / f"empty-{name}"
    path.write_bytes(b"")
    with pytest.raises(FormatError) as info:
        READERS[name][0](path)
    assert info.value.line == 1


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("compress", [gzip.compress, bz2.compress])
@settings(max_examples=100, deadline=None)
@given(data=st.data())
def test_mutated_compressed_logs_raise_only_format_errors(folder, compress, data):
    """A compressed log with edited, inserted or cut bytes: a FormatError (line or byte offset), or a sane log."""
    seed = data.draw(st.sampled_from(CARMEN_SEEDS))
    packed = compress(seed.encode())
    edits = data.draw(
        st.lists(st.tuples(st.integers(min_value=0, max_value=len(packed) - 1), st.integers(0, 255)), max_size=3)
    )
    for at, value in edits:
        packed = packed[:at] + bytes([value]) + packed[at + 1 :]
    cut = data.draw(st.integers(min_value=0, max_value=len(packed)))
    _only_format_errors("carmen", folder / f"packed-{compress.__module__}", packed[:cut])
