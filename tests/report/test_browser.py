"""The report page opened in headless Chromium at 1400 px: every image loads, nothing is wider than the
window, long explanations sit in ``<details>`` blocks after the figures, the summary table is there, a
screenshot.

Needs the Debian packages ``chromium`` (and ``chromium-driver``), which ``.ci/run`` installs; skipped when
no Chromium is found. The page is checked through a copy of it beside the original with a small script
added at its end: after the load event it writes into ``<body>`` how many images there are, how many
loaded (``complete`` with ``naturalWidth > 0``), which did not, how many rows the summary table has, the
window's width, the elements that reach beyond it (with every ``<details>`` closed, then open; an element
inside a box that scrolls or clips sideways does not count), the page's scroll width, the sections with a
``<details>`` block, those where such a block comes before the first figure or table, and the explanatory
paragraphs left outside one; ``chromium --dump-dom`` then prints the DOM with those attributes. The
report itself holds no script.
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
from slamtrials.cost import RunCost
from slamtrials.errors import SimulationError
from slamtrials.report.build import build_report
from slamtrials.trial.exploration import exploration_measures

WORLDS = ["office_small_01", "lab_small_01", "house_small_01"]
#: What every run records, so that the cost and exploration sections have figures and tables too.
COST = RunCost(2.0, 40.0, 3.0, 250.0, 20.0, 30.0, updates_timed=5)
MEASURES = exploration_measures([0.0, 30.0, 60.0, 90.0], [0.1, 0.92, 0.97, 0.98], [0.0, 9.0, 17.0, 25.0], "fake")
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
#: The width of the window the page is checked in (px).
WIDTH = 1400
CHECK = """
<script>
window.addEventListener("load", function () {
  var body = document.body;
  var width = document.documentElement.clientWidth;
  function clipped(element) {  // inside a box that scrolls or clips sideways: it cannot widen the page
    for (var p = element.parentElement; p && p !== body; p = p.parentElement) {
      var overflow = getComputedStyle(p).overflowX;
      if (overflow === "auto" || overflow === "scroll" || overflow === "hidden") { return true; }
    }
    return false;
  }
  function name(element) {
    return element.tagName.toLowerCase() + (element.id ? "#" + element.id : "") +
      "(" + Math.round(element.getBoundingClientRect().width) + "px)";
  }
  function overflowing() {  // rendered elements that reach beyond the window's sides
    var found = [];
    Array.prototype.forEach.call(body.getElementsByTagName("*"), function (element) {
      var box = element.getBoundingClientRect();
      if (box.width === 0 && box.height === 0) { return; }  // not rendered (in a closed details block)
      if ((box.right > width + 0.5 || box.left < -0.5) && !clipped(element)) { found.push(name(element)); }
    });
    return found.slice(0, 12).join(" ");
  }
  var images = Array.prototype.slice.call(document.images);
  var broken = images.filter(function (img) { return !(img.complete && img.naturalWidth > 0); });
  var table = document.getElementById("summary-table");
  var details = Array.prototype.slice.call(document.querySelectorAll("section details"));
  var withDetails = [], detailsFirst = [];
  Array.prototype.forEach.call(document.querySelectorAll("section"), function (section) {
    var blocks = section.querySelectorAll("details");
    if (!blocks.length) { return; }
    withDetails.push(section.id);
    var shown = Array.prototype.filter.call(section.querySelectorAll("figure, table"), function (element) {
      return !element.closest("details");
    });
    // the section's first figure or table shown must come before its first details block
    if (shown.length && blocks[0].compareDocumentPosition(shown[0]) & Node.DOCUMENT_POSITION_FOLLOWING) {
      detailsFirst.push(section.id);
    }
  });
  var loose = Array.prototype.filter.call(document.querySelectorAll("p.explain"), function (p) {
    return !p.closest("details");
  });
  body.setAttribute("data-images", String(images.length));
  body.setAttribute("data-images-loaded", String(images.length - broken.length));
  body.setAttribute("data-broken", broken.map(function (img) { return img.getAttribute("src"); }).join(" "));
  body.setAttribute("data-summary-rows", String(table ? table.tBodies[0].rows.length : -1));
  // Table I inside its sideways-scrolling box: how much wider than the box it is (0: it fits, no scrolling)
  body.setAttribute("data-summary-hidden", String(table ? table.parentElement.scrollWidth - table.parentElement.clientWidth : -1));
  body.setAttribute("data-viewport", String(width));
  body.setAttribute("data-overflow", overflowing());
  body.setAttribute("data-scroll-width", String(document.documentElement.scrollWidth));
  body.setAttribute("data-details", String(details.length));
  body.setAttribute("data-details-sections", withDetails.join(" "));
  body.setAttribute("data-details-first", detailsFirst.join(" "));
  body.setAttribute("data-loose-prose", loose.map(function (p) { return p.id || "?"; }).join(" "));
  details.forEach(function (block) { block.open = true; });
  body.setAttribute("data-overflow-open", overflowing());
  body.setAttribute("data-scroll-width-open", String(document.documentElement.scrollWidth));
  body.setAttribute("data-checked", "yes");
});
</script>
"""
#: The sections whose explanations are long enough to be collapsed, each in a details block of its own.
EXPLAINED = {"table-1", "cost", "exploration", "map-quality"}


def browser() -> str | None:
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    return None


pytestmark = [
    pytest.mark.slow,  # a report and a headless Chromium per check: about 12 s
    pytest.mark.skipif(
        browser() is None, reason="Chromium is not installed (apt-get install chromium chromium-driver)"
    ),
]


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


def checked_dom(page: Path, tmp_path: Path, *, name: str = "check.html", text: str | None = None) -> dict[str, str]:
    """Load a copy of ``page`` (same folder, so relative paths hold; ``text`` instead of its own when given)
    with :data:`CHECK` added, in a window :data:`WIDTH` px wide; return the body's data attributes."""
    text = page.read_text(encoding="utf-8") if text is None else text
    copy = page.with_name(name)
    copy.write_text(text.replace("</body>", CHECK + "</body>"), encoding="utf-8")
    try:
        result = run_browser(tmp_path, f"--window-size={WIDTH},1000", "--dump-dom", copy.as_uri())
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
        return FakeTrial(std_t=0.08, std_r=0.02, cost=COST, exploration=MEASURES)(world, config, seed)


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    """The report of a FakeTrial campaign of three worlds (one failed): real run folders, maps and frames,
    cost and exploration measures."""
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
    assert images >= 10 and images == report.read_text(encoding="utf-8").count("<img ")
    assert int(found["images-loaded"]) == images, f"images that did not load: {found.get('broken')}"
    assert int(found["summary-rows"]) == len(WORLDS)


