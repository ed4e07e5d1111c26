"""Footskate cleanup on real captures: legs, floor and footplants found, the cleanup's bounds in five
states of every take (as captured, drifting, smoothed, spliced, legs resized), edited plants
honoured, bad input refused, the metrics, and the step on the command line and in recipes."""

import dataclasses
import itertools
import json
from pathlib import Path

import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA
from corpus import ids, real_files
from motiontheater.cli import main
from motiontheater.feet.contacts import Contacts, Plant
from motiontheater.feet.footskate import clean_footskate, contacts_of, prepare
from motiontheater.feet.legs import find_legs, leg_arrays, resolve_legs
from motiontheater.feet.skate import knee_bends, measure, skate_metrics
from motiontheater.model.rig import body_view
from mtcore.kinematics import world_kinematics

CMU = 0.0254 / 0.45  # metres per CMU/HDM05 unit
TAKES = {  # take: (skeleton, file, metres per unit for BVH)
    "01_01": ("cmu/01.asf", "cmu/01_01.amc", None),
    "02_01": ("cmu/02.asf", "cmu/02_01.amc", None),
    "07_05": ("cmu/07-walk.asf", "cmu/07_05-walk.amc", None),
    "09_06": ("cmu/09-run.asf", "cmu/09_06-run.amc", None),
    "16_15": ("cmu/16.asf", "cmu/16_15.amc", None),
    "hdm05 jog bd": ("hdm05/HDM_bd.asf", "hdm05/HDM_bd_jogLeftCircle4StepsRstart_001_120.amc", None),
    "hdm05 jog bk": ("hdm05/HDM_bk.asf", "hdm05/HDM_bk_jogLeftCircle4StepsRstart_003_120.amc", None),
    "bvh 01_01": (None, "cmu/01_01.bvh", CMU),
    "bvh 16_15 (heel from the take)": (None, "cmu/16_15.bvh", 0.01),
    "bvh zombie (z up)": (None, "bvh/zombie.bvh", 0.084),
}
STATES = ("as captured", "drifting", "smoothed", "spliced", "legs long", "legs short")
_CACHE: dict = {}


def load(take: str) -> tuple[mt.Motion, float | None]:
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    asf, path, mpu = TAKES[take]
    motion = mt.read_bvh(DATA / path) if asf is None else mt.read_amc(DATA / path, mt.read_asf(DATA / asf))
    if take == "bvh 01_01":  # its first frame is a T-pose, not the take (see the corpus's README)
        motion = motion.crop(motion.first_frame + 1, motion.last_frame)
    return motion, mpu


def resized_legs(motion: mt.Motion, factor: float) -> mt.Motion:
    """The same channels on a skeleton whose thighs and shins are ``factor`` times as long."""
    skeleton = motion.skeleton
    legs = resolve_legs(skeleton)
    turned = {name for leg in legs.legs for name in (leg.hip, leg.knee)}
    if skeleton.convention == "bvh":  # an offset is the segment of the joint above
        moved = {skeleton.children(name)[0] for name in turned}
        bones = tuple(
            dataclasses.replace(b, direction=tuple(np.array(b.direction) * factor), length=b.length * factor)
            if b.name in moved
            else b
            for b in skeleton.bones
        )
    else:
        bones = tuple(
            dataclasses.replace(b, length=b.length * factor) if b.name in turned else b for b in skeleton.bones
        )
    return motion.replace(skeleton=dataclasses.replace(skeleton, bones=bones))


