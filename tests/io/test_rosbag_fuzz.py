"""Damaged bags (truncated, garbled bytes) never crash the reader: it returns a run or raises FormatError.

Plain and compressed (ROS 1 LZ4 chunks, ROS 2 zstd MCAP chunks) bags, ROS 2 metadata.yaml and bare MCAP.
"""

from __future__ import annotations

import shutil
import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from slamtrials.errors import FormatError
from slamtrials.io.rosbag import run_from_bag, write_rosbag1, write_rosbag2
from slamtrials.record import LaserGeometry, RunRecord

# Fuzzing runs hundreds of generated files per test: the whole suite runs it, the fast lane does not.
pytestmark = pytest.mark.slow

FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _record() -> RunRecord:
    rng = np.random.default_rng(7)
    n, beams = 12, 16
    return RunRecord(
        t=np.arange(n) * 0.1,
        scans=rng.uniform(0.1, 30.0, (n, beams)).astype(np.float32),
        odometry=np.cumsum(rng.normal(0, 0.1, (n, 3)), axis=0),
        truth=np.cumsum(rng.normal(0, 0.1, (n, 3)), axis=0),
        stalled=rng.random(n) < 0.3,
        laser=LaserGeometry.from_dict(
            {"angle_min": -1.0, "angle_increment": 0.1, "range_min": 0.0, "range_max": 30.0, "mount": [0.1, 0.0, 0.2]}
        ),
        metadata={"seed": 7, "sim_config": {"dt": 0.1}},
    )


@cache
def _originals() -> dict[str, bytes]:
    """The bytes of small valid ROS 1 bags, ROS 2 MCAP files and a ROS 2 metadata.yaml."""
    folder = Path(tempfile.mkdtemp(prefix="slamtrials-fuzz-"))
    try:
        write_rosbag1(folder / "run.bag", _record())
        write_rosbag1(folder / "lz4.bag", _record(), compress=True)
        write_rosbag2(folder / "run", _record())
        write_rosbag2(folder / "zstd", _record(), compress=True)
        return {
            "bag": (folder / "run.bag").read_bytes(),
            "bag-lz4": (folder / "lz4.bag").read_bytes(),
            "mcap": (folder / "run" / "run.mcap").read_bytes(),
            "mcap-zstd": (folder / "zstd" / "zstd.mcap").read_bytes(),
            "yaml": (folder / "run" / "metadata.yaml").read_bytes(),
        }
    finally:
        shutil.rmtree(folder)


def _read_or_format_error(path: Path, must_read: bool) -> None:
    try:
        run = run_from_bag(path)
    except FormatError as exc:
        assert not must_read, str(exc)
        assert exc.path is not None and str(exc)
        return
    if must_read:
        np.testing.assert_array_equal(run.scans, _record().scans)
    assert isinstance(run, RunRecord)
    assert run.scans.shape[0] == len(run.t) == len(run.odometry) == len(run.truth) == len(run.stalled)


def _garble(data: bytes, edits: list[tuple[int, int]]) -> bytes:
    out = bytearray(data)
    for position, value in edits:
        out[position % len(out)] = value
    return bytes(out)


def _check(kind: str, content: bytes, must_read: bool = False) -> None:
    with tempfile.TemporaryDirectory(prefix="slamtrials-fuzz-") as tmp:
        folder = Path(tmp)
        if kind.startswith("bag"):
            target = folder / "run.bag"
            target.write_bytes(content)
        elif kind == "mcap-alone":
            target = folder / "run.mcap"
            target.write_bytes(content)
        else:
            target = folder / "run"
            target.mkdir()
            originals = _originals()
            (target / "run.mcap").write_bytes(content if kind.startswith("mcap") else originals["mcap"])
            (target / "metadata.yaml").write_bytes(content if kind == "yaml" else originals["yaml"])
        _read_or_format_error(target, must_read)


ALL_KINDS = ["bag", "bag-lz4", "mcap", "mcap-zstd", "mcap-alone", "yaml"]
KINDS = st.sampled_from(ALL_KINDS)
EDITS = st.lists(st.tuples(st.integers(0, 2**31), st.integers(0, 255)), min_size=1, max_size=8)


def _source(kind: str) -> bytes:
    return _originals()["mcap" if kind == "mcap-alone" else kind]


def test_the_originals_read_back():
    for kind in ALL_KINDS:
        _check(kind, _source(kind), must_read=True)


@FUZZ
@given(kind=KINDS, fraction=st.floats(0.0, 1.0, exclude_max=True))
def test_truncated_bags_raise_format_error(kind, fraction):
    data = _source(kind)
    _check(kind, data[: int(len(data) * fraction)])


@FUZZ
@given(kind=KINDS, edits=EDITS)
def test_garbled_bags_raise_format_error(kind, edits):
    _check(kind, _garble(_source(kind), edits))


@FUZZ
@given(
    kind=st.sampled_from(["bag", "bag-lz4", "mcap", "mcap-zstd"]),
    start=st.integers(0, 2**31),
    length=st.integers(1, 64),
    seed=st.integers(0, 2**32 - 1),
)
def test_garbled_runs_of_bytes_raise_format_error(kind, start, length, seed):
    data = bytearray(_source(kind))
    start %= len(data)
    noise = np.random.default_rng(seed).integers(0, 256, length, dtype=np.uint8).tobytes()
    data[start : start + length] = noise[: len(data) - start]
    _check(kind, bytes(data))
