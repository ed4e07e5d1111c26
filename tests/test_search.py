"""Search by example over real takes: HDM05 classes found across actors (leave one actor out),
features that no rig, unit or up axis changes, ranks equal to warping every window, an index
brought up to date take by take, and the verbs as a user runs them."""

import json
import os
import shutil

import numpy as np
import pytest

import motiontheater as mt
from corpus import real_files
from motiontheater.cli import main
from motiontheater.databases import features
from motiontheater.databases.features import POINTS, RELATIONS, body, describe, moves, pose_features, words
from motiontheater.databases.index import Database, build
from motiontheater.databases.search import nearest_frames, search
from mtcore.search import dtw, pack_bits
from twins.search import body_relations
from variants import with_offset_channels, with_static_root

HDM = real_files("hdm05/*.amc")
POINT = {name: i for i, (name, _) in enumerate(POINTS)}
TAKES = [p for p in real_files("*/*.amc") + real_files("*/*.bvh") if p.name != "rest.bvh"]
VARIANTS = {
    "game rig": lambda take: with_static_root(with_offset_channels(take), shift=(250.0, 0.0, -400.0)),
    "z-up": lambda take: with_static_root(take, turn=(90.0, 0.0, 0.0), keep_world=False),
    "in mm": lambda take: take.with_units(length_factor=1000 * take.skeleton.meters_per_unit, length="mm"),
}


def _actor(path) -> str:
    return os.path.basename(path).split("_")[1]


def _motion_class(path) -> str:
    return os.path.basename(path).split("_")[2]


@pytest.fixture(scope="module")
def hdm05():
    if not HDM:
        pytest.skip("the real-file corpus (../shared/data/hdm05) is absent")
    built = build([str(HDM[0].parent)], workers=1)
    assert not built.failed and len(built.database) == len(HDM)
    return built.database


def _ranked(db, query_path, k, clip=None):
    take = mt.read_take(query_path)
    if clip is not None:
        middle, half = take.first_frame + take.frames // 2, round(clip * take.frame_rate / 2)
        take = take.crop(max(take.first_frame, middle - half), min(take.last_frame, middle + half))
    return search(db, take, k, exclude=lambda t: _actor(t) == _actor(query_path)).hits


@pytest.mark.parametrize("clip", [None, 2.0], ids=["whole takes", "2 s clips"])
def test_hdm05_classes_are_found_across_actors(hdm05, clip):
    """Each take of one actor queries the other actors' takes: a hit is a take of its class."""
    p1 = p2 = p5 = average = 0.0
    for entry in hdm05.entries:
        relevant = [_motion_class(h.take) == _motion_class(entry.take) for h in _ranked(hdm05, entry.take, 22, clip)]
        assert len(relevant) == 22 and sum(relevant) == 2  # every other actor's take, ranked
        p1 += relevant[0]
        p2 += sum(relevant[:2]) / 2
        p5 += sum(relevant[:5]) / 5
        found = np.flatnonzero(relevant) + 1
        average += np.mean(np.arange(1, len(found) + 1) / found)
    n = len(hdm05.entries)
    figures = {"P@1": p1 / n, "P@2": p2 / n, "P@5": p5 / n, "mAP": average / n}
    print(clip, figures)
    assert figures["P@2"] >= 0.90 and figures["mAP"] >= 0.90, figures


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_features_do_not_depend_on_the_rig_unit_or_up_axis(variant, tmp_path):
    """A take written as another producer's BVH (a static root above the hips, position channels on
    every joint, z up, millimetres) and read back has the same features."""
    bvh = real_files("cmu/16_15.bvh")
    if not bvh:
        pytest.skip("the real-file corpus (../shared/data) is absent")
    take = mt.read_take(bvh[0])
    path = tmp_path / "variant.bvh"
    mt.write_bvh(VARIANTS[variant](take), path)
    other = mt.read_take(path)
    np.testing.assert_allclose(pose_features(body(other)), pose_features(body(take)), atol=1e-4)


