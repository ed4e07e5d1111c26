"""The viewer page without a browser: what it holds, how big it is, what it refuses."""

import base64
import json
import re
import zlib

import numpy as np
import pytest

import motiontheater as mt
from corpus import real_files
from motiontheater.feet.upright import take_up
from motiontheater.views.viewer import DEFAULT_MAX_FRAMES, EDIT_STEPS, page, write_page
from variants import with_offset_channels, with_static_root


def page_data(html: str) -> dict:
    return json.loads(
        re.search(r'<script type="application/json" id="mt-data">(.*?)</script>', html, re.DOTALL).group(1)
    )


def decoded(take: dict) -> np.ndarray:
    """The twin of the page's decodeValues: (frames, channels)."""
    frames, channels = take["frames"], len(take["channels"])
    planes = np.frombuffer(zlib.decompress(base64.b64decode(take["values"]["data"])), np.uint8)
    words = planes.reshape(4, -1).T.copy().view("<i4").ravel()
    exceptions = iter(np.frombuffer(base64.b64decode(take["values"]["exceptions"]), "<f8"))
    values = [next(exceptions) if w & 31 == 31 else (w >> 5) / 10.0 ** (w & 31) for w in words.tolist()]
    return np.array(values).reshape(channels, frames).T


def cmu_take(name: str = "01_01") -> mt.Motion:
    path = next((p for p in real_files(f"cmu/{name}.amc")), None)
    if path is None:
        pytest.skip("CMU 01_01 not in the corpus")
    return mt.read_amc(path, mt.read_asf(mt.skeleton_path_for(path)))


def small_take(frames: int = 40, seed: int = 0) -> mt.Motion:
    skeleton = mt.Skeleton(
        bones=(
            mt.Bone("hip", direction=(0, -1, 0), length=2.0, dofs=("rx", "ry", "rz")),
            mt.Bone("knee", direction=(0, -1, 0), length=2.0, dofs=("rx",)),
            mt.Bone("toe", direction=(0, 0, 1), length=0.5),
        ),
        hierarchy=(("root", ("hip",)), ("hip", ("knee",)), ("knee", ("toe",))),
        units=(("mass", "1.0"), ("length", "0.45"), ("angle", "deg")),
    )
    rng = np.random.default_rng(seed)
    values = np.round(rng.normal(scale=30, size=(frames, len(skeleton.channels))), 4)
    return mt.Motion(skeleton, values)


@pytest.mark.parametrize("kind", ["amc", "bvh"])
def test_values_are_stored_exactly(data_dir, kind):
    path = data_dir / "cmu" / f"01_01.{kind}"
    motion = mt.read_bvh(path) if kind == "bvh" else mt.read_amc(path, mt.read_asf(data_dir / "cmu" / "01.asf"))
    take = page_data(page([motion]))["takes"][0]
    values = decoded(take)
    # equal as numbers, bit for bit but for the sign of zero
    assert np.array_equal(values, motion.values)
    assert take["frames"] == motion.frames and take["step"] == 1


def test_values_that_are_not_short_decimals_survive(rng):
    motion = small_take()
    values = motion.values.copy()
    values[3, 1] = np.nan
    values[4, 2] = np.pi  # 16 digits
    values[5, 3] = 1.5e-300
    values[6, 4] = -123456789.0  # past the word's mantissa
    values[7, 5] = 3.64024e-15  # exponent notation, as CMU writes near-zeros
    values[8] = rng.normal(size=values.shape[1])
    motion = motion.replace(values=values)
    got = decoded(page_data(page([motion]))["takes"][0])
    assert np.array_equal(got, motion.values, equal_nan=True)


def test_cmu_01_01_page_is_small(data_dir):
    html = page([cmu_take()], names=["01_01.amc"])
    assert len(html.encode()) <= 1_500_000
    assert "http://" not in html and "https://" not in html  # nothing to fetch


def test_page_is_self_contained():
    html = page([small_take()])
    assert html.count("<script") == 2  # the data and the viewer, both inline
    assert not re.search(r"<(script|link|img)[^>]+(src|href)=", html)
    assert "__JS__" not in html and "__DATA__" not in html and "__CSS__" not in html


