"""The take check's channel pass (mt_check_channels), from its contract, one channel at a time."""

from __future__ import annotations

import math

import numpy as np

from mtcore.check import FROZEN, GAP, REPEAT, SPIKE, STEP

from . import rotations


def _runs(flags: list[bool]) -> list[tuple[int, int]]:
    """(first, last) of each run of True."""
    out, start = [], None
    for t, f in enumerate([*flags, False]):
        if f and start is None:
            start = t
        elif not f and start is not None:
            out.append((start, t - 1))
            start = None
    return out


def _peak(scores: list[float], first: int, last: int) -> tuple[float, int]:
    """The score of largest magnitude in first..last (the first such) and its row."""
    at = max(range(first, last + 1), key=lambda t: (abs(scores[t]), -t))
    return scores[at], at


def _mirror(i: int, n: int) -> int:
    if i < 0:
        i = -i
    if i > n - 1:
        i = 2 * (n - 1) - i
    return min(max(i, 0), n - 1)


def check_channels_twin(values, spike_limit, step_limit, min_run, begin=0, end=None):
    x = np.asarray(values, dtype=float)
    rows, channels = x.shape
    end = rows if end is None else end
    spike_limit = np.broadcast_to(np.asarray(spike_limit, float), (channels,))
    step_limit = np.broadcast_to(np.asarray(step_limit, float), (channels,))
    checked = range(begin, end)
    events: list[tuple[int, int, int, int, int, float]] = []
    roughness, smooth = np.zeros(channels), np.zeros(channels, dtype=np.intp)
    for k in range(channels):
        v = x[:, k]
        nan = [math.isnan(v[t]) if t in checked else False for t in range(rows)]
        for first, last in _runs(nan):
            events.append((k, first, last, GAP, first, 0.0))
        # frozen: rows equal to the row before, each run joined to the row it repeats
        same = [t in checked and t > 0 and v[t] == v[t - 1] for t in range(rows)]
        for first, last in _runs(same):
            first -= 1
            if last - first + 1 >= min_run or first < begin or last + 1 >= end:
                events.append((k, first, last, FROZEN, first, float(v[first])))
        deviation = [0.0] * rows
        jump = [0.0] * rows
        for t in checked:
            if math.isnan(v[t]):
                continue
            before = v[t - 1] if t > 0 else v[t]
            after = v[t + 1] if t + 1 < rows else v[t]
            r = v[t] - 0.5 * (before + after)
            if 0 < t < rows - 1 and abs(r) <= spike_limit[k]:
                roughness[k] += r * r
                smooth[k] += 1
            if rows >= 3:
                window = [v[_mirror(t + d, rows)] for d in (-2, -1, 0, 1, 2)]
                if not any(math.isnan(w) for w in window):
                    d = v[t] - float(np.median(window))
                    if abs(d) > spike_limit[k]:
                        deviation[t] = d
            if t > 0:
                change = v[t] - v[t - 1]
                beside = []
                if t > 1:
                    beside.append(v[t - 1] - v[t - 2])
                if t + 1 < rows:
                    beside.append(v[t + 1] - v[t])
                if beside and all(abs(change - b) > step_limit[k] for b in beside):
                    j = change - sum(beside) / len(beside)
                    if abs(j) > step_limit[k]:
                        jump[t] = j
        for kind, scores in ((SPIKE, deviation), (STEP, jump)):
            for first, last in _runs([s != 0.0 for s in scores]):
                size, at = _peak(scores, first, last)
                events.append((k, first, last, kind, at, size))
    repeats = [t in checked and t > 0 and bool(np.all(x[t] == x[t - 1])) and channels > 0 for t in range(rows)]
    for first, last in _runs(repeats):
        events.append((channels, first, last, REPEAT, first, 0.0))
    events.sort(key=lambda e: (e[0], e[1], e[3]))
    table = np.array([e[:5] for e in events], dtype=np.intp).reshape(-1, 5)
    sizes = np.array([e[5] for e in events], dtype=float)
    return table, sizes, roughness, smooth