def state_of(take: str, state: str) -> tuple[mt.Motion, float | None]:
    motion, mpu = load(take)
    unit = mpu or motion.skeleton.meters_per_unit
    if state == "drifting":  # the root drifts 3 cm to and fro every 2 s
        values = motion.values.copy()
        values[:, motion.columns("root", "tx")[0]] += 0.03 / unit * np.sin(2 * np.pi * motion.times / 2.0)
        motion = motion.replace(values=values)
    elif state == "smoothed":
        motion = motion.mean(size=15)
    elif state == "spliced":  # the take laid over itself 20 frames on, blended over 10 frames
        a, last = motion.first_frame + motion.frames // 3, motion.last_frame
        motion = mt.combine(motion, motion, cut=(a + 20, last), scale=(a, last - 20), blend=10)
    elif state in ("legs long", "legs short"):
        motion = resized_legs(motion, 1.08 if state == "legs long" else 0.92)
    return motion, mpu


def cleaned(take: str, state: str):
    """(input, its cleanup, metres per unit), computed once per run."""
    if (take, state) not in _CACHE:
        motion, mpu = state_of(take, state)
        result = clean_footskate(motion, meters_per_unit=mpu)
        _CACHE[(take, state)] = (motion, result, result.meters_per_unit)
    return _CACHE[(take, state)]


# ---------------------------------------------------------------- legs, up, floor

EXPECTED_LEGS = {
    "cmu/01.asf": ("lfemur", "ltibia", "lfoot", "ltoes"),
    "hdm05/HDM_dg.asf": ("lfemur", "ltibia", "lfoot", "ltoes"),
    "bvh/walk01.bvh": ("LeftUpLeg", "LeftLeg", "LeftFoot", None),
    "bvh/test_mocapbank.bvh": ("LeftHip", "LeftKnee", "LeftAnkle", None),
    "bvh/test_freebvh.bvh": ("mixamorig:LeftUpLeg", "mixamorig:LeftLeg", "mixamorig:LeftFoot", "mixamorig:LeftToeBase"),
    "bvh/AV_8Walk_Meredith_HVHA_Rep1.bvh": ("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase"),
    "cmu/16_15.bvh": ("lfemur", "ltibia", "lfoot", "ltoes"),
}


@pytest.mark.parametrize("path", EXPECTED_LEGS)
def test_legs_are_found_by_name_and_hierarchy(path, data_dir):
    skeleton = (mt.read_bvh(data_dir / path) if path.endswith(".bvh") else None) or None
    skeleton = skeleton.skeleton if skeleton is not None else mt.read_asf(data_dir / path)
    left, right = find_legs(skeleton)
    assert (left.hip, left.knee, left.ankle, left.toe) == EXPECTED_LEGS[path]
    assert (left.side, right.side) == ("left", "right")
    assert right.ankle != left.ankle and right.hip != left.hip


def test_an_asf_converted_from_bvh_is_read_by_its_segments(data_dir):
    # to_asf names a bone after the joint it starts at: its "LeftUpLeg" runs from the hip to the knee
    converted = mt.to_asf(mt.read_bvh(data_dir / "cmu" / "01_01.bvh")).skeleton
    left, _ = find_legs(converted)
    assert (left.hip, left.knee, left.ankle, left.toe) == ("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase")


def test_a_skeleton_without_feet_is_refused_with_the_reason(data_dir):
    skeleton = mt.read_asf(data_dir / "edge" / "test.asf")  # LeftHip -> LeftKnee -> LeftAnkle, no foot
    with pytest.raises(ValueError, match="no left leg .*'LeftAnkle' is as long as a shin and has no foot below it"):
        find_legs(skeleton)
    motion = mt.read_amc(data_dir / "edge" / "test.amc", skeleton)
    with pytest.raises(ValueError, match="no left leg"):
        clean_footskate(motion)


def test_legs_can_be_named(data_dir):
    skeleton = mt.read_asf(data_dir / "cmu" / "01.asf")
    names = ["lfemur", "ltibia", "lfoot", "rfemur", "rtibia", "rfoot"]
    left, right = find_legs(skeleton, names)
    assert (left.toe, right.ankle) == (None, "rfoot")
    with pytest.raises(ValueError, match="6 or 8 names"):
        find_legs(skeleton, names[:5])
    with pytest.raises(mt.UnknownNameError, match="no bone 'lshin'"):
        find_legs(skeleton, ["lfemur", "lshin", *names[2:]])
    with pytest.raises(ValueError, match="'lfoot' is not a child of 'lfemur'"):
        resolve_legs(skeleton, ["lfemur", "lfoot", "ltibia", *names[3:]])
    with pytest.raises(ValueError, match="the hip 'lhipjoint' has no rotation channels"):
        resolve_legs(skeleton, ["lhipjoint", "lfemur", "ltibia", *names[3:]])


