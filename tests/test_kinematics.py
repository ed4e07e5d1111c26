"""Forward kinematics against the HDM05 toolbox, a numpy twin, and invariances."""

import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import motiontheater as mt
from corpus import ids, real_files
from mtcore import rotations as rot
from mtcore.kinematics import JointTree, forward_kinematics, local_quaternions, world_kinematics
from twins.kinematics import motion_kinematics as twin

REFS = real_files("hdm05/*.ref.npz")
AMCS = real_files("*/*.amc")


def load(amc):
    return mt.read_amc(amc, mt.read_asf(mt.skeleton_path_for(amc)))


@pytest.mark.parametrize("ref", REFS, ids=ids(REFS))
def test_hdm05_toolbox_positions_and_rotations(ref):
    expected = np.load(ref)
    motion = load(ref.with_name(ref.name.replace(".ref.npz", ".amc")))
    assert list(expected["bone_names"]) == list(motion.skeleton.joint_names)
    # The toolbox's units: ASF lengths and root translation divided by :units length.
    positions = motion.positions() / 0.45
    np.testing.assert_allclose(positions, expected["positions"], rtol=0, atol=1e-9)
    quaternions = motion.rotations(local=True, quaternions=True)
    reference = expected["rotation_quat_wxyz"]
    valid = ~np.isnan(reference[..., 0])  # the toolbox leaves bones without dofs NaN
    assert valid.sum() == reference.shape[0] * 29
    closest = np.minimum(np.abs(quaternions - reference).max(-1), np.abs(quaternions + reference).max(-1))
    assert closest[valid].max() < 1e-9


@pytest.mark.parametrize("amc", AMCS, ids=ids(AMCS))
def test_c_kernel_equals_numpy_twin(amc):
    motion = load(amc)
    positions, local, world = twin(motion)
    scale = max(1.0, np.abs(positions).max())
    np.testing.assert_allclose(motion.positions(), positions, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(motion.rotations(), world, rtol=0, atol=1e-12)
    np.testing.assert_allclose(motion.rotations(local=True), local, rtol=0, atol=1e-12)
    starts = motion.positions(start=True)
    np.testing.assert_array_equal(starts[:, 0], motion.positions()[:, 0])
    parent = motion.skeleton.joint_names.index(motion.skeleton.parent(motion.skeleton.bone_names[-1]))
    np.testing.assert_array_equal(starts[:, -1], motion.positions()[:, parent])


def test_rest_pose_is_parent_plus_direction_times_length(data_dir):
    for asf in sorted(data_dir.glob("*/*.asf")):
        skeleton = mt.read_asf(asf)
        rest = skeleton.rest_positions()
        names = skeleton.joint_names
        np.testing.assert_array_equal(rest[0], skeleton.root.position)
        for bone in skeleton.bones:
            d = np.asarray(bone.direction)
            expected = rest[names.index(skeleton.parent(bone.name))] + d / np.linalg.norm(d) * bone.length
            np.testing.assert_allclose(rest[names.index(bone.name)], expected, rtol=0, atol=1e-9, err_msg=bone.name)
        np.testing.assert_array_equal(
            skeleton.rest_positions(start=True)[names.index(skeleton.bone_names[0])],
            rest[names.index(skeleton.parent(skeleton.bone_names[0]))],
        )


@pytest.fixture
def cmu(data_dir):
    return load(data_dir / "cmu" / "01_01.amc")


def test_positions_invariant_to_angle_unit(cmu):
    np.testing.assert_allclose(cmu.to_radians().positions(), cmu.positions(), rtol=0, atol=1e-9)


def test_positions_in_meters_scale_by_the_unit(cmu):
    factor = 0.0254 / 0.45
    np.testing.assert_allclose(cmu.to_meters().positions(), cmu.positions() * factor, rtol=0, atol=1e-9)
    np.testing.assert_allclose(cmu.positions(meters=True), cmu.positions() * factor, rtol=0, atol=1e-12)


def test_positions_invariant_to_axis_order(data_dir, tmp_path):
    """Every bone's axis written in ZYX order with the angles rewritten: the same positions."""
    asf = (data_dir / "cmu" / "01.asf").read_bytes()

    def rewrite(match):
        angles = [float(x) for x in match.group(1).split()]
        zyx = Rotation.from_euler("xyz", angles, degrees=True).as_euler("zyx", degrees=True)
        return b"axis " + b" ".join(repr(float(a)).encode() for a in zyx[::-1]) + b" ZYX"

    (tmp_path / "zyx.asf").write_bytes(re.sub(rb"axis ([-\d.e+ ]+?)\s+XYZ", rewrite, asf))
    original = load(data_dir / "cmu" / "01_01.amc")
    rewritten = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(tmp_path / "zyx.asf"))
    assert rewritten.skeleton.bone("lfemur").axis_order == "ZYX"
    np.testing.assert_allclose(rewritten.positions(), original.positions(), rtol=0, atol=1e-9)