def pace_twin(values, weight):
    """Each step's changes from the rows around it, one row at a time, the channels with a
    missing or infinite change left out."""
    x = np.asarray(values, float)
    rows, channels = x.shape
    w = np.broadcast_to(weight, channels)
    moved, paced, stepped = np.zeros(rows), np.zeros(rows), np.zeros(rows)

    for t in range(1, rows - 2):
        for k in range(channels):
            mean = ((x[t, k] - x[t - 1, k]) + (x[t + 2, k] - x[t + 1, k])) / 2
            step = x[t + 1, k] - x[t, k]
            if math.isfinite(mean) and math.isfinite(step):
                moved[t] += w[k] * mean * mean
                paced[t] += w[k] * step * mean
                stepped[t] += w[k] * step * step
    return moved, paced, stepped


def pace_cases(rng: np.random.Generator) -> list[tuple]:
    out = []
    for rows, channels in ((0, 2), (1, 1), (3, 2), (4, 3), (5, 1), (60, 6)):
        x = rng.normal(size=(rows, channels)).cumsum(axis=0) * 40
        if rows > 10:
            x[7, 1] = math.nan
            x[20, 2] = math.inf
            x[30:, 0] += 400.0  # a jump
        weight = rng.uniform(0, 2, channels)
        out.append((x, weight))
    return out + [(np.zeros((6, 0)), 1.0)]


def check_legs_twin(points, hips, rest, tips, settings):
    """The legs' measures frame by frame from the contract: every window's lowest searched, every
    run of frames on the floor walked from its start."""
    p, hips = np.asarray(points, float), np.asarray(hips, float)
    legs, frames = p.shape[:2]
    up, slope = np.asarray(settings.up, float), np.asarray(settings.slope, float)
    mpu, w = settings.meters_per_unit, settings.window
    drift = np.full((legs, 2, frames), math.nan)
    depth, back = np.full((legs, frames), math.nan), np.zeros((legs, frames))
    standing = np.zeros(6, np.uintp)
    for i in range(legs):
        for t in range(frames):
            knee, ankle, ball, heel, tip = p[i, t]
            rise = hips[i, t] - ankle
            if np.isfinite(rise).all():
                axis = int(np.argmax(np.abs(rise)))
                standing[2 * axis + int(rise[axis] < 0)] += 1
            thigh, shin, foot = knee - hips[i, t], ankle - knee, ball - ankle
            with np.errstate(all="ignore"):
                bend = math.degrees(
                    math.acos(np.clip(thigh @ shin / (np.linalg.norm(thigh) * np.linalg.norm(shin)), -1, 1))
                )
                across = abs(shin @ foot / (np.linalg.norm(shin) * np.linalg.norm(foot)))
                turn = np.cross(thigh, shin) @ np.cross(shin, foot)
            if turn > 0 and across < settings.foot_across and bend < settings.folded:
                back[i, t] = bend
            points_resting = (heel, ball, tip)[: 3 if tips[i] else 2]
            heights = [(q @ (up - slope) - settings.level) - rest[i][k] for k, q in enumerate(points_resting)]
            finite = [h for h in heights if not math.isnan(h)]
            if finite:
                depth[i, t] = -min(finite)
        for k, index in enumerate((3, 2)):  # heel, ball
            q = p[i, :, index]
            h = q @ up
            flat = q - h[:, None] * up
            steps = [np.linalg.norm(flat[t + 1] - flat[t]) * settings.frame_rate for t in range(frames - 1)]
            start = None
            for t in range(frames):
                around = [x for x in h[max(0, t - w) : t + w + 1] if not math.isnan(x)]
                lift = h[t] - min(around) if around else math.nan
                beside = [steps[s] for s in (t - 1, t) if 0 <= s < frames - 1]
                speed = 0.0 if frames == 1 else (math.nan if any(map(math.isnan, beside)) else max(beside))
                if lift * mpu < settings.floor_height and speed * mpu < settings.floor_speed:
                    start = t if start is None else start
                    drift[i, k, t] = np.linalg.norm(flat[t] - flat[start])
                else:
                    start = None
    return drift, depth, back, standing