def test_names_cannot_break_out_of_the_data():
    html = page([small_take()], names=["</script><script>alert(1)</script>"])
    assert html.count("</script>") == 2
    assert page_data(html)["takes"][0]["name"] == "</script><script>alert(1)</script>"
    assert "<title>motiontheater: &lt;/script&gt;" in html


def test_long_takes_are_decimated_with_a_note():
    """One hour at 120 Hz, 62 channels: the page keeps 1 frame in 15 and says so."""
    frames = 432_000
    skeleton = small_take().skeleton
    t = np.arange(frames)[:, None] / 120.0
    values = np.round(20 * np.sin(t * np.arange(1, len(skeleton.channels) + 1)), 4)
    motion = mt.Motion(skeleton, values)
    data = page_data(page([motion], names=["hour"]))
    take = data["takes"][0]
    assert take["step"] == 15 and take["frames"] == 28_800 <= DEFAULT_MAX_FRAMES
    assert np.array_equal(decoded(take), values[::15])
    assert "1 frame in 15 of its 432,000 is shown (8 Hz)" in data["note"] and "editing is off" in data["note"]
    assert data["editable"] is False


def test_compared_takes_and_footplants():
    a, b = small_take(seed=1), small_take(frames=30, seed=2)
    flags = np.zeros(40, bool)
    flags[5:12] = flags[20:] = True
    data = page_data(page([a, b], names=["before", "after"], contacts=[{"toe": flags}, None]))
    assert [t["name"] for t in data["takes"]] == ["before", "after"]
    point = a.skeleton.point_names.index("toe")
    assert data["takes"][0]["plants"] == [{"label": "toe", "point": point, "spans": [[5, 11], [20, 39]]}]
    assert data["takes"][1]["plants"] == []
    assert data["editable"] is True


def test_a_contacts_table_marks_heels_and_balls(data_dir):
    """A Contacts table gives a row per foot point: the ball at the ball, a derived heel (CMU has no
    heel joint) at the ankle above it, with the table's plants as spans of frame indices."""
    from motiontheater.feet.contacts import Contacts, Plant

    motion = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))
    table = Contacts([Plant("lfoot", "heel", 11, 50), Plant("rfoot", "ball", 2000, 2751)], 1, motion.frames)
    rows = page_data(page([motion], contacts=[table]))["takes"][0]["plants"]
    points = motion.skeleton.point_names
    assert [(r["label"], points[r["point"]], r["spans"]) for r in rows] == [
        ("lfoot heel", "ltibia", [[10, 49]]),  # an ASF bone's point is where it ends: ltibia ends at the ankle
        ("lfoot ball", "lfoot", []),
        ("rfoot heel", "rtibia", []),
        ("rfoot ball", "rfoot", [[1999, 2750]]),
    ]
    decimated = page_data(page([motion], contacts=[table], max_frames=1000))["takes"][0]["plants"]
    assert decimated[0]["spans"] == [[4, 16]]  # frames 13, 16 .. 49 of the 1 in 3 shown (indices 12 .. 48)
    with pytest.raises(ValueError, match="another take"):
        page([motion.replace(values=motion.values[:100])], contacts=[table])
    with pytest.raises(mt.errors.UnknownNameError, match="nose"):
        page([motion], contacts=[Contacts([Plant("nose", "ball", 1, 2)], 1, motion.frames)])


def test_each_take_is_drawn_on_its_own_up_axis(data_dir):
    """The data holds each take's up axis and the turn that stands it along +y (take_up's); compared
    takes keep their own; a given up is every take's; the values stay the take's own."""
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    lying = with_static_root(walk, turn=(90.0, 0.0, 0.0), keep_world=False)
    zombie = mt.read_bvh(data_dir / "bvh" / "zombie.bvh")
    amc = cmu_take()
    takes = page_data(page([lying, walk, zombie, amc]))["takes"]
    assert [t["up"] for t in takes] == ["z", "y", "z", "y"]
    for t, motion in zip(takes, [lying, walk, zombie, amc]):
        np.testing.assert_array_equal(np.reshape(t["turn"], (3, 3)), take_up(motion).turn)
    assert np.array_equal(decoded(takes[0]), lying.values)  # drawn turned, stored as it is
    given = page_data(page([lying, walk], up="-x"))["takes"]
    assert [t["up"] for t in given] == ["-x", "-x"]
    np.testing.assert_array_equal(np.reshape(given[1]["turn"], (3, 3)), take_up(walk, "-x").turn)
    with pytest.raises(ValueError, match="up must be an axis"):
        page([walk], up="up")