def test_nan_reaches_the_joint_and_its_descendants_only(cmu):
    values = cmu.values.copy()
    values[10, cmu.columns("lfemur", "ry")[0]] = np.nan
    positions = cmu.replace(values=values).positions()
    names = cmu.skeleton.joint_names
    below = {"lfemur", "ltibia", "lfoot", "ltoes"}
    for i, name in enumerate(names):
        assert np.isnan(positions[10, i]).all() == (name in below), name
    assert not np.isnan(positions[[9, 11]]).any()


def test_result_does_not_depend_on_workers(cmu):
    one = cmu.positions(workers=1)
    for workers in (2, 3, -1):
        np.testing.assert_array_equal(cmu.positions(workers=workers), one)


def test_motion_of_another_skeleton_is_refused(data_dir, cmu):
    other = mt.read_asf(data_dir / "edge" / "test.asf")
    with pytest.raises(ValueError, match=r"values must have shape \(frames, 60\) for this skeleton, got \(2751, 62\)"):
        cmu.replace(skeleton=other)


def single_joint(kind, scale=1.0):
    return JointTree(
        parent=[-1],
        order=[0],
        axis=[np.eye(3)],
        direction=[np.zeros(3)],
        segment=[np.zeros(3)],
        dof_start=[0, 1],
        dof_kind=[kind],
        dof_column=[0],
        angle_scale=scale,
    )


def test_sin_and_cos_to_an_ulp(rng):
    """The kernel's own sin/cos (vectorised over frames) against libm, large angles included."""
    x = np.concatenate(
        [
            rng.uniform(-10, 10, 20000),
            rng.uniform(-1e6, 1e6, 20000),
            np.linspace(-7, 7, 10001),
            [0.0, -0.0, np.pi / 4, np.pi / 2, np.pi, 2.0**30, 2.0**31, 1e300, 5e-324],
        ]
    )
    _, _, local = forward_kinematics(x[:, None], single_joint(2), local=True)
    np.testing.assert_allclose(local[:, 0, 0, 0], np.cos(x), rtol=0, atol=2.3e-16)
    np.testing.assert_allclose(local[:, 0, 1, 0], np.sin(x), rtol=0, atol=2.3e-16)
    special = np.array([[np.inf], [-np.inf], [np.nan]])
    assert np.isnan(forward_kinematics(special, single_joint(0), local=True)[2]).any(axis=(1, 2, 3)).all()


def test_quaternions_equal_scipy(rng):
    rotations = Rotation.random(5000, random_state=1)
    matrices = np.concatenate(
        [
            rotations.as_matrix(),
            Rotation.from_rotvec([[np.pi, 0, 0], [0, np.pi, 0], [0, 0, np.pi], [0, 0, 0]]).as_matrix(),
        ]
    )
    q = rot.matrices_to_quaternions(matrices)
    expected = Rotation.from_matrix(matrices).as_quat(scalar_first=True)
    assert (q[:, 0] >= 0).all()
    np.testing.assert_allclose(np.minimum(np.abs(q - expected).max(-1), np.abs(q + expected).max(-1)), 0, atol=1e-12)