def test_nothing_is_wider_than_a_1400_px_window(report, tmp_path):
    found = checked_dom(report, tmp_path)
    assert int(found["viewport"]) == WIDTH
    # no element reaches beyond the window, and the page has no horizontal scroll bar, with the details
    # blocks closed (as the page opens) and open
    assert found["overflow"] == "" and int(found["scroll-width"]) <= WIDTH, found
    assert found["overflow-open"] == "" and int(found["scroll-width-open"]) <= WIDTH, found
    # Table I is read whole at that width: its box need not scroll sideways
    assert int(found["summary-hidden"]) == 0, f"Table I is {found['summary-hidden']} px wider than the page"


def test_long_explanations_are_collapsed_after_the_figures(report, tmp_path):
    found = checked_dom(report, tmp_path)
    sections = set(found["details-sections"].split())
    assert EXPLAINED | {"runs"} <= sections  # the runs table is collapsed too
    assert int(found["details"]) >= len(EXPLAINED) + 1
    assert found["details-first"] == "", f"sections with a details block before their first figure or table: {found}"
    assert found["loose-prose"] == "", f"explanations outside a details block: {found}"


def _unfold_details(page: str) -> str:
    """``page`` with every explanatory details block replaced by its content, shown."""
    page = re.sub(r'<details class="explain"><summary>[^<]*</summary>', "", page)
    return re.sub(r"(</p>|</ul>)</details>", r"\1", page)


def _details_first(page: str) -> str:
    """``page`` with the cost section's details block moved before its figure."""
    block = re.search(
        r'<details class="explain"><summary>[^<]*</summary><p class="explain" id="cost-note">.*?</details>', page, re.S
    )
    assert block is not None
    page = page.replace(block.group(0), "", 1)
    return page.replace('<section id="cost"><h2>', '<section id="cost">' + block.group(0) + "<h2>", 1)


@pytest.mark.parametrize(
    ("change", "key", "expected"),
    [
        # a block wider than the window, outside any box that scrolls: the page gets a horizontal scroll bar
        (
            lambda page: page.replace("</h1>", '</h1><div id="too-wide" style="width:2000px">wide</div>', 1),
            "overflow",
            "div#too-wide(2000px)",
        ),
        (
            lambda page: page.replace(
                "</section>", '<div id="wide-inside" style="width:1800px">wide</div></section>', 1
            ),
            "overflow",
            "div#wide-inside(1800px)",
        ),
        (
            _unfold_details,
            "loose-prose",
            "summary-caption metric-share-note outlier-note cost-note exploration-note map-quality-note",
        ),
        (_details_first, "details-first", "cost"),
    ],
    ids=["wide-block", "wide-in-section", "prose-not-collapsed", "details-before-figure"],
)
def test_the_checks_fail_on_a_broken_page(report, tmp_path, change, key, expected):
    # the checks themselves work: each deliberately broken copy of the page is reported
    original = report.read_text(encoding="utf-8")
    broken = change(original)
    assert broken != original
    found = checked_dom(report, tmp_path, name="broken-check.html", text=broken)
    assert found[key] == expected, found
    if key == "overflow":
        assert int(found["scroll-width"]) > WIDTH


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
    result = run_browser(tmp_path, f"--screenshot={shot}", f"--window-size={WIDTH},2400", report.as_uri())
    assert result.returncode == 0 and shot.is_file(), result.stderr[-2000:]
    with Image.open(shot) as image:
        image.verify()
    with Image.open(shot) as image:
        assert image.size == (WIDTH, 2400)
        pixels = np.asarray(image.convert("L"), dtype=np.float64)
    assert pixels.std() > 10  # text, tables and figures, not a blank page
    assert (pixels < 100).mean() > 0.005 and (pixels > 200).mean() > 0.3  # dark text and plots on a light page
