"""One slow, obvious twin per C entry point (every mt_* function of csrc/mtcore.h).

``TWINS`` maps the name of each entry point to a :class:`Twin`: the mtcore call that
reaches it (``fast``), the twin that computes the same from the contract in plain Python
or numpy (``slow``, the same arguments), argument tuples over the shapes and options that
matter (``cases``) and how the two results must agree (``same``).  The model is
bottleneck's ``slow/`` functions paired with the fast ones by ``tests/util.py::func_dict``.

``EXEMPT`` names the entry points that are not kernels, and why they need no twin.
tests/test_twins.py pairs every twin with its kernel, checks that none is missing and that
no input is modified; tests/test_concurrent.py calls every ``fast`` from eight threads.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

import mtcore
from mtcore import footskate as fs
from mtcore import rotations as rot
from mtcore import search as mt_search
from mtcore import signal as mt_signal
from mtcore import text as mt_text
from mtcore.check import channel_events, elbow_bends, pace, roughness, seen_runs, trim_runs
from mtcore.check import leg_measures as check_legs
from mtcore.combine import combine_frames
from mtcore.kinematics import JointTree, forward_kinematics, local_quaternions
from mtcore.retarget import RetargetPlan, retarget_rotations

from . import check, combine, filters, footskate, kinematics, retarget, rotations
from . import search as search_twins
from . import signal as signal_twins
from . import text as text_twins  # binds twins.text too: mtcore's is mt_text


@dataclass(frozen=True)
class Twin:
    fast: Callable[..., Any]
    slow: Callable[..., Any]
    cases: Callable[[np.random.Generator], list[tuple]]
    same: Callable[[Any, Any], None]


def exact(got, want) -> None:
    """Equal bit for bit but for NaN payloads: arrays (shape, dtype, values, NaN places), tuples of them, texts."""
    if isinstance(got, tuple):
        assert isinstance(want, tuple) and len(got) == len(want)
        for g, w in zip(got, want):
            exact(g, w)
    elif isinstance(got, np.ndarray):
        want = np.asarray(want)
        assert got.shape == want.shape, (got.shape, want.shape)
        np.testing.assert_array_equal(got, want.astype(got.dtype))
        np.testing.assert_array_equal(np.signbit(got), np.signbit(want))
    else:
        assert got == want, (got, want)


def close(atol: float) -> Callable[[Any, Any], None]:
    """Equal to atol times the larger of 1 and the largest finite magnitude (NaN and infinities exactly)."""

    def same(got, want) -> None:
        if isinstance(got, tuple):
            for g, w in zip(got, want, strict=True):
                same(g, w)
            return
        got, want = np.asarray(got), np.asarray(want)
        assert got.shape == want.shape, (got.shape, want.shape)
        finite = want[np.isfinite(want)]
        scale = max(1.0, float(np.abs(finite).max())) if finite.size else 1.0
        np.testing.assert_allclose(got, want, rtol=0, atol=atol * scale)

    return same


def angles_close(got, want) -> None:
    """Angles equal to 1e-12 radians modulo a turn (pi and -pi agree)."""
    np.testing.assert_allclose(np.angle(np.exp(1j * (got - want))), 0.0, rtol=0, atol=1e-12)


# --- filters --------------------------------------------------------------------------------

FILTERS = {"median": mtcore.median_filter1d, "uniform": mtcore.uniform_filter1d, "binomial": mtcore.binomial_filter1d}
SHAPES = [((0,), 0), ((1,), 0), ((6,), 0), ((7, 3), 0), ((3, 7), 1), ((2, 5, 4), 1), ((4, 1, 18), 2)]


def filter_cases(rng: np.random.Generator) -> list[tuple]:
    """Every filter and mode on every shape, sizes 1 to beyond the line, origins at both ends."""
    out = []
    for kind in filters.KINDS:
        for mode in filters.MODES:
            for shape, axis in SHAPES:
                size = int(rng.choice([1, 2, 3, 4, 5, 8, 9, 12, 25]))
                origin = int(rng.integers(-(size // 2), (size - 1) // 2 + 1))
                dtype = rng.choice([np.float64, np.float32])
                x = (rng.standard_normal(shape) * 10).astype(dtype)
                if x.size > 3:
                    x.flat[rng.integers(x.size)] = rng.choice([np.nan, np.inf, -np.inf])
                out.append((kind, x, size, axis, mode, 0.75, origin))
    return out


def fast_filter(kind, x, size, axis, mode, cval, origin):
    return FILTERS[kind](x, size, axis, mode=mode, cval=cval, origin=origin)


def slow_filter(kind, x, size, axis, mode, cval, origin):
    return filters.filter1d(kind, x, size, axis, mode, float(x.dtype.type(cval)), origin).astype(x.dtype)


def filter_same(got, want) -> None:
    close(1e-5 if got.dtype == np.float32 else 1e-12)(got, want)


# --- text -----------------------------------------------------------------------------------

KEYS = [b"root", b"lfemur", b"ltibia", b"head"]
OFFSETS = [0, 6, 9, 0]
COUNTS = [6, 3, 1, 0]  # head: a key without numbers
CHANNELS = 11  # column 10 is no key's: NaN


def numbers(rng: np.random.Generator, n: int) -> np.ndarray:
    """Mocap-like short decimals and doubles of every magnitude."""
    short = np.round(rng.uniform(-400, 400, n), int(rng.integers(0, 7)))
    wide = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 300, n)
    return np.where(rng.random(n) < 0.5, short, wide)


def frame_text_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for frames in (0, 1, 2, 7):
        values = numbers(rng, frames * CHANNELS).reshape(frames, CHANNELS)
        first = int(rng.integers(0, 1000))
        newline = [b"\n", b"\r\n", b"\r"][int(rng.integers(3))]
        lines = [b"# a comment", b""]
        for f in range(frames):
            lines.append(b"%d" % (first + f))
            for i in rng.permutation(len(KEYS)):
                words = [text_twins.format_number(v).encode() for v in values[f, OFFSETS[i] : OFFSETS[i] + COUNTS[i]]]
                lines.append(b"\t".join([KEYS[i], *words]) if f % 2 else b" ".join([KEYS[i], *words]))
        out.append((newline.join(lines) + newline, KEYS, OFFSETS, COUNTS, CHANNELS))
    return out


def table_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for rows, columns in ((0, 3), (1, 1), (3, 4), (9, 2)):
        values = numbers(rng, rows * columns).reshape(rows, columns)
        lines = [b" ".join(text_twins.format_number(v).encode() for v in row) for row in values]
        out.append((b"\r\n".join(lines) + b"\r\n", rows, columns))
    return out


SPECIAL = [0.0, -0.0, math.inf, -math.inf, math.nan, -math.nan, 5e-324, 1.7976931348623157e308, 1e16, 1e-5, 123456.0]


def number_cases(rng: np.random.Generator) -> list[tuple]:
    return [(v,) for v in SPECIAL + numbers(rng, 300).tolist()]


def value_cases(rng: np.random.Generator) -> list[tuple]:
    return [(numbers(rng, r * c).reshape(r, c),) for r, c in ((0, 2), (1, 1), (3, 4), (5, 11))]


def frame_value_cases(rng: np.random.Generator) -> list[tuple]:
    return [
        (numbers(rng, f * CHANNELS).reshape(f, CHANNELS), int(rng.integers(0, 10**6)), KEYS, OFFSETS, COUNTS)
        for f in (0, 1, 3, 8)
    ]


def written(write: Callable[[Callable[[bytes], object]], None]) -> bytes:
    out: list[bytes] = []
    write(out.append)
    return b"".join(out)


# --- kinematics -----------------------------------------------------------------------------


def random_tree(rng: np.random.Generator, joints: int) -> JointTree:
    """Joints in a random order (parents first), each with random dofs of every kind."""
    order = rng.permutation(joints)
    parent = np.full(joints, -1)
    for i in range(1, joints):
        parent[order[i]] = order[rng.integers(i)]
    dof_start, dof_kind = [0], []
    for _ in range(joints):
        dof_kind += rng.integers(0, 7, int(rng.integers(0, 6))).tolist()
        dof_start.append(len(dof_kind))
    axis = rotations.matrices(rng.uniform(-3, 3, (joints, 3)), "xyz")
    axis[rng.random(joints) < 0.3] = np.eye(3)  # the plain case C = I
    direction = rng.normal(size=(joints, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    return JointTree(
        parent=parent,
        order=order,
        axis=axis,
        direction=direction,
        segment=direction * rng.uniform(0.5, 3, (joints, 1)),
        dof_start=dof_start,
        dof_kind=dof_kind,
        dof_column=rng.permutation(max(len(dof_kind), 1))[: len(dof_kind)],
        angle_scale=float(rng.choice([1.0, math.pi / 180])),
        parent_frame=rng.integers(0, 2, joints),
    )


def kinematics_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for joints, frames in ((1, 0), (1, 1), (3, 8), (6, 9), (9, 17)):
        tree = random_tree(rng, joints)
        out.append((rng.uniform(-180, 180, (frames, max(len(tree.dof_kind), 1))), tree))
    return out


def local_quaternion_cases(rng: np.random.Generator) -> list[tuple]:
    """Trees as kinematics_cases, frames across the kernel's blocks and spans; no joint, one, all
    of them, some twice; with and without a turn of the first one."""
    out = []
    for joints, frames in ((1, 0), (1, 1), (3, 8), (6, 9), (9, 17), (4, 300)):
        tree = random_tree(rng, joints)
        values = rng.uniform(-180, 180, (frames, max(len(tree.dof_kind), 1)))
        turn = rotations.matrices(rng.uniform(-3, 3, 3), "zxy")
        for chosen in ([], [joints - 1], list(range(joints)), rng.integers(0, joints, joints + 2).tolist()):
            out += [(values, tree, chosen, None), (values, tree, chosen, turn)]
    return out


# --- rotations ------------------------------------------------------------------------------

ROTATION_SHAPES = [(0,), (1,), (7,), (2, 3)]


def euler_cases(rng: np.random.Generator) -> list[tuple]:
    out = [
        (rng.uniform(-7, 7, shape + (3,)), order, bool(rng.integers(2)))
        for shape in ROTATION_SHAPES
        for order in rot.ORDERS
    ]
    return out + [(rng.uniform(-7, 7, (5, len(axes))), axes, True) for axes in ("", "z", "yx", "xyzx", "zzyxz")]


def fast_euler(angles, axes, extrinsic):
    if axes in rot.ORDERS:
        return rot.euler_to_matrices(angles, axes, extrinsic=extrinsic)
    # any sequence of axes: the kernel's own generality, below the public three-angle orders
    return rot._sequence_matrices(np.asarray(angles, float), [rot.AXES[a] for a in axes], False, 1.0)


def matrices_to_euler_cases(rng: np.random.Generator) -> list[tuple]:
    """Away from gimbal lock, where the angles are unique."""
    out = []
    for order in rot.ORDERS:
        for extrinsic in (True, False):
            angles = rng.uniform(-3, 3, (20, 3))
            angles[:, 1] = rng.uniform(0.05, 3.09, 20) if order[0] == order[2] else rng.uniform(-1.52, 1.52, 20)
            out.append((rotations.euler_to_matrices(angles, order, extrinsic), order, extrinsic))
    return out


def rotation_matrix_cases(rng: np.random.Generator) -> list[tuple]:
    return [(rotations.matrices(rng.uniform(-3, 3, shape + (3,)), "zyx"),) for shape in ROTATION_SHAPES]


def quaternion_cases(rng: np.random.Generator) -> list[tuple]:
    return [(rng.normal(size=shape + (4,)) * rng.uniform(0.1, 10),) for shape in ROTATION_SHAPES]


def rotvec_cases(rng: np.random.Generator) -> list[tuple]:
    cases = [(rng.normal(size=shape + (3,)) * 2,) for shape in ROTATION_SHAPES]
    return cases + [(np.array([[0.0, 0, 0], [1e-9, 0, 0], [0, 0, 3.0]]),)]


def unroll_quaternion_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for frames in (0, 1, 2, 9):
        q = rng.normal(size=(2, frames, 3, 4))
        if frames > 2:
            q[1, 1, 2] = np.nan
        out.append((q, 1))
    return out + [(rng.normal(size=(30, 4)), 0)]


def unroll_euler_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for order in ("xyz", "zxy", "zxz", "yxy"):
        for degrees in (False, True):
            half = 180.0 if degrees else math.pi
            a = rng.uniform(-half, half, (2, 40, 3))
            a[:, ::2] += 2 * half * rng.integers(-3, 4, (2, 20, 3))
            a[1, 10] = np.nan
            out.append((a, order, 1, degrees))
    return out


def unwrap_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for frames in (0, 1, 2, 7, 64):
        for period in (360.0, 2 * math.pi):
            raw = np.cumsum(rng.normal(0, period / 8, (frames, 5)), axis=0)
            raw = (raw + period / 2) % period - period / 2  # jumps where it wraps
            raw[rng.random(raw.shape) < 0.08] = np.nan
            raw[rng.random(raw.shape) < 0.04] = -np.inf
            raw[:, 4] = -0.0  # a column that never jumps keeps its zeros' signs
            state = (rng.normal(0, period, 3), rng.integers(-2, 3, 3).astype(float))
            out += [(raw, period, None, None), (raw, period, [4, 0, 2], state), (raw, period, [], None)]
    return out


def wrap_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for frames in (0, 1, 2, 7, 64):
        for period in (360.0, 2 * math.pi):
            raw = np.cumsum(rng.normal(0, period / 4, (frames, 6)), axis=0)  # strays out of range
            raw[rng.random(raw.shape) < 0.08] = np.nan
            raw[rng.random(raw.shape) < 0.04] = -np.inf
            h = period / 2  # the take's ranges: centred, positive, neither, nothing finite, on the bounds
            low = np.array([-h * 0.9, 0.1 * h, -h, np.inf, -h, 0.0])
            high = np.array([h * 0.5, 1.9 * h, 1.5 * h, -np.inf, h, period])
            out += [(raw, low, high, period, None), (raw, low[:3], high[:3], period, [4, 0, 2])]
    return out


def fast_wrap(values, low, high, period, columns):
    out = np.array(values, dtype=float)
    rot.wrap_angles(out, low, high, period, columns)
    return out


def ranges_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for frames in (0, 1, 2, 7, 64):
        raw = rng.normal(0, 100, (frames, 6))
        raw[rng.random(raw.shape) < 0.2] = np.nan
        raw[rng.random(raw.shape) < 0.1] = np.inf
        raw[:, 5] = np.nan  # a column with nothing finite
        state = (rng.normal(-50, 10, 6), rng.normal(50, 10, 6), np.where(rng.random(6) < 0.5, np.nan, 1.0))
        out += [(raw, None), (raw, state)]
    return out


def slerp_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for shape in ROTATION_SHAPES:
        q0 = rng.normal(size=shape + (4,))
        q1 = q0 + rng.normal(size=shape + (4,)) * rng.choice([1e-9, 0.1, 3.0])
        out.append((q0, q1, rng.uniform(-0.5, 1.5, shape)))
    return out


def rotvec_interpolation_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for shape in ROTATION_SHAPES:
        for aligned in (False, True):
            out.append(
                (
                    rng.normal(size=shape + (3,)) * 2,
                    rng.normal(size=shape + (3,)) * 2,
                    rng.uniform(0, 1, shape),
                    aligned,
                )
            )
    return out + [(np.zeros(3), np.array([0.0, 0, 3.5]), 0.5, True)]


def atan2_cases(rng: np.random.Generator) -> list[tuple]:
    special = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1.0, -1.0, 5e-324, 1e308])
    grid = tuple(g.ravel() for g in np.meshgrid(special, special))
    sizes = [(rng.standard_normal((2, n)) * 10.0 ** rng.uniform(-300, 300, (2, n))) for n in (0, 1, 31, 32, 33, 100)]
    return [grid, *((y, x) for y, x in sizes)]


def fast_atan2(y, x):
    from mtcore._cdata import c_array
    from mtcore._mtcore import lib

    y, x = np.ascontiguousarray(y, float), np.ascontiguousarray(x, float)
    out = np.empty_like(y)
    assert lib.mt_atan2(c_array(y), c_array(x), y.size, c_array(out)) == 0
    return out


def sincos_cases(rng: np.random.Generator) -> list[tuple]:
    special = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 5e-324, 2.0**30, 1e300])
    return [(special,), *((rng.uniform(-s, s, n),) for s, n in ((1, 0), (10, 1), (1e4, 33), (1e9, 100)))]


def fast_sincos(x):
    from mtcore._cdata import c_array
    from mtcore._mtcore import lib

    x = np.ascontiguousarray(x, float)
    s, c = np.empty_like(x), np.empty_like(x)
    assert lib.mt_sincos(c_array(x), x.size, c_array(s), c_array(c)) == 0
    return s, c


def interpolate_euler_cases(rng: np.random.Generator) -> list[tuple]:
    """Keys for every frame or one per joint, 0 to 9 joints (a block of lanes is 8), each blend and
    continuity, Tait-Bryan and proper, degrees and radians; middle angles kept off gimbal lock,
    the keys near each other as the frames of a take are."""
    out = []
    for frames, joints in ((0, 2), (1, 1), (7, 3), (5, 9), (12, 1)):
        for order, extrinsic, degrees in (("xyz", True, True), ("zxy", False, False), ("zxz", True, False)):
            half = 180.0 if degrees else math.pi
            lo, hi = (0.2, 0.8) if order[0] == order[2] else (-0.3, 0.3)
            k0 = np.stack([rng.uniform(-1, 1, joints), rng.uniform(lo, hi, joints), rng.uniform(-1, 1, joints)], -1)
            per_frame = frames % 2 == 1
            k0 = k0 * half + (rng.normal(size=(frames, joints, 3)) * 0.05 * half if per_frame else 0.0)
            k1 = k0 + rng.normal(size=k0.shape) * 0.3 * half
            t = rng.uniform(0, 1, frames)
            start = k0[0] if per_frame and frames else k0
            start = np.broadcast_to(start, (joints, 3)) + 2 * half * rng.integers(-2, 3, (joints, 3))
            reference = rng.uniform(-4 * half, 4 * half, (frames, joints, 3))
            for blend in rot.BLENDS:
                out += [(k0, k1, t, order, extrinsic, degrees, blend, None, None)]
                out += [(k0, k1, t, order, extrinsic, degrees, blend, start, None)]
                out += [(k0, k1, t, order, extrinsic, degrees, blend, None, reference)]
    k0 = np.array([[10.0, 20, 30], [np.nan, 0, 0]])
    t = np.linspace(0, 1, 6)
    return out + [(k0, k0 + 40, t, "xyz", True, True, "slerp", np.zeros((2, 3)), None)]  # NaN along a path


def fast_interpolate_euler(k0, k1, t, order, extrinsic, degrees, blend, start, reference):
    return rot.interpolate_euler(
        k0, k1, t, order, extrinsic=extrinsic, degrees=degrees, blend=blend, start=start, reference=reference
    )


# --- retarget -------------------------------------------------------------------------------


def rotation_tree(rng: np.random.Generator, joints: int) -> JointTree:
    """A target tree: each joint with 0 to 3 rotation channels about distinct axes (proper Euler
    sequences too), among translations now and then, in radians or degrees."""
    tree = random_tree(rng, joints)
    dof_start, dof_kind = [0], []
    for _ in range(joints):
        count = int(rng.integers(0, 4))
        axes = rng.permutation(3)[:count].tolist()
        extra = rng.integers(3, 7, int(rng.integers(0, 2))).tolist()  # translations, in the order anywhere
        if count == 3 and rng.random() < 0.3:
            axes[2] = axes[0]  # proper Euler: x y x and the like
        at = int(rng.integers(0, count + 1))
        dof_kind += axes[:at] + extra + axes[at:]
        dof_start.append(len(dof_kind))
    return dataclasses.replace(
        tree,
        dof_start=dof_start,
        dof_kind=dof_kind,
        dof_column=rng.permutation(max(len(dof_kind), 1))[: len(dof_kind)],
    )


def retarget_cases(rng: np.random.Generator) -> list[tuple]:
    """Random source and target trees and plans: joints followed or at rest, bones re-aimed onto
    random source points, swivels over one-channel joints, aims or none, turns between axes."""
    out = []
    for sources, targets, frames in ((1, 1, 0), (2, 1, 1), (4, 5, 8), (6, 7, 9), (5, 9, 70)):
        source, target = random_tree(rng, sources), rotation_tree(rng, targets)
        turns = [
            sum(k <= 2 for k in target.dof_kind[target.dof_start[j] : target.dof_start[j + 1]]) for j in range(targets)
        ]
        hinges = [j for j in range(targets) if turns[j] == 1]
        key_points = rng.integers(0, sources, (targets, 2))
        key_points[rng.random(targets) < 0.2] = -1
        plan = RetargetPlan(
            follow=np.where(rng.random(targets) < 0.2, -1, rng.integers(0, sources, targets)),
            correction=rotations.matrices(rng.uniform(-3, 3, (targets, 3)), "xyz"),
            key_points=key_points,
            key_vector=rng.normal(size=(targets, 3)),
            refit=rng.integers(0, 2, targets),
            hinge=[
                int(rng.choice(hinges)) if hinges and turns[j] == 3 and rng.random() < 0.7 else -1
                for j in range(targets)
            ],
            aim=rng.normal(size=(targets, 3)) * (rng.random((targets, 1)) < 0.7),
            align=rotations.matrices(rng.uniform(-3, 3, 3), "xyz")
            if rng.random() < 0.5
            else np.eye(3)[rng.permutation(3)],
        )
        if np.linalg.det(plan.align) < 0:
            plan = dataclasses.replace(plan, align=-plan.align)
        values = rng.uniform(-180, 180, (frames, max(len(source.dof_kind), 1)))
        out.append((values, source, target, max(len(target.dof_kind), 1), plan))
    return out


def turns_close(got, want) -> None:
    """Angles equal to 1e-9 of a turn (the period: whichever of 2 pi and 360 the values are in)."""
    got, want = np.asarray(got), np.asarray(want)
    assert got.shape == want.shape, (got.shape, want.shape)
    for period in (2 * math.pi, 360.0):
        difference = np.abs(np.remainder(got - want + period / 2, period) - period / 2)
        if difference.max(initial=0) <= 1e-9 * period:
            return
    raise AssertionError(f"angles differ by up to {np.abs(got - want).max()}")


# --- combine --------------------------------------------------------------------------------


def combine_cases(rng: np.random.Generator) -> list[tuple]:
    """Random frame maps: pure old, pure new, cross-fades, ramps, selections, offsets, no old motion."""
    out = []
    for frames, channels in ((0, 3), (1, 1), (9, 4), (40, 7)):
        old, new = rng.normal(size=(frames + 5, channels)), rng.normal(size=(frames + 3, channels))
        weight = rng.choice([0.0, 1.0, 0.25, 0.5], frames)
        old_row = rng.integers(0, len(old), frames)
        new_row = rng.integers(0, len(new), frames)
        next_row = np.minimum(new_row + 1, len(new) - 1)
        ramp = rng.choice([0.0, 0.3], frames)
        selected = rng.integers(0, 2, channels).astype(np.uint8)
        offset_channels = rng.permutation(channels)[: min(2, channels)]
        offsets = rng.normal(size=(3, len(offset_channels)))
        offset_row = rng.integers(-1, 3, frames)
        out.append((old, new, old_row, new_row, weight, next_row, ramp, selected, offset_row, offsets, offset_channels))
        out.append((old, new, old_row, np.where(weight > 0, new_row, -1), weight, None, None, None, None, None, ()))
        out.append((None, new, np.full(frames, -1), new_row, np.ones(frames), next_row, ramp, None, None, None, ()))
    return out


def _combine_keywords(old, new, old_row, new_row, weight, next_row, ramp, selected, offset_row, offsets, channels):
    return (old, new, old_row, new_row, weight), dict(
        next_row=next_row,
        ramp=ramp,
        selected=selected,
        offset_row=offset_row,
        offsets=offsets,
        offset_channels=channels,
    )


def fast_combine(*args):
    positional, keywords = _combine_keywords(*args)
    return combine_frames(*positional, **keywords)


def slow_combine(*args):
    positional, keywords = _combine_keywords(*args)
    return combine.combine_frames(*positional, **keywords)


# --- signal processing ------------------------------------------------------------------------


def signal_lines(rng: np.random.Generator) -> list[np.ndarray]:
    """(frames, channels) lines of the lengths that matter: empty, one frame, odd, even, long."""
    return [
        rng.normal(size=(frames, channels)).cumsum(axis=0) for frames, channels in ((1, 1), (7, 2), (64, 3), (301, 2))
    ]


def equalize_cases(rng: np.random.Generator) -> list[tuple]:
    gains = [(), (1.0,), (0.0, 0.0), (1.5, 0.5, 2.0, 1.0)]
    return [
        (x, g, mode)
        for x in signal_lines(rng)
        for g in gains
        if len(g) <= mt_signal.band_count(len(x))  # a line of n frames has floor(log2 n) bands
        for mode in ("nearest", "reflect", "wrap")
    ]


def sosfiltfilt_cases(rng: np.random.Generator) -> list[tuple]:
    # and wider lines: whole groups of 16 channels, a last group ending at the last channel (62), one borrowing
    # from the group before (17), two chunks (65)
    wide = [rng.normal(size=(frames, channels)).cumsum(axis=0) for frames, channels in ((97, 17), (80, 62), (60, 65))]
    out = []
    for order, cut, kind in ((1, 0.2, "low"), (4, 0.1, "low"), (3, 0.3, "high"), (2, (0.1, 0.4), "band")):
        sos = mt_signal.butter_sos(order, cut, kind)
        lines = signal_lines(rng)[1:] + wide
        out += [(sos, x, padtype) for x in lines for padtype in ("odd", "even", "constant")]
        out = [c for c in out if len(c[1]) > 3 * (2 * len(c[0]) + 1)]  # scipy's padding needs a long enough line
    return out


def upfirdn_cases(rng: np.random.Generator) -> list[tuple]:
    return [
        (rng.normal(size=taps), x, up, down)
        for x in signal_lines(rng)
        for taps, up, down in ((1, 1, 1), (5, 1, 3), (9, 4, 1), (21, 3, 2))
    ]


def fast_upfirdn(h, x, up, down):
    """The kernel over its full output with no extension: upsample, convolve, downsample."""
    from mtcore._cdata import c_array
    from mtcore._mtcore import lib

    h, x = np.ascontiguousarray(h, float), np.ascontiguousarray(x, float)
    out = np.empty((((len(x) - 1) * up + len(h) - 1) // down + 1, x.shape[1]))
    status = lib.mt_upfirdn(
        c_array(h), len(h), up, down, c_array(x), len(x), x.shape[1], c_array(None), 0, c_array(None), 0, 0, 0,
        len(out), c_array(out),
    )  # fmt: skip
    assert status == 0
    return out


def gap_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for x in signal_lines(rng):
        holes = x.copy()
        holes[rng.random(x.shape) < 0.2] = np.nan
        holes[: min(2, len(x))] = np.nan  # a run at the start stays
        out += [(holes, max_gap, method) for max_gap in (1, 3) for method in ("linear", "cubic")]
    return out


def fast_fill(x, max_gap, method):
    filled = mt_signal.fill_gaps(x, max_gap, method)
    return filled.values, filled.unfilled


def nan_run_cases(rng: np.random.Generator) -> list[tuple]:
    return [(x, max_gap, method) for x, max_gap, method in gap_cases(rng)][::2]


def parse_cases(rng: np.random.Generator) -> list[tuple]:
    digits = [str(d) for d in rng.integers(0, 10**9, 20)]
    return [(t,) for t in ("0", "-0", "1e-5", "inf", "-nan", ".5", "5.", "1.23246e-013", *digits)] + [
        (f"{m}e{e}",) for m, e in zip(rng.normal(size=20) * 1e3, rng.integers(-320, 300, 20))
    ]


def mapped_cases(rng: np.random.Generator) -> list[tuple]:
    data = rng.integers(0, 256, 70_000, dtype=np.uint8).tobytes()
    return [(data, begin, end) for begin, end in ((0, 0), (0, 1), (5, 70_000), (65_530, 69_999), (100, 100_000))]


def style_cases(rng: np.random.Generator) -> list[tuple]:
    """Texts of AMC-like lines: numbers with exponents of every width, names holding an 'e', frame
    lines with blanks, each line ended by LF, CRLF or CR at random (or not at all, at the end)."""
    words = [b"lfemur", b"joint_e-01", b"1e-5", b"2.5E+07", b"1.23246e-013", b"-3.e+0012", b"5e-14", b"7", b"-0.25"]
    endings = [b"\n", b"\r\n", b"\r"]
    out = [(b"",), (b"1",), (b"e-012 3.5E+007\n",), (b" 12 \t\r\nroot 1\n",), (b"1\r\r\n\n",)]
    for _ in range(40):
        lines = []
        for _ in range(int(rng.integers(1, 30))):
            if rng.random() < 0.2:
                line = b" " * int(rng.integers(3)) + b"%d" % rng.integers(0, 999) + b"\t" * int(rng.integers(2))
            else:
                line = b" ".join(words[int(i)] for i in rng.integers(0, len(words), int(rng.integers(0, 6))))
            lines.append(line + endings[int(rng.integers(3))] * int(rng.integers(0, 2) or rng.random() < 0.9))
        out.append((b"".join(lines),))
    return out


def copy_mapped(data: bytes, begin: int, end: int) -> bytes:
    """The guarded copy from a real mapping of a file holding ``data``."""
    import mmap
    import tempfile

    with tempfile.TemporaryFile() as f:
        f.write(data)
        f.flush()
        with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as mapped:
            return mt_text.copy_text(mapped, begin, end)


# --- footskate ------------------------------------------------------------------------------

LEG_LAYOUTS = [  # rotation channels of hip, knee, ankle, toe, as the captures have them and not
    [[2, 0, 1], [0, -1, -1], [0, 2, -1], [0, -1, -1]],  # CMU ASF: a hinge knee, a two-channel foot
    [[2, 0, 1], [2, 0, 1], [2, 0, 1], [2, 0, 1]],  # BVH ZXY everywhere
    [[0, 1, 0], [1, 2, 1], [2, 0, 2], [0, 1, 0]],  # proper Euler
    [[0, 2, 1], [0, 2, -1], [1, -1, -1], [-1, -1, -1]],  # a one-channel ankle, no toe joint
]


def random_leg(rng: np.random.Generator, layout) -> fs.LegChain:
    """A y-up leg of about human size (metres) with random axis frames C."""
    segments = np.array([[0, -0.42, 0.02], [0, -0.42, -0.02], [0, -0.08, 0.14], [0, -0.08, -0.04], [0, 0, 0.05]])
    segments = segments + rng.normal(0, 0.01, (5, 3))
    if layout[3][0] < 0:
        segments[4] = 0
    return fs.LegChain(axis=rotations.matrices(rng.uniform(-3, 3, (4, 3)), "xyz"), axes=layout, segments=segments)


def random_walk(rng: np.random.Generator, chain: fs.LegChain, frames: int) -> dict:
    """A leg walking along z: hips, parents, smooth angles, its points, random plants and
    targets near the points (some beyond reach), clearances and the floor under the feet."""
    t = np.arange(frames) / 30.0
    hips = np.stack([np.full(frames, 0.1), 0.88 + 0.02 * np.sin(7 * t), 1.2 * t], axis=1)
    parents = rotations.matrices(np.stack([0.05 * np.sin(3 * t), 0.1 * np.sin(2 * t), 0 * t], axis=1), "xyz")
    phase = rng.uniform(0, 6, (1, 4, 3))
    angles = 0.3 * np.sin(6 * t[:, None, None] + phase) * (chain.axes >= 0)
    points = footskate.leg_points([chain], hips[None], parents[None], angles[None])[0]
    planted = np.zeros((frames, 2), bool)
    for k in range(2):
        start = 0
        while start < frames:
            start += int(rng.integers(0, 8))
            length = int(rng.integers(1, 20))
            planted[start : start + length, k] = True
            start += length
    targets = points[:, [3, 2]] + rng.normal(0, 0.06, (frames, 2, 3))
    clearance = np.array([0.06, 0.03, 0.01]) + rng.uniform(-0.01, 0.01, 3)
    level = float(points[:, 3, 1].min(initial=0.0)) - 0.06 + rng.uniform(-0.05, 0.05)
    options = fs.CleanupOptions(
        level=level,
        slope=(float(rng.uniform(-0.05, 0.05)), 0.0, 0.0),
        blend=int(rng.choice([0, 1, 6, 24])),
        root_window=int(rng.choice([0, 2, 6])),
        root_passes=int(rng.choice([0, 1, 3])),
        knee_soft=float(rng.choice([0.0, 0.05])),
        knee_keep=float(rng.choice([0.0, 0.5, 1.0])),
    )
    return dict(hips=hips, parents=parents, angles=angles, points=points, planted=planted, targets=targets,
                clearance=clearance, options=options)  # fmt: skip


def walks(rng: np.random.Generator) -> list[tuple[fs.LegChain, dict]]:
    return [
        (chain, random_walk(rng, chain, frames))
        for layout in LEG_LAYOUTS
        for frames in (0, 1, 2, 9, 40)
        for chain in (random_leg(rng, layout),)
    ]


def leg_points_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for legs, frames in ((1, 0), (1, 1), (2, 7), (2, 30)):
        chains = tuple(random_leg(rng, LEG_LAYOUTS[int(rng.integers(len(LEG_LAYOUTS)))]) for _ in range(legs))
        hips = rng.normal(size=(legs, frames, 3))
        parents = rotations.matrices(rng.uniform(-3, 3, (legs, frames, 3)), "zyx")
        angles = rng.uniform(-3, 3, (legs, frames, 4, 3)) * np.stack([c.axes >= 0 for c in chains])[:, None]
        out += [(chains, hips, parents, angles, feet) for feet in (False, True)]
    return out


def placed_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for legs, frames, joints, kept in ((1, 0, 5, 1), (1, 1, 5, 1), (2, 7, 9, 3), (2, 33, 31, 4)):
        positions = rng.normal(size=(frames, joints, 3)) * 50
        world = rotations.matrices(rng.uniform(-3, 3, (frames, kept, 3)), "zyx")
        at = rng.integers(0, joints, (legs, 6))
        at[:, 5] = rng.integers(0, kept, legs)
        at[0, 4] = -1  # no toe tip
        out.append((positions, world, at, rng.normal(size=(legs, 3)) * 5))
    return out


def plan_cases(rng: np.random.Generator) -> list[tuple]:
    return [
        (chain, w["angles"], w["points"], w["planted"], w["targets"], w["clearance"], w["options"])
        for chain, w in walks(rng)
    ]


def fast_plan(*args) -> tuple:
    plan = fs.plan_leg(*args)
    return plan.enforced, plan.goal, plan.turn, plan.weight, plan.reach, plan.knee


def root_cases(rng: np.random.Generator) -> list[tuple]:
    """Goals in and beyond reach of one or two hips, weights 0 (free), between and 1."""
    out = []
    for legs, frames in ((1, 0), (1, 1), (2, 2), (1, 17), (2, 40)):
        hips = rng.normal(0, 0.1, (legs, frames, 3))
        goals = hips + rng.normal(0, 1, (legs, frames, 3))
        reaches = rng.uniform(0.5, 1.2, (legs, frames))
        weights = rng.choice([0.0, 0.3, 1.0], (legs, frames))
        options = fs.CleanupOptions(root_window=int(rng.choice([0, 1, 4])), root_passes=int(rng.choice([0, 3])))
        out.append((hips, goals, reaches, weights, options))
    return out


def solve_cases(rng: np.random.Generator) -> list[tuple]:
    """The walks with their twin-made plans and root."""
    out = []
    for chain, w in walks(rng):
        plan = footskate.plan_leg(
            chain, w["angles"], w["points"], w["planted"], w["targets"], w["clearance"], w["options"]
        )
        root = footskate.adjust_root(w["hips"][None], plan[1][None], plan[4][None], plan[3][None], w["options"])
        out.append(
            (chain, w["hips"], w["parents"], w["angles"], w["points"], w["planted"], *plan[1:4], plan[5], root,
             w["clearance"], w["options"])
        )  # fmt: skip
    return out


def joint_rotations(chain: fs.LegChain, angles: np.ndarray) -> np.ndarray:
    """The local rotations (frames, 4, 3, 3) of solved angles: near gimbal lock only those are
    defined, not the split of an Euler triple."""
    return np.stack([footskate.local(chain, j, angles[:, j]) for j in range(4)], axis=1)


def fast_solve(chain, hips, parents, angles, points, planted, goal, turn, weight, knee, root, clearance, options):
    plan = fs.LegPlan(np.empty(0), goal, turn, weight, np.empty(0), knee)
    return joint_rotations(
        chain, fs.solve_leg(chain, hips, parents, angles, points, planted, plan, root, clearance, options)
    )


def slow_solve(chain, *args):
    return joint_rotations(chain, footskate.solve_leg(chain, *args))


def write_cases(rng: np.random.Generator) -> list[tuple]:
    """Motions of one or two legs, some angles solved anew (NaN among them), the root moved in some
    frames (by -0.0 too), channels at -0.0 and the root's columns anywhere among the legs'."""
    out = []
    for legs, frames, width in ((1, 0, 15), (1, 1, 20), (2, 7, 31), (2, 40, 62)):
        values = rng.normal(0, 90, (frames, width))
        values[rng.random(values.shape) < 0.1] = -0.0
        picked = rng.permutation(width)[: 12 * legs + 3]
        columns = np.where(rng.random((legs, 4, 3)) < 0.7, picked[: 12 * legs].reshape(legs, 4, 3), -1)
        scale = float(rng.choice([np.pi / 180, 1.0]))
        angles = np.where(columns[:, None] >= 0, values[:, np.maximum(columns, 0)].transpose(1, 0, 2, 3) * scale, 0.0)
        solved = np.where(rng.random(angles.shape) < 0.4, angles + rng.normal(0, 0.1, angles.shape), angles)
        solved[rng.random(angles.shape) < 0.05] = np.nan
        root = np.where(rng.random((frames, 3)) < 0.5, rng.normal(0, 1, (frames, 3)), rng.choice([0.0, -0.0]))
        out.append((values, angles, solved, columns, scale, root, picked[12 * legs :]))
    return out


def speed_cases(rng: np.random.Generator) -> list[tuple]:
    """Tracks of points of 0 to 40 frames, some NaN, measured one or several points of a frame at a time."""
    out = []
    for tracks, frames, per_frame in ((1, 0, 1), (2, 1, 5), (1, 2, 1), (2, 3, 5), (3, 40, 5)):
        points = rng.normal(0, 1, (tracks, frames, per_frame, 3)).cumsum(axis=1)
        points[rng.random(points.shape) < 0.02] = np.nan
        which = [0] if per_frame == 1 else [3, 2, 4]
        out += [(points, which, float(rng.choice([30.0, 120.0])), central) for central in (False, True)]
    return out


def plant_cases(rng: np.random.Generator) -> list[tuple]:
    """Rows of heights and speeds that wander in and out of the thresholds (NaN among them), with
    gaps and lengths of every kind."""
    out = []
    for rows, frames in ((1, 0), (1, 1), (2, 2), (4, 60), (3, 400)):
        heights = np.abs(rng.normal(0, 0.03, (rows, frames)).cumsum(axis=1) % 0.08 - 0.01)
        speed = np.abs(rng.normal(0, 0.3, (rows, frames)))
        central = speed * rng.uniform(0.3, 1.0, (rows, frames))
        for a in (heights, speed, central):
            a[rng.random(a.shape) < 0.01] = np.nan
        for gap, shortest, rise in ((0, 0, 0.0), (3, 5, 0.005), (12, 6, 0.01)):
            th = fs.PlantThresholds(0.02, 0.05, 0.03, 0.4, 0.02, 0.35, 0.4, rise, gap, shortest)
            out.append((heights, speed, central, th))
    return out


# --- search by example ----------------------------------------------------------------------


def fast_feature_index(takes):
    index = mt_search.FeatureIndex(takes)
    return index.keys, index.offsets.astype(np.intp), index.ids.astype(np.intp)


# --- the take check ---------------------------------------------------------------------------


def check_cases(rng: np.random.Generator) -> list[tuple]:
    """Random walks with spikes, steps, NaN runs, frozen runs and repeated rows, over sizes from
    empty to a few hundred rows, the whole line or a piece of it checked."""
    out = []
    for rows in (0, 1, 2, 3, 4, 5, 8, 31, 300):
        for channels in (0, 1, 4):
            x = np.cumsum(rng.standard_normal((rows, channels)), axis=0)
            if rows > 4 and channels:
                for _ in range(rows // 10 + 1):
                    t, k = int(rng.integers(rows)), int(rng.integers(channels))
                    what = rng.integers(5)
                    if what == 0:
                        x[t, k] += rng.choice([-1, 1]) * rng.uniform(5, 50)
                    elif what == 1:
                        x[t:, k] += rng.choice([-1, 1]) * rng.uniform(5, 50)
                    elif what == 2:
                        x[t : t + int(rng.integers(1, 5)), k] = np.nan
                    elif what == 3:
                        x[t : t + int(rng.integers(2, 9)), k] = x[t, k]
                    else:
                        x[t : t + int(rng.integers(1, 4))] = x[t - 1]
            spike = rng.uniform(0.5, 8, channels) if rng.random() < 0.7 else float(rng.uniform(0, 8))
            step = rng.uniform(0.5, 8, channels)
            begin = int(rng.integers(0, rows // 3 + 1))
            end = int(rng.integers(begin, rows + 1)) if rng.random() < 0.5 else rows
            out.append((x, spike, step, int(rng.integers(1, 6)), begin, end))
    return out


def fast_roughness(values, squares, counts):
    squares, counts = squares.copy(), counts.copy()
    roughness(values, squares, counts)
    return squares, counts


def fast_check(x, spike, step, min_run, begin, end):
    found = channel_events(x, spike, step, min_run, begin, end)
    return found.events, found.sizes, found.roughness, found.smooth_rows


# --- the registry ---------------------------------------------------------------------------

TWINS: dict[str, Twin] = {
    "mt_filter1d": Twin(fast_filter, slow_filter, filter_cases, filter_same),
    "mt_scan_frames": Twin(mt_text.scan_frames, text_twins.scan_frames, frame_text_cases, exact),
    "mt_scan_table": Twin(mt_text.scan_table, text_twins.scan_table, table_cases, exact),
    "mt_text_style": Twin(lambda data: tuple(mt_text.text_style(data)), text_twins.text_style, style_cases, exact),
    "mt_format_double": Twin(mtcore.format_number, text_twins.format_number, number_cases, exact),
    "mt_format_table": Twin(
        lambda values: written(lambda w: mt_text.format_table(values, w)), text_twins.format_table, value_cases, exact
    ),
    "mt_format_frames": Twin(
        lambda values, first, keys, offsets, counts: written(
            lambda w: mt_text.format_frames(values, first, keys, offsets, counts, w)
        ),
        text_twins.format_frames,
        frame_value_cases,
        exact,
    ),
    "mt_forward_kinematics": Twin(
        lambda values, tree: forward_kinematics(values, tree, world=True, local=True),
        kinematics.forward_kinematics,
        kinematics_cases,
        close(1e-12),
    ),
    "mt_local_quaternions": Twin(local_quaternions, kinematics.local_quaternions, local_quaternion_cases, close(1e-6)),
    "mt_euler_to_matrices": Twin(fast_euler, rotations.euler_to_matrices, euler_cases, close(1e-14)),
    # the twin's quaternions are its matrices' eigenvectors (w >= 0 picks the sign)
    "mt_euler_to_quaternions": Twin(
        lambda angles, order, extrinsic: rot.euler_to_quaternions(angles, order, extrinsic=extrinsic),
        lambda angles, order, extrinsic: rotations.matrices_to_quaternions(
            rotations.euler_to_matrices(angles, order, extrinsic)
        ),
        lambda rng: [case for case in euler_cases(rng) if case[1] in rot.ORDERS],
        close(1e-12),
    ),
    "mt_matrices_to_euler": Twin(
        lambda m, order, extrinsic: rot.matrices_to_euler(m, order, extrinsic=extrinsic),
        rotations.matrices_to_euler,
        matrices_to_euler_cases,
        angles_close,
    ),
    "mt_matrices_to_quaternions": Twin(
        rot.matrices_to_quaternions, rotations.matrices_to_quaternions, rotation_matrix_cases, close(1e-14)
    ),
    "mt_quaternions_to_matrices": Twin(
        rot.quaternions_to_matrices, rotations.quaternions_to_matrices, quaternion_cases, close(1e-14)
    ),
    "mt_quaternions_to_rotvecs": Twin(
        rot.quaternions_to_rotvecs, rotations.quaternions_to_rotvecs, quaternion_cases, close(1e-14)
    ),
    "mt_rotvecs_to_quaternions": Twin(
        rot.rotvecs_to_quaternions, rotations.rotvecs_to_quaternions, rotvec_cases, close(1e-15)
    ),
    "mt_unroll_quaternions": Twin(
        lambda q, axis: rot.unroll_quaternions(q, axis), rotations.unroll_quaternions, unroll_quaternion_cases, exact
    ),
    "mt_unroll_euler": Twin(
        lambda a, order, axis, degrees: rot.unroll_euler(a, order, axis=axis, degrees=degrees),
        rotations.unroll_euler,
        unroll_euler_cases,
        close(1e-12),
    ),
    "mt_unwrap_angles": Twin(rot.unwrap_angles, rotations.unwrap_angles, unwrap_cases, exact),
    "mt_wrap_angles": Twin(fast_wrap, rotations.wrap_angles, wrap_cases, exact),
    "mt_finite_ranges": Twin(rot.finite_ranges, rotations.finite_ranges, ranges_cases, exact),
    "mt_slerp": Twin(rot.slerp, rotations.slerp, slerp_cases, close(1e-12)),
    "mt_interpolate_rotvecs": Twin(
        lambda v0, v1, t, aligned: rot.interpolate_rotvecs(v0, v1, t, aligned=aligned),
        rotations.interpolate_rotvecs,
        rotvec_interpolation_cases,
        close(1e-14),
    ),
    "mt_atan2": Twin(fast_atan2, np.arctan2, atan2_cases, close(4.5e-16)),
    "mt_sincos": Twin(fast_sincos, rotations.sincos, sincos_cases, close(2.3e-16)),
    "mt_interpolate_euler": Twin(
        fast_interpolate_euler, rotations.interpolate_euler, interpolate_euler_cases, close(1e-12)
    ),
    "mt_combine": Twin(fast_combine, slow_combine, combine_cases, exact),
    "mt_copy_mapped": Twin(copy_mapped, lambda data, begin, end: data[begin:end], mapped_cases, exact),
    "mt_retarget": Twin(retarget_rotations, retarget.retarget_rotations, retarget_cases, turns_close),
    "mt_parse_number": Twin(lambda t: mt_text.parse_number(t.encode()), float, parse_cases, close(0.0)),  # bytes: C
    "mt_equalize": Twin(
        lambda x, g, mode: mt_signal.equalize(x, g, 0, mode), signal_twins.equalize_twin, equalize_cases, close(1e-12)
    ),
    "mt_sosfiltfilt": Twin(
        lambda sos, x, padtype: mt_signal.sosfiltfilt(sos, x, 0, padtype),
        lambda sos, x, padtype: signal_twins.sosfiltfilt_twin(sos, x, padtype),
        sosfiltfilt_cases,
        close(1e-12),
    ),
    "mt_upfirdn": Twin(fast_upfirdn, signal_twins.upfirdn_twin, upfirdn_cases, close(1e-12)),
    "mt_fill_gaps": Twin(fast_fill, signal_twins.fill_gaps_twin, gap_cases, close(1e-9)),
    # rows and kinds exactly; sizes and the roughness sum to rounding (both sum in row order)
    "mt_check_channels": Twin(fast_check, check.check_channels_twin, check_cases, close(1e-12)),
    "mt_check_pace": Twin(
        lambda x, w: tuple(vars(pace(x, w)).values()), check.pace_twin, check.pace_cases, close(1e-9)
    ),
    # the sums added in another order than numpy's
    "mt_check_roughness": Twin(fast_roughness, check.roughness_twin, check.roughness_cases, close(1e-12)),
    # acos in the knee's bend, the floor's heights and drifts summed as the contract says
    "mt_check_legs": Twin(
        lambda *case: tuple(vars(check_legs(*case)).values()),
        check.check_legs_twin,
        check.check_legs_cases,
        close(1e-9),
    ),
    "mt_check_elbows": Twin(elbow_bends, check.elbow_bends_twin, check.elbow_cases, close(1e-12)),
    # the twin's SLERP is its own: degrees off the path to rounding (acos near 1 takes its root)
    "mt_check_trim": Twin(trim_runs, check.trim_twin, check.trim_cases, close(1e-6)),
    # the twin's SLERP and products its own: metres to rounding
    "mt_check_seen": Twin(seen_runs, check.seen_twin, check.seen_cases, close(1e-9)),
    "mt_nan_runs": Twin(
        lambda x, *_: mt_signal.nan_runs(x), lambda x, *_: signal_twins.nan_runs_twin(x), nan_run_cases, exact
    ),
    "mt_leg_points": Twin(
        lambda chains, hips, parents, angles, feet: fs.leg_points(chains, hips, parents, angles, feet=feet),
        lambda chains, hips, parents, angles, feet: footskate.leg_points(chains, hips, parents, angles, feet=feet),
        leg_points_cases,
        close(1e-12),
    ),
    "mt_placed_legs": Twin(fs.placed_legs, footskate.placed_legs, placed_cases, close(1e-12)),
    # the plan's goals and turns and the solved rotations to 1e-9 and 1e-6: acos and asin near 1
    # (a knee almost straight, a toe just touching the floor) take square roots of rounding
    "mt_footskate_plan": Twin(fast_plan, footskate.plan_leg, plan_cases, close(1e-9)),
    "mt_footskate_root": Twin(fs.adjust_root, footskate.adjust_root, root_cases, close(1e-9)),
    "mt_footskate_solve": Twin(fast_solve, slow_solve, solve_cases, close(1e-6)),
    "mt_footskate_write": Twin(fs.write_channels, footskate.write_channels, write_cases, exact),
    "mt_plant_masks": Twin(fs.plant_masks, footskate.plant_masks, plant_cases, exact),
    "mt_resting_points": Twin(fs.resting_points, footskate.resting_points, footskate.ground_cases, exact),
    # LAPACK's solve against elimination: the same system, rounded otherwise
    "mt_fit_floor": Twin(fs.fit_floor, footskate.fit_floor, footskate.fit_cases, close(1e-9)),
    "mt_point_speeds": Twin(
        lambda p, which, rate, central: fs.point_speeds(p, which, rate, central=central),
        lambda p, which, rate, central: footskate.point_speeds(p, which, rate, central=central),
        speed_cases,
        exact,
    ),
    "mt_lb_envelope": Twin(
        lambda x, r: tuple(mt_search.lb_envelope(x, r)), search_twins.lb_envelope, search_twins.envelope_cases, exact
    ),
    "mt_lb_keogh": Twin(
        lambda c, u, lo, t: mt_search.lb_keogh(c, (u, lo), t),
        search_twins.lb_keogh,
        search_twins.keogh_cases,
        close(1e-12),
    ),
    "mt_dtw": Twin(mt_search.dtw, search_twins.dtw, search_twins.dtw_cases, close(1e-12)),
    "mt_dtw_search": Twin(
        lambda *case: tuple(mt_search.dtw_search(*case)[:2]),
        search_twins.dtw_search,
        search_twins.dtw_search_cases,
        lambda got, want: (exact(got[0], want[0]), close(1e-12)(got[1], want[1])),
    ),
    "mt_kdtree_query": Twin(
        lambda points, leaf, queries, k, exclude: tuple(
            mt_search.KDTree(points, leaf).query(queries, k, exclude=exclude, workers=1)
        ),
        lambda points, leaf, queries, k, exclude: search_twins.knn(points, queries, k, exclude),
        search_twins.knn_cases,
        lambda got, want: (exact(got[0], want[0]), close(1e-12)(got[1], want[1])),
    ),
    # the words exactly; the values to rounding (acos, atan2 and sqrt of the C library and Python's)
    "mt_relations": Twin(
        lambda *case: tuple(mt_search.relations(*case)),
        search_twins.relations,
        search_twins.relation_cases,
        lambda got, want: (exact(got[0], want[0]), close(1e-12)(got[1], want[1])),
    ),
    "mt_hysteresis": Twin(mt_search.hysteresis, search_twins.hysteresis, search_twins.hysteresis_cases, exact),
    "mt_pack_bits": Twin(mt_search.pack_bits, search_twins.pack_bits, search_twins.pack_cases, exact),
    "mt_segments": Twin(
        lambda w: tuple(mt_search.segments(w)), search_twins.segments, search_twins.segment_cases, exact
    ),
    "mt_feature_index_build": Twin(
        fast_feature_index, search_twins.feature_index, search_twins.feature_index_cases, exact
    ),
    "mt_feature_index_find": Twin(
        lambda takes, query: mt_search.FeatureIndex(takes).find(query),
        search_twins.feature_find,
        search_twins.feature_find_cases,
        exact,
    ),
}

EXEMPT = {
    "mt_strerror": "a message per status code, not a kernel (test_status checks every code has its own)",
    "mt_filter1d_block": "a constant of mt_filter1d's contract (test_filters_layouts checks any split gives the same bits)",
    "mt_format_bound": "a capacity bound for mt_format_frames, which fails with MT_ERANGE below it",
    "mt_format_table_bound": "a capacity bound for mt_format_table, which fails with MT_ERANGE below it",
    "mt_guard_install": "installs a signal handler once; test_hardening shrinks mapped files under the scanners",
    "mt_number_code": "names the number writer's code on this processor; test_numbers runs each code against the portable",
    "mt_number_code_runs": "whether this processor runs a number writer's code; test_numbers checks it with the writers",
    "mt_kdtree_depth": "a size for the buffers of mt_kdtree_build (test_search_kernels checks the leaves it makes)",
    "mt_kdtree_build": "builds what mt_kdtree_query searches, no result of its own; test_search_kernels checks its splits",
}
