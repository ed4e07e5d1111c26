"""``motiontheater check`` as a user runs it: a listing, JSON that other tools read, reports as
HTML (looked at in Chromium), JSON and CSV, recipes that ``apply`` runs as they are, and bad
input told in a sentence."""

import csv
import json
import shutil

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.cli import main

KEYS = {"take", "kind", "joints", "first", "last", "severity", "size", "unit"}


@pytest.fixture
def spiked(data_dir, tmp_path):
    """A copy of CMU 02_01 with a 40 degree spike in lfemur at frame 100 and NaN in rtibia at 200-203."""
    shutil.copy(data_dir / "cmu" / "02.asf", tmp_path)
    take = mt.read_take(data_dir / "cmu" / "02_01.amc")
    values = take.values.copy()
    values[99, take.columns("lfemur", "rx")[0]] += 40.0
    values[199:203, take.columns("rtibia")] = np.nan
    path = tmp_path / "02_01.amc"
    mt.write_take(take.replace(values=values, origin=None), path, allow_non_finite=True)
    return path


def _json(capsys, *args):
    assert main(["check", *map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_json_names_every_finding_by_take_frames_joints_and_unit(spiked, capsys):
    findings = _json(capsys, spiked)
    assert findings and all(KEYS <= set(f) for f in findings)
    assert {f["take"] for f in findings} == {str(spiked)}
    spike = [f for f in findings if f["kind"] == "spike" and f["joints"] == ["lfemur"]]
    assert [(f["first"], f["last"], f["unit"]) for f in spike] == [(100, 100, "deg")]
    assert 35 < spike[0]["size"] < 45
    gap = [f for f in findings if f["kind"] == "gap"]
    assert [(f["joints"], f["first"], f["last"], f["unit"]) for f in gap] == [(["rtibia"], 200, 203, "s")]


def test_the_recipes_fix_the_take_when_apply_runs_them(spiked, tmp_path, capsys):
    fixes = tmp_path / "fixes"
    assert main(["check", str(spiked), "--recipes", str(fixes), "--quiet"]) == 0
    assert "1 recipe in" in capsys.readouterr().out
    recipe = fixes / "02_01.amc.toml"
    fixed = tmp_path / "fixed.amc"
    assert main(["apply", str(spiked), "--recipe", str(recipe), "-o", str(fixed)]) == 0
    # the spike and the gap each filled; a run of one step told once, with its count (a check's
    # recipe may hold hundreds)
    assert recipe.read_text().count('run = "fill_gaps"') == 2
    assert f"(fill_gaps x2) on {mt.read_take(spiked).frames} frames of {spiked}" in capsys.readouterr().out
    after = _json(capsys, fixed)
    assert not [f for f in after if f["kind"] in ("spike", "gap") and f["severity"] != "low" and 95 < f["first"] < 210]
    before, repaired = mt.read_take(spiked), mt.read_take(fixed)
    rows = np.r_[0:98, 101:198, 204 : before.frames]  # away from the spike and the gap, every value as it was
    np.testing.assert_array_equal(repaired.values[rows], before.values[rows])


def test_batch_runs_each_takes_own_recipe_from_the_folder_check_wrote(spiked, data_dir, tmp_path, capsys):
    """Two takes, one with findings to fix: batch --recipe FOLDER fixes it as apply does, leaves
    the other out (it has nothing to fix), and --resume knows both again."""
    takes = tmp_path / "takes"
    takes.mkdir()
    for path in (spiked, spiked.with_name("02.asf"), data_dir / "cmu" / "02_03.amc"):  # 02_03: nothing to fix
        shutil.copy(path, takes)
    fixes, out = tmp_path / "fixes", tmp_path / "fixed"
    assert main(["check", str(takes), "--recipes", str(fixes), "--quiet"]) == 0
    assert sorted(p.name for p in fixes.iterdir()) == ["02_01.amc.toml"]
    capsys.readouterr()
    assert main(["batch", str(takes), "--recipe", str(fixes), "-o", str(out), "--quiet"]) == 0
    assert sorted(p.name for p in out.glob("*.amc")) == ["02_01.amc"]
    alone = tmp_path / "alone.amc"
    assert main(["apply", str(spiked), "--recipe", str(fixes / "02_01.amc.toml"), "-o", str(alone)]) == 0
    np.testing.assert_array_equal(mt.read_take(out / "02_01.amc").values, mt.read_take(alone).values)
    capsys.readouterr()
    assert main(["batch", str(takes), "--recipe", str(fixes), "-o", str(out), "--resume"]) == 0
    told = capsys.readouterr().out
    assert "0 processed, 1 skipped (already done), 1 without a recipe (nothing to fix), 0 failed of 2 takes" in told
    (fixes / "02_01.amc.toml").write_text("[[step]]\nrun = 'no such step'\n")
    assert main(["batch", str(takes), "--recipe", str(fixes), "-o", str(tmp_path / "again")]) == 1
    assert f"FAILED {takes / '02_01.amc'}: {fixes / '02_01.amc.toml'}: step 1: no step 'no such step'" in (
        capsys.readouterr().err
    )


def test_reports_are_written_as_json_csv_and_html(spiked, tmp_path, capsys):
    for suffix in ("json", "csv", "html"):
        target = tmp_path / f"report.{suffix}"
        assert main(["check", str(spiked), "-o", str(target), "--quiet"]) == 0
        assert f"wrote {target}" in capsys.readouterr().out
    assert json.loads((tmp_path / "report.json").read_text()) == _json(capsys, spiked)
    rows = list(csv.DictReader((tmp_path / "report.csv").open()))
    assert {r["kind"] for r in rows} >= {"spike", "gap"} and all(r["take"] == str(spiked) for r in rows)
    assert (tmp_path / "report_views" / "02_01.amc.html").is_file()


def test_the_listing_says_what_and_where(spiked, capsys):
    assert main(["check", str(spiked)]) == 0
    out = capsys.readouterr().out
    assert "lfemur turns" in out and "frame 100" in out and "frames 200-203" in out
    assert out.strip().splitlines()[-1].startswith("check: 1 take in")


def test_bad_input_is_told_not_raised(tmp_path, capsys):
    broken = tmp_path / "broken.bvh"
    broken.write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n")
    assert main(["check", str(broken), "--json"]) == 0
    captured = capsys.readouterr()
    (finding,) = json.loads(captured.out)
    assert finding["kind"] == "unreadable" and str(broken) in finding["detail"]
    assert "Traceback" not in captured.err
    assert main(["check", str(tmp_path / "missing.amc")]) != 0
    assert "missing.amc" in capsys.readouterr().err
    assert main(["check", str(broken), "-o", str(tmp_path / "report.txt")]) != 0
    err = capsys.readouterr().err
    assert "report.txt" in err and ".html" in err and not (tmp_path / "report.txt").exists()


def test_unroll_keeps_every_position_and_undoes_a_flip(data_dir):
    take = mt.read_take(data_dir / "cmu" / "02_01.amc")
    columns = take.columns("lfemur")
    values = take.values.copy()
    a, b, c = (values[50:80, k] for k in columns)
    values[50:80, columns[0]], values[50:80, columns[1]], values[50:80, columns[2]] = a + 180, 180 - b, c - 180
    flipped = take.replace(values=values, origin=None)
    np.testing.assert_allclose(flipped.positions(), take.positions(), atol=1e-9)
    undone = flipped.unroll(joints=["lfemur"], frames=(51, 80))
    np.testing.assert_allclose(undone.values, take.values, atol=1e-9)
    np.testing.assert_allclose(undone.positions(), take.positions(), atol=1e-9)


def test_scale_multiplies_lengths_and_refuses_a_bad_factor(data_dir):
    take = mt.read_take(data_dir / "cmu" / "02_01.amc")
    scaled = take.scale(factor=10.0)
    np.testing.assert_allclose(scaled.positions(), take.positions() * 10, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(scaled.scale(factor=0.1).values, take.values, rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match="factor must be a positive number"):
        take.scale(factor=0.0)


def test_the_html_report_sorts_and_opens_the_viewer_at_a_finding(spiked, tmp_path, capsys):
    browsers = pytest.importorskip("test_view_browser", reason="selenium is not installed")
    if browsers.BROWSER is None or browsers.DRIVER is None:
        pytest.skip("no Chromium with chromedriver here (Debian: apt-get install chromium chromium-driver)")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    report = tmp_path / "report.html"
    assert main(["check", str(spiked), "-o", str(report), "--quiet"]) == 0
    options = webdriver.ChromeOptions()
    options.binary_location = browsers.BROWSER
    for flag in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1280,800"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(browsers.DRIVER), options=options)
    try:
        driver.get(report.as_uri())

        def column(i):
            return [
                r.find_elements(By.TAG_NAME, "td")[i].text for r in driver.find_elements(By.CSS_SELECTOR, "tbody tr")
            ]

        ranks = [{"low": 0, "medium": 1, "high": 2}[s] for s in column(0)]
        assert ranks == sorted(ranks, reverse=True) and len(ranks) >= 2  # worst first
        driver.find_element(By.XPATH, "//th[text()='kind']").click()
        assert column(1) == sorted(column(1))
        assert driver.find_elements(By.CSS_SELECTOR, "svg.plot polyline")  # the worst channels are drawn
        spike = driver.find_element(By.XPATH, "//tr[td[2]='spike' and td[4]='lfemur']//a")
        spike.click()
        WebDriverWait(driver, 30).until(lambda d: d.execute_script("return document.body.dataset.ready === '1'"))
        state = driver.execute_script(
            "const s = window.mtView.state; return [s.cur, s.selected, s.takes[0].joints[s.selected]]"
        )
        assert state[0] == 99 and state[2] == "lfemur"  # frame 100 is row 99
    finally:
        driver.quit()
