"""``slamtrials trial`` scores its final map against the floor plan: run.json's ``map_quality``, the line it
prints, and run folders of earlier versions (without one) still load."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from slamtrials.cli.main import app
from slamtrials.io.runfolder import read_run
from slamtrials.metric.mapquality import MAP_QUALITY_FIGURES, MAP_QUALITY_KEY, MapQuality
from slamtrials.trial import TrialSummary

runner = CliRunner()


def _plan(path):
    """A 6 m x 4 m room with a pillar, as a PNG at 5 cm per pixel (black walls, white floor)."""
    pixels = np.full((84, 124), 255, dtype=np.uint8)
    pixels[:2, :] = pixels[-2:, :] = pixels[:, :2] = pixels[:, -2:] = 0
    pixels[30:54, 60:64] = 0
    Image.fromarray(pixels).save(path)
    return path


@pytest.fixture(scope="module")
def trial_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mapped")
    config = folder / "trial.yaml"
    config.write_text("sim:\n  profile: paper\ntermination:\n  small_period: 60\n  max_time: 300\n")
    out = folder / "run"
    result = runner.invoke(
        app,
        ["trial", "--world", str(_plan(folder / "room.png")), "--resolution", "0.05", "--seed", "2"]
        + ["--config", str(config), "--out", str(out)],
    )
    assert result.exit_code == 0, result.output
    return out, result.output


@pytest.mark.slow
def test_run_json_holds_the_map_quality_and_the_trial_prints_it(trial_run):
    out, output = trial_run
    doc = json.loads((out / "run.json").read_text())
    stored = doc[MAP_QUALITY_KEY]
    assert stored["format"] == "slamtrials-mapquality/1"
    assert set(MAP_QUALITY_FIGURES) | {"cell_m", "alignment_rms_m"} <= set(stored)
    quality = MapQuality.of(doc)
    assert quality is not None and quality.cell_m == 0.05
    # a noise-free laser in a small room: a good map
    assert quality.occupied_precision_2 > 0.9 and quality.occupied_recall_2 > 0.9
    assert quality.free_iou > 0.85 and quality.ghost_free_m2 < 0.5
    assert quality.alignment_rms_m < 0.1
    assert "map: walls precision" in output and "free IoU" in output and "ghost" in output


@pytest.mark.slow
def test_a_run_json_without_map_quality_still_loads(trial_run, tmp_path):
    out, _ = trial_run
    old = tmp_path / "old"
    old.mkdir()
    for path in out.iterdir():
        (old / path.name).write_bytes(path.read_bytes())
    doc = json.loads((old / "run.json").read_text())
    del doc[MAP_QUALITY_KEY]  # as a version before map quality wrote it
    (old / "run.json").write_text(json.dumps(doc))
    record = read_run(old)
    assert MapQuality.of(record.metadata) is None
    assert TrialSummary.of(record) == TrialSummary.of(read_run(out))
    assert np.array_equal(record.estimate, read_run(out).estimate)