def test_the_body_is_followed_and_what_stands_still_above_it_is_not_drawn(data_dir):
    """A game rig (six channels everywhere, a static root): its body is the hips and the static
    root is marked still; the joints, channels and values are still the take's own."""
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    rig = with_static_root(with_offset_channels(walk), shift=(300.0, 0.0, -200.0))
    plain, game = page_data(page([walk, rig]))["takes"]
    assert (plain["body"], plain["still"]) == (0, [])
    names = rig.skeleton.joint_names
    assert (game["body"], game["still"]) == (names.index("Hips"), [names.index("root")])
    assert game["joints"] == list(names) and game["channels"] == [list(c) for c in rig.channels]
    assert np.array_equal(decoded(game), rig.values)
    # a root that moves carries the body itself: nothing is hidden
    values = rig.values.copy()
    values[:, 0] += np.linspace(0.0, 50.0, rig.frames)
    moving = page_data(page([rig.replace(values=values)]))["takes"][0]
    assert (moving["body"], moving["still"]) == (0, [])


def test_cli_view_up_turns_every_take(tmp_path, data_dir, monkeypatch):
    from motiontheater.cli import main

    monkeypatch.chdir(tmp_path)
    take, other = data_dir / "bvh" / "zombie.bvh", data_dir / "bvh" / "walk01.bvh"
    found = page_data_of(main, ["view", str(take), str(other), "--no-open"], tmp_path / "zombie.html")
    assert [t["up"] for t in found["takes"]] == ["z", "y"]
    given = page_data_of(main, ["view", str(take), str(other), "--no-open", "--up", "y"], tmp_path / "zombie.html")
    assert [t["up"] for t in given["takes"]] == ["y", "y"]


def test_editor_steps_are_registered_steps():
    from motiontheater.model.registry import lookup

    kinds = [s["kind"] for s in EDIT_STEPS]
    assert kinds == ["slerp", "euler", "expmap", "aligned_expmap", "median3", "median", "mean", "binomial"]
    for spec in EDIT_STEPS:
        options = {o.name for o in lookup(spec["run"]).all_options}
        assert {"frames", "joints"} <= options
        assert ("size" in options) == spec["size"]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(takes=[]), "at least one take"),
        (dict(max_frames=1), "max_frames"),
        (dict(names=["a", "b"]), "one name"),
        (dict(contacts=[{"nose": np.zeros(40, bool)}]), "not a point"),
        (dict(contacts=[{"toe": np.zeros(39, bool)}]), "one flag per frame"),
    ],
)
def test_bad_arguments_are_refused(kwargs, message):
    takes = kwargs.pop("takes", [small_take()])
    with pytest.raises(ValueError, match=message):
        page(takes, **kwargs)


def test_empty_take_is_refused():
    motion = small_take()
    with pytest.raises(ValueError, match="no frames"):
        page([motion.replace(values=motion.values[:0])])


def test_write_page_writes_nothing_on_failure(tmp_path):
    target = tmp_path / "page.html"
    with pytest.raises(ValueError):
        write_page([], target)
    assert not list(tmp_path.iterdir())
    write_page([small_take()], target)
    assert target.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_cli_view_writes_the_page(tmp_path, data_dir, monkeypatch, capsys):
    from motiontheater.cli import main

    monkeypatch.chdir(tmp_path)
    take, other = data_dir / "cmu" / "01_01.amc", data_dir / "cmu" / "01_01.bvh"
    assert main(["view", str(take), str(other), "--no-open"]) == 0
    assert "wrote 01_01.html" in capsys.readouterr().out
    data = page_data((tmp_path / "01_01.html").read_text(encoding="utf-8"))
    assert [t["name"] for t in data["takes"]] == ["01_01.amc", "01_01.bvh"]
    assert main(["view", str(take), "--no-open", "--max-frames", "1000", "-o", "small.html"]) == 0
    data = page_data((tmp_path / "small.html").read_text(encoding="utf-8"))
    assert data["takes"][0]["step"] == 3 and "1 frame in 3 of its 2,751" in data["note"]