@pytest.mark.parametrize(("take", "up"), [("07_05", "y"), ("bvh 01_01", "y"), ("bvh zombie (z up)", "z")])
def test_the_up_axis(take, up):
    motion, mpu = load(take)
    _arrays, ground, _ = prepare(motion, meters_per_unit=mpu)
    assert ground.up == tuple(float(axis == up) for axis in "xyz")


def test_the_floor_leans_as_the_capture_does_and_points_rest_at_their_clearance():
    motion, _ = load("07_05")  # the floor of this capture climbs 6 cm over its 4 m walk
    arrays, ground, mpu = prepare(motion)
    assert 0.8 < ground.tilt_degrees < 1.5
    assert ground.clearance.min() == 0 and (ground.clearance >= 0).all()
    table = contacts_of(None, motion, arrays, ground, mpu)
    heights = ground.heights(arrays.points)[:, :, :2][table.masks(arrays.legs)] * mpu
    assert abs(np.median(heights)) < 0.005  # planted points are where they rest
    level, _ = load("07_05")
    _, flat, _ = prepare(level, floor=0.0)
    assert flat.slope == (0.0, 0.0, 0.0) and flat.level == 0.0


def test_a_floor_above_the_character_is_refused():
    motion, _ = load("07_05")
    with pytest.raises(ValueError, match=r"the floor at 30 \(along y\) is above the character"):
        clean_footskate(motion, floor=30.0)


def test_a_heel_the_rest_pose_cannot_give_comes_from_the_take():
    # this BVH's rest pose points the feet down the legs; the heel is found below the ankle in flat stance
    motion, mpu = load("bvh 16_15 (heel from the take)")
    legs = resolve_legs(motion.skeleton)
    assert np.isnan(legs.segments[:, 3]).all()
    arrays, ground, mpu = prepare(motion, meters_per_unit=mpu)
    assert np.isfinite(arrays.legs.segments[:, 3]).all()
    flat = contacts_of(None, motion, arrays, ground, mpu).masks(arrays.legs).all(axis=-1)
    heel, ball = arrays.points[:, :, 3], arrays.points[:, :, 2]
    drop = ((heel - ball) @ np.asarray(ground.up))[flat] * mpu
    assert np.abs(np.median(drop)) < 0.01  # heel and ball at one height when the foot is flat
    with pytest.raises(ValueError, match="no flat stance"):
        leg_arrays(motion.replace(values=motion.values[:2]), legs)


# ---------------------------------------------------------------- footplants


@pytest.mark.parametrize("state", STATES)
@pytest.mark.parametrize("take", TAKES)
def test_detected_plants_hold_every_still_low_frame_and_no_fast_one(take, state):
    # speeds by central differences (numpy.gradient), and no planted frame fast by forward or backward ones
    # either, unless the central one calls it still: a one-frame jitter of the markers
    motion, mpu = state_of(take, state)
    arrays, ground, mpu = prepare(motion, meters_per_unit=mpu)
    masks = contacts_of(None, motion, arrays, ground, mpu).masks(arrays.legs)
    heights = ground.heights(arrays.points)[:, :, :2] * mpu
    for leg in range(len(arrays.legs)):
        for k, column in enumerate((3, 2)):
            p = arrays.points[leg, :, column] * mpu
            central = np.linalg.norm(np.gradient(p, axis=0), axis=-1) * motion.frame_rate
            step = np.linalg.norm(np.diff(p, axis=0), axis=-1) * motion.frame_rate
            either = np.maximum(np.r_[step, 0.0], np.r_[0.0, step])
            still = (heights[leg, :, k] < 0.02) & (central < 0.05)
            assert masks[leg, still, k].all(), f"leg {leg} point {k}: a still frame on the floor is not planted"
            assert not masks[leg, central > 0.5, k].any(), f"leg {leg} point {k}: a planted frame is fast"
            assert not masks[leg, (either > 0.5) & ~still, k].any(), f"leg {leg} point {k}: a planted frame is fast"


