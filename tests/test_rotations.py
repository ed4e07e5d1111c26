"""mtcore.rotations against scipy.spatial.transform.Rotation and slow numpy twins:
every Euler order both ways, gimbal lock, angles near 0 and pi, continuity, interpolation
(the CS838 comparison), bad arguments."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation, Slerp

from mtcore import rotations as rot
from twins import rotations as twin

ORDERS = rot.ORDERS
KINDS = [pytest.param(True, id="extrinsic"), pytest.param(False, id="intrinsic")]


def scipy_seq(order: str, extrinsic: bool) -> str:
    return order if extrinsic else order.upper()


def wrapped(a):
    """Angle differences as the shortest signed angles (so that pi and -pi agree)."""
    return np.angle(np.exp(1j * np.asarray(a)))


def euler_samples(rng, order: str, n: int = 2000) -> np.ndarray:
    """Random angles (some beyond a turn), then gimbal lock: the middle angle exactly
    +-90 degrees (Tait-Bryan) or 0 and 180 (proper Euler)."""
    angles = rng.uniform(-7, 7, (n, 3))
    lock = rng.uniform(-np.pi, np.pi, (400, 3))
    lock[:, 1] = rng.choice([0.0, np.pi] if order[0] == order[2] else [-np.pi / 2, np.pi / 2], 400)
    return np.concatenate([angles, lock])


def total_turn(q):
    """Sum of the angles turned between consecutive frames of quaternions (frames, 4)."""
    r = Rotation.from_quat(q, scalar_first=True)
    return (r[1:] * r[:-1].inv()).magnitude().sum()


# --- Euler angles -------------------------------------------------------------------------


@pytest.mark.parametrize("extrinsic", KINDS)
@pytest.mark.parametrize("order", ORDERS)
def test_euler_to_matrices_equals_scipy_and_the_twin(rng, order, extrinsic):
    angles = euler_samples(rng, order)
    m = rot.euler_to_matrices(angles, order, extrinsic=extrinsic)
    np.testing.assert_allclose(
        m, Rotation.from_euler(scipy_seq(order, extrinsic), angles).as_matrix(), rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(m, twin.euler_to_matrices(angles, order, extrinsic), rtol=0, atol=1e-14)
    degrees = rot.euler_to_matrices(np.degrees(angles), order, extrinsic=extrinsic, degrees=True)
    np.testing.assert_allclose(degrees, m, rtol=0, atol=1e-14)


@pytest.mark.parametrize("extrinsic", KINDS)
@pytest.mark.parametrize("order", ORDERS)
def test_matrices_to_euler_equals_scipy(rng, order, extrinsic):
    seq = scipy_seq(order, extrinsic)
    general = Rotation.random(3000, random_state=7).as_matrix()
    angles = rot.matrices_to_euler(general, order, extrinsic=extrinsic)
    with np.errstate(all="ignore"):
        expected = Rotation.from_matrix(general).as_euler(seq)
    assert np.abs(wrapped(angles - expected)).max() < 1e-10  # scipy's own angles are good to ~1e-14
    np.testing.assert_allclose(Rotation.from_euler(seq, angles).as_matrix(), general, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        rot.matrices_to_euler(general, order, extrinsic=extrinsic, degrees=True), np.degrees(angles), rtol=0, atol=1e-12
    )
    # scipy's ranges
    middle = angles[:, 1]
    if order[0] == order[2]:
        assert ((middle >= 0) & (middle <= np.pi)).all()
    else:
        assert (np.abs(middle) <= np.pi / 2).all()
    assert (np.abs(angles[:, [0, 2]]) <= np.pi).all()


@pytest.mark.parametrize("extrinsic", KINDS)
@pytest.mark.parametrize("order", ORDERS)
def test_gimbal_lock_reproduces_the_matrix_with_the_third_angle_zero(rng, order, extrinsic):
    """At gimbal lock only a + c or a - c is defined: compare matrices, not angles."""
    seq = scipy_seq(order, extrinsic)
    lock = euler_samples(rng, order)[-400:]
    m = Rotation.from_euler(seq, lock).as_matrix()
    angles = rot.matrices_to_euler(m, order, extrinsic=extrinsic)
    np.testing.assert_allclose(Rotation.from_euler(seq, angles).as_matrix(), m, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rot.euler_to_matrices(angles, order, extrinsic=extrinsic), m, rtol=0, atol=1e-12)
    assert (angles[:, 2] == 0).all()  # as scipy chooses
    with pytest.warns(UserWarning, match="Gimbal lock"):
        expected = Rotation.from_matrix(m).as_euler(seq)
    assert np.abs(wrapped(angles - expected)).max() < 1e-12


@pytest.mark.parametrize("extrinsic", KINDS)
@pytest.mark.parametrize("order", ["xyz", "zyx", "yzx", "zxz", "yxy"])
def test_near_gimbal_lock_round_trips(rng, order, extrinsic):
    """Within 1e-15 .. 1e-3 of the lock, where asin- and acos-based formulas lose digits."""
    lock_angle = 0.0 if order[0] == order[2] else np.pi / 2
    offsets = np.repeat(10.0 ** -np.arange(3, 16), 50) * rng.choice([-1, 1], 650)
    angles = rng.uniform(-np.pi, np.pi, (650, 3))
    angles[:, 1] = lock_angle + offsets
    m = rot.euler_to_matrices(angles, order, extrinsic=extrinsic)
    back = rot.matrices_to_euler(m, order, extrinsic=extrinsic)
    np.testing.assert_allclose(rot.euler_to_matrices(back, order, extrinsic=extrinsic), m, rtol=0, atol=1e-13)


@given(angles=st.tuples(*[st.floats(-20, 20)] * 3), order=st.sampled_from(ORDERS), extrinsic=st.booleans())
@settings(max_examples=500, deadline=None)
def test_euler_round_trip_property(angles, order, extrinsic):
    m = rot.euler_to_matrices(np.array(angles), order, extrinsic=extrinsic)
    back = rot.matrices_to_euler(m, order, extrinsic=extrinsic)
    np.testing.assert_allclose(rot.euler_to_matrices(back, order, extrinsic=extrinsic), m, rtol=0, atol=1e-13)
    assert np.abs(back).max() <= np.pi


# --- quaternions and rotation vectors -----------------------------------------------------


def test_quaternions_and_matrices_equal_scipy():
    r = Rotation.random(5000, random_state=1)
    m = np.concatenate([r.as_matrix(), Rotation.from_rotvec(np.pi * np.eye(3)).as_matrix(), np.eye(3)[None]])
    q = rot.matrices_to_quaternions(m)
    expected = Rotation.from_matrix(m).as_quat(scalar_first=True, canonical=True)
    assert (q[:, 0] >= 0).all()
    np.testing.assert_allclose(
        np.minimum(np.abs(q - expected).max(-1), np.abs(q + expected).max(-1)), 0, atol=1e-15
    )  # w = 0 at a half turn: either sign
    unnormalised = r.as_quat(scalar_first=True) * np.linspace(0.1, 10, 5000)[:, None]
    np.testing.assert_allclose(rot.quaternions_to_matrices(unnormalised), r.as_matrix(), rtol=0, atol=1e-15)


def test_rotvecs_equal_scipy():
    r = Rotation.random(5000, random_state=2)
    v = r.as_rotvec()
    np.testing.assert_allclose(
        rot.rotvecs_to_quaternions(v), r.as_quat(scalar_first=True, canonical=True), rtol=0, atol=1e-15
    )
    q = r.as_quat(scalar_first=True) * np.where(np.arange(5000) % 2, -3.0, 0.5)[:, None]  # any sign and norm
    np.testing.assert_allclose(rot.quaternions_to_rotvecs(q), v, rtol=0, atol=1e-14)
    np.testing.assert_allclose(rot.rotvecs_to_matrices(v), r.as_matrix(), rtol=0, atol=1e-14)
    np.testing.assert_allclose(rot.matrices_to_rotvecs(r.as_matrix()), v, rtol=0, atol=1e-14)
    long_way = v * (1 - 2 * np.pi / np.linalg.norm(v, axis=-1, keepdims=True))  # angles in (pi, 2 pi)
    np.testing.assert_allclose(rot.rotvecs_to_matrices(long_way), r.as_matrix(), rtol=0, atol=1e-14)
    assert (rot.rotvecs_to_quaternions(long_way)[:, 0] >= 0).all()


# the series end at an angle of 1e-4 (to quaternions) and 2e-4 (back)
@pytest.mark.parametrize(
    "angle",
    [
        0.0,
        1e-300,
        1e-20,
        1e-9,
        9.99e-5,
        1e-4,
        1.001e-4,
        1.999e-4,
        2e-4,
        2.001e-4,
        1e-3,
        0.5,
        np.pi - 1e-3,
        np.pi - 1e-9,
        np.pi - 4e-16,
        np.pi,
    ],
)
def test_rotvecs_near_zero_and_half_turns(rng, angle):
    """Series at small angles (no 0/0), atan2 rather than acos near pi: accurate throughout,
    against the closed form in extended precision."""
    axes = rng.normal(size=(500, 3))
    v = axes / np.linalg.norm(axes, axis=-1, keepdims=True) * angle
    q = rot.rotvecs_to_quaternions(v)
    theta = np.linalg.norm(v.astype(np.longdouble), axis=-1, keepdims=True)
    factor = np.sin(theta / 2) / np.where(theta > 0, theta, 1) if angle else 0.5
    expected = np.concatenate([np.cos(theta / 2), v * factor], axis=-1)
    assert (q[:, 0] >= 0).all()
    expected *= np.sign(np.sum(expected * q, axis=-1, keepdims=True))  # either sign where w = 0 within rounding
    np.testing.assert_allclose(q, expected.astype(float), rtol=0, atol=4e-16)  # |v| is rounded: w to 2e-16
    back = rot.quaternions_to_rotvecs(q)
    if angle < np.pi - 1e-6:
        np.testing.assert_allclose(back, v, rtol=1e-15, atol=1e-300)
    else:  # a half turn about either direction of the axis
        np.testing.assert_allclose(np.abs(back), np.abs(v), rtol=0, atol=2e-15)
        np.testing.assert_allclose(rot.rotvecs_to_matrices(back), rot.rotvecs_to_matrices(v), rtol=0, atol=2e-15)


@pytest.mark.parametrize("extrinsic", KINDS)
@pytest.mark.parametrize("order", ORDERS)
def test_conversions_through_euler_equal_scipy(rng, order, extrinsic):
    seq = scipy_seq(order, extrinsic)
    angles = euler_samples(rng, order, 500)
    r = Rotation.from_euler(seq, angles)
    q = rot.euler_to_quaternions(angles, order, extrinsic=extrinsic)
    np.testing.assert_allclose(q, r.as_quat(scalar_first=True, canonical=True), rtol=0, atol=1e-12)
    v = rot.euler_to_rotvecs(angles, order, extrinsic=extrinsic)
    np.testing.assert_allclose(Rotation.from_rotvec(v).as_matrix(), r.as_matrix(), rtol=0, atol=1e-12)
    for back in (
        rot.quaternions_to_euler(q, order, extrinsic=extrinsic),
        rot.rotvecs_to_euler(v, order, extrinsic=extrinsic),
    ):
        np.testing.assert_allclose(Rotation.from_euler(seq, back).as_matrix(), r.as_matrix(), rtol=0, atol=1e-12)


def test_any_leading_shape_dtype_and_layout(rng):
    angles = rng.uniform(-3, 3, (4, 5, 6, 3))
    m = rot.euler_to_matrices(angles, "zyx", extrinsic=False)
    assert m.shape == (4, 5, 6, 3, 3)
    np.testing.assert_array_equal(m[2, 3, 4], rot.euler_to_matrices(angles[2, 3, 4], "zyx", extrinsic=False))
    assert rot.matrices_to_quaternions(np.zeros((0, 7, 3, 3))).shape == (0, 7, 4)
    assert rot.matrices_to_euler(np.empty((3, 0, 3, 3)), "xyx", extrinsic=True).shape == (3, 0, 3)
    q = rot.matrices_to_quaternions(m)
    variants = [q.astype(np.float32), np.stack([q, -q], axis=-1)[..., 0], q.astype(">f8"), np.asfortranarray(q)]
    frozen = q.copy()
    frozen.flags.writeable = False
    for variant in variants + [frozen]:
        np.testing.assert_allclose(
            rot.quaternions_to_matrices(variant), m, rtol=0, atol=1e-6 if variant.dtype == np.float32 else 1e-15
        )
    np.testing.assert_array_equal(rot.euler_to_matrices(angles.tolist(), "zyx", extrinsic=False), m)


def test_inputs_are_never_modified(rng):
    q = rng.normal(size=(20, 2, 4))
    v = rng.normal(size=(20, 2, 3))
    m = rot.quaternions_to_matrices(q)
    copies = [a.copy() for a in (q, v, m)]
    for call in (
        lambda: rot.quaternions_to_matrices(q),
        lambda: rot.matrices_to_euler(m, "xyz", extrinsic=True),
        lambda: rot.quaternions_to_rotvecs(q),
        lambda: rot.rotvecs_to_quaternions(v),
        lambda: rot.unroll_quaternions(q),
        lambda: rot.unroll_euler(v, "zxz"),
        lambda: rot.slerp(q[0], q[1], 0.3),
        lambda: rot.interpolate_rotvecs(v[0], v[1], 0.3, aligned=True),
    ):
        call()
    for a, b in zip((q, v, m), copies):
        np.testing.assert_array_equal(a, b)


def test_nan_and_zero_quaternions_give_nan():
    assert np.isnan(rot.quaternions_to_matrices(np.zeros(4))).all()
    assert np.isnan(rot.quaternions_to_rotvecs(np.zeros(4))).all()
    assert np.isnan(rot.matrices_to_euler(np.full((3, 3), np.nan), "zyz", extrinsic=False)).all()
    assert np.isnan(rot.rotvecs_to_quaternions([np.nan, 0, 0])).all()


# --- continuity ---------------------------------------------------------------------------


@pytest.mark.parametrize("frames", [0, 1, 2, 7, 500])
def test_unroll_quaternions_equals_the_twin(rng, frames):
    q = rng.normal(size=(3, frames, 5, 4))
    out = rot.unroll_quaternions(q, axis=1)
    assert out.shape == q.shape
    for i in range(3):
        for j in range(5):
            np.testing.assert_array_equal(out[i, :, j], twin.unroll_quaternions(q[i, :, j]))
    np.testing.assert_array_equal(rot.unroll_quaternions(np.moveaxis(q, 1, 0)), np.moveaxis(out, 1, 0))
    np.testing.assert_array_equal(rot.unroll_quaternions(q, axis=-3), out)


def test_unroll_quaternions_makes_a_canonical_path_continuous():
    turn = np.linspace(0, 20, 1000)[:, None] * np.array([0.36, 0.48, 0.8])
    canonical = Rotation.from_rotvec(turn).as_quat(scalar_first=True, canonical=True)
    assert (np.sum(canonical[1:] * canonical[:-1], -1) < 0).any()
    out = rot.unroll_quaternions(canonical)
    assert (np.sum(out[1:] * out[:-1], -1) > 0.99).all()
    np.testing.assert_array_equal(np.abs(out), np.abs(canonical))
    q = canonical.copy()
    q[500] = np.nan  # a restart after the gap, from the raw sign
    out = rot.unroll_quaternions(q)
    np.testing.assert_array_equal(out[501], q[501])
    np.testing.assert_array_equal(out, twin.unroll_quaternions(q))


@pytest.mark.parametrize("degrees", [False, True])
@pytest.mark.parametrize("order", ["xyz", "zxy", "zxz", "yxy"])
def test_unroll_euler_equals_the_twin(rng, order, degrees):
    half = 180.0 if degrees else np.pi
    raw = rng.uniform(-half, half, (2, 300, 3))
    raw[:, ::2] += 2 * half * rng.integers(-3, 4, (2, 150, 3))
    raw[1, 100] = np.nan
    out = rot.unroll_euler(raw, order, axis=1, degrees=degrees)
    for i in range(2):
        np.testing.assert_allclose(
            out[i], twin.unroll_euler_line(raw[i], order[0] == order[2], half), rtol=0, atol=1e-9
        )
    m = rot.euler_to_matrices(raw, order, extrinsic=True, degrees=degrees)
    np.testing.assert_allclose(
        rot.euler_to_matrices(out, order, extrinsic=True, degrees=degrees), m, rtol=0, atol=1e-12
    )  # the same rotations


@pytest.mark.parametrize("extrinsic", KINDS)
@pytest.mark.parametrize("order", ORDERS)
def test_unroll_euler_recovers_a_smooth_path(rng, order, extrinsic):
    """A smooth path of several turns whose middle angle leaves its range (through gimbal lock),
    through matrices and back: wrapped angles and the other solution in places, then unrolled."""
    frames = 2000
    path = np.cumsum(rng.normal(0, 0.02, (frames, 3)), axis=0) + np.linspace(0, 15, frames)[:, None]
    centre, swing = (np.pi / 2, 2.0) if order[0] == order[2] else (0.9, 0.9)  # leaves [0, pi] or [-pi/2, pi/2]
    path[:, 1] = centre + swing * np.sin(np.linspace(0, 20, frames))
    raw = rot.matrices_to_euler(rot.euler_to_matrices(path, order, extrinsic=extrinsic), order, extrinsic=extrinsic)
    assert np.abs(np.diff(raw, axis=0)).max() > 3  # jumps to remove
    np.testing.assert_allclose(rot.unroll_euler(raw, order), path, rtol=0, atol=1e-9)


# --- interpolation ------------------------------------------------------------------------


def test_slerp_equals_scipy(rng):
    r0, r1 = Rotation.random(1000, random_state=3), Rotation.random(1000, random_state=4)
    t = rng.uniform(-0.2, 1.2, 1000)
    q0, q1 = r0.as_quat(scalar_first=True), r1.as_quat(scalar_first=True)
    q = rot.slerp(q0 * 2.5, -q1, t)
    expected = r0 * Rotation.from_rotvec(t[:, None] * (r0.inv() * r1).as_rotvec())  # short arc: angle <= pi
    np.testing.assert_allclose(rot.quaternions_to_matrices(q), expected.as_matrix(), rtol=0, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1, rtol=0, atol=1e-15)
    inside = np.flatnonzero((t >= 0) & (t <= 1))  # scipy's Slerp does not extrapolate
    for i in inside[::20]:
        scipy_slerp = Slerp([0, 1], Rotation.concatenate([r0[i], r1[i]]))
        np.testing.assert_allclose(rot.quaternions_to_matrices(q[i]), scipy_slerp(t[i]).as_matrix(), rtol=0, atol=1e-14)
    np.testing.assert_allclose(rot.slerp(q0, q1, 0.0), q0, rtol=0, atol=1e-15)
    ends = rot.slerp(q0, q1, 1.0)
    np.testing.assert_allclose(ends * np.sign(np.sum(ends * q1, -1))[:, None], q1, rtol=0, atol=1e-15)
    inside = rot.slerp(q0, q1, rng.uniform(0, 1, 1000))
    assert (np.sum(inside * q0, -1) >= 0).all()  # continuous with the first key


def test_slerp_between_equal_and_nearly_equal_keys(rng):
    q = Rotation.random(200, random_state=5).as_quat(scalar_first=True)
    t = np.linspace(0, 1, 200)
    np.testing.assert_allclose(rot.slerp(q, q, t), q, rtol=0, atol=1e-15)
    np.testing.assert_allclose(rot.slerp(q, -q, t), q, rtol=0, atol=1e-15)
    r0 = Rotation.from_quat(q, scalar_first=True)
    for eps in (1e-15, 1e-9, 1e-6, 1e-3):
        nudge = Rotation.random(200, random_state=6).as_rotvec() * eps
        out = rot.slerp(q, (r0 * Rotation.from_rotvec(nudge)).as_quat(scalar_first=True), t)
        expected = r0 * Rotation.from_rotvec(t[:, None] * nudge)
        np.testing.assert_allclose(rot.quaternions_to_matrices(out), expected.as_matrix(), rtol=0, atol=1e-15)
        np.testing.assert_allclose(np.linalg.norm(out, axis=-1), 1, rtol=0, atol=4e-16)


def test_slerp_broadcasts_keys_against_fractions(rng):
    q0, q1 = Rotation.random(7, random_state=8).as_quat(scalar_first=True), np.array([1.0, 0, 0, 0])
    t = np.linspace(0, 1, 11)
    out = rot.slerp(q0, q1, t[:, None])
    assert out.shape == (11, 7, 4)
    np.testing.assert_array_equal(out[4, 2], rot.slerp(q0[2], q1, t[4]))


def test_rotvec_interpolation_equals_the_twins(rng):
    v0, v1 = rng.uniform(-4, 4, (2, 3000, 3))
    t = rng.uniform(0, 1, 3000)
    np.testing.assert_allclose(rot.interpolate_rotvecs(v0, v1, t), v0 + t[:, None] * (v1 - v0), rtol=0, atol=1e-15)
    aligned = rot.interpolate_rotvecs(v0, v1, t, aligned=True)
    np.testing.assert_allclose(aligned, twin.interpolate_rotvecs(v0, v1, t, aligned=True), rtol=0, atol=1e-13)
    ends = rot.interpolate_rotvecs(v0, v1, np.array([[0.0], [1.0]]), aligned=True)
    for end, key in zip(ends, (v0, v1)):
        np.testing.assert_allclose(rot.rotvecs_to_matrices(end), rot.rotvecs_to_matrices(key), rtol=0, atol=1e-14)
    # a start key at the identity and an end key past a half turn: a whole turn about the end key's axis
    start = rot.interpolate_rotvecs(np.zeros(3), [0, 0, 4.0], 0.0, aligned=True)
    np.testing.assert_allclose(start, [0, 0, 2 * np.pi], rtol=0, atol=0)


def test_cs838_keys_either_side_of_a_half_turn():
    """Keys -(pi - eps) and pi - eps about +y, 51 frames: SLERP and the aligned exponential map
    turn 2 eps the short way; the plain exponential map and Euler angles turn 2 (pi - eps)."""
    eps = 0.05
    k0, k1 = np.array([0, -(np.pi - eps), 0]), np.array([0, np.pi - eps, 0])
    t = np.linspace(0, 1, 51)
    q0, q1 = rot.rotvecs_to_quaternions(k0), rot.rotvecs_to_quaternions(k1)
    paths = {
        "slerp": rot.slerp(q0, q1, t),
        "exp-map": rot.rotvecs_to_quaternions(rot.interpolate_rotvecs(k0, k1, t)),
        "aligned exp-map": rot.rotvecs_to_quaternions(rot.interpolate_rotvecs(k0, k1, t, aligned=True)),
        "euler": rot.euler_to_quaternions(k0 + t[:, None] * (k1 - k0), "xyz", extrinsic=True),  # angles about y
    }
    turns = {name: total_turn(q) for name, q in paths.items()}
    assert turns["slerp"] == pytest.approx(2 * eps, abs=1e-12)
    assert turns["aligned exp-map"] == pytest.approx(2 * eps, abs=1e-12)
    assert turns["exp-map"] == pytest.approx(2 * (np.pi - eps), abs=1e-12)
    assert turns["euler"] == pytest.approx(2 * (np.pi - eps), abs=1e-12)
    for q in paths.values():  # every path has the keys at its ends and turns about y only
        m = rot.quaternions_to_matrices(q)
        np.testing.assert_allclose(m[[0, -1]], rot.rotvecs_to_matrices(np.array([k0, k1])), rtol=0, atol=1e-14)
        np.testing.assert_allclose(m[:, 1], [[0, 1, 0]] * 51, rtol=0, atol=1e-15)
    steps = Rotation.from_quat(paths["slerp"], scalar_first=True)
    np.testing.assert_allclose((steps[1:] * steps[:-1].inv()).magnitude(), 2 * eps / 50, rtol=0, atol=1e-14)


# --- bad arguments ------------------------------------------------------------------------


class NoC:
    """Stands in for the C library: any use fails the test."""

    def __getattr__(self, name):
        raise AssertionError(f"{name} called before the arguments were checked")


Z3, Z4 = np.zeros(3), np.zeros(4)
BAD_CALLS = [
    (
        lambda: rot.euler_to_matrices(Z3, "xyw", extrinsic=True),
        ValueError,
        "^order must be one of 'xyz', 'xzy', 'yxz', 'yzx', 'zxy', 'zyx', 'xyx', 'xzx', 'yxy', 'yzy', 'zxz', 'zyz'; got 'xyw'$",
    ),
    (
        lambda: rot.euler_to_matrices(Z3, "XYZ", extrinsic=False),
        ValueError,
        r"got 'XYZ' \(lowercase; extrinsic= says fixed or turning axes\)",
    ),
    (lambda: rot.matrices_to_euler(np.eye(3), "xxy", extrinsic=True), ValueError, r"order must be one of"),
    (lambda: rot.quaternions_to_euler(Z4, "xy", extrinsic=True), ValueError, r"got 'xy'"),
    (
        lambda: rot.rotvecs_to_euler(Z3, 3, extrinsic=True),
        ValueError,
        "^order must be one of 'xyz', 'xzy', 'yxz', 'yzx', 'zxy', 'zyx', 'xyx', 'xzx', 'yxy', 'yzy', 'zxz', 'zyz'; got 3$",
    ),
    (lambda: rot.euler_to_matrices(Z3, "xyz"), TypeError, r"missing 1 required keyword-only argument: 'extrinsic'"),
    (
        lambda: rot.euler_to_matrices(Z3, "xyz", extrinsic="yes"),
        TypeError,
        r"extrinsic must be True or False, got 'yes'",
    ),
    (lambda: rot.euler_to_matrices(Z3, "xyz", extrinsic=True, degrees=1), TypeError, r"degrees must be True or False"),
    (
        lambda: rot.euler_to_matrices(np.zeros((5, 2)), "xyz", extrinsic=True),
        ValueError,
        r"^angles must have shape \(\.\.\., 3\), got shape \(5, 2\)$",
    ),
    (
        lambda: rot.matrices_to_quaternions(np.zeros((5, 3, 4))),
        ValueError,
        r"^matrices must have shape \(\.\.\., 3, 3\), got shape \(5, 3, 4\)$",
    ),
    (
        lambda: rot.matrices_to_euler(Z3, "xyz", extrinsic=True),
        ValueError,
        r"^matrices must have shape \(\.\.\., 3, 3\), got shape \(3,\)$",
    ),
    (
        lambda: rot.quaternions_to_matrices(np.zeros((2, 3))),
        ValueError,
        r"^quaternions must have shape \(\.\.\., 4\), got shape \(2, 3\)$",
    ),
    (
        lambda: rot.rotvecs_to_quaternions(np.float64(1.0)),
        ValueError,
        r"^rotvecs must have shape \(\.\.\., 3\), got shape \(\)$",
    ),
    (
        lambda: rot.quaternions_to_rotvecs(Z4 + 0j),
        TypeError,
        r"^quaternions must hold real numbers \(bool, integer or float\), got dtype complex128$",
    ),
    (lambda: rot.euler_to_quaternions(Z3 + 0j, "xyz", extrinsic=True), TypeError, r"got dtype complex128"),
    (
        lambda: rot.rotvecs_to_matrices(np.array(["a", "b", "c"])),
        TypeError,
        r"^rotvecs must hold real numbers \(bool, integer or float\), got dtype <U1$",
    ),
    (
        lambda: rot.unroll_quaternions(np.zeros((5, 4)), axis=1),
        ValueError,
        r"axis must be an axis of frames, not the last axis of quaternions \(its 4 components\)",
    ),
    (
        lambda: rot.unroll_quaternions(np.zeros((5, 4)), axis=2),
        ValueError,
        r"^axis must be in \[-2, 1\] for a 2-dimensional array, got 2$",
    ),
    (
        lambda: rot.unroll_quaternions(np.zeros((5, 4)), axis=0.0),
        TypeError,
        r"^axis must be an integer, got float 0\.0$",
    ),
    (lambda: rot.unroll_euler(np.zeros((5, 3)), "xyz", axis=-1), ValueError, r"not the last axis of angles"),
    (lambda: rot.unroll_euler(np.zeros((5, 3)), "XYZ"), ValueError, r"order must be one of"),
    (
        lambda: rot.slerp(np.zeros((3, 4)), np.zeros((2, 4)), 0.5),
        ValueError,
        r"q0 \(3, 4\), q1 \(2, 4\) and t \(\) do not broadcast together",
    ),
    (
        lambda: rot.slerp(Z4, Z4, [0.5j]),
        TypeError,
        r"^t must hold real numbers \(bool, integer or float\), got dtype complex128$",
    ),
    (lambda: rot.interpolate_rotvecs(Z3, Z4, 0.5), ValueError, r"v1 must have shape \(\.\.\., 3\)"),
    (lambda: rot.interpolate_rotvecs(Z3, Z3, 0.5, aligned=None), TypeError, r"aligned must be True or False"),
]


@pytest.mark.parametrize("call, exc, message", BAD_CALLS)
def test_bad_arguments_are_refused_before_any_c_call(monkeypatch, call, exc, message):
    monkeypatch.setattr(rot, "lib", NoC())
    with pytest.raises(exc, match=message):
        call()