def check_legs_cases(rng: np.random.Generator) -> list[tuple]:
    """Legs that stand, slide and step (feet resting on the floor for stretches, then lifted),
    knees bent both ways, NaN frames; y-up and z-down floors, sloped; windows from none to
    beyond the take."""
    from mtcore.check import LegCheck

    out = []
    for legs, frames, window, up in ((0, 5, 2, (0, 1, 0)), (1, 0, 2, (0, 1, 0)), (1, 1, 3, (0, 1, 0)),
                                     (2, 2, 0, (0, 0, -1)), (2, 9, 1, (0, 1, 0)), (2, 80, 6, (0, 0, -1)),
                                     (1, 40, 100, (1, 0, 0))):  # fmt: skip
        up = np.array(up, float)
        slope = np.zeros(3)
        slope[np.flatnonzero(up == 0)[0]] = 0.02
        lifted = np.where(np.sin(np.arange(frames) / 6.0) > 0.3, 0.15, 0.0)  # steps
        slide = np.cumsum(rng.normal(0, 0.01, frames)) * (np.arange(frames) % 30 < 15)
        points = rng.normal(0, 0.3, (legs, frames, 5, 3))
        for i in range(legs):
            for k in (2, 3):  # ball and heel: on the floor, sliding, lifted
                points[i, :, k] = rng.normal(0, 0.002, (frames, 3)) + slide[:, None] * np.roll(up, 1)
                points[i, :, k] += (lifted * (i + 1) + 0.01 * k)[:, None] * up
        hips = points[:, :, 0] + rng.normal(0, 0.4, (legs, frames, 3))
        if frames > 10:
            points[0, 4, 3] = math.nan
            points[-1, 7:9] = math.nan
            hips[0, 2, 1] = math.inf
            hips[0, 3] = points[0, 3, 1] + (0.5, -0.5, 0.2)  # standing along x and -y alike: x counts
        tips = rng.random(legs) < 0.5
        settings = LegCheck(tuple(up), tuple(slope), float(rng.normal(0, 0.01)), 0.9, 120.0, window, 0.03, 0.6,
                            math.cos(math.radians(45)), 90.0)  # fmt: skip
        out.append((points, hips, rng.uniform(0, 0.05, (legs, 3)), tips, settings))
    return out


def trim_twin(q, first, last, limits):
    """Each run trimmed as the contract says: both ends measured against the SLERP (the twin's)
    between the frames around what is left, the first dropped before the last, every frame
    measured once neither is."""
    q = np.asarray(q, float)
    frames = len(q)

    def off(a: int, b: int, r: int) -> float:
        path = rotations.slerp(q[a - 1], q[b + 1], (r - a + 1) / (b - a + 2))
        return math.degrees(2 * math.acos(min(abs(float(q[r] @ path)), 1.0)))

    out = np.array(first, np.uintp), np.array(last, np.uintp), np.full(len(first), math.nan)
    for i, (a, b) in enumerate(zip(map(int, first), map(int, last))):
        if a < 1 or b > frames - 2 or np.isnan(q[a - 1 : b + 2]).any():
            continue
        while a < b and (off(a, b, a) <= limits[i] or off(a, b, b) <= limits[i]):
            if off(a, b, a) <= limits[i]:
                a += 1
            else:
                b -= 1
        out[0][i], out[1][i], out[2][i] = a, b, max(off(a, b, r) for r in range(a, b + 1))
    return out


def trim_cases(rng: np.random.Generator) -> list[tuple]:
    """A joint turning smoothly with excursions of one to five frames (some whose ends lie on
    the path), runs at the take's ends, over stretches of it and of one frame, a NaN frame."""
    from mtcore.rotations import euler_to_quaternions

    out = []
    for frames in (0, 1, 2, 3, 9, 60, 200):
        angles = np.cumsum(rng.normal(0, 2, (frames, 3)), axis=0)
        first, last = list(rng.integers(0, max(frames, 1), 6 if frames else 0)), []
        last = [min(a + int(rng.integers(0, 6)), frames - 1) for a in first]
        for start in range(2, frames - 12, 9):
            size = int(rng.integers(1, 6))
            angles[start : start + size] += rng.normal(0, 40, 3)
            first.append(max(start - int(rng.integers(0, 3)), 0))  # with frames on the path at its ends
            last.append(min(start + size - 1 + int(rng.integers(0, 3)), frames - 1))
        q = euler_to_quaternions(angles, "zxy", extrinsic=False, degrees=True)
        if frames == 60:
            q[40] = math.nan
        out.append((q, np.array(first, int), np.array(last, int), rng.uniform(0.5, 20, len(first))))
    return out


