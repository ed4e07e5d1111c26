"""The fused interpolation kernel (mt_interpolate_euler) against the chain of single-step kernels it
replaces, and the vectorised atan2, sin and cos of the rotation kernels against the C library's."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mtcore import rotations as rot
from mtcore._cdata import c_array
from mtcore._mtcore import ffi, lib

BLENDS = list(rot.BLENDS)


def atan2(y, x) -> np.ndarray:
    y, x = np.ascontiguousarray(y, float), np.ascontiguousarray(x, float)
    out = np.empty_like(y)
    assert lib.mt_atan2(c_array(y), c_array(x), y.size, c_array(out)) == 0
    return out


def sincos(x) -> tuple[np.ndarray, np.ndarray]:
    x = np.ascontiguousarray(x, float)
    s, c = np.empty_like(x), np.empty_like(x)
    assert lib.mt_sincos(c_array(x), x.size, c_array(s), c_array(c)) == 0
    return s, c


def libm(function, *args) -> np.ndarray:
    """The C library's function (through Python's math module) over arrays, one value at a time."""
    return np.array([function(*a) for a in zip(*(np.asarray(x, float).ravel() for x in args))])


def same_bits(got, want) -> bool:
    return bool(np.all((got == want) & (np.signbit(got) == np.signbit(want)) | (np.isnan(got) & np.isnan(want))))


SPECIAL = [0.0, -0.0, math.inf, -math.inf, math.nan, 1.0, -1.0]  # libm's exact cases: axes, diagonals, limits
ODD = [5e-324, -5e-324, 2.2e-308, 1e308, -1e308, 0.66, 1.5]


def test_atan2_is_the_c_librarys_within_an_ulp_of_pi(rng):
    n = 200_000
    magnitude = 10.0 ** rng.uniform(-320, 307, (2, n))  # subnormals to near overflow, ratios of any size
    y, x = rng.uniform(-9.9, 9.9, (2, n)) * magnitude
    near = rng.uniform(-1, 1, (2, n))  # and angles of every octant, ratios near the 0.66 and 1 seams
    seams = np.array([0.66, 1.0, math.tan(math.pi / 8)])[rng.integers(3, size=n)] * (1 + rng.normal(size=n) * 1e-9)
    for yy, xx in ((y, x), (near[0], near[1]), (seams * near[1], near[1])):
        np.testing.assert_allclose(atan2(yy, xx), libm(math.atan2, yy, xx), rtol=0, atol=np.spacing(math.pi))
    ys, xs = (grid.ravel() for grid in np.meshgrid(SPECIAL, SPECIAL))
    assert same_bits(atan2(ys, xs), libm(math.atan2, ys, xs))  # zeros' signs, infinities, NaN, exact octants
    ys, xs = (grid.ravel() for grid in np.meshgrid(SPECIAL + ODD, SPECIAL + ODD))
    np.testing.assert_allclose(atan2(ys, xs), libm(math.atan2, ys, xs), rtol=0, atol=np.spacing(math.pi))


def test_atan2_is_odd_and_exact_where_libm_is(rng):
    y, x = rng.standard_normal((2, 1000))
    assert same_bits(atan2(-y, x), -atan2(y, x))
    assert same_bits(atan2(x, x), np.where(x > 0, math.pi / 4, -3 * math.pi / 4))


@pytest.mark.parametrize("scale", [1.0, 10.0, 1e3, 1e6, 2.0**30, 1e300])
def test_sincos_is_the_c_librarys(rng, scale):
    x = rng.uniform(-scale, scale, 100_000)
    s, c = sincos(x)
    np.testing.assert_allclose(s, libm(math.sin, x), rtol=0, atol=2.3e-16)
    np.testing.assert_allclose(c, libm(math.cos, x), rtol=0, atol=2.3e-16)


def test_sincos_special_values():
    x = np.array([0.0, -0.0, 5e-324, -1e-300, math.inf, -math.inf, math.nan, 2.0**30, -1e17])
    s, c = sincos(x)
    finite = np.isfinite(x)
    assert same_bits(s[finite], libm(math.sin, x[finite])) and same_bits(c[finite], libm(math.cos, x[finite]))
    assert np.isnan(s[~finite]).all() and np.isnan(c[~finite]).all()


def keys_off_lock(rng, order: str, shape: tuple[int, ...], half: float) -> np.ndarray:
    """Euler triples whose middle angle keeps 0.2 rad from gimbal lock, where a and c are ill-conditioned."""
    lo, hi = (0.2, math.pi - 0.2) if order[0] == order[2] else (-math.pi / 2 + 0.2, math.pi / 2 - 0.2)
    k = rng.uniform(-math.pi, math.pi, shape + (3,))
    k[..., 1] = rng.uniform(lo, hi, shape)
    return k * half / math.pi


def chain(k0, k1, t, order, extrinsic, degrees, blend):
    """The single-step kernels in the order the fused kernel replaced: quaternions, blend, Euler angles."""
    q0, q1 = (rot.euler_to_quaternions(k, order, extrinsic=extrinsic, degrees=degrees) for k in (k0, k1))
    if k0.ndim == 2:
        q0, q1 = q0[None], q1[None]
    if blend == "slerp":
        q = rot.slerp(q0, q1, t[:, None])
    else:
        v0, v1 = rot.quaternions_to_rotvecs(q0), rot.quaternions_to_rotvecs(q1)
        q = rot.rotvecs_to_quaternions(rot.interpolate_rotvecs(v0, v1, t[:, None], aligned=blend == "aligned_expmap"))
    return rot.quaternions_to_euler(q, order, extrinsic=extrinsic, degrees=degrees)


@pytest.mark.parametrize("blend", BLENDS)
@pytest.mark.parametrize("order", rot.ORDERS)
def test_interpolate_euler_is_the_chain_it_replaced(rng, order, blend):
    for extrinsic in (True, False):
        for degrees in (True, False):
            half = 180.0 if degrees else math.pi
            k0, k1 = keys_off_lock(rng, order, (9,), half), keys_off_lock(rng, order, (9,), half)
            t = np.linspace(0, 1, 41)
            got = rot.interpolate_euler(k0, k1, t, order, extrinsic=extrinsic, degrees=degrees, blend=blend)
            want = chain(k0, k1, t, order, extrinsic, degrees, blend)
            rotations = [Rotation.from_euler(order if extrinsic else order.upper(), a.reshape(-1, 3), degrees=degrees)
                         for a in (got, want)]  # fmt: skip
            assert ((rotations[0].inv() * rotations[1]).magnitude() < 1e-14).all()
            # the angles too, where the path stays off gimbal lock (SLERP may pass near it)
            lock = np.abs(np.cos(np.radians(want[..., 1]) if degrees else np.cos(want[..., 1])))
            lock = lock if order[0] != order[2] else np.sqrt(1 - lock**2)
            off = lock > 0.05
            diff = np.angle(np.exp(1j * (got - want) * math.pi / half))
            np.testing.assert_allclose(diff[off], 0, rtol=0, atol=1e-12)


@pytest.mark.parametrize("blend", BLENDS)
def test_a_path_and_nearest_turns_are_the_steps_they_name(rng, blend):
    """start= is unroll_euler from the start triples; reference= is each angle's nearest turns (ties to even)."""
    for order, degrees in (("zxy", True), ("xyx", False)):
        half = 180.0 if degrees else math.pi
        k0, k1 = rng.uniform(-2 * half, 2 * half, (2, 5, 3))
        t = np.linspace(0, 1, 60)
        common = dict(extrinsic=False, degrees=degrees, blend=blend)
        angles = rot.interpolate_euler(k0, k1, t, order, **common)
        start = k0 + 2 * half * rng.integers(-2, 3, k0.shape)
        path = rot.interpolate_euler(k0, k1, t, order, start=start, **common)
        expected = rot.unroll_euler(np.concatenate([start[None], angles]), order, degrees=degrees)[1:]
        np.testing.assert_array_equal(path, expected)
        reference = rng.uniform(-5 * half, 5 * half, angles.shape)
        reference[0, 0, 0] = angles[0, 0, 0] + 3 * half  # a tie: three half turns away, rounds to two turns
        turned = rot.interpolate_euler(k0, k1, t, order, reference=reference, **common)
        np.testing.assert_array_equal(turned, angles + 2 * half * np.round((reference - angles) / (2 * half)))


