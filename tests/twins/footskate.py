"""Footskate cleanup in vectorised numpy: the slow twin of mtcore.footskate's C kernels.

Same signatures and results (to rounding) as :func:`mtcore.footskate.leg_points`,
:func:`mtcore.footskate.cleanup`, :func:`mtcore.footskate.write_channels`,
:func:`mtcore.footskate.point_speeds` and :func:`mtcore.footskate.plant_masks`; every phase is written over all frames
at once, the plants' targets frame by frame as the method states them.
"""

import numpy as np

from mtcore.footskate import CleanupOptions, LegChain

HEEL, BALL = 0, 1
TINY = 1e-12


# ---------------------------------------------------------------- rotations


def dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def mv(m, v):
    return np.einsum("...ij,...j->...i", m, v)


def mm(a, b):
    return np.einsum("...ij,...jk->...ik", a, b)


def tr(m):
    return np.swapaxes(m, -1, -2)


def unit(v):
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(n > 0, v / np.where(n > 0, n, 1), 0.0)


def about(axis, angle):
    """Rotations (..., 3, 3) by angle about unit axis (Rodrigues)."""
    axis = np.broadcast_to(axis, np.shape(angle) + (3,))
    x, y, z = axis[..., 0], axis[..., 1], axis[..., 2]
    c, s = np.cos(angle), np.sin(angle)
    t = 1 - c
    return np.stack(
        [
            np.stack([c + t * x * x, t * x * y - s * z, t * x * z + s * y], -1),
            np.stack([t * x * y + s * z, c + t * y * y, t * y * z - s * x], -1),
            np.stack([t * x * z - s * y, t * y * z + s * x, c + t * z * z], -1),
        ],
        -2,
    )


def basis(k):
    e = np.zeros(3)
    e[k] = 1.0
    return e


def between(u, v):
    """The smallest rotations (..., 3, 3) taking the directions of u onto those of v."""
    u, v = unit(u), unit(v)
    axis = np.cross(u, v)
    s, c = np.linalg.norm(axis, axis=-1), dot(u, v)
    angle = np.arctan2(s, c)
    # opposite directions: a half turn about any axis perpendicular to u
    other = np.where(np.abs(u[..., :1]) < 0.9, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
    fallback = unit(np.cross(u, other))
    axis = np.where((s > TINY)[..., None], unit(axis), fallback)
    return about(axis, np.where(s > TINY, angle, np.where(c < 0, np.pi, 0.0)))


def rotvec(m):
    """Rotation vectors of rotations (..., 3, 3), angle in [0, pi]."""
    w = np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]], -1)
    s = np.linalg.norm(w, axis=-1) / 2
    c = (np.trace(m, axis1=-2, axis2=-1) - 1) / 2
    angle = np.arctan2(s, c)
    small = s < 1e-6
    factor = np.where(small, 0.5 + angle**2 / 12, angle / (2 * np.where(small, 1, s)))
    out = w * factor[..., None]
    near_pi = (c < -0.99) & ~small
    if near_pi.any():  # the axis from the symmetric part, its sign from the antisymmetric one
        b = (m[near_pi] + tr(m[near_pi])) / 2 - c[near_pi, None, None] * np.eye(3)
        column = np.argmax(np.linalg.norm(b, axis=-2), axis=-1)
        axis = unit(np.take_along_axis(b, column[:, None, None], axis=-1)[..., 0])
        axis = np.where(dot(axis, w[near_pi])[:, None] < 0, -axis, axis)
        out[near_pi] = axis * angle[near_pi, None]
    return out


def from_rotvec(v):
    angle = np.linalg.norm(v, axis=-1)
    return about(unit(v), angle)


def wrap_near(angle, reference):
    """angle plus the whole turns that bring it nearest to reference."""
    return angle + 2 * np.pi * np.round((reference - angle) / (2 * np.pi))


def wrap(angle):
    return angle - 2 * np.pi * np.round(angle / (2 * np.pi))


# ---------------------------------------------------------------- joints


def channels(chain: LegChain, j: int) -> int:
    return chain.channels(j)


def dof_rotation(chain: LegChain, j: int, angles):
    """M (..., 3, 3) of joint j's channels: each applies about a fixed axis after the ones before."""
    m = np.broadcast_to(np.eye(3), angles.shape[:-1] + (3, 3))
    for n in range(channels(chain, j)):
        m = mm(about(basis(chain.axes[j, n]), angles[..., n]), m)
    return m


def local(chain: LegChain, j: int, angles):
    c = chain.axis[j]
    return c @ dof_rotation(chain, j, angles) @ c.T


def euler_nearest(m, axes, reference):
    """Angles (..., 3) about fixed axes (i, j, k) applying in order, M = R_k(c) R_j(b) R_i(a), of
    rotations m: of the two solutions, the one nearest reference, each angle whole turns from it."""
    i, j, k = (int(a) for a in axes)
    proper = i == k
    if proper:
        k = 3 - i - j
    eps = 1.0 if (i, j, k) in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1.0
    if proper:
        b = np.arctan2(np.hypot(m[..., j, i], m[..., k, i]), m[..., i, i])
        lock = np.hypot(m[..., j, i], m[..., k, i]) < 1e-9
        c = np.where(lock, reference[..., 2], np.arctan2(m[..., j, i], -eps * m[..., k, i]))
        last = i
    else:
        b = np.arctan2(-eps * m[..., k, i], np.hypot(m[..., i, i], m[..., j, i]))
        lock = np.hypot(m[..., i, i], m[..., j, i]) < 1e-9
        c = np.where(lock, reference[..., 2], np.arctan2(eps * m[..., j, i], m[..., i, i]))
        last = k
    x = mm(about(basis(last), -c), m)  # = R_j(b) R_i(a): its row j is that of R_i(a)
    a = np.arctan2(-eps * x[..., j, k], x[..., j, j])
    first = np.stack([a, b, c], -1)
    second = np.stack([a + np.pi, (0.0 if proper else np.pi) - b, c + np.pi], -1)
    first, second = wrap_near(first, reference), wrap_near(second, reference)
    pick = ((second - reference) ** 2).sum(-1) < ((first - reference) ** 2).sum(-1)
    return np.where((pick & ~lock)[..., None], second, first)


