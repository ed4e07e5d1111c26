"""The footskate kernels (mtcore.footskate, csrc/footskate.c) against their numpy twin, phase by phase,
over real legs, legs of every channel layout, frame counts from 0 up, and every option."""

import itertools
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA
from motiontheater.feet.contacts import plant_targets, runs
from motiontheater.feet.footskate import contacts_of, prepare
from mtcore import footskate as fs
from mtcore._mtcore import ffi, lib
from twins import footskate as twin

TAKES = {
    "cmu 07_05 walk": ("cmu/07-walk.asf", "cmu/07_05-walk.amc", None),
    "hdm05 jog": ("hdm05/HDM_bd.asf", "hdm05/HDM_bd_jogLeftCircle4StepsRstart_001_120.amc", None),
    "bvh walk01 (no toes)": (None, "bvh/walk01.bvh", 0.01),
    "bvh zombie (z up)": (None, "bvh/zombie.bvh", 0.084),
}
LAYOUTS = {  # rotation channels of hip, knee, ankle, toe: the kernels must hold for any
    "as captured": None,
    "three everywhere": [[0, 1, 2], [2, 0, 1], [1, 2, 0], [0, 2, 1]],
    "proper Euler": [[0, 1, 0], [1, 2, 1], [2, 0, 2], [0, 1, 0]],
    "hinges": [[0, 2, 1], [0, -1, -1], [1, -1, -1], [0, -1, -1]],
    "two-channel knee, no toe": [[2, 1, 0], [0, 2, -1], [2, 0, -1], [-1, -1, -1]],
}
OPTIONS = [
    dict(),
    dict(blend=0, root_window=0, root_passes=0),
    dict(blend=1, root_window=1, root_passes=1, knee_soft=0.0, knee_keep=0.0),
    dict(blend=7, root_window=3, root_passes=5, knee_soft=0.2, knee_keep=1.0),
]


def load(name):
    asf, take, mpu = TAKES[name]
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    motion = mt.read_bvh(DATA / take) if asf is None else mt.read_amc(DATA / take, mt.read_asf(DATA / asf))
    arrays, ground, mpu = prepare(motion, meters_per_unit=mpu)
    masks = contacts_of(None, motion, arrays, ground, mpu).masks(arrays.legs)
    return arrays, ground, masks


def relayout(chain, axes):
    """The chain with other rotation channels (the same angle columns read by them)."""
    if axes is None:
        return chain
    segments = chain.segments.copy()
    if axes[3][0] < 0:
        segments[4] = 0
    return fs.LegChain(axis=chain.axis, axes=np.array(axes), segments=segments)


def options_of(ground, **changes):
    return fs.CleanupOptions(
        up=tuple(map(float, ground.up)), slope=tuple(map(float, ground.slope)), level=float(ground.level), **changes
    )


def close(a, b, atol, what):
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, what
    np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=what)
    np.testing.assert_allclose(a, b, rtol=0, atol=atol, equal_nan=True, err_msg=what)


@pytest.mark.parametrize("take", TAKES)
@pytest.mark.parametrize("layout", LAYOUTS)
def test_every_phase_equals_the_twin(take, layout):
    arrays, ground, masks = load(take)
    chains = [relayout(c, LAYOUTS[layout]) for c in arrays.chains]
    points = fs.leg_points(chains, arrays.hips, arrays.parents, arrays.angles)
    scale = float(np.abs(points).max())
    close(points, twin.leg_points(chains, arrays.hips, arrays.parents, arrays.angles), 1e-12 * scale, "points")
    targets = plant_targets(masks, points)
    for changes in OPTIONS:
        opt = options_of(ground, **changes)
        plans, twins = [], []
        for i, chain in enumerate(chains):
            plan = fs.plan_leg(chain, arrays.angles[i], points[i], masks[i], targets[i], ground.clearance[i], opt)
            expected = twin.plan_leg(chain, arrays.angles[i], points[i], masks[i], targets[i], ground.clearance[i], opt)
            tolerances = dict(enforced=1e-12 * scale, goal=1e-9 * scale, turn=1e-9, weight=0, reach=1e-9 * scale)
            for (name, atol), value in zip({**tolerances, "knee": 1e-9}.items(), expected):
                close(getattr(plan, name), value, atol, f"{name} {changes}")
            plans.append(plan)
            twins.append(expected)
        goals, reaches, weights = (np.stack([getattr(p, n) for p in plans]) for n in ("goal", "reach", "weight"))
        root = fs.adjust_root(arrays.hips, goals, reaches, weights, opt)
        close(root, twin.adjust_root(arrays.hips, goals, reaches, weights, opt), 1e-9 * scale, f"root {changes}")
        for i, (chain, plan) in enumerate(zip(chains, plans)):
            args = (arrays.hips[i], arrays.parents[i], arrays.angles[i], points[i], masks[i])
            out = fs.solve_leg(chain, *args, plan, root, ground.clearance[i], opt)
            expected = twin.solve_leg(
                chain, *args, plan.goal, plan.turn, plan.weight, plan.knee, root, ground.clearance[i], opt
            )
            # the joints' rotations (to 1e-6: acos near 1, where a toe just touches the floor, takes the
            # square root of rounding): near gimbal lock (the proper Euler layouts) only a + c of an Euler
            # triple is defined, and the split may differ
            for j in range(4):
                close(
                    twin.local(chain, j, out[:, j]), twin.local(chain, j, expected[:, j]), 1e-6, f"joint {j} {changes}"
                )
            # a frame one leaves alone, bit for bit, the other changes at most by rounding
            for a, b in ((out, expected), (expected, out)):
                alone = (a == arrays.angles[i]).all(axis=(1, 2))
                assert np.abs(b[alone] - arrays.angles[i][alone]).max(initial=0) < 1e-12