def test_plants_of_a_walk_are_heel_then_ball_once_a_step():
    motion, _ = load("07_05")
    arrays, ground, mpu = prepare(motion)
    table = contacts_of(None, motion, arrays, ground, mpu)
    for foot in ("lfoot", "rfoot"):
        heels, balls = table.of(foot, "heel"), table.of(foot, "ball")
        steps = [h for h in heels if h.last - h.first > 30 and h.last < motion.last_frame]
        assert len(steps) in (2, 3)
        for heel in steps:  # a heel strike is followed by the ball coming down within the same plant
            assert any(heel.first <= ball.first <= heel.last for ball in balls)
        assert all(isinstance(p.first, int) and isinstance(p.last, int) for p in heels + balls)


def test_the_contacts_table_round_trips_and_reports_bad_lines(tmp_path):
    table = Contacts(
        [Plant("lfoot", "heel", 12, 57), Plant("lfoot", "ball", 31, 80), Plant("rfoot", "ball", 3, 9)], 1, 517, 120.0
    )
    path = tmp_path / "plants.csv"
    table.to_csv(path)
    assert path.read_text().splitlines()[:3] == [
        "# motiontheater contacts: frames 1..517 at 120 Hz",
        "foot,point,first,last",
        "lfoot,ball,31,80",
    ]
    assert Contacts.read_csv(path, first_frame=1, frames=517).plants == table.plants
    with pytest.raises(
        mt.FormatError,
        match=r"plants.csv, line 1: these contacts are for frames 1..517, and the take has frames 1..400",
    ):
        Contacts.read_csv(path, first_frame=1, frames=400)
    bad = tmp_path / "bad.csv"
    bad.write_text("foot,point,first,last\nlfoot,heel,12,x\n")
    with pytest.raises(mt.FormatError, match=r"bad.csv, line 2: expected whole frame numbers, found '12' and 'x'"):
        Contacts.read_csv(bad, first_frame=1, frames=517)
    bad.write_text("foot,point,first,last\nlfoot,toe,12,20\n")
    with pytest.raises(mt.FormatError, match="line 2: the point must be heel or ball, found 'toe'"):
        Contacts.read_csv(bad, first_frame=1, frames=517)
    bad.write_text("foot,point,first,last\nlfoot,heel,500,600\n")
    with pytest.raises(mt.FormatError, match=r"line 2: plant 500..600 is not within the take's frames 1..517"):
        Contacts.read_csv(bad, first_frame=1, frames=517)
    bad.write_text("lfoot,heel,12,20\n")
    with pytest.raises(mt.FormatError, match="line 1: expected the header 'foot,point,first,last'"):
        Contacts.read_csv(bad, first_frame=1, frames=517)
    merged = Contacts([Plant("lfoot", "heel", 1, 5), Plant("lfoot", "heel", 6, 9)], 1, 20)
    assert merged.plants == (Plant("lfoot", "heel", 1, 9),)


def test_contacts_of_another_take_are_refused(tmp_path):
    motion, _ = load("07_05")
    other, _ = load("16_15")
    arrays, ground, mpu = prepare(other)
    path = tmp_path / "16_15.csv"
    contacts_of(None, other, arrays, ground, mpu).to_csv(path)
    with pytest.raises(mt.FormatError, match="these contacts are for frames 1..471, and the take has frames 1..517"):
        clean_footskate(motion, path)
    zombie, mpu = load("bvh zombie (z up)")
    arrays, ground, mpu = prepare(zombie, meters_per_unit=mpu)
    foreign = Contacts([Plant("LeftFoot", "heel", 1, 10)], motion.first_frame, motion.frames)
    with pytest.raises(mt.UnknownNameError, match="foot 'LeftFoot', which is not a foot of this skeleton"):
        clean_footskate(motion, foreign)


