"""Rotations of whole arrays, in C: Euler angles, matrices, quaternions and
rotation vectors (exponential maps), their continuity along frames, and
interpolation between keys.

Conventions (those of ``scipy.spatial.transform.Rotation``, which the tests
reproduce to 1e-12):

- Matrices (..., 3, 3) are row-major and act on column vectors, v' = R v.
- Quaternions (..., 4) are (w, x, y, z), scalar first.  Inputs need not be
  unit: they are normalised, and a zero quaternion gives NaN.  Conversions
  return the sign with w >= 0.
- Rotation vectors (..., 3) are the axis times the angle in radians;
  conversions return angles in [0, pi].
- Euler angles (..., 3) (a, b, c) about the axes of ``order``, one of
  :data:`ORDERS`: three lowercase letters, Tait-Bryan (three distinct axes)
  or proper Euler (the first axis again last).  The keyword ``extrinsic``
  (always required) says about which axes: for order "ijk",

  - ``extrinsic=True``: about the fixed axes, in order: R = R_k(c) R_j(b) R_i(a)
    (scipy's lowercase "ijk");
  - ``extrinsic=False``: intrinsic, about the axes as they turn:
    R = R_i(a) R_j(b) R_k(c) (scipy's uppercase "IJK").

  Angles are radians, or degrees with ``degrees=True``.  Angles found from
  rotations lie, as in scipy, in a, c in [-pi, pi], b in [-pi/2, pi/2]
  (Tait-Bryan) or [0, pi] (proper Euler).  At gimbal lock (b = +-pi/2, or
  b = 0 or pi) only a + c or a - c is defined: c is then 0.

Arrays may have any leading shape, any real dtype and any memory layout
(they are computed in float64); inputs are never modified.  Arguments are
checked before any C call: TypeError for a dtype that is not real, ValueError
for a wrong shape or an unknown order.
"""

from __future__ import annotations

import math

import numpy as np

from . import _checks
from ._cdata import c_array
from ._mtcore import ffi, lib
from ._status import check

__all__ = [
    "ORDERS",
    "euler_to_matrices",
    "euler_to_quaternions",
    "euler_to_rotvecs",
    "finite_ranges",
    "interpolate_euler",
    "interpolate_rotvecs",
    "matrices_to_euler",
    "matrices_to_quaternions",
    "matrices_to_rotvecs",
    "quaternions_to_euler",
    "quaternions_to_matrices",
    "quaternions_to_rotvecs",
    "rotvecs_to_euler",
    "rotvecs_to_matrices",
    "rotvecs_to_quaternions",
    "slerp",
    "unroll_euler",
    "unroll_quaternions",
    "unwrap_angles",
    "wrap_angles",
]

BLENDS = {"slerp": lib.MT_BLEND_SLERP, "expmap": lib.MT_BLEND_EXPMAP, "aligned_expmap": lib.MT_BLEND_ALIGNED_EXPMAP}
ORDERS = ("xyz", "xzy", "yxz", "yzx", "zxy", "zyx", "xyx", "xzx", "yxy", "yzy", "zxz", "zyz")
AXES = {"x": lib.MT_DOF_RX, "y": lib.MT_DOF_RY, "z": lib.MT_DOF_RZ}


def _order(order) -> list[int]:
    if isinstance(order, str) and order in ORDERS:  # every call asks: the message only for a wrong one
        return [AXES[letter] for letter in order]
    hint = " (lowercase; extrinsic= says fixed or turning axes)" if str(order).lower() in ORDERS else ""
    return [AXES[letter] for letter in _checks.choice(order, "order", ORDERS, hint=hint)]


def _scale(degrees) -> float:
    return math.pi / 180 if _checks.flag(degrees, "degrees") else 1.0


def _sequence_matrices(angles: np.ndarray, codes: list[int], intrinsic: bool, scale: float) -> np.ndarray:
    """Matrices (..., 3, 3) of float64 angles (..., len(codes)) about the axes ``codes``."""
    out = np.empty(angles.shape[:-1] + (3, 3))
    check(
        lib.mt_euler_to_matrices(
            c_array(angles), out.size // 9, ffi.new("int[]", codes), len(codes), intrinsic, scale, c_array(out)
        ),
        "mt_euler_to_matrices",
    )
    return out