@pytest.mark.parametrize("joints", [1, 3, 8, 31, 33])
def test_keys_per_frame_or_per_joint_give_the_same_bits(rng, joints):
    k0, k1 = rng.uniform(-3, 3, (2, joints, 3))
    t = rng.uniform(0, 1, 45)
    for blend in BLENDS:
        common = dict(extrinsic=True, blend=blend, start=k0)
        each = (np.broadcast_to(k, (len(t), joints, 3)) for k in (k0, k1))
        np.testing.assert_array_equal(
            rot.interpolate_euler(*each, t, "xzy", **common), rot.interpolate_euler(k0, k1, t, "xzy", **common)
        )


def test_a_path_restarts_after_nan_and_keys_give_their_rotations(rng):
    k0, k1 = rng.uniform(-90, 90, (2, 4, 3))
    k1[2, 1] = np.nan
    t = np.linspace(0, 1, 7)
    out = rot.interpolate_euler(k0, k1, t, "xyz", extrinsic=True, degrees=True, start=k0 + 360)
    assert np.isnan(out[:, 2]).all() and not np.isnan(np.delete(out, 2, axis=1)).any()
    ends = rot.interpolate_euler(k0, k1, np.array([0.0, 1.0]), "xyz", extrinsic=True, degrees=True)
    fine = ~np.isnan(k1).any(axis=1)
    for end, keys in ((ends[0], k0), (ends[1], k1)):
        r = Rotation.from_euler("xyz", end[fine], degrees=True).inv() * Rotation.from_euler(
            "xyz", keys[fine], degrees=True
        )
        assert (r.magnitude() < 1e-14).all()


