"""The viewer page in headless Chromium: time to interactive and playback rate, each against a
reference page measured in the same browser in the same run.

Run: python -m pytest benchmarks/bench_view.py
- load: the page of cmu/01_01 (2751 frames x 31 joints) until the viewer is interactive (its
  "mt-ready" performance mark, from navigation start) against the same bytes as an inert page
  (the data without the viewer) until its load event.  Target: interactive within 1.5 s.
- playback: requestAnimationFrame ticks per second while the take plays against an empty page
  that only counts ticks.  Target: the page holds the display's rate (60/s; ratio >= 0.95).
- one hour at 120 Hz (01_01 tiled with jitter, 432,000 frames x 62 channels): Python build time, page size
  and time to interactive of the decimated page (1 frame in 15 kept).
"""

import re
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA, NOTES
from motiontheater.views.viewer import page

webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed")
BROWSER = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)
COUNT_TICKS = """
window.ticks = 0;
(function tick() { window.ticks++; requestAnimationFrame(tick); })();
"""


@pytest.fixture(scope="module")
def browser():
    if BROWSER is None or shutil.which("chromedriver") is None:
        pytest.skip("no Chromium with chromedriver here")
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = BROWSER
    for flag in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1280,800"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)
    yield driver
    driver.quit()


@pytest.fixture(scope="module")
def take():
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    return mt.read_amc(DATA / "cmu" / "01_01.amc", mt.read_asf(DATA / "cmu" / "01.asf"))


def open_and_wait(driver, path: Path) -> float:
    """Milliseconds from navigation start to the viewer's ready mark."""
    driver.get(path.as_uri())
    deadline = time.monotonic() + 60
    while not driver.execute_script("return document.body && document.body.dataset.ready === '1'"):
        assert time.monotonic() < deadline, "the page did not become interactive"
        time.sleep(0.02)
    return driver.execute_script("return performance.getEntriesByName('mt-ready')[0].startTime")


def loaded(driver, path: Path) -> float:
    """Milliseconds from navigation start to the load event of an inert page."""
    driver.get(path.as_uri())
    return driver.execute_script("return performance.getEntriesByType('navigation')[0].loadEventEnd")


LOAD = "open cmu/01_01's page until interactive"


@pytest.fixture(scope="module")
def pages(take, tmp_path_factory):
    folder = tmp_path_factory.mktemp("pages")
    html = page([take], names=["01_01.amc"])
    viewer, inert = folder / "viewer.html", folder / "inert.html"
    viewer.write_text(html, encoding="utf-8")
    # the same bytes without the viewer's script: what reading the file alone costs
    inert.write_text(re.sub(r"<script>\n.*?</script>", "<script></script>", html, flags=re.DOTALL), encoding="utf-8")
    return viewer, inert


def test_load_inert_page(benchmark, record, browser, pages):
    _, inert = pages
    benchmark.pedantic(lambda: loaded(browser, inert), rounds=5, iterations=1, warmup_rounds=1)
    record(LOAD, "same bytes inert", 1, unit="pages")


def test_load_01_01(benchmark, record, browser, pages):
    viewer, _ = pages
    ready = []
    benchmark.pedantic(lambda: ready.append(open_and_wait(browser, viewer)), rounds=5, iterations=1, warmup_rounds=1)
    record(LOAD, "mtcore", 1, unit="pages", target="interactive <= 1500 ms, page <= 1.5 MB")
    NOTES.append(
        f"viewer page of cmu/01_01: {viewer.stat().st_size / 1e6:.2f} MB, interactive {min(ready):.0f} ms after "
        f"navigation at best, {np.median(ready):.0f} ms median (the page's mt-ready mark)"
    )


def test_playback_rate(benchmark, browser, take, tmp_path):
    viewer = tmp_path / "viewer.html"
    viewer.write_text(page([take]), encoding="utf-8")
    blank = tmp_path / "blank.html"
    blank.write_text(f"<!DOCTYPE html><html><body><script>{COUNT_TICKS}</script></body></html>", encoding="utf-8")
    seconds = 3.0

    def play():
        open_and_wait(browser, viewer)
        browser.execute_script("mtView.play()")
        start = browser.execute_script("return [mtView.state.stats.playTicks, performance.now()]")
        time.sleep(seconds)
        end = browser.execute_script("return [mtView.state.stats.playTicks, performance.now()]")
        return (end[0] - start[0]) / ((end[1] - start[1]) / 1000)

    rates = []
    benchmark.pedantic(lambda: rates.append(play()), rounds=2, iterations=1)
    stats = browser.execute_script("return mtView.state.stats")
    browser.get(blank.as_uri())
    time.sleep(0.5)
    start = browser.execute_script("return [window.ticks, performance.now()]")
    time.sleep(seconds)
    end = browser.execute_script("return [window.ticks, performance.now()]")
    reference = (end[0] - start[0]) / ((end[1] - start[1]) / 1000)
    NOTES.append(
        f"playback of cmu/01_01: {max(rates):.1f} animation frames/s vs {reference:.1f}/s on an empty page "
        f"({max(rates) / reference:.2f}); drawing {stats['drawMs'] / max(1, stats['ticks']):.2f} ms a tick on "
        f"average, {stats['maxDrawMs']:.1f} ms at most; target ratio >= 0.95 (60/s)"
    )


def test_one_hour_take(benchmark, record, browser, take, tmp_path):
    values = np.tile(take.values, (432_000 // take.frames + 1, 1))[:432_000]
    # jitter at the files' last decimal, so that the repeats do not compress away
    values = np.round(values + np.random.default_rng(0).normal(scale=0.01, size=values.shape), 4)
    hour = take.replace(values=values)
    html = benchmark.pedantic(lambda: page([hour], names=["hour"]), rounds=1, iterations=1)
    record("build the page of a one-hour take (432,000 x 62)", "mtcore", hour.values.size)
    viewer = tmp_path / "hour.html"
    viewer.write_text(html, encoding="utf-8")
    ready = open_and_wait(browser, viewer)
    note = browser.execute_script("return document.getElementById('note').textContent")
    assert "1 frame in 15" in note
    NOTES.append(
        f"one hour at 120 Hz (432,000 x 62): page built in {benchmark.stats.stats.min:.1f} s, "
        f"{len(html.encode()) / 1e6:.1f} MB, interactive {ready:.0f} ms after navigation; shown: {note}"
    )
