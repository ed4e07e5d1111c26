"""Retargeting on real captures: same rig (rotations carried over to 1e-9), other rigs (bone directions
within 5 degrees), the root scaled by the legs, units and up axes, maps, and bad input."""

import dataclasses
import itertools
from pathlib import Path

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.characters.retarget import RetargetPlan, _cleanup_options
from motiontheater.characters.rigs import CHAINS, match_chain, recognise
from motiontheater.model.errors import DuplicateError, UnknownNameError
from motiontheater.model.skeleton import Skeleton

UNITS = {"cmu/01_01.bvh": "0.45"}  # the CMU BVH conversion is in the ASF's unit, which its size does not tell


def read(data_dir: Path, name: str) -> mt.Motion:
    return mt.read_take(data_dir / name, unit=UNITS.get(name))


def skeleton(data_dir: Path, name: str) -> Skeleton:
    return mt.read_asf(data_dir / name) if name.endswith(".asf") else mt.read_bvh(data_dir / name).skeleton


@pytest.fixture(scope="module")
def cmu(data_dir):
    return mt.read_take(data_dir / "cmu" / "01_01.amc")


def pivots(motion: mt.Motion) -> np.ndarray:
    """(frames, joints, 3): where each joint turns (an ASF bone's start, a BVH joint itself), in metres."""
    points = motion.positions(meters=True)
    if motion.skeleton.convention == "bvh":
        return points
    return points[:, np.maximum(motion.skeleton.tree.parent, 0)]


def angles_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Degrees between vectors (..., 3), accurate near 0 (atan2 of sine and cosine)."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, -1)))


# --- the same rig -------------------------------------------------------------------------------


def test_same_rig_carries_every_local_rotation_over(data_dir, cmu):
    target = mt.read_asf(data_dir / "cmu" / "02.asf")
    plan = mt.plan_retarget(cmu.skeleton, target)
    assert plan.mode == "rotations"
    result = mt.retarget(cmu, target, cleanup=False)
    assert result.skeleton is target
    difference = np.abs(result.rotations(local=True) - cmu.rotations(local=True)).max()
    assert difference < 1e-9
    # the test means something: the two subjects' bones point up to 11 degrees apart at rest
    rest = angles_between(
        np.array([b.direction for b in cmu.skeleton.bones]), np.array([b.direction for b in target.bones])
    )
    assert rest.max() > 10


def test_same_rig_there_and_back_reproduces_the_channels(data_dir, cmu):
    there = mt.retarget(cmu, mt.read_asf(data_dir / "cmu" / "02.asf"), cleanup=False)
    back = mt.retarget(there, cmu.skeleton, cleanup=False)
    assert np.abs(back.values - cmu.values).max() < 1e-9
    assert (back.frame_rate, back.first_frame, back.frames) == (cmu.frame_rate, cmu.first_frame, cmu.frames)


@pytest.mark.parametrize("actor", ["bk", "dg"])
def test_hdm05_actor_onto_another(data_dir, actor):
    take = mt.read_take(data_dir / "hdm05" / "HDM_bd_kickLFront1Reps_003_120.amc")
    target = mt.read_asf(data_dir / "hdm05" / f"HDM_{actor}.asf")
    result = mt.retarget(take, target, cleanup=False)
    assert np.abs(result.rotations(local=True) - take.rotations(local=True)).max() < 1e-9


def test_directions_on_the_same_rig_follow_the_bones_instead(data_dir, cmu):
    target = mt.read_asf(data_dir / "cmu" / "02.asf")
    result = mt.retarget(cmu, target, mode="directions", cleanup=False)
    source, ours = pivots(cmu), pivots(result)
    for a, b in (("lfemur", "ltibia"), ("ltibia", "lfoot"), ("lhumerus", "lradius"), ("lowerback", "upperback")):
        i, k = (cmu.skeleton.joint_names.index(n) for n in (a, b))
        assert angles_between(ours[:, k] - ours[:, i], source[:, k] - source[:, i]).max() < 1e-6


# --- other rigs ---------------------------------------------------------------------------------