def test_interpolate_euler_shapes_and_nothing_to_do(rng):
    k = rng.uniform(-1, 1, (3, 3))
    assert rot.interpolate_euler(k, k, np.empty(0), "xyz", extrinsic=True).shape == (0, 3, 3)
    assert rot.interpolate_euler(np.empty((0, 3)), np.empty((0, 3)), [0.5], "xyz", extrinsic=True).shape == (1, 0, 3)


@pytest.mark.parametrize(
    ("call", "exc", "message"),
    [
        (lambda k, t: rot.interpolate_euler(k, k, t, "xyz", extrinsic=True, blend="nlerp"), ValueError, "blend must"),
        (lambda k, t: rot.interpolate_euler(k, k[:1], t, "xyz", extrinsic=True), ValueError, r"k0 and k1 must"),
        (lambda k, t: rot.interpolate_euler(k[None], k[None], t, "xyz", extrinsic=True), ValueError, "frames = len"),
        (
            lambda k, t: rot.interpolate_euler(k, k, t[:, None], "xyz", extrinsic=True),
            ValueError,
            r"^t must be one-dimensional of shape \(frames,\), got shape \(4, 1\)$",
        ),
        (lambda k, t: rot.interpolate_euler(k, k, t, "XYZ", extrinsic=True), ValueError, "lowercase"),
        (lambda k, t: rot.interpolate_euler(k, k, t, "xyz", extrinsic=1), TypeError, "extrinsic must"),
        (
            lambda k, t: rot.interpolate_euler(k, k, t, "xyz", extrinsic=True, start=k, reference=k),
            ValueError,
            "not both",
        ),
        (lambda k, t: rot.interpolate_euler(k, k, t, "xyz", extrinsic=True, start=k[:1]), ValueError, "start must"),
        (lambda k, t: rot.interpolate_euler(k, k, t, "xyz", extrinsic=True, reference=k), ValueError, "reference must"),
        (lambda k, t: rot.interpolate_euler(k.astype(complex), k, t, "xyz", extrinsic=True), TypeError, "real"),
    ],
)
def test_interpolate_euler_refuses_bad_arguments(rng, call, exc, message):
    with pytest.raises(exc, match=message):
        call(rng.uniform(-1, 1, (2, 3)), np.linspace(0, 1, 4))


def test_the_kernel_checks_its_arguments():
    k, t, out = np.zeros(6), np.zeros(2), np.zeros(12)
    good = dict(per_frame=0, axes=[0, 1, 2], blend=lib.MT_BLEND_SLERP, continuity=lib.MT_CONTINUITY_NONE, ref=k)

    def call(per_frame, axes, blend, continuity, ref):
        return lib.mt_interpolate_euler(
            c_array(k), c_array(k), per_frame, c_array(t), 2, 2, ffi.new("int[]", axes), 0, 0, blend, continuity,
            c_array(ref), c_array(out),
        )  # fmt: skip

    assert call(**good) == lib.MT_OK
    for bad in (dict(axes=[0, 0, 1]), dict(axes=[0, 3, 1]), dict(blend=3), dict(continuity=-1), dict(continuity=3)):
        assert call(**{**good, **bad}) == lib.MT_EINVAL, bad
    assert call(**{**good, "continuity": lib.MT_CONTINUITY_PATH, "ref": None}) == lib.MT_EINVAL
    assert lib.mt_atan2(ffi.NULL, c_array(k), 1, c_array(out)) == lib.MT_EINVAL
    assert lib.mt_sincos(c_array(k), 1, ffi.NULL, c_array(out)) == lib.MT_EINVAL
    assert lib.mt_atan2(ffi.NULL, ffi.NULL, 0, ffi.NULL) == lib.MT_OK  # nothing to do