def test_bad_tables_are_refused():
    """In Python, before any C call, with the argument named; the C kernel checks them again."""
    good = dict(
        parent=[-1, 0],
        order=[0, 1],
        axis=[np.eye(3)] * 2,
        direction=np.zeros((2, 3)),
        segment=np.zeros((2, 3)),
        dof_start=[0, 1, 2],
        dof_kind=[0, 3],
        dof_column=[0, 1],
    )
    bad = [
        (dict(order=[0]), ValueError, r"order must be one-dimensional of shape \(2,\), got shape \(1,\)"),
        (
            dict(parent=[1, -1], order=[0, 1]),
            ValueError,
            r"each joint after its parent: joint 0 at order\[0\] before 1",
        ),
        (dict(order=[0, 0]), ValueError, r"every joint once, got joint 0 twice \(order\[1\]\)"),
        (dict(parent=[-1, 2]), ValueError, r"parent must lie in -1 .. 1, got parent\[1\] = 2"),
        (dict(parent=[-1.0, 0.5]), TypeError, "parent must hold integers, got dtype float64"),
        (dict(dof_kind=[0, 7]), ValueError, r"dof_kind must lie in 0 .. 6, got dof_kind\[1\] = 7"),
        (dict(dof_column=[0, -1]), ValueError, r"dof_column must lie in 0 .. \d+, got dof_column\[1\] = -1"),
        (dict(dof_start=[0, 2, 1]), ValueError, r"dof_start must rise from 0 to the length of dof_kind \(2\)"),
        (dict(dof_start=[0, 1, 3]), ValueError, r"dof_start must lie in 0 .. 2"),
        (dict(axis=np.eye(3)), ValueError, r"axis must be three-dimensional of shape \(2, 3, 3\), got shape \(3, 3\)"),
        (dict(segment=None), TypeError, "segment must be an array, got None"),
        (
            dict(direction=[["a"] * 3] * 2),
            TypeError,
            r"^direction must hold real numbers \(bool, integer or float\), got dtype <U1$",
        ),
        (dict(parent_frame=[0, 2]), ValueError, r"parent_frame must lie in 0 .. 1"),
        (dict(angle_scale=np.nan), ValueError, "angle_scale must be finite, got nan"),
    ]
    for change, exc, message in bad:
        with pytest.raises(exc, match=message):
            JointTree(**{**good, **change})
    tree = JointTree(**good)
    with pytest.raises(ValueError, match="reads column 1 but values have 1 channels"):
        forward_kinematics(np.zeros((3, 1)), tree)
    with pytest.raises(ValueError, match=r"values must be two-dimensional of shape \(any, any\), got shape \(3,\)"):
        forward_kinematics(np.zeros(3), tree)
    with pytest.raises(TypeError, match="tree must be a JointTree, got dict"):
        forward_kinematics(np.zeros((3, 2)), good)
    with pytest.raises(ValueError, match="reads column 0 but values have 0 channels"):
        forward_kinematics(np.zeros((3, 0)), single_joint(0))


def test_the_c_kernel_checks_the_tree_again():
    """A table that skips the Python checks (a child before its parent) is refused in C."""
    from mtcore._cdata import c_array
    from mtcore._mtcore import ffi, lib

    parent, order = np.array([1, -1]), np.array([0, 1])
    start = np.zeros(3, np.uintp)
    positions = np.empty((1, 2, 3))
    status = lib.mt_forward_kinematics(
        c_array(np.zeros((1, 1))), 1, 1, 2, c_array(parent, "long long[]"), c_array(order, "long long[]"),
        c_array(np.tile(np.eye(3), (2, 1))), c_array(np.zeros(6)), c_array(np.zeros(6)), c_array(start, "size_t[]"),
        ffi.NULL, ffi.NULL, ffi.NULL, 1.0, 0, 1, c_array(positions), ffi.NULL, ffi.NULL, ffi.NULL, 0,
    )  # fmt: skip
    assert status == lib.MT_EINVAL


@pytest.mark.parametrize("amc", AMCS, ids=ids(AMCS))
def test_local_quaternions_are_scipys_rotations_of_the_local_matrices(amc):
    """Every joint of every real take: the keys are scipy's quaternions of forward kinematics'
    local rotations, up to the sign, which keeps each joint's keys on one side from frame to frame."""
    take = load(amc)
    _, _, local = forward_kinematics(take.values, take.skeleton.tree, local=True)
    joints = np.arange(take.skeleton.tree.joints)
    keys = local_quaternions(take.values, take.skeleton.tree, joints)
    assert keys.dtype == np.float32 and keys.shape == (len(joints), take.frames, 4)
    want = Rotation.from_matrix(local.reshape(-1, 3, 3)).as_quat().reshape(take.frames, -1, 4).transpose(1, 0, 2)
    sign = np.sign(np.sum(keys * want, axis=-1, keepdims=True))
    np.testing.assert_allclose(keys, sign * want, rtol=0, atol=2e-7)
    assert (keys[:, 0, 3] >= 0).all() and (np.sum(keys[:, 1:] * keys[:, :-1], axis=-1) >= 0).all()