@pytest.mark.parametrize("path", TAKES, ids=[f"{p.parent.name}/{p.name}" for p in TAKES])
def test_the_relations_table_states_muellers_facts_on_every_real_take(path):
    """The C kernel's table of relations gives, bit for bit, the facts written out one by one."""
    take = mt.read_take(path)
    try:
        b = body(take)
    except ValueError as e:
        assert "rig tables" in str(e) or "no length" in str(e)  # a body the rig tables cannot find
        pytest.skip(f"{path.name}: {e}")
    got, facts = words(b), body_relations(b)
    np.testing.assert_array_equal(got, pack_bits(facts))
    assert len(RELATIONS) == facts.shape[1] and describe(int(got[0])) == [
        name for name, on in zip(RELATIONS, facts[0]) if on
    ]


def test_a_rig_without_hands_has_its_wrists_where_its_forearms_end():
    """Blender's Rigify export (bvhTools test3) and MoDi end their arms at the forearm's End Site:
    that is the wrist (a BVH joint sits where it turns: the forearm's own point is the elbow), so
    their takes are bodies the index holds."""
    rigs = {
        "bvhTools_test3.bvh": ("forearm.L_End", "forearm.R_End"),
        "MoDi_000000_joints_1_frames_64.bvh": ("L_Elbow_End", "R_Elbow_End"),
    }
    found = [p for name in rigs for p in real_files(f"bvh-producers/{name}")]
    if len(found) < len(rigs):
        pytest.skip("the real-file corpus (../shared/data/bvh-producers) is absent")
    for path in found:
        take = mt.read_take(path)
        names = [take.skeleton.point_names[j] for j in features._joints(take)]
        assert (names[POINT["left_wrist"]], names[POINT["right_wrist"]]) == rigs[path.name]
        b = body(take)
        forearm = np.linalg.norm(b.at("left_wrist") - b.at("left_elbow"), axis=1)
        assert forearm.min() > 0.2 and np.ptp(forearm) < 1e-9 * forearm.max()  # a bone: as long in every frame


def test_a_cmu_query_finds_itself_in_every_rig(tmp_path):
    cmu, bvh = real_files("cmu/16_15.amc"), real_files("cmu/16_15.bvh")
    if not cmu or not bvh:
        pytest.skip("the real-file corpus (../shared/data) is absent")
    take = mt.read_take(bvh[0])
    for name, make in VARIANTS.items():
        mt.write_bvh(make(take), tmp_path / f"{name.replace(' ', '_')}.bvh")
    shutil.copy(cmu[0].with_name("16.asf"), tmp_path)
    shutil.copy(cmu[0], tmp_path)  # the ASF/AMC it was converted from
    db = build([str(tmp_path)], workers=1).database
    hits = search(db, take.crop(60, 240), 4).hits
    # every rig the same distance (not 0: the query's frames fall between the database's 10 Hz
    # rows); the AMC that CMU converted a little farther (neck, head and hands placed apart)
    assert len(hits) == 4 and hits[3].take.endswith("16_15.amc"), hits
    assert np.ptp([h.distance for h in hits[:3]]) < 1e-9 and hits[3].distance < 0.01, hits
    assert all(abs(h.first - 60) <= 12 and abs(h.last - 240) <= 12 for h in hits), hits


def test_the_ranking_equals_warping_every_window(hdm05):
    """Unfiltered, the hits and their distances are what DTW of every window of every take gives."""
    for query_path in (HDM[0], HDM[7], HDM[20]):
        take = mt.read_take(query_path).crop(*_middle(mt.read_take(query_path), 1.5))
        hits = search(hdm05, take, 5, use_index=False).hits
        q = pose_features(body(take))
        m = len(q)
        radius = max(1, int(np.ceil(0.2 * m)))
        best = {}
        for e in hdm05.entries:
            rows = hdm05.poses[e.start : e.start + e.rows]
            if e.rows >= m:
                d = min(dtw(q, rows[s : s + m], radius) for s in range(e.rows - m + 1)) / m
            else:
                d = dtw(q, rows, m - e.rows + radius) / m
            best[e.take] = d
        brute = sorted(best.items(), key=lambda kv: (kv[1], kv[0]))[:5]
        assert [h.take for h in hits] == [t for t, _ in brute]
        np.testing.assert_allclose([h.distance for h in hits], [d for _, d in brute], rtol=0, atol=1e-12)


def _middle(take, seconds):
    middle, half = take.first_frame + take.frames // 2, round(seconds * take.frame_rate / 2)
    return max(take.first_frame, middle - half), min(take.last_frame, middle + half)