# ---------------------------------------------------------------- the cleanup's bounds


def channels_of_legs(motion: mt.Motion, legs) -> set[int]:
    return {c for name in legs.joint_names for c in motion.columns(name)} | set(
        motion.columns("root", ("tx", "ty", "tz"))
    )


@pytest.mark.parametrize("state", STATES)
@pytest.mark.parametrize("take", [t for t in TAKES if not t.startswith("bvh")] + ["bvh 01_01"])
def test_the_cleanup_holds_its_bounds(take, state):
    motion, result, mpu = cleaned(take, state)
    legs = result.legs
    after = leg_arrays(result.motion, legs, meters_per_unit=mpu)
    before = leg_arrays(motion, legs, meters_per_unit=mpu)
    report = measure(after, result.ground, result.contacts, motion.frame_rate, result.meters_per_unit)
    assert report.worst("sliding_mean_mm") <= 1.0
    assert report.worst("sliding_max_mm") <= 5.0
    assert report.worst("penetration_mm") <= 5.0
    assert report.worst("float_mm") <= 1.0
    # the skating ratio on the detected plants; 0 before the cleanup too, by construction (detection
    # plants no point faster than 0.45 m/s, skating needs 0.5): a table that plants moving feet shows it counts
    # (test_the_planted_skating_ratio_counts_plants_over_a_swing)
    assert report.worst("planted_skating_ratio") <= 0.01
    # only the root's translation and the legs' joints change
    others = [c for c in range(motion.values.shape[1]) if c not in channels_of_legs(motion, legs)]
    np.testing.assert_array_equal(result.motion.values[:, others], motion.values[:, others])
    # no knee pops: the largest frame-to-frame change of a knee's bend at most 2 degrees over the input's
    pops = [np.abs(np.diff(knee_bends(a), axis=1)).max() for a in (before, after)]
    assert pops[1] <= pops[0] + 2.0
    assert result.root_rms_mm() < 30.0  # the root moves by millimetres, where a leg falls short


def test_a_cleanup_of_a_clean_cleanup_moves_little():
    # the feet, not the angles or the knees: a knee near straight turns degrees, and moves a
    # centimetre sideways, for a fraction of a millimetre between hip and ankle
    _motion, result, mpu = cleaned("07_05", "as captured")
    again = clean_footskate(result.motion, result.contacts, legs=result.legs)
    first, second = (leg_arrays(r.motion, result.legs).points[:, :, 1:] for r in (result, again))
    assert np.abs(second - first).max() * mpu < 0.002