def test_local_quaternions_turn_the_first_joint_only(cmu):
    turn = Rotation.from_euler("x", -90, degrees=True).as_matrix()
    tree = cmu.skeleton.tree
    plain, turned = local_quaternions(cmu.values, tree, [0, 5]), local_quaternions(cmu.values, tree, [0, 5], turn)
    np.testing.assert_array_equal(turned[1], plain[1])
    want = (Rotation.from_matrix(turn) * Rotation.from_quat(plain[0].astype(float))).as_quat()
    np.testing.assert_allclose(np.abs(np.sum(turned[0] * want, axis=-1)), 1, atol=1e-6)


def test_nan_reaches_its_joints_keys_at_its_frame_only(cmu):
    values = cmu.values.copy()
    values[10, cmu.columns("lfemur", "ry")[0]] = np.nan
    names = cmu.skeleton.joint_names
    keys = local_quaternions(values, cmu.skeleton.tree, np.arange(len(names)))
    broken = np.isnan(keys).any(axis=-1)
    assert broken.sum() == 1 and broken[names.index("lfemur"), 10]
    plain = local_quaternions(cmu.values, cmu.skeleton.tree, np.arange(len(names)))
    np.testing.assert_array_equal(keys[:, 11:], plain[:, 11:])  # the next keys keep their side


def test_local_quaternions_refuse_bad_arguments(cmu):
    tree = cmu.skeleton.tree
    with pytest.raises(
        ValueError, match=rf"joints must lie in 0 .. {tree.joints - 1}, got joints\[1\] = {tree.joints}"
    ):
        local_quaternions(cmu.values, tree, [0, tree.joints])
    with pytest.raises(ValueError, match=r"turn must be two-dimensional of shape \(3, 3\)"):
        local_quaternions(cmu.values, tree, [0], np.eye(4))
    with pytest.raises(ValueError, match="reads column 61 but values have 3 channels"):
        local_quaternions(cmu.values[:, :3], tree, [0])
    with pytest.raises(TypeError, match="tree must be a JointTree, got dict"):
        local_quaternions(cmu.values, {}, [0])
    assert local_quaternions(cmu.values[:0], tree, [0, 1]).shape == (2, 0, 4)
    assert local_quaternions(cmu.values, tree, []).shape == (0, cmu.frames, 4)


def test_a_pruned_tree_puts_the_joints_it_keeps_where_the_whole_tree_does(rng):
    from twins import random_tree

    for joints in (1, 2, 7, 15):
        tree = random_tree(rng, joints)
        values = rng.uniform(-180, 180, (5, max(len(tree.dof_kind), 1)))
        whole = forward_kinematics(values, tree, world=True, local=True)
        for wanted in ([], [0], rng.integers(0, joints, 3).tolist(), list(range(joints))):
            pruned, index = tree.pruned(wanted)
            kept = np.flatnonzero(index >= 0)
            ancestors = set()
            for j in wanted:
                while j >= 0:
                    ancestors.add(j)
                    j = int(tree.parent[j])
            assert set(kept.tolist()) == ancestors and pruned.joints == len(kept)
            for got, want in zip(forward_kinematics(values, pruned, world=True, local=True), whole):
                np.testing.assert_array_equal(got[:, index[kept]], want[:, kept])


def test_the_quaternion_kernel_checks_its_joints_again():
    from mtcore._cdata import c_array
    from mtcore._mtcore import ffi, lib

    tree = single_joint(0)
    out = np.empty((1, 1, 4), np.float32)
    for chosen in ([-1], [1]):
        status = lib.mt_local_quaternions(
            c_array(np.zeros((1, 1))), 1, 1, 1, c_array(tree.axis), c_array(tree.dof_start, "size_t[]"),
            c_array(tree.dof_kind, "int[]"), c_array(tree.dof_column, "size_t[]"), 1.0, 1,
            c_array(np.array(chosen), "long long[]"), ffi.NULL, c_array(out, "float[]"),
        )  # fmt: skip
        assert status == lib.MT_EINVAL