def realize(chain: LegChain, j: int, wanted, aim, reference):
    """Angles (..., 3) of joint j nearest to ``wanted`` local rotations that its channels can take:
    three channels give it exactly; two turn the body vector ``aim`` where wanted turns it; one
    turns aim as near as its axis allows.  Angles are whole turns from ``reference``."""
    count = channels(chain, j)
    c = chain.axis[j]
    out = reference.copy()
    if count == 3:
        return euler_nearest(tr(c) @ wanted @ c, chain.axes[j], reference)
    p = unit(np.broadcast_to(aim @ c, wanted.shape[:-1]))  # C^T aim
    q = unit(mv(tr(c) @ wanted, aim))  # C^T L aim
    if count == 1:
        e = basis(chain.axes[j, 0])
        pp, qq = p - dot(p, e)[..., None] * e, q - dot(q, e)[..., None] * e
        a = np.arctan2(dot(e, np.cross(pp, qq)), dot(pp, qq))
        out[..., 0] = wrap_near(a, reference[..., 0])
        return out
    ei, ej = basis(chain.axes[j, 0]), basis(chain.axes[j, 1])
    jj = int(chain.axes[j, 1])
    big_a, big_b = p[..., jj], np.cross(ei, p)[..., jj]
    rho = np.hypot(big_a, big_b)
    kappa = np.clip(q[..., jj] / np.where(rho > TINY, rho, 1), -1, 1)
    base, spread = np.arctan2(big_b, big_a), np.arccos(kappa)
    best, best_cost = None, None
    for sign in (1.0, -1.0):
        a = wrap_near(base + sign * spread, reference[..., 0])
        r = mv(about(ei, a), p)
        rp, qp = r - dot(r, ej)[..., None] * ej, q - dot(q, ej)[..., None] * ej
        b = wrap_near(np.arctan2(dot(ej, np.cross(rp, qp)), dot(rp, qp)), reference[..., 1])
        cost = (a - reference[..., 0]) ** 2 + (b - reference[..., 1]) ** 2
        pair = np.stack([a, b], -1)
        if best is None:
            best, best_cost = pair, cost
        else:
            better = cost < best_cost
            best = np.where(better[..., None], pair, best)
    out[..., :2] = np.where((rho > TINY)[..., None], best, reference[..., :2])
    return out


# ---------------------------------------------------------------- legs


def leg_fk(chain: LegChain, hips, parents, angles):
    """Local rotations (4 of (..., 3, 3)), the foot's world rotation and the points (..., 5, 3)."""
    s = chain.segments
    locals_ = [local(chain, j, angles[..., j, :]) for j in range(4)]
    thigh = mm(parents, locals_[0])
    shin = mm(thigh, locals_[1])
    foot = mm(shin, locals_[2])
    knee = hips + mv(thigh, s[0])
    ankle = knee + mv(shin, s[1])
    ball = ankle + mv(foot, s[2])
    heel = ankle + mv(foot, s[3])
    tip = ball + mv(mm(foot, locals_[3]), s[4])
    return locals_, foot, np.stack([knee, ankle, ball, heel, tip], -2)


def leg_points(chains, hips, parents, angles, *, feet=False):
    legs = [leg_fk(c, hips[i], parents[i], angles[i]) for i, c in enumerate(chains)]
    points = np.stack([leg[2] for leg in legs])
    return (points, np.stack([leg[1] for leg in legs])) if feet else points


def placed_legs(positions, world, at, heels):
    """The hips and points of legs from the joints' positions and the feet's world rotations."""
    at = np.asarray(at)
    hips = np.stack([positions[:, a[0]] for a in at]) if len(at) else np.zeros((0, len(positions), 3))
    points = np.zeros((len(at), len(positions), 5, 3))
    for i, (hip, knee, ankle, ball, tip, row) in enumerate(at.tolist()):
        points[i, :, 0], points[i, :, 1], points[i, :, 2] = positions[:, knee], positions[:, ankle], positions[:, ball]
        points[i, :, 3] = positions[:, ankle] + np.einsum("fij,j->fi", world[:, row], heels[i])
        points[i, :, 4] = positions[:, tip if tip >= 0 else ball]
    return hips, points


def height(p, options: CleanupOptions):
    return p @ (np.asarray(options.up) - np.asarray(options.slope)) - options.level


def lift(p, h, options: CleanupOptions):
    """p moved along up until its height is h (vertical: the slope is perpendicular to up)."""
    return p + (h - height(p, options))[..., None] * np.asarray(options.up)


# ---------------------------------------------------------------- targets


