"""Every step on every real BVH, and on the same takes as other producers lay them out: a game
studio's rig (a static root joint far from the origin, position channels on every joint that hold
its OFFSET), a z-up export (the take under a quarter-turned static root) and a take in
millimetres.  The motion must not change: each step's result draws the same points, in metres
and turned upright, as on the take as found."""

import re

import numpy as np
import pytest

import motiontheater as mt
from corpus import real_files
from motiontheater.feet.upright import take_up
from variants import with_offset_channels, with_static_root

BVHS = [p for p in real_files("*/*.bvh") if p.name != "rest.bvh"]  # rest.bvh: 1 frame, nothing to step
NO_LEGS = {"sinusoidal.bvh"}  # a synthetic 3-bone chain

VARIANTS = {
    "as found": lambda take: take,
    "game rig": lambda take: with_static_root(with_offset_channels(take), shift=(250.0, 0.0, -400.0)),
    "z-up": lambda take: with_static_root(take, turn=(90.0, 0.0, 0.0), keep_world=False),
    "in mm": lambda take: take.with_units(length_factor=1000 * take.skeleton.meters_per_unit, length="mm"),
}


def steps_for(take):
    """(name, step) pairs that every take goes through, their options chosen from its frames."""
    frames = take.frames
    middle = (take.first_frame + frames // 4, take.first_frame + frames // 2)
    found = [
        ("median", lambda m: m.median(size=5)),
        ("mean", lambda m: m.mean(size=5)),
        ("binomial", lambda m: m.binomial(size=3)),
        ("slerp", lambda m: m.slerp(frames=middle)),
        ("equalize", lambda m: m.equalize(gains=(0.5, 1.5)[: max(1, int(np.log2(frames)))])),
        ("butterworth", lambda m: m.butterworth(cutoff=min(6.0, 0.4 * m.frame_rate))),
        ("resample", lambda m: m.resample(rate=m.frame_rate / 2)),
        ("fill_gaps", lambda m: m.fill_gaps()),
        ("combine", lambda m: mt.combine(m, m, cut=(m.first_frame, m.first_frame + frames // 2), preserve="ground")),
    ]
    return found


TURNED_UP = {"y": "z", "z": "-y"}  # where a quarter turn about x takes each up axis


def drawn(motion, up):
    """World positions (frames, points, 3) in metres, stood along +y from ``up``."""
    return motion.positions(meters=True) @ take_up(motion, up).turn.T


def same_motion(got, expected, variant, atol=1e-6):
    """The same points in metres, each stood upright (the game rig's static root keeps every point
    where it was; the z-up one turns them), the static root's own point left out.  The up axes
    are the take's, as the variant lays it out (what finds them is tested in test_upright.py)."""
    up = take_up(expected).axis
    a, b = drawn(got, TURNED_UP[up] if variant == "z-up" else up), drawn(expected, up)
    if variant in ("game rig", "z-up"):
        a = a[:, 1:]
    for i, name in enumerate(expected.skeleton.point_names):
        np.testing.assert_allclose(a[:, i], b[:, i], rtol=0, atol=atol, err_msg=name)


CASES = [(p, v) for p in BVHS for v in VARIANTS]


@pytest.mark.parametrize(("path", "variant"), CASES, ids=[f"{p.name}-{v}" for p, v in CASES])
def test_every_step_moves_every_rig_as_it_moves_the_take(path, variant):
    take = mt.read_bvh(path)
    laid_out = VARIANTS[variant](take)
    for name, step in steps_for(take):
        try:
            expected = step(take)
        except ValueError as refused:  # too few frames for it: refused alike, in the same words
            with pytest.raises(ValueError, match=re.escape(str(refused))):
                step(laid_out)
            continue
        got = step(laid_out)
        assert got.skeleton.channels == laid_out.skeleton.channels, name
        assert got.frames == expected.frames and got.frame_rate == pytest.approx(expected.frame_rate), name
        assert np.isfinite(got.values).all() == np.isfinite(expected.values).all(), name
        same_motion(got, expected, variant)


FEET = [(p, v) for p in BVHS if p.name not in NO_LEGS for v in VARIANTS]


@pytest.mark.parametrize(("path", "variant"), FEET, ids=[f"{p.name}-{v}" for p, v in FEET])
def test_the_feet_steps_find_the_same_plants_and_metrics_on_every_rig(path, variant):
    take = mt.read_bvh(path)
    laid_out = VARIANTS[variant](take)
    result, on_variant = mt.clean_footskate(take), mt.clean_footskate(laid_out)
    assert on_variant.contacts.plants == result.contacts.plants
    before, after = mt.skate_metrics(laid_out), mt.skate_metrics(take)
    for mine, theirs in zip(before.feet, after.feet):
        assert mine.sliding_mean_mm == pytest.approx(theirs.sliding_mean_mm, abs=1e-3)
        assert mine.penetration_mm == pytest.approx(theirs.penetration_mm, abs=1e-3)
    same_motion(on_variant.motion, result.motion, variant)  # the IK solves in another frame: within a micrometre


@pytest.mark.parametrize(("path", "variant"), FEET, ids=[f"{p.name}-{v}" for p, v in FEET])
def test_every_rig_retargets_onto_cmu_and_back(data_dir, tmp_path, path, variant):
    take = mt.read_bvh(path)
    laid_out = VARIANTS[variant](take)
    cmu = mt.read_asf(data_dir / "cmu" / "01.asf")
    on_cmu = mt.retarget(laid_out, cmu, cleanup=False)
    expected = mt.retarget(take, cmu, cleanup=False)
    # a static root's turn (the z-up export) is the file's axes: on CMU's y-up rig it stands as the take does
    np.testing.assert_allclose(on_cmu.values, expected.values, rtol=0, atol=1e-6)
    written = tmp_path / "rig.bvh"  # the rig as a file of its own: a target read with its take
    mt.write_bvh(laid_out, written)
    target = mt.read_bvh(written).skeleton
    back = mt.retarget(on_cmu, target, cleanup=False)
    assert back.skeleton is target and np.isfinite(back.values).all()