def test_indexing_again_reads_only_new_and_changed_takes(tmp_path):
    if len(HDM) < 3:
        pytest.skip("the real-file corpus (../shared/data/hdm05) is absent")
    folder = tmp_path / "takes"
    folder.mkdir()
    for path in HDM[:3]:
        shutil.copy(path, folder)
        shutil.copy(path.with_name(path.name.split("_")[0] + "_" + _actor(path) + ".asf"), folder)
    first = build([str(folder)], workers=1)
    assert len(first.indexed) == 3 and not first.kept
    target = tmp_path / "db.npz"
    first.database.save(target)
    takes = sorted(folder.glob("*.amc"))
    os.utime(takes[0], ns=(1, 1))  # changed
    takes[1].unlink()  # gone
    again = build([str(folder)], Database.load(target), workers=1)
    assert again.indexed == (str(takes[0]),) and again.kept == (str(takes[2]),) and again.dropped == (str(takes[1]),)
    same = {e.take: e for e in first.database.entries}[str(takes[2])]
    kept = {e.take: e for e in again.database.entries}[str(takes[2])]
    np.testing.assert_array_equal(
        again.database.poses[again.database.rows_of(kept)], first.database.poses[first.database.rows_of(same)]
    )


def test_index_and_search_verbs(tmp_path, capsys):
    if not HDM:
        pytest.skip("the real-file corpus (../shared/data/hdm05) is absent")
    db = tmp_path / "hdm05.npz"
    assert main(["index", str(HDM[0].parent), "-o", str(db), "--quiet"]) == 0
    assert "33 takes" in capsys.readouterr().out
    kick = next(p for p in HDM if "kickLFront" in p.name)
    page = tmp_path / "hits.html"
    assert main(["search", str(db), str(kick), "-k", "3", "--json", "--view", str(page)]) == 0
    out = capsys.readouterr()
    hits = json.loads(out.out)
    assert [set(h) >= {"take", "first", "last", "distance"} for h in hits] == [True] * 3
    assert hits[0]["take"] == str(kick) and hits[0]["distance"] < 1e-9
    assert all("kickLFront" in h["take"] for h in hits), hits
    assert page.stat().st_size > 0 and "wrote" in out.err
    # the query a take that is longer than any other, and half of it: how each was searched told
    longest = max(HDM, key=lambda p: mt.read_take(p).frames)
    shorter = sum(mt.read_take(p).frames < mt.read_take(longest).frames for p in HDM)
    assert main(["search", str(db), str(longest), "-k", "1"]) == 0
    told = capsys.readouterr().out
    assert f"of 1 windows, 1 warped; {shorter} take(s) shorter than the query, each warped whole" in told, told
    assert main(["search", str(db), str(longest), "-k", "1", "--frames", "1:120"]) == 0
    assert f"; {shorter} take(s) shorter" not in capsys.readouterr().out  # a second of it fits most takes


def test_bad_databases_and_queries_are_told_in_a_sentence(tmp_path, capsys):
    if not HDM:
        pytest.skip("the real-file corpus (../shared/data/hdm05) is absent")
    other = tmp_path / "other.npz"
    np.savez(other, x=np.arange(3))
    before = other.read_bytes()
    assert main(["index", str(HDM[0]), "-o", str(other)]) != 0
    assert "not a motiontheater search database" in capsys.readouterr().err
    assert other.read_bytes() == before  # a file that is not ours is never overwritten
    assert main(["search", str(tmp_path / "none.npz"), str(HDM[0])]) != 0
    assert "no such database" in capsys.readouterr().err
    db = tmp_path / "db.npz"
    assert main(["index", str(HDM[0]), "-o", str(db), "--quiet"]) == 0
    assert main(["search", str(db), str(HDM[0]), "--frames", "1:10"]) != 0
    assert "at least 0.3 s" in capsys.readouterr().err