def random_masks(rng, frames):
    masks = np.zeros((2, frames, 2), bool)
    for leg, point in itertools.product(range(2), range(2)):
        t = 0
        while t < frames:
            t += int(rng.integers(0, 12))
            length = int(rng.integers(1, 30))
            masks[leg, t : t + length, point] = True
            t += length
    return masks


@pytest.mark.parametrize("frames", [0, 1, 2, 3, 8, 57, 200])
def test_short_takes_and_random_plants_equal_the_twin(frames, rng):
    arrays, ground, _ = load("cmu 07_05 walk")
    start = int(rng.integers(0, arrays.hips.shape[1] - frames))
    part = slice(start, start + frames)
    hips, parents, angles = arrays.hips[:, part], arrays.parents[:, part], arrays.angles[:, part]
    angles = angles + rng.normal(0, 0.02, angles.shape) * (angles != 0)
    points = fs.leg_points(arrays.chains, hips, parents, angles)
    masks = random_masks(rng, frames)
    targets = plant_targets(masks, points) + rng.normal(0, 0.1, (2, frames, 2, 3))
    opt = options_of(ground, blend=9, root_window=2)
    got = fs.cleanup(arrays.chains, hips, parents, angles, points, masks, targets, ground.clearance, opt)
    expected = twin.cleanup(arrays.chains, hips, parents, angles, points, masks, targets, ground.clearance, opt)
    close(got[1], expected[1], 1e-9, "root")
    close(got[2], expected[2], 1e-9, "enforced")
    for leg, j in itertools.product(range(2), range(4)):
        chain = arrays.chains[leg]
        close(twin.local(chain, j, got[0][leg, :, j]), twin.local(chain, j, expected[0][leg, :, j]), 1e-6, "angles")
    assert got[0].shape == (2, frames, 4, 3) and got[1].shape == (frames, 3)


def test_plants_are_held_and_everything_else_is_left_alone():
    arrays, ground, masks = load("hdm05 jog")
    opt = options_of(ground)
    targets = plant_targets(masks, arrays.points)
    angles, root, enforced = fs.cleanup(
        arrays.chains, arrays.hips, arrays.parents, arrays.angles, arrays.points, masks, targets, ground.clearance, opt
    )
    new = fs.leg_points(arrays.chains, arrays.hips + root, arrays.parents, angles)
    for k, column in enumerate((3, 2)):
        held = masks[..., k]
        miss = np.linalg.norm(new[..., column, :][held] - enforced[..., k, :][held], axis=-1)
        assert miss.max() < 0.01  # file units (inch / 0.45): a quarter of a millimetre
        assert np.isnan(enforced[..., k, :][~held]).all()
        # each plant's target is one point, on the floor at the point's clearance
        for leg in range(2):
            for s, e in zip(*runs(held[leg])):
                assert np.ptp(enforced[leg, s:e, k], axis=0).max() == 0
                height = ground.above(enforced[leg, s, k]) - ground.clearance[leg, k]
                assert abs(height) < 1e-9
    untouched = np.abs(root).max(-1) == 0
    assert untouched.any()
    assert (angles[:, untouched] == arrays.angles[:, untouched]).mean() > 0.5


def test_the_kernels_run_in_threads_to_the_same_bits():
    arrays, ground, masks = load("bvh zombie (z up)")
    opt = options_of(ground)
    targets = plant_targets(masks, arrays.points)
    args = (arrays.chains, arrays.hips, arrays.parents, arrays.angles, arrays.points, masks, targets, ground.clearance)
    serial = fs.cleanup(*args, opt)
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda _: fs.cleanup(*args, opt), range(8)))
    for result in results:
        for a, b in zip(result, serial):
            np.testing.assert_array_equal(a, b)


