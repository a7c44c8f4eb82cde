"""The report page opened in headless Chromium: every image loads, the summary table is there, a screenshot.

Needs the Debian packages ``chromium`` (and ``chromium-driver``), which ``.ci/run`` installs; skipped when
no Chromium is found. The page is checked through a copy of it beside the original with a small script
added at its end: after the load event it writes into ``<body>`` how many images there are, how many
loaded (``complete`` with ``naturalWidth > 0``), which did not, and how many rows the summary table has;
``chromium --dump-dom`` then prints the DOM with those attributes. The report itself holds no script.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from slamtrials.campaign import CampaignConfig, run_campaign
from slamtrials.campaign.testing import FakeTrial
from slamtrials.errors import SimulationError
from slamtrials.report.build import build_report

WORLDS = ["office_small_01", "lab_small_01", "house_small_01"]
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
CHECK = """
<script>
window.addEventListener("load", function () {
  var images = Array.prototype.slice.call(document.images);
  var broken = images.filter(function (img) { return !(img.complete && img.naturalWidth > 0); });
  var table = document.getElementById("summary-table");
  var body = document.body;
  body.setAttribute("data-images", String(images.length));
  body.setAttribute("data-images-loaded", String(images.length - broken.length));
  body.setAttribute("data-broken", broken.map(function (img) { return img.getAttribute("src"); }).join(" "));
  body.setAttribute("data-summary-rows", String(table ? table.tBodies[0].rows.length : -1));
  body.setAttribute("data-checked", "yes");
});
</script>
"""


def browser() -> str | None:
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    return None


pytestmark = pytest.mark.skipif(
    browser() is None, reason="Chromium is not installed (apt-get install chromium chromium-driver)"
)


def run_browser(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    command = [
        browser(),
        "--headless",
        "--disable-gpu",
        "--hide-scrollbars",
        "--no-first-run",
        "--disable-extensions",
        f"--user-data-dir={tmp_path / 'profile'}",
        "--virtual-time-budget=15000",
        *args,
    ]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        command.insert(2, "--no-sandbox")  # Chromium refuses to run as root with its sandbox
    return subprocess.run(command, capture_output=True, text=True, timeout=180)


def checked_dom(page: Path, tmp_path: Path, *, name: str = "check.html") -> dict[str, str]:
    """Load a copy of ``page`` (same folder, so relative paths hold) with :data:`CHECK` added; return the body's data attributes."""
    text = page.read_text(encoding="utf-8")
    copy = page.with_name(name)
    copy.write_text(text.replace("</body>", CHECK + "</body>"), encoding="utf-8")
    try:
        result = run_browser(tmp_path, "--dump-dom", copy.as_uri())
    finally:
        copy.unlink()
    assert result.returncode == 0, result.stderr[-2000:]
    body = re.search(r"<body([^>]*)>", result.stdout)
    assert body is not None, result.stdout[:2000]
    return dict(re.findall(r'data-([a-z-]+)="([^"]*)"', body.group(1)))


class FailingIn:
    def __init__(self, world_name: str):
        self.world_name = world_name

    def __call__(self, world, config, seed):
        if world.name == self.world_name:
            raise SimulationError("the robot does not fit at the start pose")
        return FakeTrial(std_t=0.08, std_r=0.02)(world, config, seed)


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    """The report of a FakeTrial campaign of three worlds (one failed): real run folders, maps and frames."""
    from distributed import Client, LocalCluster

    folder = tmp_path_factory.mktemp("browser") / "campaign"
    config = CampaignConfig.from_dict(
        {
            "worlds": WORLDS,
            "seed": 3,
            "slam": {"algorithm": "odometry", "preset": None},
            "runs": {"initial": 5, "max_runs": 5},
        }
    )
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        run_campaign(config, folder, scheduler=client, trial_fn=FailingIn("house_small_01"))
    return build_report(folder, repeats=20, pdf=False)


def test_every_image_loads_and_the_summary_table_is_present(report, tmp_path):
    found = checked_dom(report, tmp_path)
    assert found.get("checked") == "yes", found
    images = int(found["images"])
    assert images >= 8 and images == report.read_text(encoding="utf-8").count("<img ")
    assert int(found["images-loaded"]) == images, f"images that did not load: {found.get('broken')}"
    assert int(found["summary-rows"]) == len(WORLDS)


def test_a_broken_image_is_detected(report, tmp_path):
    # the check itself works: one image pointing at a missing file is reported
    original = report.read_text(encoding="utf-8")
    broken = report.with_name("broken.html")
    broken.write_text(
        original.replace('src="figures/report_fig5_all_runs.png"', 'src="figures/missing.png"', 1), encoding="utf-8"
    )
    try:
        found = checked_dom(broken, tmp_path, name="broken-check.html")
    finally:
        broken.unlink()
    assert int(found["images-loaded"]) == int(found["images"]) - 1 and found["broken"] == "figures/missing.png"


def test_screenshot_is_a_non_blank_png(report, tmp_path):
    from PIL import Image

    shot = tmp_path / "report.png"
    result = run_browser(tmp_path, f"--screenshot={shot}", "--window-size=1280,2400", report.as_uri())
    assert result.returncode == 0 and shot.is_file(), result.stderr[-2000:]
    with Image.open(shot) as image:
        image.verify()
    with Image.open(shot) as image:
        assert image.size == (1280, 2400)
        pixels = np.asarray(image.convert("L"), dtype=np.float64)
    assert pixels.std() > 10  # text, tables and figures, not a blank page
    assert (pixels < 100).mean() > 0.005 and (pixels > 200).mean() > 0.3  # dark text and plots on a light page