def test_removed_plants_are_not_enforced_and_added_ones_are():
    motion, result, mpu = cleaned("07_05", "drifting")
    legs = result.legs
    table = result.contacts
    # the heel plant that slides most in the input
    before = leg_arrays(motion, legs)
    slides = []
    for plant in table.plants:
        leg, column = legs.feet.index(plant.foot), {"heel": 3, "ball": 2}[plant.point]
        rows = slice(plant.first - motion.first_frame, plant.last - motion.first_frame + 1)
        p = before.points[leg, rows, column]
        slides.append((np.linalg.norm(p - p[0], axis=-1).max() * mpu, plant))
    _, dropped = max(slides, key=lambda s: s[0])
    fewer = Contacts([p for p in table.plants if p != dropped], table.first_frame, table.frames)
    edited = clean_footskate(motion, fewer, legs=legs)
    leg, column = legs.feet.index(dropped.foot), {"heel": 3, "ball": 2}[dropped.point]
    rows = slice(dropped.first - motion.first_frame, dropped.last - motion.first_frame + 1)
    held = leg_arrays(result.motion, legs).points[leg, rows, column]
    free = leg_arrays(edited.motion, legs).points[leg, rows, column]
    assert np.linalg.norm(held - held[0], axis=-1).max() * mpu < 0.001
    assert np.linalg.norm(free - free[0], axis=-1).max() * mpu > 0.005  # no longer held
    # a plant added where the ball was not planted: the ball is held there
    ball = [p for p in table.of(dropped.foot, "ball")]
    gaps = [(a.last + 1, b.first - 1) for a, b in itertools.pairwise(ball) if b.first - a.last > 20]
    first, last = gaps[0][0] + 2, gaps[0][0] + 8
    more = Contacts([*table.plants, Plant(dropped.foot, "ball", first, last)], table.first_frame, table.frames)
    added = clean_footskate(motion, more, legs=legs)
    rows = slice(first - motion.first_frame, last - motion.first_frame + 1)
    p = leg_arrays(added.motion, legs).points[leg, rows, 2]
    q = before.points[leg, rows, 2]
    assert np.linalg.norm(p - p[0], axis=-1).max() * mpu < 0.001
    assert np.linalg.norm(q - q[0], axis=-1).max() * mpu > 0.005


def test_without_plants_only_sinking_feet_change():
    motion, _ = load("09_06")  # a run: the feet are in the air most of the time
    result = clean_footskate(motion, Contacts([], motion.first_frame, motion.frames))
    assert (result.root_offsets == 0).all()
    arrays = leg_arrays(motion, result.legs)
    sinking = (result.ground.heights(arrays.points) < 0).any(axis=(0, 2))
    near = np.convolve(sinking, np.ones(2 * 12 + 1), mode="same") > 0  # a lift fades over half the blend
    unchanged = (result.motion.values == motion.values).all(axis=1)
    assert sinking.any() and (~near).any()
    assert unchanged[~near].all()
    assert not unchanged[sinking].any()
    after = measure(leg_arrays(result.motion, result.legs), result.ground, result.contacts, motion.frame_rate, 1.0)
    assert after.worst("penetration_mm") < 0.01  # thousandths of a unit: the 2-channel ankle's residue


# ---------------------------------------------------------------- metrics


def test_the_skating_ratio_is_the_papers(rng):
    # the papers' own definition, on horizontal speeds at 20 Hz: 5 cm, 0.5 m/s, a 5-frame mean (zeros past the ends)
    from scipy.ndimage import uniform_filter1d

    motion, _ = load("07_05")
    arrays, ground, mpu = prepare(motion)
    table = contacts_of(None, motion, arrays, ground, mpu)
    report = measure(arrays, ground, table, motion.frame_rate, mpu)
    up = np.asarray(ground.up)
    heights = ground.heights(arrays.points) * mpu
    for leg, foot in enumerate(report.feet):
        skating = np.zeros(motion.frames - 1, bool)
        for k, column in enumerate((3, 2)):
            p = arrays.points[leg, :, column]
            p = (p - (p @ up)[:, None] * up) * mpu
            speed = np.linalg.norm(np.diff(p, axis=0), axis=-1) * motion.frame_rate
            mean = uniform_filter1d(speed, size=31, mode="constant")  # 0.25 s at 120 Hz
            low = heights[leg, :, k] < 0.05
            skating |= low[:-1] & low[1:] & (speed > 0.5) & (mean > 0.5)
        assert foot.skating_ratio == pytest.approx(skating.mean(), abs=1e-12)
        assert 0.1 < foot.skating_ratio < 0.5  # a walk's swing passes the floor low and fast