def seen_twin(places, world, joint, origin, axis, points, quaternions, first, last, meters, keys=None, row=None):
    """Each run's rows one at a time: the points' distance from midway between the rows around,
    and from where the SLERP (the twin's) between the rows ``keys`` (those around the run)
    would put them; the joint's world rotation at ``row`` of world (default its own index)."""
    places, world, q = np.asarray(places, float), np.asarray(world, float), np.asarray(quaternions, float)
    points = np.asarray(points, int)
    off, filled = np.zeros(len(first)), np.zeros(len(first))

    def farthest(vectors) -> float:
        found = [float(np.linalg.norm(v)) for v in vectors]
        return max([x for x in found if not math.isnan(x)], default=0.0)

    before, after = (np.asarray(first) - 1, np.asarray(last) + 1) if keys is None else keys
    for i, (a, b) in enumerate(zip(map(int, first), map(int, last))):
        k0, k1 = int(before[i]), int(after[i])
        for r in range(a, b + 1):
            p = places * meters
            off[i] = max(off[i], farthest(p[r, points] - 0.5 * (p[r - 1, points] + p[r + 1, points])))
            path = rotations.slerp(q[k0], q[k1], (r - k0) / (k1 - k0))
            frame = world[r, joint if row is None else row] @ np.asarray(axis, float)
            error = rotations.quaternions_to_matrices(q[r]).T @ rotations.quaternions_to_matrices(path)
            local = [frame.T @ (places[r, k] - places[r, origin]) for k in points]
            filled[i] = max(filled[i], farthest([error @ x - x for x in local]) * meters)
        off[i] *= 2 if b > a else 1
    return off, filled


def seen_cases(rng: np.random.Generator) -> list[tuple]:
    """A chain of joints turning at random, runs of one to four rows over it, points below the
    joint and none, a NaN place and a NaN rotation."""
    from mtcore.rotations import euler_to_matrices, euler_to_quaternions

    out = []
    for frames, joints, count in ((3, 3, 1), (12, 6, 3), (40, 8, 0), (40, 8, 5)):
        places = rng.normal(0, 10, (frames, joints, 3))
        world = euler_to_matrices(rng.uniform(-180, 180, (frames, joints, 3)), "zyx", extrinsic=True, degrees=True)
        axis = euler_to_matrices(rng.uniform(-90, 90, 3), "xyz", extrinsic=True, degrees=True)
        q = euler_to_quaternions(np.cumsum(rng.normal(0, 5, (frames, 3)), axis=0), "zxy", extrinsic=False, degrees=True)
        first = rng.integers(1, frames - 1, 6)
        last = np.minimum(first + rng.integers(0, 4, 6), frames - 2)
        if frames == 40 and count:
            places[20, 2] = math.nan
            q[30] = math.nan
        points = rng.choice(np.arange(1, joints), count, replace=False)
        out.append((places, world, 1, 0, axis, points, q, first, last, 0.05))
        at = np.arange(2, frames - 1)  # jumps: the rotation going on from the two rows before
        out.append((places, world, 1, 0, axis, points, q, at, at, 0.05, (at - 2, at - 1)))
        # the world rotations of a few joints only, the joint's in the second row
        out.append((places, world[:, [0, 1]], 1, 0, axis, points, q, first, last, 0.05, None, 1))
    return out


def roughness_twin(values, squares, counts):
    """Each inner row's residual from the mean of its neighbours, one at a time; the finite ones summed."""
    x = np.asarray(values, float)
    squares, counts = squares.copy(), counts.copy()
    for t in range(1, len(x) - 1):
        for k in range(x.shape[1]):
            r = (x[t - 1, k] + x[t + 1, k]) * -0.5 + x[t, k]
            if math.isfinite(r):
                squares[k] += r * r
                counts[k] += 1
    return squares, counts