def test_frame_search_equals_brute_force_and_finds_the_frame_itself(hdm05):
    for query_path in (HDM[1], HDM[12], HDM[30]):
        take = mt.read_take(query_path)
        frame = take.first_frame + 24  # a frame the database keeps a row of (every 12th at 120 Hz)
        hits = nearest_frames(hdm05, take, frame, 8)
        q = moves(body(take))[2].astype(np.float64)
        d = np.sum((hdm05.moves.astype(np.float64) - q) ** 2, axis=1)
        order = np.lexsort((np.arange(len(d)), d))[:8]
        assert [(h.take, h.first) for h in hits] == [
            (hdm05.entries[int(hdm05.owner(np.array([r]))[0])].take, int(hdm05.frames[r])) for r in order
        ]
        np.testing.assert_allclose([h.distance for h in hits], d[order], rtol=0, atol=1e-12)
        assert hits[0].take == str(query_path) and hits[0].first == frame and hits[0].distance < 1e-12
    others = nearest_frames(hdm05, take, frame, 3, exclude=lambda t: t == str(query_path))
    assert len(others) == 3 and all(h.take != str(query_path) for h in others)


@pytest.mark.parametrize("rate", [120.0, 30.0, 25.0, 7.0])
def test_the_frame_searched_for_is_the_query_not_the_nearest_database_row(rate):
    """The database keeps 10 rows a second; a frame between them is still what is looked for."""
    if not HDM:
        pytest.skip("the real-file corpus (../shared/data/hdm05) is absent")
    take = mt.read_take(HDM[5]).replace(frame_rate=rate)  # the same frames, other ticks between them
    grid = body(take)
    for frame in (take.first_frame, take.first_frame + 5, take.first_frame + take.frames // 3, take.last_frame):
        at = body(take, frame=frame)
        assert frame in at.frames and np.all(np.diff(at.frames) >= 1)
        assert abs(len(at.frames) - len(grid.frames)) <= 1  # the same 10 Hz, shifted
        alone = body(take.crop(frame, frame))  # that one frame's features, from nothing else
        row = int(np.flatnonzero(at.frames == frame)[0])
        np.testing.assert_allclose(at.points[row], alone.points[0], rtol=0, atol=1e-12)


def test_a_searched_database_holds_one_float32_copy_of_its_rows_and_saves_them_unchanged(hdm05, tmp_path):
    hdm05.save(tmp_path / "before.npz")
    db = Database.load(tmp_path / "before.npz")
    poses, moves_ = db.poses.copy(), db.moves.copy()
    search(db, mt.read_take(HDM[3]), 2), nearest_frames(db, mt.read_take(HDM[3]), 30, 2)
    kept = [v for v in vars(db).values() if isinstance(v, np.ndarray) and v.ndim == 2]
    assert len(kept) == 1 and kept[0].dtype == np.float32  # DTW's series; the tree keeps the moves
    assert db.tree.rows.dtype == np.float32
    np.testing.assert_array_equal(db.poses, poses)
    np.testing.assert_array_equal(db.moves, moves_)
    db.save(tmp_path / "after.npz")
    again = Database.load(tmp_path / "after.npz")
    np.testing.assert_array_equal(again.poses, poses)
    np.testing.assert_array_equal(again.moves, moves_)


def test_the_view_page_plays_the_query_and_the_hits_in_chromium(hdm05, tmp_path, capsys):
    browsers = pytest.importorskip("test_view_browser", reason="selenium is not installed")
    if browsers.BROWSER is None or browsers.DRIVER is None:
        pytest.skip("no Chromium with chromedriver here (Debian: apt-get install chromium chromium-driver)")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.support.ui import WebDriverWait

    db = tmp_path / "hdm05.npz"
    hdm05.save(db)
    squat = next(p for p in HDM if "squat" in p.name)
    page = tmp_path / "hits.html"
    assert main(["search", str(db), str(squat), "-k", "3", "--json", "--view", str(page)]) == 0
    hits = json.loads(capsys.readouterr().out)
    options = webdriver.ChromeOptions()
    options.binary_location = browsers.BROWSER
    for flag in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1280,800"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(browsers.DRIVER), options=options)
    try:
        driver.get(page.as_uri())
        WebDriverWait(driver, 30).until(lambda d: d.execute_script("return document.body.dataset.ready === '1'"))
        shown = driver.execute_script("return window.mtView.state.takes.map(t => [t.name, t.frames])")
        assert [name for name, _ in shown] == ["query"] + [
            f"{i}. {h['take']} from {h['first']}" for i, h in enumerate(hits, 1)
        ]
        assert [frames for _, frames in shown][1:] == [h["last"] - h["first"] + 1 for h in hits]  # each its window
        assert not browsers.console_errors(driver)
    finally:
        driver.quit()