def enforced_targets(planted, targets, clearance, foot_length, options):
    """Phase 1 for one leg: frame by frame, a point planted at the frame before keeps its target;
    a new one takes the given target on the floor, set at the foot's length from the other
    point's target when that one is planted too (both new: both move, about their middle) or
    was planted at most ``switch_gap(options)`` frames before (a roll from heel to ball, or
    back, without both down at once).  Returns the targets (frames, 2, 3), NaN where not
    planted, and for such a roll the other point's last target at its first frame (NaN elsewhere)."""
    frames = len(planted)
    out = np.full((frames, 2, 3), np.nan)
    partner = np.full((frames, 3), np.nan)
    up, slope = np.asarray(options.up), np.asarray(options.slope)
    last = [-(10**9), -(10**9)]  # the last frame each point was planted
    gap = switch_gap(options)
    for t in range(frames):
        new = [False, False]
        for point in (HEEL, BALL):
            if not planted[t, point]:
                continue
            if t > 0 and planted[t - 1, point]:
                out[t, point] = out[t - 1, point]
            else:
                out[t, point] = lift(targets[t, point], clearance[point], options)
                new[point] = True
        rolled = [new[p] and not planted[t, 1 - p] and t - last[1 - p] <= gap + 1 for p in (HEEL, BALL)]
        if (planted[t].all() and any(new)) or any(rolled):
            heel = out[t, HEEL] if not rolled[BALL] else out[last[HEEL], HEEL]
            ball = out[t, BALL] if not rolled[HEEL] else out[last[BALL], BALL]
            horizontal = (ball - heel) - ((ball - heel) @ up) * up
            direction = unit(horizontal)
            gamma = slope @ direction  # the floor's rise per unit along that direction
            rise = clearance[BALL] - clearance[HEEL]
            # |x direction + (rise + gamma x) up| = foot length: the horizontal distance x
            qa, qb, qc = 1 + gamma**2, 2 * gamma * rise, rise**2 - foot_length**2
            x = max(0.0, (-qb + np.sqrt(max(qb * qb - 4 * qa * qc, 0.0))) / (2 * qa))
            if all(new):
                middle = (heel + ball) / 2
                out[t, HEEL] = lift(middle - direction * x / 2, clearance[HEEL], options)
                out[t, BALL] = lift(middle + direction * x / 2, clearance[BALL], options)
            elif new[BALL]:
                out[t, BALL] = lift(heel + direction * x, clearance[BALL], options)
            else:
                out[t, HEEL] = lift(ball - direction * x, clearance[HEEL], options)
            if rolled[BALL]:
                partner[t] = heel
            if rolled[HEEL]:
                partner[t] = ball
        for point in (HEEL, BALL):
            if planted[t, point]:
                last[point] = t
    return out, partner