def test_the_planted_skating_ratio_counts_plants_over_a_swing():
    # a ball plant laid over the start of each foot's swing (low and fast after push-off): it skates there
    # before the cleanup, and the cleanup holds it
    motion, result, mpu = cleaned("16_15", "as captured")
    table = result.contacts

    def metrics(m: mt.Motion, contacts: Contacts):
        return skate_metrics(m, contacts, legs=result.legs, ground=result.ground, meters_per_unit=mpu)

    assert metrics(motion, table).worst("planted_skating_ratio") == 0  # the detected plants hold no fast point
    swings = []
    for foot in result.legs.feet:
        balls = table.of(foot, "ball")
        start = next(a.last + 1 for a, b in itertools.pairwise(balls) if b.first - a.last > 30)
        swings.append(Plant(foot, "ball", start + 2, start + 14))
    edited = Contacts([*table.plants, *swings], table.first_frame, table.frames)
    before = metrics(motion, edited)
    assert min(f.planted_skating_ratio for f in before.feet) > 0.01
    after = metrics(clean_footskate(motion, edited, legs=result.legs).motion, edited)
    assert after.worst("planted_skating_ratio") <= 0.01


def test_the_metrics_of_a_sliding_take_and_of_its_cleanup():
    motion, result, _mpu = cleaned("07_05", "drifting")
    before = skate_metrics(motion, result.contacts, legs=result.legs, ground=result.ground)
    after = skate_metrics(result.motion, result.contacts, legs=result.legs, ground=result.ground)
    assert before.worst("sliding_max_mm") > 20 and after.worst("sliding_max_mm") < 1
    assert before.worst("penetration_mm") > 20 and after.worst("penetration_mm") < 1
    data = json.loads(after.to_json())
    assert [f["foot"] for f in data["feet"]] == ["lfoot", "rfoot"] and data["frames"] == motion.frames
    assert "| lfoot |" in after.text()


# ---------------------------------------------------------------- the step, the verbs


def test_the_step_is_a_method_a_pipeline_step_and_a_recipe(tmp_path):
    motion, result, _ = cleaned("07_05", "as captured")
    np.testing.assert_array_equal(motion.cleanup().values, result.motion.values)
    np.testing.assert_array_equal(mt.Pipeline.of("cleanup").apply(motion).values, result.motion.values)
    recipe = tmp_path / "steps.toml"
    recipe.write_text('[[step]]\nrun = "mean"\nsize = 15\n\n[[step]]\nrun = "cleanup"\nblend = 0.25\n')
    smoothed_clean = mt.Pipeline.read(recipe).apply(motion)
    np.testing.assert_array_equal(
        smoothed_clean.values, clean_footskate(motion.mean(size=15), blend=0.25).motion.values
    )


def test_the_verbs(tmp_path, capsys):
    take = DATA / "cmu" / "07_05-walk.amc"
    if not take.exists():
        pytest.skip("real capture corpus not found")
    plants, out = tmp_path / "plants.csv", tmp_path / "clean.amc"
    assert main(["contacts", str(take), "-o", str(plants)]) == 0
    rows = plants.read_text().splitlines()
    kept = "\n".join(rows[:-1]) + "\n"  # the last plant deleted, by hand
    plants.write_text(kept)
    assert main(["cleanup", str(take), "-o", str(out), "--contacts", str(plants)]) == 0
    motion, _ = load("07_05")
    table = Contacts.read_csv(plants, first_frame=1, frames=motion.frames)
    np.testing.assert_array_equal(
        mt.read_amc(out, motion.skeleton).values, clean_footskate(motion, table).motion.values
    )
    capsys.readouterr()
    assert (
        main(["skate", str(out), "--asf", str(DATA / "cmu" / "07-walk.asf"), "--contacts", str(plants), "--json"]) == 0
    )
    report = json.loads(capsys.readouterr().out)
    assert max(f["sliding_max_mm"] for f in report["feet"]) < 5
    assert main(["skate", str(take)]) == 0
    assert "sliding mean mm" in capsys.readouterr().out