def roughness_cases(rng: np.random.Generator) -> list[tuple]:
    """Takes of 0 to 60 rows with gaps and infinities, added to sums already held."""
    out = []
    for rows, channels in ((0, 2), (1, 3), (2, 1), (3, 2), (60, 5)):
        x = rng.normal(size=(rows, channels)).cumsum(axis=0)
        if rows > 10:
            x[7, 1], x[20, 2], x[30:33, 4] = math.nan, math.inf, math.nan
        out.append((x, rng.uniform(0, 5, channels), rng.integers(0, 9, channels).astype(np.uintp)))
    return out


def elbow_bends_twin(positions, world, turning, placing, bent_deg, least, hinge):
    """Each arm's upper arm and forearm at each frame, their cross product turned into the upper
    arm's axes by numpy, one frame at a time; the axis by numpy's eigh, of the unit turns of the
    frames bent past bent_deg."""
    p, w = np.asarray(positions, float), np.asarray(world, float)
    arms, frames = len(turning), len(p)
    bend, judged = np.full((arms, frames), math.nan), np.zeros(arms, bool)
    for a, (upper, (shoulder, elbow, hand)) in enumerate(zip(turning, placing)):
        turn, straight = np.zeros((frames, 3)), np.zeros(frames)
        for t in range(frames):
            arm, forearm = p[t, elbow] - p[t, shoulder], p[t, hand] - p[t, elbow]
            turn[t] = w[t, upper].T @ np.cross(arm, forearm)
            straight[t] = arm @ forearm
        length = np.sqrt((turn**2).sum(axis=1))
        with np.errstate(invalid="ignore"):
            bent = (straight < length / math.tan(math.radians(bent_deg))) & (length > 0)
        if bent.sum() < max(2, least):
            continue
        units = turn[bent] / length[bent, None]
        shares, axes = np.linalg.eigh(units.T @ units / len(units))
        if not shares[-1] > hinge:
            continue
        axis = axes[:, -1] if np.sum(units @ axes[:, -1] > 0) * 2 >= len(units) else -axes[:, -1]
        bend[a], judged[a] = np.degrees(np.arctan2(turn @ axis, straight)), True
    return bend, judged


def elbow_cases(rng: np.random.Generator) -> list[tuple]:
    """No arm to two, 0 to 61 frames, world rotations of every joint or of a few, a NaN place;
    arms that bend about one axis in the upper arm's (a few frames backwards, a little off the
    axis), which bend every way, or too seldom for the least count."""
    out = []
    for arms, frames, joints, turned in ((0, 5, 3, 2), (1, 0, 4, 4), (1, 1, 3, 1), (2, 7, 6, 3), (2, 40, 9, 9)):
        positions = rng.normal(size=(frames, joints, 3))
        if frames > 5:
            positions[3, 1] = math.nan
        world = rotations.matrices(rng.uniform(-3, 3, (frames, turned, 3)), "zyx")
        turning = rng.integers(0, turned, arms)
        placing = np.array([rng.permutation(joints)[:3] for _ in range(arms)], np.intp).reshape(arms, 3)
        out.append((positions, world, turning, placing, 30.0, 3.0, 0.8))
    for frames, back, off, least in ((12, 3, 0.05, 3.0), (61, 7, 0.05, 30.0), (61, 7, 0.05, 100.0), (25, 4, 2.0, 3.0)):
        world = rotations.matrices(rng.uniform(-3, 3, (frames, 2, 3)), "zyx")
        positions = np.zeros((frames, 6, 3))
        for a in range(2):
            bends = np.radians(rng.uniform(40, 150, frames))
            bends[rng.choice(frames, back, replace=False)] *= -0.3  # bent backwards
            elbow = np.array([1.0, 0.0, 0.0]) + rng.normal(0, 0.01, (frames, 3))
            forearm = np.stack([np.cos(bends), np.sin(bends), rng.normal(0, off, frames)], axis=1)
            local = np.stack([np.zeros((frames, 3)), elbow, elbow + forearm], axis=1)
            positions[:, 3 * a : 3 * a + 3] = np.einsum("fij,fkj->fki", world[:, a], local)
        positions[frames // 2, 4] = math.nan
        out.append((positions, world, np.array([0, 1]), np.array([[0, 1, 2], [3, 4, 5]]), 30.0, least, 0.8))
    return out