CROSS = [
    ("cmu/01_01.amc", "bvh/walk01.bvh"),
    ("bvh/walk01.bvh", "cmu/01.asf"),
    ("cmu/01_01.amc", "bvh/test_freebvh.bvh"),  # Mixamo
    ("bvh/test_mocapbank.bvh", "cmu/02.asf"),  # Biovision names
    ("cmu/01_01.amc", "bvh/zombie.bvh"),  # z-up, four spine joints
    ("cmu/16_15.bvh", "bvh/walk01.bvh"),  # CMU names in a BVH
    ("cmu/01_01.bvh", "hdm05/HDM_dg.asf"),  # the CMU BVH conversion
    ("cmu/01_01.amc", "bvh-producers/MoDi_000000_joints_1_frames_64.bvh"),  # SMPL names, metres
    ("bvh-producers/bvhTools_test3.bvh", "cmu/02.asf"),  # Blender Rigify names, metres, moving thighs
    ("cmu/01_01.amc", "bvh-producers/AxisNeuronFakeServer_test.bvh"),  # Perception Neuron, fingers
    ("bvh-producers/pybvh_bvh_test2.bvh", "cmu/01.asf"),  # Xsens MVN names
    ("cmu/02_01.amc", "bvh-producers/lafan1-resolved_Geno_bind.bvh"),  # six channels on every joint
    ("bvh-producers/makehuman_cmu_10_01.bvh", "bvh/walk01.bvh"),  # Character Studio names
    ("bvh-producers/video2bvh_cxk.bvh", "cmu/01.asf"),  # z-up, millimetres
    ("cmu/01_01.amc", "bvh-producers/bvhTools_test2_lafan1.bvh"),  # a rest pose lying along x
    ("bvh-producers/bvhTools_test2_lafan1.bvh", "cmu/01.asf"),
    ("cmu/01_01.bvh", "bvh/jesse_dance.bvh"),  # a rest pose whose spine runs along x
    ("bvh/jesse_dance.bvh", "bvh-producers/bvhTools_test2_lafan1.bvh"),  # neither rest pose stands
]
SEGMENTS = [
    (f"{side}_{a}", f"{side}_{b}")
    for side in ("left", "right")
    for a, b in (("thigh", "shin"), ("shin", "foot"), ("upper_arm", "forearm"), ("forearm", "hand"))
]


def segments(plan: RetargetPlan) -> list[tuple[str, str, str]]:
    """(name, target joint, target joint) of the thighs, shins, upper arms, forearms, the spine's
    segments and the neck's, between mapped joints of the target."""
    parts = plan.joint_map.target_rig.parts
    mapped = {t for _, t in plan.joint_map.pairs}
    found = [(f"{a}", parts[a][0], parts[b][0]) for a, b in SEGMENTS if a in parts and b in parts]
    column = [j for part in ("spine", "neck", "head") for j in parts.get(part, ()) if j in mapped]
    found += [("spine/neck", a, b) for a, b in itertools.pairwise(column)]
    return [(name, a, b) for name, a, b in found if a in mapped and b in mapped]


@pytest.mark.parametrize("pair", CROSS, ids=[f"{a}->{b}" for a, b in CROSS])
def test_other_rig_bones_point_where_the_sources_do(data_dir, pair):
    take, target = read(data_dir, pair[0]), skeleton(data_dir, pair[1])
    plan = mt.plan_retarget(take.skeleton, target)
    assert plan.mode == "directions"
    result = mt.retarget(take, target, cleanup=False)
    source_of = {t: s for s, t in plan.joint_map.pairs}
    s_index = {n: i for i, n in enumerate(take.skeleton.point_names)}
    t_index = {n: i for i, n in enumerate(target.point_names)}
    ours, theirs = pivots(result), pivots(take) @ plan.align.T
    checked = segments(plan)
    names = {name for name, _, _ in checked}
    assert {"left_thigh", "left_shin", "left_upper_arm", "spine/neck"} <= names  # forearms too, where there are hands
    for name, a, b in checked:
        mine = ours[:, t_index[b]] - ours[:, t_index[a]]
        source = theirs[:, s_index[source_of[b]]] - theirs[:, s_index[source_of[a]]]
        worst = angles_between(mine, source).max()
        assert worst <= 5.0, f"{name} {a}->{b}: {worst:.2f} degrees from the source's"


