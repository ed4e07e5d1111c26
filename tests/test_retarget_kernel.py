"""The retargeting kernel (mt_retarget) against its numpy twin, over real rigs and made-up channel layouts."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.model.skeleton import Skeleton
from mtcore.kinematics import forward_kinematics
from mtcore.retarget import RetargetPlan, retarget_rotations
from twins import retarget as twin

PAIRS = [
    ("cmu/01.asf", "bvh/walk01.bvh"),  # ASF onto BVH: every target joint three channels
    ("bvh/walk01.bvh", "cmu/01.asf"),  # BVH onto ASF: knees and elbows hinges, feet and clavicles two channels
    ("cmu/01.asf", "bvh/zombie.bvh"),  # y-up onto z-up, a spine of three onto one of four
    ("bvh/test_freebvh.bvh", "cmu/02.asf"),  # Mixamo onto CMU: a spine of three onto three, toes
    ("bvh/test_mocapbank.bvh", "bvh/AV_8Walk_Meredith_HVHA_Rep1.bvh"),  # a spine of two onto one
]


def skeleton(data_dir: Path, name: str) -> Skeleton:
    return mt.read_asf(data_dir / name) if name.endswith(".asf") else mt.read_bvh(data_dir / name).skeleton


def random_values(sk: Skeleton, frames: int, rng, spread: float = 60.0) -> np.ndarray:
    """Channels of a made-up motion: angles up to ``spread`` degrees, translations of the rest pose's size."""
    values = np.zeros((frames, len(sk.channels)))
    for column, (_, dof) in enumerate(sk.channels):
        values[:, column] = rng.uniform(-spread, spread, frames) if dof.startswith("r") else rng.normal(0, 10, frames)
    return values


def angles_equal(a: np.ndarray, b: np.ndarray, tolerance: float) -> None:
    """Equal as angles in degrees: whole turns apart counts as equal (±180 is one angle)."""
    difference = np.abs(np.remainder(a - b + 180, 360) - 180)
    assert difference.max(initial=0) < tolerance


@pytest.mark.parametrize("pair", PAIRS, ids=[f"{a}->{b}" for a, b in PAIRS])
@pytest.mark.parametrize("frames", [0, 1, 7, 8, 9, 64, 65, 130])
def test_kernel_matches_the_numpy_twin(data_dir, rng, pair, frames):
    source, target = (skeleton(data_dir, name) for name in pair)
    plan = mt.plan_retarget(source, target)
    assert plan.mode == "directions"
    values = random_values(source, frames, rng)
    got = retarget_rotations(values, plan.source_tree, target.tree, len(target.channels), plan.kernel, workers=1)
    want = twin.retarget_rotations(values, plan.source_tree, target.tree, len(target.channels), plan.kernel)
    assert got.shape == (frames, len(target.channels))
    angles_equal(got, want, 1e-8)


def test_the_pairs_use_every_path_of_the_kernel(data_dir):
    """Re-aimed bones, swivels over hinges, a turn between world axes, one and two channels with and
    without an aim: the pairs above reach each of them."""
    plans = [mt.plan_retarget(*(skeleton(data_dir, name) for name in pair)).kernel for pair in PAIRS]
    assert any(p.refit.any() for p in plans)
    assert any((p.hinge >= 0).any() for p in plans)
    assert any(not np.array_equal(p.align, np.eye(3)) for p in plans)
    assert any((p.key_points[:, 0] < 0).any() and (p.follow >= 0).any() for p in plans)


def variant(sk: Skeleton, dofs: dict[str, tuple[str, ...]]) -> Skeleton:
    """The skeleton with other rotation channels on some joints."""
    bones = tuple(dataclasses.replace(b, dofs=dofs.get(b.name, b.dofs)) for b in sk.bones)
    return dataclasses.replace(sk, bones=bones)


@pytest.mark.parametrize(
    "dofs",
    [
        {"Spine1": ("rz", "rx", "rz"), "Neck": ("ry", "rx", "ry")},  # proper Euler angles
        {"Spine1": ("rx", "rz"), "LeftArm": ("rz", "ry")},  # two channels: with no aim (several children) and with
        {"Spine1": ("ry",), "LeftLeg": ("rx",)},  # one channel: its twist (no aim), and a hinge (a swivel above)
        {"LeftUpLeg": ("rx", "ry", "rz", "tx"), "RightForeArm": ("tz", "ry")},  # translations among the turns
    ],
    ids=["proper", "two", "one", "translations"],
)
def test_kernel_matches_the_twin_on_other_channel_layouts(data_dir, rng, dofs):
    source = mt.read_asf(data_dir / "cmu" / "01.asf")
    target = variant(mt.read_bvh(data_dir / "bvh" / "walk01.bvh").skeleton, dofs)
    plan = mt.plan_retarget(source, target)
    values = random_values(source, 97, rng)
    got = retarget_rotations(values, plan.source_tree, target.tree, len(target.channels), plan.kernel, workers=1)
    want = twin.retarget_rotations(values, plan.source_tree, target.tree, len(target.channels), plan.kernel)
    angles_equal(got, want, 1e-8)
    translations = [c for c, (_, d) in enumerate(target.channels) if not d.startswith("r")]
    assert not got[:, translations].any()  # the kernel writes rotation channels only