def test_the_verbs_read_the_length_unit_given(capsys):
    """CMU's BVH conversions are in its ASF unit (inch / 0.45), told by their names and size; a unit
    given replaces it, and the metres measured follow."""
    take = DATA / "cmu" / "01_01.bvh"
    if not take.exists():
        pytest.skip("real capture corpus not found")
    reports = {}
    for unit in (None, "0.45", "in"):
        assert main(["skate", str(take), "--json", *(["--unit", unit] if unit else [])]) == 0
        reports[unit] = json.loads(capsys.readouterr().out)
    assert reports["in"] == json.loads(skate_metrics(mt.read_bvh(take, unit="in")).to_json())
    assert reports["0.45"] == reports[None] != reports["in"]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["edge/test.amc"], "no left leg in skeleton"),
        (["cmu/07_05-walk.amc", "--floor", "30"], "is above the character"),
        (["cmu/07_05-walk.amc", "--contacts", "{other}"], "they are for another take"),
        (["cmu/07_05-walk.amc", "--legs", "lfemur,ltibia"], "6 or 8 names"),
        (["bvh/sinusoidal.bvh"], "no left leg"),
    ],
)
def test_bad_input_is_refused_and_nothing_is_written(argv, message, tmp_path, capsys):
    if not DATA.is_dir():
        pytest.skip("real capture corpus not found")
    other = tmp_path / "other.csv"
    Contacts([Plant("lfoot", "heel", 1, 5)], 1, 100).to_csv(other)
    out = tmp_path / ("out" + Path(argv[0]).suffix)
    args = [str(DATA / argv[0]), "-o", str(out), *(a.replace("{other}", str(other)) for a in argv[1:])]
    assert main(["cleanup", *args]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_the_report_prints_no_negative_zero(data_dir):
    report = mt.skate_metrics(mt.read_take(data_dir / "cmu" / "01_01.amc"))
    foot = report.feet[0]
    tiny = dataclasses.replace(report, feet=(dataclasses.replace(foot, penetration_mm=-0.001, float_mm=-0.0),))
    assert "-0.00" not in tiny.text() and "| 0.00 | 0.00 |" in tiny.text()


REAL_TAKES = real_files("*/*.amc") + real_files("*/*.bvh")


@pytest.mark.parametrize("path", REAL_TAKES, ids=ids(REAL_TAKES))
def test_legs_placed_by_the_takes_kinematics_are_those_of_their_angles(path):
    """leg_arrays from the take's kinematics (the check's: mtcore.footskate.placed_legs) puts the
    hips and every leg point where leg_points of the legs' angles does, to rounding, on every
    rig; what the cleanup reads besides (angles, parents, chains, columns) is worked out, when
    read, as the legs' own kinematics give it."""
    view = body_view(mt.read_take(path)).motion
    try:
        legs = resolve_legs(view.skeleton)
    except ValueError as e:
        pytest.skip(f"no legs: {e}")
    kinematics = world_kinematics(view.values, view.skeleton.tree, turned=sorted({*legs.rotators[:, 2], *legs.parents}))
    placed, worked = leg_arrays(view, legs, kinematics=kinematics), leg_arrays(view, legs)
    derived_heels = bool(np.isnan(legs.segments[:, 3]).any())  # worked out from the take's angles
    assert ("angles" in vars(placed)) == derived_heels  # else placed without reading them
    scale = float(np.nanmax(np.abs(worked.points)))
    for name in ("points", "hips", "parents", "angles"):
        got, want = getattr(placed, name), getattr(worked, name)
        assert got.shape == want.shape and np.array_equal(np.isnan(got), np.isnan(want)), name
        np.testing.assert_allclose(
            got, want, rtol=0, atol=1e-12 * (1.0 if name in ("parents", "angles") else scale), err_msg=name
        )
    np.testing.assert_array_equal(placed.columns, worked.columns)
    for mine, theirs in zip(placed.chains, worked.chains):
        for field in ("axis", "axes", "segments"):
            np.testing.assert_array_equal(getattr(mine, field), getattr(theirs, field))