@pytest.mark.parametrize("pair", CROSS[:2], ids=[f"{a}->{b}" for a, b in CROSS[:2]])
def test_other_rig_motion_is_continuous(data_dir, pair):
    take, target = read(data_dir, pair[0]), skeleton(data_dir, pair[1])
    result = mt.retarget(take, target, cleanup=False)
    rotations = [c for c, (_, d) in enumerate(target.channels) if d.startswith("r")]
    assert np.abs(np.diff(result.values[:, rotations], axis=0)).max() < 90
    # each joint turns per frame about as much as the source joint it follows
    step = {}
    for motion in (take, result):
        q = motion.rotations(quaternions=True)
        step[motion] = np.degrees(2 * np.arccos(np.clip(np.abs(np.sum(q[1:] * q[:-1], -1)), 0, 1))).max(axis=0)
    plan = mt.plan_retarget(take.skeleton, target)
    for s, t in plan.joint_map.pairs:
        i, k = take.skeleton.point_names.index(s), target.point_names.index(t)
        assert step[result][k] < step[take][i] + 6


# --- the root, units and axes -------------------------------------------------------------------

ROOTS = [("cmu/01_01.amc", "cmu/02.asf"), *CROSS]


@pytest.mark.parametrize("pair", ROOTS, ids=[f"{a}->{b}" for a, b in ROOTS])
def test_hip_height_is_the_sources_times_the_leg_ratio(data_dir, pair):
    take, target = read(data_dir, pair[0]), skeleton(data_dir, pair[1])
    plan = mt.plan_retarget(take.skeleton, target)
    result = mt.retarget(take, target, cleanup=False)
    up_s, up_t = (
        np.eye(3)["xyz".index(axis[1])] * (-1 if axis[0] == "-" else 1) for axis in (plan.source_up, plan.target_up)
    )
    source = take.positions(meters=True)[:, 0] @ up_s
    ours = result.positions(meters=True)[:, 0] @ up_t
    assert np.abs(ours - plan.leg_ratio * source).max() < 1e-9
    # and the whole root position, turned into the target's axes
    whole = take.positions(meters=True)[:, 0] @ plan.align.T * plan.leg_ratio
    assert np.abs(result.positions(meters=True)[:, 0] - whole).max() < 1e-9


def test_the_leg_ratio_is_of_hip_heights_in_metres(data_dir, cmu):
    target = mt.read_asf(data_dir / "cmu" / "02.asf")
    plan = mt.plan_retarget(cmu.skeleton, target)
    heights = []
    for sk in (cmu.skeleton, target):
        rest = sk.rest_positions()
        heights.append((rest[0, 1] - rest[:, 1].min()) * sk.meters_per_unit)
    assert plan.leg_ratio == pytest.approx(heights[1] / heights[0], rel=1e-12)
    assert 0.8 < plan.leg_ratio < 1.25


def test_a_z_up_target_gets_a_z_up_motion(data_dir, cmu):
    zombie = mt.read_bvh(data_dir / "bvh" / "zombie.bvh")
    plan = mt.plan_retarget(cmu.skeleton, zombie.skeleton)
    assert (plan.source_up, plan.target_up) == ("+y", "+z")
    result = mt.retarget(cmu, zombie.skeleton, cleanup=False)
    points = result.positions()
    head, feet = target_index(result, "Head"), target_index(result, "LeftFoot")
    assert (points[:, head, 2] > points[:, feet, 2]).mean() > 0.99  # standing, along z


def target_index(motion: mt.Motion, name: str) -> int:
    return motion.skeleton.point_names.index(name)


def test_units_change_nothing_in_metres(data_dir, cmu):
    """The same target in metres instead of its own units: the same motion in the world, to rounding;
    and the same for the source."""
    target = mt.read_asf(data_dir / "cmu" / "02.asf")
    in_metres = target.with_units(length_factor=target.meters_per_unit, length="0.0254")
    assert in_metres.meters_per_unit == 1.0
    for mode in ("rotations", "directions"):
        a = mt.retarget(cmu, target, mode=mode, cleanup=False).positions(meters=True)
        b = mt.retarget(cmu, in_metres, mode=mode, cleanup=False).positions(meters=True)
        c = mt.retarget(cmu.to_meters(), target, mode=mode, cleanup=False).positions(meters=True)
        assert np.abs(a - b).max() < 1e-9
        assert np.abs(a - c).max() < 1e-9