def test_the_source_tree_is_cut_to_what_the_target_reads(data_dir, rng):
    source = mt.read_asf(data_dir / "cmu" / "01.asf")
    plan = mt.plan_retarget(source, mt.read_bvh(data_dir / "bvh" / "walk01.bvh").skeleton)
    kept = [source.joint_names[j] for j in plan.source_joints]
    assert {"lfingers", "lthumb", "rtoes"}.isdisjoint(kept) and {"root", "lhipjoint", "upperback", "lwrist"} <= set(
        kept
    )
    values = random_values(source, 50, rng)
    whole, _, _ = forward_kinematics(values, source.tree)
    cut, _, _ = forward_kinematics(values, plan.source_tree)
    np.testing.assert_array_equal(cut, whole[:, plan.source_joints])


def test_splitting_frames_over_threads_changes_no_bit(data_dir, rng):
    source, target = mt.read_asf(data_dir / "cmu" / "01.asf"), mt.read_asf(data_dir / "cmu" / "02.asf")
    plan = mt.plan_retarget(source, target, mode="directions")
    values = random_values(source, 1001, rng)
    one = retarget_rotations(values, plan.source_tree, target.tree, len(target.channels), plan.kernel, workers=1)
    for workers in (2, 3, 7):
        many = retarget_rotations(
            values, plan.source_tree, target.tree, len(target.channels), plan.kernel, workers=workers
        )
        np.testing.assert_array_equal(one, many)


def test_inputs_are_not_modified_and_out_keeps_other_channels(data_dir, rng):
    source = mt.read_asf(data_dir / "cmu" / "01.asf")
    target = mt.read_bvh(data_dir / "bvh" / "walk01.bvh").skeleton
    plan = mt.plan_retarget(source, target)
    values = random_values(source, 33, rng)
    before = values.copy()
    out = np.full((33, len(target.channels)), 7.0)
    retarget_rotations(values, plan.source_tree, target.tree, len(target.channels), plan.kernel, out=out)
    np.testing.assert_array_equal(values, before)
    np.testing.assert_array_equal(out[:, :3], 7.0)  # the root's position channels are the caller's


def test_nan_in_a_channel_gives_nan_where_it_reaches_and_nothing_breaks(data_dir, rng):
    source = mt.read_asf(data_dir / "cmu" / "01.asf")
    target = mt.read_bvh(data_dir / "bvh" / "walk01.bvh").skeleton
    plan = mt.plan_retarget(source, target)
    values = random_values(source, 20, rng)
    values[5, source.columns_of(["lhumerus"])[0]] = np.nan
    out = retarget_rotations(values, plan.source_tree, target.tree, len(target.channels), plan.kernel)
    arm = target.columns_of(["LeftArm"])
    assert np.isnan(out[5, arm]).all()
    assert np.isfinite(np.delete(out, 5, axis=0)).all()
    assert np.isfinite(out[5, target.columns_of(["RightArm", "LeftUpLeg"])]).all()


def test_bad_tables_are_refused_before_the_kernel_runs(data_dir):
    source = mt.read_asf(data_dir / "cmu" / "01.asf")
    target = mt.read_bvh(data_dir / "bvh" / "walk01.bvh").skeleton
    whole = mt.plan_retarget(source, target)
    plan, tree = whole.kernel, whole.source_tree
    n = len(target.channels)
    values = np.zeros((4, len(source.channels)))
    with pytest.raises(ValueError, match="values have"):
        retarget_rotations(values[:, :10], tree, target.tree, n, plan)
    with pytest.raises(ValueError, match="target tree reads column"):
        retarget_rotations(values, tree, target.tree, n - 3, plan)
    with pytest.raises(ValueError, match="names a source joint beyond"):
        retarget_rotations(values, tree, target.tree, n, dataclasses.replace(plan, follow=plan.follow + 100))
    with pytest.raises(ValueError, match="correction must have shape"):
        RetargetPlan(**{**{f.name: getattr(plan, f.name) for f in dataclasses.fields(plan)}, "correction": np.eye(3)})
    with pytest.raises(ValueError, match="out must be"):
        retarget_rotations(values, tree, target.tree, n, plan, out=np.zeros((4, n), np.float32))
    # a joint with four rotation channels passes the Python checks; the kernel refuses it
    four = variant(target, {"Spine1": ("rx", "ry", "rz", "rx")})
    with pytest.raises(ValueError, match="mt_retarget"):
        retarget_rotations(values, tree, four.tree, len(four.channels), plan)
