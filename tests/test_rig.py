"""The rig model: the body joint and the channels that only hold offsets, seen through a BodyView
that steps work on and restore from, on real takes and the variants other producers would write."""

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.model.rig import body_joint, body_view
from variants import with_offset_channels, with_static_root

BVHS = real_files("*/*.bvh")


def positions_by_name(motion):
    p = motion.positions()
    return {n: p[:, i] for i, n in enumerate(motion.skeleton.point_names)}


@pytest.mark.parametrize("path", BVHS, ids=ids(BVHS))
def test_every_real_bvh_has_a_body_and_a_view_that_draws_it(path):
    motion = mt.read_bvh(path)
    view = body_view(motion)
    assert view.motion.frames == motion.frames
    seen, drawn = positions_by_name(view.motion), positions_by_name(motion)
    size = max(1.0, float(np.nanmax(np.ptp(motion.skeleton.rest_positions(), axis=0))))
    for name, points in seen.items():  # offsets folded as they stand in frame 1: within what a file prints
        np.testing.assert_allclose(points, drawn[name], rtol=0, atol=1e-5 * size)
    assert view.restore(view.motion).values.tobytes() == motion.values.tobytes()


@pytest.mark.parametrize("name", ["walk01.bvh", "16_15.bvh", "jesse_dance.bvh"])
def test_a_static_root_and_offset_channels_change_nothing(data_dir, name):
    take = mt.read_bvh(next(data_dir.glob(f"*/{name}")))
    game = with_static_root(with_offset_channels(take))
    assert len(game.skeleton.channels) > len(take.skeleton.channels) + 3
    hips = game.skeleton.bone_names[0]
    assert body_joint(take) == "root" and body_joint(game) == hips
    view = body_view(game)
    assert view.body == hips and view.above is None
    assert view.motion.skeleton.channels == take.skeleton.channels  # the same layout as the take
    assert view.motion.values.tobytes() == take.values.tobytes()  # and the same numbers
    # a result on the view goes back into the game rig's layout, the offsets and static root as found
    smoothed = view.motion.median(size=5)
    back = view.restore(smoothed)
    assert back.skeleton is game.skeleton
    expected = with_static_root(with_offset_channels(take.median(size=5)))
    assert back.values.tobytes() == expected.values.tobytes()


def test_a_turned_static_root_is_folded_into_the_body(data_dir):
    take = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    z_up = with_static_root(take, turn=(90.0, 0.0, 0.0), shift=(10.0, -3.0, 2.5))  # an exporter's z-up frame
    view = body_view(z_up)
    assert view.above is not None
    drawn, seen = positions_by_name(z_up), positions_by_name(view.motion)
    for name, points in seen.items():
        np.testing.assert_allclose(points, drawn[name], atol=1e-9)
    np.testing.assert_allclose(view.restore(view.motion).values, z_up.values, atol=1e-9)


def test_the_body_is_the_first_joint_that_travels_else_the_hips_by_name(data_dir):
    take = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    still = take.replace(values=np.broadcast_to(take.values[:1], take.values.shape).copy())
    assert body_joint(still) == "root"  # the root is called Hips in the file, and that is the root
    standing = with_static_root(with_offset_channels(still))
    assert body_joint(standing) == "Hips"  # nothing travels: the hips by name
    asf = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))
    assert body_view(asf).identity


@pytest.mark.parametrize("name", ["walk01.bvh", "16_15.bvh"])
def test_feet_steps_on_a_game_rig_are_the_takes_own(data_dir, name):
    """Six channels on every joint and a static root above the hips: the footplants, the cleanup
    and its metrics are those of the take as its producer laid it out, the game rig's offsets and
    static root written back as found."""
    take = mt.read_bvh(next(data_dir.glob(f"*/{name}")), unit="cm")
    game = with_static_root(with_offset_channels(take))
    result, on_game = mt.clean_footskate(take), mt.clean_footskate(game)
    assert on_game.contacts.plants == result.contacts.plants
    assert on_game.motion.values.tobytes() == with_static_root(with_offset_channels(result.motion)).values.tobytes()
    before, after = mt.skate_metrics(game), mt.skate_metrics(on_game.motion, on_game.contacts)
    assert before.text() == mt.skate_metrics(take).text()
    assert after.text() == mt.skate_metrics(result.motion, result.contacts).text()
    assert game.cleanup().values.tobytes() == on_game.motion.values.tobytes()