def test_bone_lengths_are_exactly_the_targets(data_dir, cmu):
    for name in ("bvh/walk01.bvh", "cmu/02.asf"):
        target = skeleton(data_dir, name)
        result = mt.retarget(cmu, target, cleanup=False)
        assert result.skeleton is target
        points = result.positions()
        parent = target.tree.parent
        lengths = np.linalg.norm(points[:, 1:] - points[:, parent[1:]], axis=-1)
        rest = np.linalg.norm(target.tree.segment[1:], axis=-1)
        assert np.abs(lengths - rest).max() < 1e-9


def test_unmapped_target_joints_keep_their_rest_rotation(data_dir):
    walk = mt.read_take(data_dir / "bvh" / "walk01.bvh")
    target = mt.read_asf(data_dir / "cmu" / "01.asf")
    plan = mt.plan_retarget(walk.skeleton, target)
    assert set(plan.joint_map.unmapped_target) >= {"upperback", "lwrist", "ltoes"}
    result = mt.retarget(walk, target, cleanup=False)
    local = result.rotations(local=True)
    for name in plan.joint_map.unmapped_target:
        np.testing.assert_allclose(
            local[:, target.joint_names.index(name)], np.broadcast_to(np.eye(3), (walk.frames, 3, 3)), atol=1e-12
        )


# --- maps ---------------------------------------------------------------------------------------


def test_alias_tables_recognise_the_corpus_rigs(data_dir):
    expected = {
        "cmu/01.asf": "cmu",
        "hdm05/HDM_bd.asf": "cmu",
        "cmu/16_15.bvh": "cmu",
        "cmu/01_01.bvh": "cmu_bvh",
        "bvh/walk01.bvh": "humanik",
        "bvh/test_freebvh.bvh": "humanik",
        "bvh/zombie.bvh": "humanik",
        "bvh/test_mocapbank.bvh": "biovision",
        "bvh-producers/MoDi_000000_joints_1_frames_64.bvh": "smpl",
        "bvh-producers/bvhTools_test3.bvh": "rigify",
    }
    for name, rig in expected.items():
        assert recognise(skeleton(data_dir, name)).rig.key == rig, name
    assert recognise(skeleton(data_dir, "bvh/sinusoidal.bvh")).rig is None


def test_chains_of_other_lengths_are_matched_end_to_end():
    assert match_chain("abc", "xy") == [("a", "x"), ("c", "y")]
    assert match_chain("ab", "wxyz") == [("a", "w"), ("b", "z")]
    assert match_chain("abc", "wxyz") == [("a", "w"), ("b", "y"), ("c", "z")]
    assert match_chain("abcde", "xyz") == [("a", "x"), ("c", "y"), ("e", "z")]
    assert match_chain("abc", "x") == [("a", "x")]
    assert match_chain("", "xyz") == []
    assert set(CHAINS) == {"spine", "neck"}


def test_a_map_file_replaces_and_adds_pairs(data_dir, cmu, tmp_path):
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh").skeleton
    path = tmp_path / "map.toml"
    path.write_text('[joints]\nupperback = "Spine1"\nthorax = ""\nlhand = ""\n"root" = "Hips"\n')
    jm = mt.joint_map(cmu.skeleton, walk, path)
    pairs = {t: s for s, t in jm.pairs}
    assert pairs["Spine1"] == "upperback" and jm.why[jm.pairs.index(("upperback", "Spine1"))] == "map file"
    assert "LeftHand" not in pairs and "thorax" in jm.unmapped_source and "lhand" in jm.unmapped_source
    assert pairs["LeftArm"] == "lhumerus"  # the tables fill in the rest
    path.write_text('aliases = false\n[joints]\nroot = "Hips"\nlfemur = "LeftUpLeg"\nltibia = "LeftLeg"\n')
    jm = mt.joint_map(cmu.skeleton, walk, path)
    assert jm.pairs == (("root", "Hips"), ("lfemur", "LeftUpLeg"), ("ltibia", "LeftLeg"))
    result = mt.retarget(cmu, walk, path, cleanup=False)
    assert result.skeleton is walk