def test_inputs_are_never_modified_and_read_only_or_strided_input_is_taken():
    arrays, ground, masks = load("cmu 07_05 walk")
    opt = options_of(ground)
    targets = plant_targets(masks, arrays.points)
    inputs = [arrays.hips, arrays.parents, arrays.angles, arrays.points, masks, targets, ground.clearance]
    copies = [a.copy() for a in inputs]
    frozen = []
    for a in inputs:
        b = np.asfortranarray(a) if a.ndim > 1 else a.copy()  # another layout
        b.flags.writeable = False
        frozen.append(b)
    got = fs.cleanup(arrays.chains, *frozen, opt)
    expected = fs.cleanup(arrays.chains, *inputs, opt)
    for a, b in zip(got, expected):
        np.testing.assert_array_equal(a, b)
    for a, b in zip(inputs, copies):
        np.testing.assert_array_equal(a, b)


def test_bad_arguments_raise_before_any_c_call():
    arrays, ground, masks = load("cmu 07_05 walk")
    chain = arrays.chains[0]
    opt = options_of(ground)
    f = arrays.hips.shape[1]
    with pytest.raises(ValueError, match=r"LegChain.axes\[1\] \(knee\) repeats an axis"):
        fs.LegChain(axis=chain.axis, axes=[[0, 1, 2], [0, 0, -1], [0, -1, -1], [-1, -1, -1]], segments=chain.segments)
    with pytest.raises(ValueError, match="the hip and knee joints need at least one rotation channel"):
        fs.LegChain(axis=chain.axis, axes=np.full((4, 3), -1), segments=chain.segments)
    with pytest.raises(ValueError, match=r"LegChain.axes\[0\] \(hip\) must list axes 0-2 then -1"):
        fs.LegChain(axis=chain.axis, axes=[[0, -1, 2], [0, -1, -1], [0, -1, -1], [-1, -1, -1]], segments=chain.segments)
    with pytest.raises(ValueError, match="LegChain.segments must have shape"):
        fs.LegChain(axis=chain.axis, axes=chain.axes, segments=np.zeros((4, 3)))
    with pytest.raises(ValueError, match="up must be a unit vector"):
        fs.CleanupOptions(up=(0, 2, 0))
    with pytest.raises(ValueError, match="slope must be a vector of 3 perpendicular to up"):
        fs.CleanupOptions(slope=(0, 0.1, 0))
    with pytest.raises(ValueError, match="blend must be a whole number >= 0"):
        fs.CleanupOptions(blend=-1)
    with pytest.raises(ValueError, match=r"knee_soft must be in \[0, pi/2\)"):
        fs.CleanupOptions(knee_soft=2.0)
    with pytest.raises(ValueError, match=r"planted must be booleans of shape \(517, 2\)"):
        fs.plan_leg(chain, arrays.angles[0], arrays.points[0], masks[0, :-1], np.zeros((f, 2, 3)), [0, 0, 0], opt)
    with pytest.raises(ValueError, match="targets must be finite where planted"):
        fs.plan_leg(chain, arrays.angles[0], arrays.points[0], masks[0], np.full((f, 2, 3), np.nan), [0, 0, 0], opt)
    with pytest.raises(ValueError, match=r"points must have shape \(517, 5, 3\)"):
        fs.plan_leg(chain, arrays.angles[0], arrays.points[0, 1:], masks[0], np.zeros((f, 2, 3)), [0, 0, 0], opt)
    with pytest.raises(ValueError, match=r"hips must have shape \(1 or 2 legs, frames, 3\)"):
        fs.adjust_root(np.zeros((3, f, 3)), np.zeros((3, f, 3)), np.zeros((3, f)), np.zeros((3, f)), opt)
    with pytest.raises(ValueError, match="cleanup takes one or two legs"):
        fs.cleanup([], arrays.hips, arrays.parents, arrays.angles, arrays.points, masks, masks, [], opt)
    with pytest.raises(TypeError, match="chains must be one or more LegChain"):
        fs.leg_points(["leg"], arrays.hips[:1], arrays.parents[:1], arrays.angles[:1])
    limits = fs.PlantThresholds(0.02, 0.05, 0.03, 0.4, 0.02, 0.35, 0.4, 0.01, 12, 6)
    with pytest.raises(ValueError, match=r"speed must have shape \(4, 517\)"):
        fs.plant_masks(np.zeros((4, f)), np.zeros((4, f - 1)), np.zeros((4, f)), limits)
    with pytest.raises(ValueError, match="firm_height and firm_speed must not exceed height and speed"):
        fs.PlantThresholds(0.02, 0.05, 0.03, 0.4, 0.04, 0.35, 0.4, 0.01, 12, 6)
    with pytest.raises(ValueError, match="which must list points below 5"):
        fs.point_speeds(arrays.points, [3, 5], 120.0)
    with pytest.raises(ValueError, match=r"points must have shape \(tracks, frames, per_frame, 3\)"):
        fs.point_speeds(arrays.points[0], [0], 120.0)
    values, solved, root = np.zeros((f, 62)), arrays.angles, np.zeros((f, 3))
    columns = np.where(arrays.columns >= 0, arrays.columns, -1)
    with pytest.raises(ValueError, match="columns and root_columns must be distinct columns of the 62 channels"):
        fs.write_channels(values, arrays.angles, solved, columns, 1.0, root, columns[0, 0])
    with pytest.raises(ValueError, match=r"solved must have shape \(1 or 2 legs, 517, 4, 3\)"):
        fs.write_channels(values, arrays.angles, solved[:, 1:], columns, 1.0, root, [0, 1, 2])
    with pytest.raises(ValueError, match=r"out.enforced must have shape \(516, 2, 3\)"):
        plans = fs.plan_leg(chain, arrays.angles[0], arrays.points[0], masks[0], np.zeros((f, 2, 3)), [0, 0, 0], opt)
        fs.plan_leg(
            chain, arrays.angles[0, 1:], arrays.points[0, 1:], masks[0, 1:], np.zeros((f - 1, 2, 3)), [0, 0, 0], opt,
            out=plans,
        )  # fmt: skip