NO_FEET = {"rest.bvh": "holds 1 frame", "sinusoidal.bvh": "a synthetic 3-bone rig, no legs"}


@pytest.mark.parametrize(
    "path", [p for p in BVHS if p.name not in NO_FEET], ids=ids([p for p in BVHS if p.name not in NO_FEET])
)
def test_every_real_bvh_is_cleaned_within_the_bounds(path):
    """The issue's bounds on the take's own plants: sliding mean <= 1 mm, max <= 5 mm, penetration <= 5 mm."""
    result = mt.clean_footskate(mt.read_bvh(path))
    report = mt.skate_metrics(result.motion, result.contacts, legs=result.legs, ground=result.ground)
    for foot in report.feet:
        assert foot.sliding_mean_mm <= 1.0 and foot.sliding_max_mm <= 5.0 and foot.penetration_mm <= 5.0, report.text()


@pytest.mark.parametrize("preserve", ["ground", "literal"])
def test_the_combiner_preserves_the_body_of_a_game_rig(data_dir, preserve):
    """A splice of a game rig's take keeps its hips continuous, as it does the take's own root:
    the static root above them stays where it stands."""
    take = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    game = with_static_root(with_offset_channels(take))
    options = dict(cut=(1, 60), scale=(80, 140), preserve=preserve)
    expected = with_static_root(with_offset_channels(mt.combine(take, take, **options)))
    got = mt.combine(game, game, **options)
    assert got.skeleton is game.skeleton and got.frames == expected.frames
    assert got.values.tobytes() == expected.values.tobytes()


def test_a_track_of_another_rate_is_refused_with_the_way_through(data_dir):
    take = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    fast = take.replace(frame_rate=4 * take.frame_rate)
    with pytest.raises(ValueError, match=r"new: a motion at 96 Hz and the old one at 24 Hz: .* resample it first"):
        mt.combine(take, fast, cut=(1, 10))


@pytest.mark.parametrize("name", ["walk01.bvh", "16_15.bvh"])
def test_retargeting_from_and_onto_a_game_rig_retargets_its_body(data_dir, name):
    """A game rig's static root and offset channels are no joints to follow or to drive: from it,
    the result is the take's own; onto it, the take's layout with its offsets and static root."""
    take = mt.read_bvh(next(data_dir.glob(f"*/{name}")), unit="cm")
    game = with_static_root(with_offset_channels(take))
    cmu = mt.read_asf(data_dir / "cmu" / "01.asf")
    np.testing.assert_allclose(mt.retarget(game, cmu).values, mt.retarget(take, cmu).values, rtol=0, atol=1e-9)
    walk = mt.read_amc(data_dir / "cmu" / "01_01.amc", cmu)
    walk = walk.replace(values=walk.values[:240])
    onto_game, onto_take = mt.retarget(walk, game.skeleton), mt.retarget(walk, take.skeleton)
    assert onto_game.skeleton is game.skeleton
    expected = with_static_root(with_offset_channels(onto_take))
    np.testing.assert_allclose(onto_game.values, expected.values, rtol=0, atol=1e-9)


def test_batch_cleans_and_retargets_game_rig_takes_as_the_api_does(data_dir, tmp_path, capsys):
    """The rig issue's batch: a recipe with the footskate cleanup over game-rig takes (a static root,
    offset channels everywhere) runs on every take, each output the API's result."""
    from motiontheater.cli import main

    inputs, out = tmp_path / "in", tmp_path / "out"
    inputs.mkdir()
    takes = {}
    for name in ("walk01.bvh", "16_15.bvh", "bvhTools_test2_lafan1.bvh"):
        game = with_static_root(with_offset_channels(mt.read_bvh(next(data_dir.glob(f"*/{name}")))), shift=(100, 0, 50))
        mt.write_bvh(game, inputs / name)
        takes[name] = mt.read_bvh(inputs / name)
    recipe = tmp_path / "recipe.toml"
    recipe.write_text('[[step]]\nrun = "median"\nsize = 5\n\n[[step]]\nrun = "cleanup"\n')
    assert main(["batch", str(inputs), "--recipe", str(recipe), "-o", str(out), "--quiet"]) == 0, capsys.readouterr()
    for name, take in takes.items():
        expected = take.median(size=5).cleanup()
        np.testing.assert_array_equal(mt.read_bvh(out / name).values, mt.read_bvh(_written(expected, tmp_path)).values)


def _written(motion, folder):
    path = folder / "expected.bvh"
    mt.write_bvh(motion, path)
    return path