@pytest.mark.parametrize(
    ("text", "error", "message"),
    [
        (
            '[joints]\nlfemurx = "LeftUpLeg"\n',
            UnknownNameError,
            r"'lfemurx' is not a joint of the source .*did you mean 'lfemur'",
        ),
        (
            '[joints]\nlfemur = "LeftUpLg"\n',
            UnknownNameError,
            r"'LeftUpLg' is not a joint of the target .*did you mean 'LeftUpLeg'",
        ),
        ('[joints]\nlfemur = "LeftUpLeg"\nrfemur = "LeftUpLeg"\n', DuplicateError, "given two sources"),
        ("[joints]\nlfemur = 3\n", ValueError, 'source = "target" pairs'),
        ('[joint]\nlfemur = "LeftUpLeg"\n', ValueError, r"unknown key\(s\) joint"),
        ("aliases = false\n", ValueError, "nothing to map"),
        ("[joints\n", ValueError, "not valid TOML"),
        (
            'aliases = false\n[joints]\nlfemur = "LeftUpLeg"\n',
            ValueError,
            "the target's root 'Hips' follows no source joint",
        ),
    ],
)
def test_bad_maps_say_what_is_wrong(data_dir, cmu, tmp_path, text, error, message):
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh").skeleton
    path = tmp_path / "map.toml"
    path.write_text(text)
    with pytest.raises(error, match=message) as caught:
        mt.plan_retarget(cmu.skeleton, walk, path)
    assert "map.toml" in str(caught.value) or "root" in str(caught.value)


def test_no_joints_in_common_is_an_error(data_dir, cmu):
    toy = mt.read_bvh(data_dir / "bvh" / "sinusoidal.bvh").skeleton
    with pytest.raises(ValueError, match="no joints in common.*--map"):
        mt.plan_retarget(cmu.skeleton, toy)


def test_unknown_units_are_an_error(data_dir, cmu):
    target = mt.read_asf(data_dir / "cmu" / "02.asf")
    odd = dataclasses.replace(target, units=(("length", "furlong"), ("angle", "deg")))
    with pytest.raises(ValueError, match="the target skeleton .*unknown length unit 'furlong'"):
        mt.plan_retarget(cmu.skeleton, odd)


def test_a_rest_pose_that_does_not_stand_is_an_error(data_dir, cmu):
    lying = mt.read_bvh(data_dir / "bvh" / "jesse_dance.bvh").skeleton  # every bone along x at rest
    mt.plan_retarget(cmu.skeleton, lying)  # planned on the twin of a frame that stands (characters.standing)
    no_frame = dataclasses.replace(lying, standing=None)  # a skeleton without its take
    with pytest.raises(ValueError, match="does not stand in its rest pose.*OFFSETs draw, and no frame"):
        mt.plan_retarget(cmu.skeleton, no_frame)


def test_a_length_unit_that_is_only_assumed_is_refused(data_dir, cmu):
    conversion = mt.read_take(data_dir / "cmu" / "01_01.bvh")
    conversion = conversion.replace(skeleton=conversion.skeleton.with_length_unit("cm", "assumed"))
    with pytest.raises(ValueError, match="the source skeleton has no known length unit.*--unit UNIT.*taken for cm"):
        mt.plan_retarget(conversion.skeleton, cmu.skeleton)
    with pytest.raises(ValueError, match="the target skeleton has no known length unit.*--to-unit UNIT"):
        mt.plan_retarget(cmu.skeleton, conversion.skeleton)
    given = conversion.skeleton.with_length_unit("0.45")
    plan = mt.plan_retarget(given, cmu.skeleton)
    assert plan.leg_ratio == pytest.approx(1.0, abs=1e-6)  # the conversion is subject 01 itself
    assert "in/0.45 = 0.0564444 m (given)" in plan.describe()


def test_rotations_mode_needs_the_same_rig(data_dir, cmu):
    with pytest.raises(ValueError, match="mode 'rotations' needs the same rig.*ASF and the other BVH"):
        mt.plan_retarget(cmu.skeleton, skeleton(data_dir, "bvh/walk01.bvh"), mode="rotations")
    with pytest.raises(ValueError, match="mode must be one of"):
        mt.plan_retarget(cmu.skeleton, cmu.skeleton, mode="sideways")


