"""Ctrl-C in a terminal reaches every process of the group: a campaign on a local Dask cluster then ends
with its one resume line, no worker's traceback and no Dask warning."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

CONFIG = """\
worlds: [office_small_01]
termination:
  max_time: 300
runs:
  initial: 6
  max_runs: 6
"""


@pytest.mark.slow
def test_ctrl_c_ends_a_campaign_with_one_line(tmp_path):
    config = tmp_path / "c.yaml"
    config.write_text(CONFIG)
    command = [
        sys.executable,
        "-m",
        "slamtrials",
        "campaign",
        "run",
        str(config),
        "--out",
        str(tmp_path / "c"),
        "--workers",
        "2",
    ]
    process = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # as in an interactive shell
    )
    runs = tmp_path / "c" / "runs"
    deadline = time.monotonic() + 120
    while not (runs.is_dir() and any(runs.iterdir())) and time.monotonic() < deadline:  # the runs are under way
        time.sleep(0.2)
    time.sleep(2.0)
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=120)
    text = err.decode()
    assert process.returncode == 130, text
    lines = [line for line in text.splitlines() if line.strip()]
    assert lines[-1] == f"interrupted; resume with: slamtrials campaign run --out {Path(tmp_path / 'c')}", text
    assert "Traceback" not in text and "WARNING" not in text and "distributed" not in text, text