def _euler(m: np.ndarray, codes: list[int], intrinsic: bool, scale: float) -> np.ndarray:
    out = np.empty(m.shape[:-2] + (3,))
    check(
        lib.mt_matrices_to_euler(c_array(m), out.size // 3, ffi.new("int[]", codes), intrinsic, scale, c_array(out)),
        "mt_matrices_to_euler",
    )
    return out


def _convert(kernel: str, x: np.ndarray, lead: tuple[int, ...], trailing: tuple[int, ...]) -> np.ndarray:
    """out (*lead, *trailing) = kernel(x) for the kernels (in, n, out)."""
    out = np.empty(lead + trailing)
    check(getattr(lib, kernel)(c_array(x), math.prod(lead), c_array(out)), kernel)
    return out


def _quaternions(m: np.ndarray) -> np.ndarray:
    return _convert("mt_matrices_to_quaternions", m, m.shape[:-2], (4,))


def _matrices(q: np.ndarray) -> np.ndarray:
    return _convert("mt_quaternions_to_matrices", q, q.shape[:-1], (3, 3))


def _rotvecs(q: np.ndarray) -> np.ndarray:
    return _convert("mt_quaternions_to_rotvecs", q, q.shape[:-1], (3,))


def _from_rotvecs(v: np.ndarray) -> np.ndarray:
    return _convert("mt_rotvecs_to_quaternions", v, v.shape[:-1], (4,))


def euler_to_matrices(angles, order: str, *, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of Euler angles (..., 3) (see the module's conventions)."""
    codes, intrinsic, scale = _order(order), not _checks.flag(extrinsic, "extrinsic"), _scale(degrees)
    return _sequence_matrices(_checks.real(angles, "angles", (..., 3)), codes, intrinsic, scale)


def matrices_to_euler(matrices, order: str, *, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    """Euler angles (..., 3) of rotation matrices (..., 3, 3), in scipy's ranges; c = 0 at gimbal lock."""
    codes, intrinsic, scale = _order(order), not _checks.flag(extrinsic, "extrinsic"), _scale(degrees)
    return _euler(_checks.real(matrices, "matrices", (..., 3, 3)), codes, intrinsic, scale)


def matrices_to_quaternions(matrices) -> np.ndarray:
    """Unit quaternions (..., 4), w >= 0, of rotation matrices (..., 3, 3) (Shepperd's method)."""
    return _quaternions(_checks.real(matrices, "matrices", (..., 3, 3)))


def quaternions_to_matrices(quaternions) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of quaternions (..., 4), normalised first."""
    return _matrices(_checks.real(quaternions, "quaternions", (..., 4)))


def quaternions_to_rotvecs(quaternions) -> np.ndarray:
    """Rotation vectors (..., 3), angles in [0, pi], of quaternions (..., 4).  Accurate at
    angles near 0 (a series) and near pi."""
    return _rotvecs(_checks.real(quaternions, "quaternions", (..., 4)))


def rotvecs_to_quaternions(rotvecs) -> np.ndarray:
    """Unit quaternions (..., 4), w >= 0, of rotation vectors (..., 3), any angle."""
    return _from_rotvecs(_checks.real(rotvecs, "rotvecs", (..., 3)))


def euler_to_quaternions(angles, order: str, *, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    """Unit quaternions (..., 4), w >= 0, of Euler angles (..., 3)."""
    codes, intrinsic, scale = _order(order), not _checks.flag(extrinsic, "extrinsic"), _scale(degrees)
    a = _checks.real(angles, "angles", (..., 3))
    out = np.empty(a.shape[:-1] + (4,))
    check(
        lib.mt_euler_to_quaternions(c_array(a), out.size // 4, ffi.new("int[]", codes), intrinsic, scale, c_array(out)),
        "mt_euler_to_quaternions",
    )
    return out


def quaternions_to_euler(quaternions, order: str, *, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    """Euler angles (..., 3) of quaternions (..., 4), as :func:`matrices_to_euler`."""
    codes, intrinsic, scale = _order(order), not _checks.flag(extrinsic, "extrinsic"), _scale(degrees)
    return _euler(_matrices(_checks.real(quaternions, "quaternions", (..., 4))), codes, intrinsic, scale)


def euler_to_rotvecs(angles, order: str, *, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    """Rotation vectors (..., 3), angles in [0, pi], of Euler angles (..., 3)."""
    return _rotvecs(euler_to_quaternions(angles, order, extrinsic=extrinsic, degrees=degrees))


def rotvecs_to_euler(rotvecs, order: str, *, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    """Euler angles (..., 3) of rotation vectors (..., 3), as :func:`matrices_to_euler`."""
    codes, intrinsic, scale = _order(order), not _checks.flag(extrinsic, "extrinsic"), _scale(degrees)
    return _euler(_matrices(_from_rotvecs(_checks.real(rotvecs, "rotvecs", (..., 3)))), codes, intrinsic, scale)


def matrices_to_rotvecs(matrices) -> np.ndarray:
    """Rotation vectors (..., 3), angles in [0, pi], of rotation matrices (..., 3, 3)."""
    return _rotvecs(matrices_to_quaternions(matrices))


def rotvecs_to_matrices(rotvecs) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of rotation vectors (..., 3)."""
    return _matrices(rotvecs_to_quaternions(rotvecs))


def _along(a: np.ndarray, axis, name: str, width: int) -> tuple[int, int, int]:
    """(outer, n, inner) of ``a`` (..., width) around its axis of frames ``axis``."""
    axis = _checks.axis(axis, a.ndim)
    if axis == a.ndim - 1:
        raise ValueError(f"axis must be an axis of frames, not the last axis of {name} (its {width} components)")
    return math.prod(a.shape[:axis]), a.shape[axis], math.prod(a.shape[axis + 1 : -1])


def unroll_quaternions(quaternions, axis: int = 0) -> np.ndarray:
    """Quaternions (..., 4) with signs continuous along ``axis``: each one after the first
    is negated (the same rotation) where its dot product with the one before is negative.
    A quaternion after a NaN one is kept as it is."""
    q = _checks.real(quaternions, "quaternions", (..., 4))
    outer, n, inner = _along(q, axis, "quaternions", 4)
    out = np.empty_like(q)
    check(lib.mt_unroll_quaternions(c_array(q), outer, n, inner, c_array(out)), "mt_unroll_quaternions")
    return out


def unroll_euler(angles, order: str, *, axis: int = 0, degrees: bool = False) -> np.ndarray:
    """Euler angles (..., 3) made continuous along ``axis``: each triple after the first becomes,
    of the triples of the same rotation, the nearest (least sum of squared differences) to the
    output before it.  Those are the triple and the other solution, (a + pi, pi - b, c + pi)
    for Tait-Bryan orders and (a + pi, -b, c + pi) for proper Euler orders, each angle shifted
    by any whole turns.  Intrinsic and extrinsic angles alike (``order`` only tells the kind).
    A triple next to one holding NaN is kept as it is.  The split of a + c or a - c at gimbal
    lock is kept as given."""
    codes, half_turn = _order(order), 180.0 if _checks.flag(degrees, "degrees") else math.pi
    a = _checks.real(angles, "angles", (..., 3))
    outer, n, inner = _along(a, axis, "angles", 3)
    out = np.empty_like(a)
    check(
        lib.mt_unroll_euler(c_array(a), outer, n, inner, codes[0] == codes[2], half_turn, c_array(out)),
        "mt_unroll_euler",
    )
    return out


def unwrap_angles(
    values, period: float, columns=None, state: tuple[np.ndarray, np.ndarray] | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Angle channels of ``values`` (frames, channels) made continuous along the frames: a new
    array (float64), with the state to carry into the frames that follow.

    A step of more than half a ``period`` (360 for degrees, 2 pi for radians) between a
    column's finite samples counts whole turns, and every later sample gets them added as exact
    multiples of the period, so any cut of a take into pieces unwraps as the whole.  NaN and
    infinities stay as they are and are stepped over: a bad sample spoils nothing after it.
    ``columns`` (default: all) are the angle channels; the others are copied.  ``state`` is
    (last, turns) as returned for the frames before: each column's last finite sample (NaN for
    none) and its whole turns counted (None at a take's start).  Returns (out, last, turns).
    """
    a = _checks.real(values, "values", ("frames", "channels"))
    out = np.array(a, dtype=np.float64, order="C")
    chosen = _columns(columns, a.shape[1])
    period = float(period)
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"period must be a positive number, got {period}")
    if state is None:
        last, turns = np.full(chosen.size, np.nan), np.zeros(chosen.size)
    else:
        last, turns = (np.array(x, dtype=np.float64).reshape(-1) for x in state)
        if last.size != chosen.size or turns.size != chosen.size:
            raise ValueError(f"state must hold {chosen.size} last values and turns, one per column")
    c_columns = _c_columns(chosen)
    check(
        lib.mt_unwrap_angles(
            c_array(out), out.shape[0], out.shape[1], c_columns, chosen.size, period, c_array(last), c_array(turns)
        ),
        "mt_unwrap_angles",
    )
    return out, last, turns


def _columns(columns, channels: int) -> np.ndarray:
    """The column indices as an array the kernels read as size_t[] (see _c_columns), checked."""
    chosen = np.arange(channels, dtype=np.intp) if columns is None else np.asarray(columns, dtype=np.intp).reshape(-1)
    if chosen.size and (chosen.min() < 0 or chosen.max() >= channels):
        raise ValueError(f"columns must be channels of the {channels} there are, got {chosen.tolist()}")
    return chosen


assert ffi.sizeof("size_t") == np.dtype(np.uintp).itemsize  # what _c_columns relies on


def _c_columns(chosen: np.ndarray):
    """Checked column indices (_columns) as the kernels' size_t[], without a copy (intp is its size)."""
    return c_array(np.ascontiguousarray(chosen).view(np.uintp), "size_t[]")


def wrap_angles(values: np.ndarray, low, high, period: float, columns=None) -> None:
    """Angle channels of ``values`` (frames, channels; C-contiguous float64, changed in place)
    put back into the range their take used: ``low[k]`` and ``high[k]`` are the take's least and
    greatest finite sample of column ``columns[k]`` (default: all; see :func:`finite_ranges`).
    Where they lie within [-period/2, period/2], that is the column's range, else where they
    lie within [0, period] that one, else the column is left; each finite sample outside its
    column's range [a, a + period] becomes ``v - period floor((v - a) / period)``.  The inverse
    of :func:`unwrap_angles` once a take is smoothed."""
    _checks.output(values, "values (changed in place)", ("frames", "channels"))
    chosen = _columns(columns, values.shape[1])
    low, high = (np.ascontiguousarray(x, dtype=np.float64).reshape(-1) for x in (low, high))
    if low.size != chosen.size or high.size != chosen.size:
        raise ValueError(f"low and high must hold {chosen.size} bounds, one per column")
    period = float(period)
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"period must be a positive number, got {period}")
    c_columns = _c_columns(chosen)
    check(
        lib.mt_wrap_angles(
            c_array(values),
            values.shape[0],
            values.shape[1],
            c_columns,
            chosen.size,
            c_array(low),
            c_array(high),
            period,
        ),
        "mt_wrap_angles",
    )


def finite_ranges(
    values, state: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What the frames of ``values`` (frames, channels) say about each channel: (low, high,
    first), the least and greatest finite sample of each column (+inf and -inf where it has
    none) and its first finite sample (NaN for none).  ``state`` is that of the frames before
    (a take given in pieces), widened into new arrays."""
    a = _checks.real(values, "values", ("frames", "channels"))
    channels = a.shape[1]
    if state is None:
        low, high, first = np.full(channels, np.inf), np.full(channels, -np.inf), np.full(channels, np.nan)
    else:
        low, high, first = (np.array(x, dtype=np.float64).reshape(-1) for x in state)
        if not low.size == high.size == first.size == channels:
            raise ValueError(f"state must hold {channels} lows, highs and firsts, one per column")
    check(
        lib.mt_finite_ranges(c_array(a), a.shape[0], channels, c_array(low), c_array(high), c_array(first)),
        "mt_finite_ranges",
    )
    return low, high, first


def _keys(k0, k1, t, names: tuple[str, str], width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Keys (..., width) and fractions (...) broadcast together, C-contiguous float64."""
    k0, k1 = _checks.real(k0, names[0], (..., width)), _checks.real(k1, names[1], (..., width))
    t = _checks.real(t, "t", (...,))
    try:
        shape = np.broadcast_shapes(k0.shape[:-1], k1.shape[:-1], t.shape)
    except ValueError:
        raise ValueError(
            f"{names[0]} {k0.shape}, {names[1]} {k1.shape} and t {t.shape} do not broadcast "
            f"together (the keys' last axis aside)"
        ) from None
    return (
        np.ascontiguousarray(np.broadcast_to(k0, shape + (width,))),
        np.ascontiguousarray(np.broadcast_to(k1, shape + (width,))),
        np.ascontiguousarray(np.broadcast_to(t, shape)),
    )


def slerp(q0, q1, t) -> np.ndarray:
    """Spherical linear interpolation from quaternions q0 to q1 (..., 4) by fractions t, along
    the shorter arc (q1 negated where q0 . q1 < 0): unit quaternions of the broadcast shape of
    q0, q1 (the last axis aside) and t, (..., 4).  t = 0 gives q0 normalised, t = 1 q1 or -q1
    normalised; t outside [0, 1] extrapolates.  E.g. frames between two keys:
    ``slerp(q0, q1, np.linspace(0, 1, frames)[:, None])`` for keys (joints, 4)."""
    q0, q1, t = _keys(q0, q1, t, ("q0", "q1"), 4)
    out = np.empty_like(q0)
    check(lib.mt_slerp(c_array(q0), c_array(q1), c_array(t), t.size, c_array(out)), "mt_slerp")
    return out


def interpolate_rotvecs(v0, v1, t, *, aligned: bool = False) -> np.ndarray:
    """Rotation vectors interpolated linearly from v0 to v1 (..., 3) by fractions t, broadcast
    as for :func:`slerp`.  Plain (``aligned=False``) this may take the long way round; with
    ``aligned=True`` v0 is first replaced by the rotation vector of its quaternion negated,
    v0 (1 - 2 pi / |v0|), where the keys' quaternions have a negative dot product, so that
    keys near the same rotation interpolate through it."""
    v0, v1, t = _keys(v0, v1, t, ("v0", "v1"), 3)
    aligned = _checks.flag(aligned, "aligned")
    out = np.empty_like(v0)
    check(
        lib.mt_interpolate_rotvecs(c_array(v0), c_array(v1), c_array(t), t.size, aligned, c_array(out)),
        "mt_interpolate_rotvecs",
    )
    return out


def interpolate_euler(
    k0,
    k1,
    t,
    order: str,
    *,
    extrinsic: bool,
    degrees: bool = False,
    blend: str = "slerp",
    start=None,
    reference=None,
) -> np.ndarray:
    """Euler angles (frames, joints, 3) between the key triples k0 and k1, in one C pass.

    The keys are (joints, 3), the same for every frame, or (frames, joints, 3); ``t`` (frames,)
    is each frame's fraction of the way from k0 to k1 (0 gives k0's rotation, 1 k1's).  ``blend``
    is one of :data:`BLENDS`: "slerp" (:func:`slerp` of the keys' quaternions), "expmap" or
    "aligned_expmap" (:func:`interpolate_rotvecs` of their rotation vectors, plain or aligned).
    Which of the Euler triples of each rotation is written:

    - neither ``start`` nor ``reference``: :func:`matrices_to_euler`'s, in scipy's ranges;
    - ``start`` (joints, 3): a path from it, each frame's triple the nearest the joint's triple of
      the frame before, as :func:`unroll_euler` gives for ``start`` followed by the frames;
    - ``reference`` (frames, joints, 3): each angle plus the whole turns that bring it nearest the
      reference's angle (halves to even).

    This is the chain of those functions to rounding (1e-15 or so; near gimbal lock only the
    rotation is that close), except that a key within rounding of a half turn has two
    rotation vectors, and the one taken may differ.  NaN in a frame gives NaN there; along
    a path, the frame after one holding NaN starts afresh.
    """
    codes, intrinsic, degrees = (
        _order(order),
        not _checks.flag(extrinsic, "extrinsic"),
        _checks.flag(degrees, "degrees"),
    )
    blend_code = _checks.choice(blend, "blend", BLENDS)
    k0, k1 = _checks.real(k0, "k0", (..., 3)), _checks.real(k1, "k1", (..., 3))
    t = _checks.real(t, "t", ("frames",))
    frames = len(t)
    if k0.ndim not in (2, 3) or k0.shape != k1.shape or (k0.ndim == 3 and len(k0) != frames):
        raise ValueError(
            f"k0 and k1 must both have shape (joints, 3) or (frames, joints, 3) with frames = len(t) = {frames}, "
            f"got {k0.shape} and {k1.shape}"
        )
    joints = k0.shape[-2]
    continuity, ref = lib.MT_CONTINUITY_NONE, None
    if start is not None and reference is not None:
        raise ValueError("give start (a path) or reference (nearest turns), not both")
    if start is not None:
        continuity, ref = lib.MT_CONTINUITY_PATH, _checks.real(start, "start", (..., 3))
        if ref.shape != (joints, 3):
            raise ValueError(f"start must have shape (joints, 3) = ({joints}, 3), got {ref.shape}")
    elif reference is not None:
        continuity, ref = lib.MT_CONTINUITY_REFERENCE, _checks.real(reference, "reference", (..., 3))
        if ref.shape != (frames, joints, 3):
            raise ValueError(
                f"reference must have shape (frames, joints, 3) = ({frames}, {joints}, 3), got {ref.shape}"
            )
    out = np.empty((frames, joints, 3))
    check(
        lib.mt_interpolate_euler(
            c_array(k0),
            c_array(k1),
            k0.ndim == 3,
            c_array(t),
            frames,
            joints,
            ffi.new("int[]", codes),
            intrinsic,
            degrees,
            blend_code,
            continuity,
            c_array(ref),
            c_array(out),
        ),
        "mt_interpolate_euler",
    )
    return out