def test_a_plan_serves_many_takes_of_its_skeletons_only(data_dir, cmu):
    walk = skeleton(data_dir, "bvh/walk01.bvh")
    plan = mt.plan_retarget(cmu.skeleton, walk)
    assert mt.plan_retarget(cmu.skeleton, walk) is plan  # kept for the next take
    np.testing.assert_array_equal(
        mt.retarget(cmu, walk, plan=plan, cleanup=False).values, mt.retarget(cmu, walk, cleanup=False).values
    )
    with pytest.raises(ValueError, match="plan given is for other skeletons"):
        mt.retarget(mt.read_take(data_dir / "bvh" / "walk01.bvh"), walk, plan=plan)


def test_the_input_is_not_modified(data_dir, cmu):
    before = cmu.values.copy()
    mt.retarget(cmu, skeleton(data_dir, "bvh/walk01.bvh"), cleanup=False)
    np.testing.assert_array_equal(cmu.values, before)


# --- the feet -----------------------------------------------------------------------------------

FEET = [
    ("cmu/01_01.amc", "cmu/02.asf"),
    ("cmu/07_05-walk.amc", "cmu/16.asf"),
    ("cmu/07_05-walk.amc", "bvh/walk01.bvh"),
    ("bvh/walk01.bvh", "cmu/01.asf"),
    ("hdm05/HDM_bd_sneak2StepsLStart_001_120.amc", "hdm05/HDM_dg.asf"),
    ("cmu/07_05-walk.amc", "bvh/zombie.bvh"),
]


@pytest.mark.parametrize("pair", FEET, ids=[f"{a}->{b}" for a, b in FEET])
def test_after_the_cleanup_the_feet_hold_the_cleanups_bounds(data_dir, pair):
    """Kovar et al.: retargeting to other proportions leaves skating, which the cleanup removes.
    Measured, as the cleanup's own tests do, on the footplants and floor it enforced."""
    footskate = pytest.importorskip("motiontheater.feet.footskate", reason="this version has no footskate cleanup")
    from motiontheater.feet.skate import skate_metrics

    take, target = read(data_dir, pair[0]), skeleton(data_dir, pair[1])
    plan = mt.plan_retarget(take.skeleton, target)
    raw = mt.retarget(take, target, cleanup=False)
    cleaned = mt.retarget(take, target)
    options = _cleanup_options(plan)
    result = footskate.clean_footskate(raw, legs=options.get("legs"), up=options["up"])
    np.testing.assert_array_equal(cleaned.values, result.motion.values)  # what the step ran
    assert result.legs.legs[0].ankle == plan.joint_map.target_rig.parts["left_foot"][0]

    def measured(motion: mt.Motion):
        return skate_metrics(motion, result.contacts, legs=result.legs, ground=result.ground)

    assert measured(raw).worst("sliding_max_mm") > 5  # the retargeted feet skated
    after = measured(cleaned)
    assert after.worst("sliding_mean_mm") <= 1.0
    assert after.worst("sliding_max_mm") <= 5.0
    # (the papers' skating ratio counts swing near the floor too: real walks score 10-40 % on it before a
    # cleanup and after, see motiontheater.feet.skate; the sliding above is the planted feet's own measure)
    assert after.worst("penetration_mm") <= 5.0
    assert cleaned.skeleton is target


def test_a_limb_left_unmapped_is_an_error_naming_its_joints(data_dir, cmu, tmp_path):
    """A rig the tables half know (its arms named otherwise) is refused, not retargeted with arms at rest."""
    text = (
        (data_dir / "bvh" / "walk01.bvh")
        .read_text()
        .replace("LeftArm", "ArmUpper_L")
        .replace("LeftForeArm", "ArmLower_L")
    )
    (tmp_path / "odd.bvh").write_text(text)
    odd = mt.read_bvh(tmp_path / "odd.bvh").skeleton
    with pytest.raises(
        ValueError,
        match=r"the target.s left arm \(no joint of it named as a known rig names it\) follow no joint of the source",
    ):
        mt.plan_retarget(cmu.skeleton, odd)
    (tmp_path / "map.toml").write_text('[joints]\nlhumerus = "ArmUpper_L"\nlradius = "ArmLower_L"\n')
    plan = mt.plan_retarget(cmu.skeleton, odd, tmp_path / "map.toml")
    assert ("lhumerus", "ArmUpper_L") in plan.joint_map.pairs
