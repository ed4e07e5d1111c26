"""Interpolators over frame ranges and their pipeline; the CS838 comparison."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

import motiontheater as mt
from motiontheater import Pipeline, interpolate, median3
from mtcore import rotations as rot

EPS = 0.1


def one_joint(values, unit="rad"):
    skeleton = mt.Skeleton(
        bones=(mt.Bone(name="arm", direction=(1, 0, 0), length=1, dofs=("rx", "ry", "rz")),),
        hierarchy=(("root", ("arm",)),),
        units=(("angle", unit),),
    )
    return mt.Motion(skeleton, values, first_frame=1)


@pytest.fixture
def cs838():
    """Keys -(pi - eps) and (pi - eps) about +y at frames 100 and 150."""
    values = np.zeros((200, 9))
    values[:100, 7] = -(np.pi - EPS)
    values[149:, 7] = np.pi - EPS
    return one_joint(values)


def total_turn(motion, first, last):
    q = rot.euler_to_quaternions(motion.values[first - 1 : last, 6:9], "xyz", extrinsic=True)
    return (2 * np.arccos(np.clip(np.abs(np.sum(q[1:] * q[:-1], -1)), 0, 1))).sum()


@pytest.mark.parametrize(
    "kind,turn",
    [("slerp", 2 * EPS), ("expmap", 2 * (np.pi - EPS)), ("euler", 2 * (np.pi - EPS)), ("aligned_expmap", 2 * EPS)],
)
def test_cs838_comparison(cs838, kind, turn):
    result = interpolate(cs838, kind, frames=(100, 150), joints=["arm"])
    assert total_turn(result, 100, 150) == pytest.approx(turn, abs=1e-9)
    np.testing.assert_array_equal(result.values[:100], cs838.values[:100])  # keys and outside untouched
    np.testing.assert_array_equal(result.values[149:], cs838.values[149:])


@pytest.mark.parametrize("convention", ["asf", "bvh"])
def test_slerp_equals_scipy_on_a_real_joint(data_dir, convention):
    if convention == "asf":
        motion = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))
        joint, order = "lfemur", "xyz"
    else:
        motion = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
        joint, order = "RightUpLeg", "ZXY"  # intrinsic, as listed
    columns = motion.columns(joint, tuple(d for d in motion.skeleton.dofs(joint) if d.startswith("r")))
    result = interpolate(motion, "slerp", frames=(20, 60), joints=[joint])
    keys = Rotation.from_euler(order, motion.values[[19, 59]][:, columns], degrees=True)
    expected = Slerp([20, 60], keys)(np.arange(21, 60))
    got = Rotation.from_euler(order, result.values[20:59, columns], degrees=True)
    assert ((expected.inv() * got).magnitude() < 1e-9).all()
    others = [c for c in range(motion.values.shape[1]) if c not in columns]
    np.testing.assert_array_equal(result.values[:, others], motion.values[:, others])


def test_translations_and_partial_joints_interpolate_linearly(data_dir):
    motion = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))
    result = interpolate(motion, "slerp", frames=(10, 20), joints=["root", "ltibia"])
    for joint, dof in (("root", "tx"), ("ltibia", "rx")):
        keys = motion.channel(joint, dof)[[9, 19]]  # the input's: the keys must not move
        np.testing.assert_allclose(result.channel(joint, dof)[9:20], np.linspace(*keys, 11), rtol=0, atol=1e-12)


def test_median3_touches_only_its_range(data_dir):
    motion = mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))
    result = motion.median3(frames=(50, 80))
    np.testing.assert_array_equal(result.values[:49], motion.values[:49])
    np.testing.assert_array_equal(result.values[80:], motion.values[80:])
    column = motion.values[49:80, 5]
    np.testing.assert_array_equal(
        result.values[50:79, 5], np.median(np.stack([column[:-2], column[1:-1], column[2:]]), 0)
    )


def test_pipeline_applies_steps_in_order(data_dir):
    motion = mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))
    pipeline = (
        Pipeline()
        .then("median3", frames=(1, 343))
        .then("slerp", frames=(100, 140), joints=["lfemur"])
        .then("binomial", frames=(200, 300), size=5)
    )
    expected = interpolate(median3(motion), "slerp", frames=(100, 140), joints=["lfemur"])
    piece = expected.replace(values=expected.values[199:300], first_frame=200).binomial(size=5)
    values = expected.values.copy()
    values[199:300] = piece.values
    np.testing.assert_array_equal(pipeline.apply(motion).values, values)
    assert len(pipeline.steps) == 3
    assert Pipeline.from_toml(pipeline.to_toml()) == pipeline


@pytest.mark.parametrize(
    "call,message",
    [
        (
            lambda m: interpolate(m, frames=(150, 100)),
            r"the key frames 150:100 must lie within the motion's frames 1..200, the first before the last",
        ),
        (lambda m: m.slerp(frames=(0, 100)), r"the key frames 0:100"),
        (lambda m: interpolate(m, "cubic", frames=(10, 20)), "method must be one of slerp, euler, expmap"),
        (lambda m: Pipeline().then("spline", frames=(1, 5)), "no step 'spline'; the steps are: "),
        (lambda m: m.slerp(frames=(10, 20), joints=["leg"]), "no bone 'leg'"),
        (lambda m: m.slerp(frames=(10, 20), size=3), "step 'slerp' has no option 'size'"),
        (lambda m: m.slerp(), "step 'slerp' needs the option 'frames'"),
    ],
)
def test_bad_requests(cs838, call, message):
    with pytest.raises(ValueError, match=message):
        call(cs838)
