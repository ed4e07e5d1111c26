"""Retargeting in vectorised numpy: the twin of ``mt_retarget`` (and, in the benchmark, of the
whole of ``motiontheater.characters.retarget.retarget``).

One numpy call per joint over all frames: the source's forward kinematics
(the twin of mt_forward_kinematics), then each target joint, parents first,
as mtcore.h describes the kernel; Euler angles by scipy.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .kinematics import forward_kinematics

EYE = np.eye(3)


def axis_rotation(axis: int, angles: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations by angles (radians) about coordinate axis 0, 1 or 2."""
    c, s = np.cos(angles), np.sin(angles)
    m = np.zeros((*np.shape(angles), 3, 3))
    a, b = (axis + 1) % 3, (axis + 2) % 3
    m[..., axis, axis] = 1
    m[..., a, a], m[..., a, b], m[..., b, a], m[..., b, b] = c, -s, s, c
    return m


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def smallest_rotation(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(n, 3, 3): the smallest rotations taking the directions u onto w (n, 3); the identity
    where either is zero or not finite."""
    lengths = np.linalg.norm(u, axis=-1) * np.linalg.norm(w, axis=-1)
    ok = (lengths > 0) & np.isfinite(lengths)
    u, w = unit(np.where(ok[:, None], u, 1.0)), unit(np.where(ok[:, None], w, 1.0))
    v, c = np.cross(u, w), np.sum(u * w, -1)
    vx = np.zeros((len(u), 3, 3))
    vx[:, 0, 1], vx[:, 0, 2], vx[:, 1, 2] = -v[:, 2], v[:, 1], -v[:, 0]
    vx[:, 1, 0], vx[:, 2, 0], vx[:, 2, 1] = v[:, 2], -v[:, 1], v[:, 0]
    opposite = c < -1 + 1e-12
    r = EYE + vx + vx @ vx / np.where(opposite, 1.0, 1 + c)[:, None, None]
    for f in np.nonzero(opposite)[0]:
        e = np.zeros(3)
        e[int(np.argmin(np.abs(u[f])))] = 1.0
        n = unit(np.cross(u[f], e))
        r[f] = 2 * np.outer(n, n) - EYE
    r[~ok] = EYE
    return r


def aim_angle(e: np.ndarray, d: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Angles about unit axis e (3,) turning d nearest to t (n, 3); NaN where a part normal to e vanishes."""
    dp, tp = d - np.outer(d @ e, e), t - np.outer(t @ e, e)
    ok = (np.linalg.norm(dp, axis=-1) > 1e-6 * np.linalg.norm(d, axis=-1)) & (
        np.linalg.norm(tp, axis=-1) > 1e-6 * np.linalg.norm(t, axis=-1)
    )
    angle = np.arctan2(np.cross(dp, tp) @ e, np.sum(dp * tp, -1))
    return np.where(ok, angle, np.nan)


def euler(m: np.ndarray, axes: list[int]) -> np.ndarray:
    """Extrinsic Euler angles about axes (in order) of matrices m (n, 3, 3)."""
    return Rotation.from_matrix(m).as_euler("".join("xyz"[a] for a in axes))


def reduce(m: np.ndarray, axes: list[int], aim: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(angles (n, count), achieved (n, 3, 3)) of rotation channels about axes nearest to m (see mtcore.h)."""
    n = len(m)
    if not axes:
        return np.zeros((n, 0)), np.broadcast_to(EYE, (n, 3, 3))
    if len(axes) == 3:
        return euler(m, axes), m
    t = m @ aim
    aims = aim @ aim > 0
    if len(axes) == 1:
        e = EYE[axes[0]]
        a = aim_angle(e, np.broadcast_to(aim, (n, 3)), t) if aims else np.full(n, np.nan)
        q = Rotation.from_matrix(m).as_quat()  # x, y, z, w
        q *= np.where(q[:, 3] < 0, -1.0, 1.0)[:, None]
        a = np.where(np.isnan(a), 2 * np.arctan2(q[:, axes[0]], q[:, 3]), a)
        return a[:, None], axis_rotation(axes[0], a)
    i, k = axes
    e1, e2 = EYE[i], EYE[k]
    along = aim @ e1
    perp = aim - along * e1
    side = np.cross(e1, perp)
    beta, gamma = e2 @ perp, e2 @ side
    rho = np.hypot(beta, gamma)
    if aims and rho > 1e-6 * np.linalg.norm(aim):
        want = t @ e2 - along * (e2 @ e1)
        phi, spread = np.arctan2(gamma, beta), np.arccos(np.clip(want / rho, -1, 1))
        best, angles, achieved = np.full(n, -np.inf), np.zeros((n, 2)), np.zeros((n, 3, 3))
        for sign in (-1, 1):
            a = phi + sign * spread
            r1 = axis_rotation(i, a)
            b = np.nan_to_num(aim_angle(e2, r1 @ aim, t))
            r = axis_rotation(k, b) @ r1
            near = np.sum(r * m, axis=(1, 2))
            better = near > best
            best = np.where(better, near, best)
            angles[better] = np.stack([a, b], -1)[better]
            achieved[better] = r[better]
        return angles, achieved
    three = euler(m, [i, 3 - i - k, k])
    angles = three[:, [0, 2]]
    return angles, axis_rotation(k, angles[:, 1]) @ axis_rotation(i, angles[:, 0])


def swivel(want, bone, child_bone, hinge, goal):
    """want (n, 3, 3) turned about its bone so that a hinged child can aim at goal (see retarget.c);
    unturned in frames where a direction vanishes."""
    vectors = (want @ bone, want @ hinge, want @ child_bone, goal)
    ok = np.all([np.linalg.norm(v, axis=-1) > 0 for v in vectors], axis=0)
    d, n, a, g = (unit(np.where(ok[:, None], v, 1.0)) for v in vectors)
    bend = np.linalg.norm(np.cross(d, g), axis=-1)
    full = np.sin(np.radians(10))
    weight = np.clip((bend / full - 0.2) / 0.8, 0, 1)
    along = np.sum(n * d, -1)
    perp = n - along[:, None] * d
    side = np.cross(d, perp)
    beta, gamma = np.sum(perp * g, -1), np.sum(side * g, -1)
    rho = np.hypot(beta, gamma)
    phi = np.arctan2(gamma, beta)
    c = (np.sum(n * a, -1) - along * np.sum(d * g, -1)) / np.where(rho > 0, rho, 1)
    spread = np.arccos(np.clip(c, -1, 1))
    first = np.remainder(phi - spread + np.pi, 2 * np.pi) - np.pi
    second = np.remainder(phi + spread + np.pi, 2 * np.pi) - np.pi
    psi = np.where(np.abs(second) < np.abs(first), second, first)
    psi = np.where(ok & (rho > 0), psi * weight, 0.0)
    turn = Rotation.from_rotvec(d * psi[:, None]).as_matrix()
    return turn @ want


def rotation_channels(tree, j):
    kinds = tree.dof_kind[tree.dof_start[j] : tree.dof_start[j + 1]]
    columns = tree.dof_column[tree.dof_start[j] : tree.dof_start[j + 1]]
    return [int(k) for k in kinds if k <= 2], [int(c) for k, c in zip(kinds, columns) if k <= 2]


def retarget_rotations(values, source, target, target_channels, plan):
    """The twin of ``mtcore.retarget.retarget_rotations`` (zeros in the other channels)."""
    points, world, _ = forward_kinematics(values, source)
    frames = len(values)
    out = np.zeros((frames, target_channels))
    glob = np.zeros((frames, target.joints, 3, 3))
    a9 = plan.align
    for j in target.order:
        p = target.parent[j]
        up = glob[:, p] if p >= 0 else np.broadcast_to(EYE, (frames, 3, 3))
        axes, columns = rotation_channels(target, j)
        s = plan.follow[j]
        if s < 0:
            glob[:, j] = up
            out[:, columns] = 0
            continue
        want = a9 @ world[:, s] @ plan.correction[j]
        a, b = plan.key_points[j]
        if plan.refit[j] and a >= 0:
            u = (points[:, b] - points[:, a]) @ a9.T
            want = smallest_rotation(want @ plan.key_vector[j], u) @ want
        h = plan.hinge[j]
        if h >= 0 and len(axes) == 3:
            h_axes, _ = rotation_channels(target, h)
            ha, hb = plan.key_points[h]
            if ha >= 0 and len(h_axes) == 1:
                goal = (points[:, hb] - points[:, ha]) @ a9.T
                want = swivel(want, plan.key_vector[j], plan.aim[h], target.axis[h][:, h_axes[0]], goal)
        c9 = target.axis[j]
        m = c9.T @ np.swapaxes(up, 1, 2) @ want @ c9
        angles, achieved = reduce(m, axes, c9.T @ plan.aim[j])
        out[:, columns] = angles / target.angle_scale
        glob[:, j] = want if len(axes) == 3 else up @ c9 @ achieved @ c9.T
    return out