def test_the_c_kernels_check_their_arguments_again():
    opt = fs.CleanupOptions().struct()
    limits = fs.PlantThresholds(0.02, 0.05, 0.03, 0.4, 0.02, 0.35, 0.4, 0.01, 12, 6)
    leg = ffi.new("struct mt_leg *")
    for j in range(4):
        leg.axes[j] = [0, -1, -1]
    assert lib.mt_leg_points(leg, 1, 3, ffi.NULL, ffi.NULL, ffi.NULL, ffi.NULL, ffi.NULL) == lib.MT_EINVAL
    assert lib.mt_leg_points(leg, 1, 0, ffi.NULL, ffi.NULL, ffi.NULL, ffi.NULL, ffi.NULL) == lib.MT_OK
    leg.axes[0] = [5, -1, -1]
    buf = ffi.new("double[64]")
    assert lib.mt_leg_points(leg, 1, 1, buf, buf, buf, buf, ffi.NULL) == lib.MT_EINVAL
    assert lib.mt_footskate_root(3, 1, buf, buf, buf, buf, opt, buf) == lib.MT_EINVAL
    opt.up = [0, 0, 0]
    assert lib.mt_footskate_root(1, 1, buf, buf, buf, buf, opt, buf) == lib.MT_EINVAL
    mask = ffi.new("unsigned char[8]")
    assert lib.mt_plant_masks(buf, buf, buf, 1, 8, ffi.NULL, mask) == lib.MT_EINVAL
    assert lib.mt_plant_masks(buf, ffi.NULL, buf, 1, 8, limits.struct(), mask) == lib.MT_EINVAL
    assert lib.mt_point_speeds(buf, 1, 2, 5, [5], 1, 1.0, buf, ffi.NULL) == lib.MT_EINVAL
    assert lib.mt_point_speeds(buf, 1, 2, 5, [4], 1, 1.0, ffi.NULL, ffi.NULL) == lib.MT_EINVAL
    columns = ffi.new("long long[24]", [-1] * 24)
    assert lib.mt_footskate_write(1, 1, 8, buf, buf, buf, columns, 1.0, buf, [0, 1, 2], buf) == lib.MT_OK
    columns[5] = 1  # the root's column too
    assert lib.mt_footskate_write(1, 1, 8, buf, buf, buf, columns, 1.0, buf, [0, 1, 2], buf) == lib.MT_EINVAL
    columns[5] = 8  # past the channels
    assert lib.mt_footskate_write(1, 1, 8, buf, buf, buf, columns, 1.0, buf, [0, 1, 2], buf) == lib.MT_EINVAL
    columns[5] = -1
    assert lib.mt_footskate_write(1, 1, 8, buf, buf, buf, columns, 0.0, buf, [0, 1, 2], buf) == lib.MT_EINVAL


def test_one_toe_tip_flag_stands_for_every_leg_and_a_wrong_count_is_named(rng):
    """tips: one flag for every leg, or one per leg; another count is refused, naming tips."""
    points, _, up, rate, mpu, speed, needed = twin.ground_cases(rng)[4]  # two legs, 60 frames
    one = fs.resting_points(points, True, up, rate, mpu, speed, needed)
    np.testing.assert_array_equal(one, fs.resting_points(points, [True, True], up, rate, mpu, speed, needed))
    with pytest.raises(ValueError, match="tips must be one flag or 2"):
        fs.resting_points(points, [True, False, True], up, rate, mpu, speed, needed)