@pytest.mark.parametrize("order", ["xyz", "xzy", "yxz", "yzx", "zxy", "zyx"])
@pytest.mark.parametrize("extrinsic", [True, False])
def test_euler_conversions_equal_the_numpy_twin(rng, order, extrinsic):
    from twins import rotations as euler_twin

    angles = rng.uniform(-np.pi, np.pi, (997, 3))
    angles[:, 1] /= 2  # the middle angle's range, where the triple is the one the conversion returns
    matrices = rot.euler_to_matrices(angles, order, extrinsic=extrinsic)
    twin = euler_twin.euler_to_matrices(angles, order, extrinsic=extrinsic)
    np.testing.assert_allclose(matrices, twin, rtol=0, atol=1e-15)
    back = rot.matrices_to_euler(matrices, order, extrinsic=extrinsic)
    np.testing.assert_allclose(back, angles, rtol=0, atol=1e-11)
    np.testing.assert_allclose(back, euler_twin.matrices_to_euler(matrices, order, extrinsic=extrinsic), atol=1e-11)


@pytest.mark.parametrize("amc", AMCS[:2], ids=ids(AMCS[:2]))
def test_world_rotations_kept_to_a_few_joints_are_theirs_of_every_joint(amc):
    """turned keeps the world rotations to those joints, in their order, the same numbers as
    every joint's; the positions do not change; a joint left out is named when asked for."""
    take = load(amc)
    tree = take.skeleton.tree
    every = world_kinematics(take.values, tree)
    few = world_kinematics(take.values, tree, turned=[0, 3, 7])
    np.testing.assert_array_equal(few.positions, every.positions)
    np.testing.assert_array_equal(few.world, every.world[:, [0, 3, 7]])
    np.testing.assert_array_equal(few.world[:, few.rows([7, 0])], every.world[:, [7, 0]])
    np.testing.assert_array_equal(every.rows([5]), [5])
    with pytest.raises(ValueError, match="joint 4 was kept"):
        few.rows([3, 4])
    with pytest.raises(ValueError, match="ascending"):
        world_kinematics(take.values, tree, turned=[3, 0])
    with pytest.raises(ValueError, match="turned must lie"):
        world_kinematics(take.values, tree, turned=[0, tree.joints])


@pytest.mark.parametrize("amc", AMCS[:2], ids=ids(AMCS[:2]))
def test_kinematics_written_into_arrays_given_are_the_new_ones(amc):
    """out: the positions and rotations written into the arrays given (and returned as they are)
    are those of new arrays, whatever the arrays held before; arrays that do not fit, or that
    share the values' memory, are refused before anything is written."""
    take = load(amc)
    tree, frames, n = take.skeleton.tree, take.frames, take.skeleton.tree.joints
    fresh = forward_kinematics(take.values, tree, world=True, local=True)
    given = tuple(np.full(shape, np.nan) for shape in ((frames, n, 3), (frames, n, 3, 3), (frames, n, 3, 3)))
    written = forward_kinematics(take.values, tree, world=True, local=True, out=given)
    for new, into, got in zip(fresh, given, written):
        assert got is into
        np.testing.assert_array_equal(got, new)
    few = world_kinematics(take.values, tree, turned=[1, 4], out=(given[0], np.zeros((frames, 2, 3, 3))))
    np.testing.assert_array_equal(few.world, fresh[1][:, [1, 4]])
    with pytest.raises(ValueError, match=r"out world must be .*shape \(\d+, 2, 3, 3\), got shape"):
        world_kinematics(take.values, tree, turned=[1, 4], out=(given[0], given[1]))
    with pytest.raises(ValueError, match="out positions must be .*float64.*got dtype float32"):
        forward_kinematics(take.values, tree, out=(given[0].astype(np.float32), None, None))
    with pytest.raises(ValueError, match="out local is given, but its rotations are not asked for"):
        forward_kinematics(take.values, tree, out=(None, None, given[2]))
    with pytest.raises(ValueError, match="out must be"):
        forward_kinematics(take.values, tree, out=(given[0],))
    channels = take.values.shape[1]
    memory = np.zeros(frames * max(channels, n * 3))
    values = memory[: frames * channels].reshape(frames, channels)
    values[:] = take.values
    with pytest.raises(ValueError, match="shares memory with the values"):
        forward_kinematics(values, tree, out=(memory[: frames * n * 3].reshape(frames, n, 3), None, None))
