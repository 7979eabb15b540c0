"""The HTML report in a real browser (issue 14 item 14): reports of bundled examples open in
headless Chromium (the distribution's, driven by playwright: no browser download) without
a console error, and every plotly figure renders, fitting its place on the page.

Skipped, with the reason, where no Chromium is installed or playwright is missing, unless
``MECHDYN_REQUIRE_BROWSER=1`` (set by ``.ci/run`` once it installed Chromium): then a
missing browser fails the test instead.
"""

import os
import shutil
from pathlib import Path

import pytest

from mechdyn.cli import main

CANDIDATES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable",
              "/usr/bin/chromium", "/usr/lib/chromium/chromium")
REQUIRED = os.environ.get("MECHDYN_REQUIRE_BROWSER") == "1"


def _unavailable(reason: str):
    if REQUIRED:
        pytest.fail(f"MECHDYN_REQUIRE_BROWSER=1 but {reason}")
    pytest.skip(reason)


def _chromium() -> str:
    """The path of a Chromium or Chrome executable: $MECHDYN_BROWSER, else the first on the
    PATH."""
    given = os.environ.get("MECHDYN_BROWSER")
    if given:
        return given
    for name in CANDIDATES:
        found = shutil.which(name)
        if found:
            return found
    _unavailable("no Chromium found (apt-get install chromium, or set MECHDYN_BROWSER)")


@pytest.fixture(scope="module")
def browser():
    executable = _chromium()
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _unavailable("playwright is not installed (pip install -e '.[dev]')")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=executable, headless=True,
                              args=["--no-sandbox", "--disable-gpu"])
        yield b
        b.close()


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """A sweep report with kinetostatics (slider-crank) and a simulation report of the press
    cycle (switching events, modes, spectrum), animations included."""
    out = tmp_path_factory.mktemp("reports")
    runs = {"sweep": ["report", "slider_crank", "--speed", "1500rpm", "--steps", "73",
                      "--trace", "rod.com"],
            "run": ["report", "press_cycle", "--simulate", "--t-end", "0.3s"]}
    paths = {}
    for name, args in runs.items():
        paths[name] = out / f"{name}.html"
        assert main([*args, "-o", str(paths[name])]) == 0
    return paths


def _open(browser, path: Path):
    """Load a report; returns (page, console errors and page errors)."""
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    errors = []
    page.on("console", lambda m: errors.append(f"console {m.type}: {m.text}")
            if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
    page.on("requestfailed", lambda r: errors.append(f"request failed: {r.url}"))
    page.on("request", lambda r: None if r.url.startswith(("file:", "data:", "blob:"))
            else errors.append(f"network request (the page must work offline): {r.url}"))
    page.goto(path.as_uri(), wait_until="load")
    # plotly draws each figure in its inline script: wait until every div has its layout
    page.wait_for_function(
        "() => [...document.querySelectorAll('div.plotly-graph-div')]"
        ".every(d => d._fullLayout !== undefined && d.querySelector('.main-svg'))",
        timeout=30_000)
    return page, errors


@pytest.mark.parametrize("which", ["sweep", "run"])
def test_report_loads_without_errors_and_every_plot_renders(browser, reports, which):
    page, errors = _open(browser, reports[which])
    try:
        divs = page.locator("div.plotly-graph-div")
        n = divs.count()
        html = reports[which].read_text(encoding="utf-8")
        assert n == html.count('class="plotly-graph-div"') >= 3
        for i in range(n):
            div = divs.nth(i)
            assert div.locator(".main-svg").count() >= 1
            drawn = div.evaluate("d => d.querySelectorAll('.scatterlayer .trace, "
                                 ".barlayer .trace').length")
            assert drawn > 0, f"figure {i} draws no trace"
            box, svg = div.bounding_box(), div.locator(".main-svg").first.bounding_box()
            assert svg["width"] <= box["width"] + 1, f"figure {i} overflows its place"
            assert svg["height"] > 200
        # the animation stands beside the first figure
        gif = page.locator(".row .aside img")
        assert gif.count() == 1 and gif.evaluate("i => i.complete && i.naturalWidth > 0")
        assert page.locator(".row .aside").bounding_box()["x"] > \
            page.locator(".row .plot").bounding_box()["x"]
        assert errors == [], errors
    finally:
        page.close()


def test_legend_click_hides_a_trace(browser, reports):
    """The plots are interactive: a click on a legend entry hides its trace."""
    page, errors = _open(browser, reports["sweep"])
    try:
        div = page.locator("div.plotly-graph-div").first
        visible = "d => d.data.filter(t => t.visible !== 'legendonly').length"
        before = div.evaluate(visible)
        div.locator(".legend .traces .legendtoggle").first.click()
        # plotly acts on a single click once its double-click delay has passed
        page.wait_for_function(
            f"() => ({visible})(document.querySelector('div.plotly-graph-div')) < {before}",
            timeout=5_000)
        assert errors == [], errors
    finally:
        page.close()