def switch_gap(options):
    """Free frames a roll from one planted point to the other may cross: a quarter of the blend."""
    return max(1, options.blend // 4)


def neighbours(mask):
    """For each frame, the last frame at or before it and the first at or after it where mask is
    set (-1 where none)."""
    frames = len(mask)
    idx = np.arange(frames)
    before = np.maximum.accumulate(np.where(mask, idx, -1)) if frames else idx
    after_rev = np.minimum.accumulate(np.where(mask, idx, frames)[::-1])[::-1] if frames else idx
    after = np.where(after_rev == frames, -1, after_rev)
    return before, after


def smoothstep(x):
    x = np.clip(x, 0, 1)
    return x * x * (3 - 2 * x)


def blend_weights(mask, window):
    """Weights of the nearest masked frames before (p) and after (n) every unmasked frame:
    s(1 - distance / w) with w = min(window, n - p), s the smoothstep; 0 without such a frame."""
    frames = len(mask)
    t = np.arange(frames)
    before, after = neighbours(mask)
    prev = np.where(mask, -1, np.r_[-1, before[:-1]] if frames else before)
    nxt = np.where(mask, -1, np.r_[after[1:], -1] if frames else after)
    gap = np.where((prev >= 0) & (nxt >= 0), nxt - prev, np.iinfo(np.int64).max)
    w = np.minimum(window, gap).astype(float)
    wp = np.where((prev >= 0) & (w > 0), smoothstep(1 - (t - prev) / np.where(w > 0, w, 1)), 0.0)
    wn = np.where((nxt >= 0) & (w > 0), smoothstep(1 - (nxt - t) / np.where(w > 0, w, 1)), 0.0)
    return np.maximum(prev, 0), wp, np.maximum(nxt, 0), wn


def blend_logs(mask, values, window):
    """values (frames, 3) where mask is set; elsewhere the weighted sum of those at the nearest
    masked frames before and after (:func:`blend_weights`), with the larger weight."""
    p, wp, n, wn = blend_weights(mask, window)
    values = np.where(mask[:, None], values, 0.0)
    mixed = wp[:, None] * values[p] + wn[:, None] * values[n]
    return np.where(mask[:, None], values, mixed), np.where(mask, 1.0, np.maximum(wp, wn))


def foot_targets(chain, planted, enforced, partner, points, window, clearance, options):
    """Phase 2 for one leg: the ankle targets (frames, 3), the foot's turns (frames, 3) as rotation
    vectors (the foot's target rotation is the turn times its rotation now), and each frame's blend weight (1 where constrained, fading to 0 within ``window`` frames of it).

    Both points planted: the foot turns by the smallest rotation taking heel -> ball onto the
    targets'.  One planted: the foot's turn is blended from the nearest frames with both, then
    turned about the planted point just enough to lift the other onto the floor if it is below;
    the ankle follows the planted point.  None: turn and ankle move are blended from the nearest
    constrained frames.  Turns blend as rotation vectors."""
    ankle, ball, heel = points[:, 1], points[:, 2], points[:, 3]
    both = planted.all(-1)
    some = planted.any(-1)
    rolled = ~np.isnan(partner[:, 0])
    heel_goal = np.where((rolled & planted[:, BALL])[:, None], partner, enforced[:, HEEL])
    ball_goal = np.where((rolled & planted[:, HEEL])[:, None], partner, enforced[:, BALL])
    pins = both | rolled
    pinned = between(ball - heel, ball_goal - heel_goal)  # read where pinned
    logs, _ = blend_logs(pins, rotvec(pinned), window)
    turn = from_rotvec(logs)
    pivot_is_ball = planted[:, BALL] & ~planted[:, HEEL]
    pivot = np.where(pivot_is_ball[:, None], ball, heel)
    goal = np.where(pivot_is_ball[:, None], enforced[:, BALL], enforced[:, HEEL])
    single = some & ~both
    other = np.where(pivot_is_ball[:, None], heel, ball)
    rest = np.where(pivot_is_ball, clearance[HEEL], clearance[BALL])
    lever = mv(turn, other - pivot)
    turn = np.where((single & ~rolled)[:, None, None], mm(raise_lever(lever, goal, rest, options), turn), turn)
    shift = goal + mv(turn, ankle - pivot) - ankle  # read where constrained
    shift, weight = blend_logs(some, shift, window)
    logs, _ = blend_logs(some, rotvec(turn), window)
    return ankle + shift, logs, weight


def raise_lever(lever, pivot, rest, options):
    """Rotations (..., 3, 3) about the pivot that lift the far end of lever (pivot + lever) from
    below its resting height ``rest`` onto it, by the smallest turn in the vertical plane of the
    lever; the identity where it is not below."""
    n = np.asarray(options.up) - np.asarray(options.slope)
    axis = unit(np.cross(lever, n))
    need = rest - height(pivot, options)  # n . R lever must reach this
    x, y = dot(n, lever), dot(n, np.cross(axis, lever))
    rho, phi = np.hypot(x, y), np.arctan2(y, x)
    spread = np.arccos(np.clip(need / np.where(rho > TINY, rho, 1), -1, 1))
    first, second = wrap(phi - spread), wrap(phi + spread)
    angle = np.where(np.abs(first) <= np.abs(second), first, second)
    low = (x < need) & (rho > TINY) & (np.linalg.norm(np.cross(lever, n), axis=-1) > TINY)
    return about(axis, np.where(low, angle, 0.0))


# ---------------------------------------------------------------- knee, root


def hinge(chain, locals_, knee_axis):
    """Knee coefficients: |hip -> ankle|^2 = base + 2 rho cos(delta - phi) turning the knee by delta."""
    s1, s2 = chain.segments[0], chain.segments[1]
    u = mv(locals_[1], s2)
    c0 = dot(s1, knee_axis) * dot(u, knee_axis)
    x = dot(s1, u) - c0
    y = dot(s1, np.cross(knee_axis, u))
    rho, phi = np.hypot(x, y), np.arctan2(y, x)
    base = dot(s1, s1) + dot(u, u) + 2 * c0
    return base, rho, phi


def knee_axis_and_side(chain, locals_):
    """The knee's hinge axis in the thigh's frame (its channel's axis, or the mean bend axis) and
    the side it bends to (+1 or -1: the sign of the median bend from straight)."""
    s1, s2 = chain.segments[0], chain.segments[1]
    if channels(chain, 1) == 1:
        axis = chain.axis[1] @ basis(chain.axes[1, 0])
    else:
        total = np.cross(s1, mv(locals_[1], s2)).sum(0)
        if not np.linalg.norm(total) > TINY * max(1.0, np.linalg.norm(s1) * np.linalg.norm(s2)) * len(locals_[1]):
            total = np.cross(s1, s2 + chain.segments[2])
        axis = unit(total)
    _, _, phi = hinge(chain, locals_, axis)
    side = 1.0 if np.sum(np.sign(wrap(-phi))) >= 0 else -1.0
    return axis, side


def reach(base, rho, phi, knee_soft, keep=0.0):
    """The longest hip -> ankle distance with the knee bent at least min(knee_soft, its bend now),
    and at least ``keep`` times its bend now."""
    now = np.abs(wrap(-phi))
    bend = np.maximum(np.minimum(knee_soft, now), keep * now)
    return np.sqrt(np.maximum(base + 2 * rho * np.cos(bend), 0.0))


def project_root(offset, centres, radii, active):
    """Phase 3 per frame: the root offsets nearest to ``offset`` (frames, 3) that put each active
    leg's hip within its radius of its ankle target (centres: the offsets that would put the hip
    on the target, (legs, frames, 3)).  One sphere: projection onto it; two: the projection onto
    one that lies in the other ball (the nearer if both do), else onto their circle."""
    out = offset.copy()
    legs = len(centres)
    inside = np.ones((legs, len(offset)), bool)
    proj = np.empty_like(centres)
    for i in range(legs):
        d = offset - centres[i]
        dist = np.linalg.norm(d, axis=-1)
        inside[i] = ~active[i] | (dist <= radii[i])
        proj[i] = centres[i] + unit(d) * radii[i][:, None]
    count = active.sum(0)
    for i in range(legs):
        one = (count == 1) & active[i] & ~inside[i]
        out[one] = proj[i][one]
    if legs >= 2:
        two = (count == 2) & active[0] & active[1] & ~(inside[0] & inside[1])
        if two.any():
            c1, c2, r1, r2, o = centres[0][two], centres[1][two], radii[0][two], radii[1][two], offset[two]
            p1 = np.where(inside[0][two, None], o, proj[0][two])
            p2 = np.where(inside[1][two, None], o, proj[1][two])
            ok1 = np.linalg.norm(p1 - c2, axis=-1) <= r2 * (1 + 1e-12)
            ok2 = np.linalg.norm(p2 - c1, axis=-1) <= r1 * (1 + 1e-12)
            d1, d2 = np.linalg.norm(p1 - o, axis=-1), np.linalg.norm(p2 - o, axis=-1)
            normal = c2 - c1
            gap = np.linalg.norm(normal, axis=-1)
            n = unit(normal)
            x = np.where(gap > TINY, (gap**2 + r1**2 - r2**2) / (2 * np.where(gap > TINY, gap, 1)), 0.0)
            x = np.clip(x, -r1, r1)
            middle = c1 + n * x[:, None]
            radius = np.sqrt(np.maximum(r1**2 - x**2, 0.0))
            q = o - middle
            q = q - dot(q, n)[:, None] * n
            other = np.where(np.abs(n[:, :1]) < 0.9, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
            q = np.where((np.linalg.norm(q, axis=-1) > TINY)[:, None], q, np.cross(n, other))
            circle = middle + unit(q) * radius[:, None]
            res = np.where(
                (ok1 & ok2 & (d1 <= d2))[:, None] | (ok1 & ~ok2)[:, None],
                p1,
                np.where(ok2[:, None], p2, circle),
            )
            out[two] = res
    return out


def moving_mean(x, half):
    """Mean over frames t - half .. t + half of x (frames, 3), the edges held, summed in
    window order (as the C kernel sums)."""
    frames = len(x)
    if half == 0 or frames == 0:
        return x.copy()
    idx = np.arange(frames)
    total = np.zeros_like(x)
    for k in range(-half, half + 1):
        total = total + x[np.clip(idx + k, 0, frames - 1)]
    return total / (2 * half + 1)


def envelope(depth, half):
    """The upper envelope of depth (frames,) >= 0 under the bump k(x) = smoothstep(1 - |x|),
    x = distance / (half + 1): max over s of depth[s] k((t - s) / (half + 1))."""
    out = depth.copy()
    for shift in range(1, half + 1):
        k = smoothstep(1 - shift / (half + 1))
        out[shift:] = np.maximum(out[shift:], k * depth[:-shift])
        out[:-shift] = np.maximum(out[:-shift], k * depth[shift:])
    return out


def smooth_root(offset, half):
    """Two moving means: a triangular window of half-width 2 * half."""
    return moving_mean(moving_mean(offset, half), half)


def two_bone(chain, hips, parents, angles, locals_, knee_axis, side, soft, ankle_goal, foot_goal, aim):
    """Phase 4 for frames of one leg: the knee bends about its hinge so that hip -> ankle has the
    goal's length, the hip turns the leg onto it, the ankle takes foot_goal (its aim vector
    exactly, with fewer than three channels).  Returns the angles (frames, 4, 3) of the joints
    that do not take the rotation asked exactly, the turn about the knee's hinge, the local
    rotations asked of hip, knee and ankle (for :func:`finish_angles`), the foot's world rotation
    and the ankle."""
    s1, s2 = chain.segments[0], chain.segments[1]
    out = angles.copy()
    base, rho, phi = hinge(chain, locals_, knee_axis)
    goal = ankle_goal - hips
    distance = np.linalg.norm(goal, axis=-1)
    longest = reach(base, rho, phi, soft)
    shortest = np.sqrt(np.maximum(base - 2 * rho, 0.0))
    d = np.clip(distance, shortest, longest)
    cosine = np.clip((d * d - base) / (2 * np.where(rho > TINY, rho, 1)), -1, 1)
    bend = np.where(rho > TINY, np.arccos(cosine), 0.0)
    delta = phi + side * bend
    knee_wanted = mm(about(knee_axis, delta), locals_[1])
    knee_local = knee_wanted
    if channels(chain, 1) == 2:
        out[:, 1] = realize(chain, 1, knee_wanted, s2, angles[:, 1])
        knee_local = local(chain, 1, out[:, 1])
    thigh = mm(parents, locals_[0])
    leg_vector = s1 + mv(knee_local, s2)
    turn = between(mv(thigh, leg_vector), goal)
    hip_wanted = mm(tr(parents), mm(turn, thigh))
    hip_local = hip_wanted
    if channels(chain, 0) < 3:
        out[:, 0] = realize(chain, 0, hip_wanted, leg_vector, angles[:, 0])
        hip_local = local(chain, 0, out[:, 0])
    thigh = mm(parents, hip_local)
    shin = mm(thigh, knee_local)
    foot_wanted = mm(tr(shin), foot_goal)
    foot_local = foot_wanted
    if channels(chain, 2) < 3:
        out[:, 2] = realize(chain, 2, foot_wanted, aim, angles[:, 2])
        foot_local = local(chain, 2, out[:, 2])
    foot = mm(shin, foot_local)
    ankle = hips + mv(thigh, s1) + mv(shin, s2)
    return (out, delta, (hip_wanted, knee_wanted, foot_wanted)), foot, ankle


def finish_angles(chain, angles, solved, aim):
    """The angles two_bone left: joints of three channels, and a one-channel knee (its angle
    plus the turn about its hinge, which is its channel's axis)."""
    out, delta, wanted = solved
    out = out.copy()
    for j in range(3):
        if channels(chain, j) == 3:
            out[:, j] = realize(chain, j, wanted[j], aim, angles[:, j])
    if channels(chain, 1) == 1:
        out[:, 1, 0] = angles[:, 1, 0] + wrap(delta)
    return out


def bend_toes(chain, foot, ball, angles, locals3, clearance_tip, options):
    """Toe angles (frames, 3) that raise a toe tip below the floor onto it, about the toe joint's
    axis (its channel's, or the foot's sideways axis)."""
    if channels(chain, 3) == 0 or not np.any(chain.segments[4]):
        return angles
    if channels(chain, 3) == 1:
        axis = chain.axis[3] @ basis(chain.axes[3, 0])
    else:
        axis = unit(np.cross(chain.segments[2], chain.segments[3]))
    k = mv(tr(foot), np.asarray(options.up) - np.asarray(options.slope))  # height gradient in the foot's frame
    u = mv(locals3, chain.segments[4])
    c0 = dot(k, axis) * dot(u, axis)
    x = dot(k, u) - c0
    y = dot(k, np.cross(axis, u))
    rho, phi = np.hypot(x, y), np.arctan2(y, x)
    need = clearance_tip - height(ball, options) - c0  # rho cos(delta - phi) must reach this
    low = height(ball, options) + dot(k, u) < clearance_tip
    spread = np.arccos(np.clip(need / np.where(rho > TINY, rho, 1), -1, 1))
    first, second = wrap(phi - spread), wrap(phi + spread)
    delta = np.where(np.abs(first) <= np.abs(second), first, second)
    wanted = mm(about(axis, delta), locals3)
    new = realize(chain, 3, wanted, chain.segments[4], angles)
    return np.where((low & (rho > TINY))[:, None], new, angles)


# ---------------------------------------------------------------- phases


def plan_leg(chain, angles, points, planted, targets, clearance, options: CleanupOptions):
    """Phases 1 and 2 for one leg: (enforced (frames, 2, 3), goal (frames, 3), turn (frames, 3),
    weight (frames,), reach (frames,), knee (4,)), as mtcore.footskate.plan_leg."""
    planted = np.asarray(planted, bool)
    locals_ = [None, local(chain, 1, angles[:, 1])]
    foot_length = np.linalg.norm(chain.segments[2] - chain.segments[3])
    enforced, partner = enforced_targets(planted, targets, clearance, foot_length, options)
    goal, turn, weight = foot_targets(chain, planted, enforced, partner, points, options.blend, clearance, options)
    axis, side = knee_axis_and_side(chain, locals_)
    base, rho, phi = hinge(chain, locals_, axis)
    longest = reach(base, rho, phi, options.knee_soft, options.knee_keep)
    return enforced, goal, turn, weight, longest, np.r_[axis, side]


def adjust_root(hips, goals, reaches, weights, options: CleanupOptions):
    """Phase 3: the root's offsets (frames, 3) for one or two legs (see mtcore.footskate.adjust_root)."""
    active = np.asarray(weights) > 0
    centres = np.asarray(goals) - np.asarray(hips)
    radii = np.asarray(reaches)
    frames = centres.shape[1]
    root = smooth_root(project_root(np.zeros((frames, 3)), centres, radii, active), options.root_window)
    for _ in range(options.root_passes):
        residual = project_root(root, centres, radii, active) - root
        if not residual.any():
            break
        root = root + smooth_root(residual, options.root_window)
    return project_root(root, centres, radii, active)


def solve_leg(chain, hips, parents, angles, points, planted, goal, turn, weight, knee, root, clearance, options):
    """Phases 4 and 5 for one leg: the new angles (frames, 4, 3) (see mtcore.footskate.solve_leg)."""
    planted = np.asarray(planted, bool)
    frames = len(hips)
    up = np.asarray(options.up)
    out = np.array(angles, dtype=float)
    locals_, foot, _ = leg_fk(chain, hips, parents, angles)
    foot_goal = mm(from_rotvec(turn), foot)
    axis, side = np.asarray(knee[:3]), float(knee[3])
    some = planted.any(-1)
    s = chain.segments
    aim = np.broadcast_to(s[2] - s[3], (frames, 3))  # heel -> ball: what a two-channel ankle keeps exact
    pivot = np.where(planted[:, HEEL][:, None], s[3], s[2])
    # a free foot that its targets put below the floor is lifted, smoothly: by the upper envelope
    # of the depths under a bump half the blend wide
    turned = from_rotvec(turn)
    low = np.minimum(
        height(goal + mv(turned, points[:, 3] - points[:, 1]), options) - clearance[0],
        height(goal + mv(turned, points[:, 2] - points[:, 1]), options) - clearance[1],
    )
    depth = np.where(some, 0.0, np.maximum(-low, 0.0))
    lift_by = np.where(some, 0.0, envelope(depth, options.blend // 2))
    goals = goal + lift_by[:, None] * up
    moved = np.abs(root).max(-1) > 0
    todo = some | (weight > 0) | moved | (lift_by > 0)
    f = np.flatnonzero(todo)
    foot_now, ball_now = foot.copy(), points[:, 2].copy()
    if len(f):
        h = hips[f] + root[f]
        loc = [m[f] for m in locals_]
        goal_f, turn_f, a = goals[f], foot_goal[f], angles[f]

        def solve(target):
            return two_bone(chain, h, parents[f], a, loc, axis, side, options.knee_soft, target, turn_f, aim[f])

        new, achieved, ankle_now = solve(goal_f)
        if channels(chain, 2) < 3:  # the ankle cannot roll: re-aim the ankle so that the pivot lands
            # once: the miss after it is a few micrometres
            goal_f = np.where(some[f][:, None], goal_f + mv(turn_f, pivot[f]) - mv(achieved, pivot[f]), goal_f)
            new, achieved, ankle_now = solve(goal_f)
        # what the legs could not quite reach is lifted frame by frame
        low = np.minimum(
            height(ankle_now + mv(achieved, s[3]), options) - clearance[0],
            height(ankle_now + mv(achieved, s[2]), options) - clearance[1],
        )
        sink = ~some[f] & (low < 0)
        if sink.any():
            goal_f = np.where(sink[:, None], goal_f - low[:, None] * up, goal_f)
            new, achieved, ankle_now = solve(goal_f)
        out[f] = finish_angles(chain, a, new, aim[f])
        foot_now[f], ball_now[f] = achieved, ankle_now + mv(achieved, s[2])
    out[:, 3] = bend_toes(chain, foot_now, ball_now, out[:, 3], locals_[3], clearance[2], options)
    return out


def cleanup(chains, hips, parents, angles, points, planted, targets, clearance, options: CleanupOptions, workers=None):
    """All phases (see mtcore.footskate.cleanup): (angles, root, enforced)."""
    chains = tuple(chains)
    plans = [
        plan_leg(c, angles[i], points[i], planted[i], targets[i], clearance[i], options) for i, c in enumerate(chains)
    ]
    root = adjust_root(hips, [p[1] for p in plans], [p[4] for p in plans], [p[3] for p in plans], options)
    out = np.stack(
        [
            solve_leg(
                c,
                hips[i],
                parents[i],
                angles[i],
                points[i],
                planted[i],
                p[1],
                p[2],
                p[3],
                p[5],
                root,
                clearance[i],
                options,
            )
            for i, (c, p) in enumerate(zip(chains, plans))
        ]
    )
    return out, root, np.stack([p[0] for p in plans])


def write_channels(values, angles, solved, columns, angle_scale, root, root_columns):
    """The cleanup's angles and root written back to the channels (see mtcore.footskate.write_channels)."""
    out = np.array(values, dtype=float)
    for i in range(len(solved)):
        used = np.asarray(columns[i]).reshape(12) >= 0
        new = np.asarray(solved[i]).reshape(len(out), 12)[:, used]
        old = np.asarray(angles[i]).reshape(len(out), 12)[:, used]
        cols = np.asarray(columns[i]).reshape(12)[used]
        out[:, cols] = np.where(new != old, new / angle_scale, out[:, cols])  # unchanged angles keep their bits
    cols = list(root_columns)
    out[:, cols] = np.where(root != 0, out[:, cols] + root, out[:, cols])  # -0.0 + 0.0 would be +0.0
    return out


def point_speeds(points, which, frame_rate, *, central=False):
    """Speeds of the points ``which`` of each frame (see mtcore.footskate.point_speeds), in numpy."""
    p = np.asarray(points, dtype=float)[:, :, list(which)].transpose(0, 2, 1, 3)  # (tracks, count, frames, 3)
    if p.shape[2] < 2:
        zeros = np.zeros(p.shape[:-1])
        return (zeros, zeros.copy()) if central else zeros
    d = np.diff(p, axis=2)
    step = np.sqrt(d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1] + d[..., 2] * d[..., 2]) * frame_rate
    speed = np.empty(p.shape[:-1])
    speed[..., 0], speed[..., -1] = step[..., 0], step[..., -1]
    np.maximum(step[..., 1:], step[..., :-1], out=speed[..., 1:-1])
    if not central:
        return speed
    g = np.gradient(p, axis=2)
    return speed, np.sqrt(g[..., 0] * g[..., 0] + g[..., 1] * g[..., 1] + g[..., 2] * g[..., 2]) * frame_rate


def runs(mask):
    """Starts and ends (exclusive) of the runs of True in a 1-d mask."""
    edges = np.diff(np.r_[0, np.asarray(mask, bool).astype(np.int8), 0])
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def plant_masks(heights, speed, central, th):
    """Footplant masks of rows of samples (see mtcore.footskate.plant_masks), a row at a time in
    whole-row numpy."""
    heights, speed, central = (np.asarray(a, float) for a in (heights, speed, central))
    sure = (heights < th.sure_height) & (central < th.sure_speed)
    close = (heights < th.height) & (speed < th.speed) | sure
    firm = (heights < th.firm_height) & (speed < th.firm_speed) | sure
    slow = speed < th.merge_speed
    out = np.zeros(heights.shape, bool)
    n = heights.shape[1]
    index = np.arange(n)
    for r in range(len(heights)):
        h, certain = heights[r], sure[r]
        starts, ends = runs(close[r])
        if not len(starts):
            continue
        firm_count = np.add.reduceat(firm[r].astype(np.int64), starts)
        starts, ends = starts[firm_count > 0], ends[firm_count > 0]
        if len(starts) > 1:  # merge short gaps that the point crosses slowly
            fast = np.r_[0, np.cumsum(~slow[r])]
            join = (starts[1:] - ends[:-1] <= th.gap) & (fast[starts[1:]] == fast[ends[:-1]])
            starts, ends = starts[np.r_[True, ~join]], ends[np.r_[~join, True]]
        if not len(starts):
            continue
        bounds = np.ravel(np.column_stack([starts, ends]))
        bounds = bounds[:-1] if bounds[-1] == n else bounds
        plant = np.searchsorted(starts, index, side="right") - 1
        inside = (plant >= 0) & (index < ends[np.maximum(plant, 0)])
        lowest = np.minimum.reduceat(h, bounds)[::2]
        still = inside & ((h <= lowest[np.maximum(plant, 0)] + th.rise) | certain)
        first = np.minimum.reduceat(np.where(still, index, n), bounds)[::2]
        last = np.maximum.reduceat(np.where(still, index, -1), bounds)[::2] + 1
        held = np.r_[0, np.cumsum(certain)]
        keep = (last > first) & ((last - first >= th.shortest) | (held[np.maximum(last, first)] > held[first]))
        edges = np.zeros(n + 1, np.int64)
        np.add.at(edges, first[keep], 1)
        np.add.at(edges, last[keep], -1)
        out[r] = np.cumsum(edges[:-1]) > 0
    return out


CONTACT = [3, 2, 4]  # heel, ball, tip among a leg's points


def resting_points(points, tips, up, frame_rate, meters_per_unit, rest_speed, needed):
    """Where the contact points rest, over all frames at once: the speeds and heights, then the
    slowest low frames of each point that rests too seldom (a stable sort: ties in frame order)."""
    points, up = np.asarray(points, float), np.asarray(up, float)
    speed = point_speeds(points, CONTACT, frame_rate).transpose(0, 2, 1) * meters_per_unit
    vertical = dot(points[:, :, CONTACT], up)
    resting = speed < rest_speed
    for i in range(points.shape[0]):
        for k in range(3):
            if resting[i, :, k].sum() < needed and np.isfinite(vertical[i, :, k]).any():
                low = vertical[i, :, k] <= np.nanpercentile(vertical[i, :, k], 20)
                slow = np.argsort(np.where(low, speed[i, :, k], np.inf), kind="stable")[:needed]
                resting[i, slow, k] = True
    resting[~np.asarray(tips, bool), :, 2] = False
    return resting & np.isfinite(vertical)


def fit_floor(points, resting, tips, up, band, prior, samples, max_tilt):
    """The floor's normal equations summed by numpy and solved by LAPACK, three times."""
    points, up, tips = np.asarray(points, float), np.asarray(up, float), np.asarray(tips, bool)
    legs, frames = points.shape[:2]
    horizontal = [a for a in range(3) if up[a] == 0]
    where = np.flatnonzero(resting)
    where = where[:: -(-len(where) // samples)] if len(where) > samples else where
    ids, point = np.unique((where // 3 // frames) * 3 + where % 3, return_inverse=True)
    flat = points.reshape(-1, 5, 3)[where // 3, np.take(CONTACT, where % 3)]
    centre = flat[:, horizontal].mean(axis=0)
    x, y = flat[:, horizontal[0]] - centre[0], flat[:, horizontal[1]] - centre[1]
    z = flat @ up
    ridge = np.sqrt(len(z)) * prior
    keep, n = np.ones(len(z), bool), len(ids)
    for _ in range(3):
        w = keep.astype(float)
        a = np.zeros((2 + n, 2 + n))
        a[0, 0], a[1, 1] = (w * x * x).sum() + ridge**2, (w * y * y).sum() + ridge**2
        a[0, 1] = a[1, 0] = (w * x * y).sum()
        a[0, 2:] = a[2:, 0] = np.bincount(point, w * x, n)
        a[1, 2:] = a[2:, 1] = np.bincount(point, w * y, n)
        a[2:, 2:] = np.diag(np.bincount(point, w, n))
        b = np.concatenate(([(w * x * z).sum(), (w * y * z).sum()], np.bincount(point, w * z, n)))
        coef = np.linalg.solve(a, b)
        keep = z - (coef[0] * x + coef[1] * y + coef[2:][point]) < band
    gradient = coef[:2] * min(1.0, max_tilt / max(np.linalg.norm(coef[:2]), 1e-300))
    slope = np.zeros(3)
    slope[horizontal] = gradient
    rests = np.full(legs * 3, np.nan)
    rests[ids] = coef[2:]
    base = np.nanmin(rests)
    clearance = np.nan_to_num(rests.reshape(legs, 3) - base)
    clearance[~tips, 2] = clearance[~tips, 1]
    return base - gradient @ centre, slope, clearance


def ground_cases(rng: np.random.Generator) -> list[tuple]:
    """Legs that stand, walk and run on their balls (a point that never rests), on floors y-up and
    z-down, tilted, NaN frames, with and without toe tips; many samples, thinned."""
    out = []
    for legs, frames, up in ((1, 1, (0, 1, 0)), (2, 3, (0, 0, -1)), (2, 60, (0, 1, 0)), (1, 400, (1, 0, 0))):
        up = np.array(up, float)
        t = np.arange(frames)
        stance = (np.sin(t / 5.0) > 0)[:, None]
        ahead = np.cumsum(~stance, axis=0) * 0.05  # where the walk has got to
        points = rng.normal(0, 0.001, (legs, frames, 5, 3)) + ahead[:, :, None] * np.roll(up, 1)
        points += (np.where(stance, 0.0, 0.1) + 0.02 * rng.random((legs, 1, 1)))[..., None] * up
        points += 0.03 * up * (points @ np.roll(up, 1))[..., None]  # a tilted floor
        if frames > 50:
            points[0, :, 2] += 5.0 * t[:, None] * np.roll(up, 2)  # a ball that never rests
            points[-1, 10:13] = np.nan
        tips = rng.random(legs) < 0.5
        for rate, needed in ((120.0, 6), (30.0, 3)):
            out.append((points, tips, up, rate, 0.9, 0.1, needed))
    return out


def fit_cases(rng: np.random.Generator) -> list[tuple]:
    return [
        (p, resting_points(p, tips, up, rate, mpu, speed, needed), tips, up, band, prior, samples, tilt)
        for p, tips, up, rate, mpu, speed, needed in ground_cases(rng)
        for band, prior, samples, tilt in ((0.015, 0.15, 50_000, 0.09), (0.002, 0.5, 7, 0.01))
    ]
