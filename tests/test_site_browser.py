"""The site in a real browser: headless Chromium (the system's, driven by Selenium through
the system's chromedriver) opens every page of a small generated site from the file
system and finds no console error, no missing image or link, MathML laid out (boxes of
non-zero size) and an animation that advances. Skipped, with the reason, where no
browser can be had (`.ci/run` installs Debian's chromium and chromium-driver when
absent)."""
from __future__ import annotations

import shutil
import tempfile
import time
from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest
from typer.testing import CliRunner

from mbfidelity.analytic.errata import errata
from mbfidelity.cli import app
from mbfidelity.comparisons.results_folder import save_errata
from mbfidelity.reports.html import write_report
from mbfidelity.systems import get_system

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
#: flags that start Chromium headless here, with nothing fetched from the network
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--window-size=1280,1000")
SYSTEM = "compound_pendulum"
#: the animation draws at 25 frames per second: in 1 s it must have moved on
WAIT_S = 1.0


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """A site of one mechanism on two engines, with its errata page and its out-of-the-box
    reading (Pymunk's error bias)."""
    out = tmp_path_factory.mktemp("site")
    res = CliRunner().invoke(app, ["run", "--systems", SYSTEM, "--sims", "mujoco,pymunk",
                                   "--out", str(out)])
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(app, ["out-of-the-box", "--systems", SYSTEM, "--sims", "pymunk",
                                   "--default", "error_bias", "--out", str(out)])
    assert res.exit_code == 0, res.output
    save_errata([e.as_dict() for e in errata(get_system(SYSTEM))], out)
    write_report(out, workers=1)
    return out


@pytest.fixture(scope="module")
def browser():
    for path in (CHROMIUM, CHROMEDRIVER):
        if not Path(path).exists():
            pytest.skip(f"no {path}: install Debian's chromium and chromium-driver")
    try:
        from selenium import webdriver
        from selenium.common.exceptions import WebDriverException
        from selenium.webdriver.chrome.service import Service
    except ImportError as exc:
        pytest.skip(f"selenium is not installed ({exc}): pip install -e '.[test]'")
    profile = tempfile.mkdtemp(prefix="mbfidelity-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in FLAGS + (f"--user-data-dir={profile}",):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    try:
        driver = webdriver.Chrome(options=options, service=Service(CHROMEDRIVER))
    except WebDriverException as exc:
        shutil.rmtree(profile, ignore_errors=True)
        pytest.skip(f"Chromium did not start: {exc.msg}")
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


def _open(driver, page: Path) -> list[dict]:
    """Load a page; its console messages (the log is emptied by reading it)."""
    driver.get_log("browser")
    driver.get(page.as_uri())
    return driver.get_log("browser")


def _target(url: str) -> tuple[Path, str]:
    parsed = urlparse(url)
    return Path(unquote(parsed.path)), parsed.fragment


def _problems(driver, page: Path) -> list[str]:
    """What is wrong with a page in the browser: console errors and warnings, images not
    shown, links and scripts that leave the file system or point at nothing."""
    found = [f"console: {m['message']}" for m in _open(driver, page)
             if m["level"] in ("SEVERE", "WARNING")]
    images = driver.execute_script(
        "return Array.from(document.images).map(i => [i.src, i.complete && "
        "i.naturalWidth > 0])")
    found += [f"image not shown: {src}" for src, shown in images if not shown]
    links = driver.execute_script(
        "return Array.from(document.querySelectorAll('a[href], script[src]'))"
        ".map(a => a.href || a.src)")
    for url in links:
        path, fragment = _target(url)
        if not url.startswith("file://"):
            found.append(f"off the file system: {url}")
        elif not path.is_file():
            found.append(f"missing: {url}")
        elif fragment and path.suffix == ".html" and f'id="{fragment}"' not in path.read_text():
            found.append(f"no anchor: {url}")
    return found


def test_every_page_opens_clean(browser, site):
    pages = sorted(site.glob("*.html"))
    assert {p.name for p in pages} == {"index.html", f"{SYSTEM}.html", "errata.html",
                                       "out_of_the_box.html"}
    for page in pages:
        assert _problems(browser, page) == [], page.name


def test_a_broken_page_is_caught(browser, site, tmp_path):
    """The checks find what they look for: a figure removed, the animation's script
    broken, a mechanism's page gone."""
    broken = tmp_path / "broken"
    shutil.copytree(site, broken)
    (broken / f"{SYSTEM}-small.png").unlink()
    (broken / "mbfidelity-animation.js").write_text("(function () {")  # a syntax error
    problems = _problems(browser, broken / f"{SYSTEM}.html")
    assert any(p.startswith("image not shown") and f"{SYSTEM}-small.png" in p
               for p in problems), problems
    assert any(p.startswith("console:") for p in problems), problems
    (broken / f"{SYSTEM}.html").unlink()
    assert any(p.startswith("missing:") for p in _problems(browser, broken / "index.html"))


def test_mathml_is_laid_out(browser, site):
    for name in (f"{SYSTEM}.html", "errata.html"):
        _open(browser, site / name)
        boxes = browser.execute_script(
            "return Array.from(document.querySelectorAll('math')).map(m => {"
            "const r = m.getBoundingClientRect(); return [r.width, r.height]})")
        assert len(boxes) > 5, name
        # every formula has an area: the browser laid the MathML out (an unknown element
        # would be inline text with no height of its own, or nothing)
        assert all(w > 0 and h > 0 for w, h in boxes), (name, boxes)
        # a fraction is taller than a line of text: MathML, not text, was laid out
        heights = browser.execute_script(
            "return Array.from(document.querySelectorAll('mfrac')).map(f => "
            "f.getBoundingClientRect().height)")
        line = browser.execute_script(
            "return parseFloat(getComputedStyle(document.body).fontSize)")
        assert heights and max(heights) > 1.2 * line, name


def test_the_animation_advances(browser, site):
    _open(browser, site / f"{SYSTEM}.html")
    boxes = browser.find_elements("css selector", ".animation")
    assert len(boxes) == 2  # the mechanism's two scenarios
    first = [b.get_attribute("data-frame") for b in boxes]
    drawn = browser.execute_script(
        "const c = document.querySelector('.animation canvas');"
        "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
        "let n = 0; for (let i = 3; i < d.length; i += 4) { if (d[i] > 0) n++; } return n")
    assert drawn > 100  # the mechanism is on the canvas
    time.sleep(WAIT_S)
    later = [b.get_attribute("data-frame") for b in boxes]
    assert all(a is not None and b is not None and a != b for a, b in zip(first, later))
    legend = boxes[0].find_element("css selector", ".legend").text
    assert "exact" in legend and "mujoco" in legend and "pymunk" in legend