def test_cli_view_marks_footplants(tmp_path, data_dir, monkeypatch, capsys):
    from motiontheater.cli import main

    monkeypatch.chdir(tmp_path)
    take = data_dir / "cmu" / "07_05-walk.amc"
    assert main(["contacts", str(take), "-o", "plants.csv"]) == 0
    detected = page_data_of(main, ["view", str(take), "--no-open", "--contacts"], tmp_path / "07_05-walk.html")
    given = page_data_of(
        main, ["view", str(take), "--no-open", "--contacts", "plants.csv"], tmp_path / "07_05-walk.html"
    )
    rows = detected["takes"][0]["plants"]
    assert [r["label"] for r in rows] == ["lfoot heel", "lfoot ball", "rfoot heel", "rfoot ball"]
    assert all(r["spans"] for r in rows) and given["takes"][0]["plants"] == rows
    assert "footplants on 07_05-walk.amc" in capsys.readouterr().out
    # an edited table is shown as edited: a plant removed is not marked
    lines = (tmp_path / "plants.csv").read_text().splitlines()
    removed = lines.pop(2).split(",")
    (tmp_path / "plants.csv").write_text("\n".join(lines) + "\n")
    edited = page_data_of(
        main, ["view", str(take), "--no-open", "--contacts", "plants.csv"], tmp_path / "07_05-walk.html"
    )
    row = next(r for r in edited["takes"][0]["plants"] if r["label"] == f"{removed[0]} {removed[1]}")
    assert [int(removed[2]) - 1, int(removed[3]) - 1] not in row["spans"]
    # plants of another take: a one-line reason, no page
    (tmp_path / "07_05-walk.html").unlink()
    other = data_dir / "cmu" / "01_01.amc"
    assert main(["view", str(other), "--no-open", "-o", "x.html", "--contacts", "plants.csv"]) == 2
    assert "another take" in capsys.readouterr().err and not (tmp_path / "x.html").exists()


def test_view_takes_the_old_name_of_contacts(tmp_path, data_dir, monkeypatch, capsys):
    """plants= and --plants still work for one release, each saying what to give instead."""
    from motiontheater.cli import main

    monkeypatch.chdir(tmp_path)
    take = data_dir / "cmu" / "07_05-walk.amc"
    new = page_data_of(main, ["view", str(take), "--no-open", "--contacts", "-o", "new.html"], tmp_path / "new.html")
    capsys.readouterr()
    old = page_data_of(main, ["view", str(take), "--no-open", "--plants", "-o", "old.html"], tmp_path / "old.html")
    err = capsys.readouterr().err
    assert err == "motiontheater view: --plants is deprecated: give --contacts (with no FILE)\n"
    assert old["takes"][0]["plants"] == new["takes"][0]["plants"] != []
    motion = mt.read_take(take)
    flags = {"ltoes": np.zeros(motion.frames, bool)}
    with pytest.warns(DeprecationWarning, match="contacts=") as caught:
        write_page([motion], tmp_path / "api.html", plants=[flags])
    assert caught[0].filename == __file__  # the warning names the caller's line
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError, match="once, as contacts="):
        page([motion], plants=[flags], contacts=[flags])


def page_data_of(main, argv, path):
    assert main(argv) == 0
    return page_data(path.read_text(encoding="utf-8"))


@pytest.mark.parametrize("verb", ["view", "plot", "render", "c3d"])
def test_cli_help_teaches(verb, capsys):
    from motiontheater.cli import main

    with pytest.raises(SystemExit) as exit:
        main([verb, "--help"])
    assert exit.value.code == 0
    text = capsys.readouterr().out
    assert "Example: motiontheater " + verb in " ".join(text.split())
