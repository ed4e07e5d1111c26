"""The take check on real takes of every producer and rig: artifacts put in at random frames and
joints are found (precision and recall of at least 0.95 per kind), the recipes it writes remove
them and touch no other frame, and what it says of the clean takes holds together."""

import collections
import math

import numpy as np
import pytest

import motiontheater as mt
from artifacts import KINDS, hits, inject
from corpus import real_files
from motiontheater.databases import pieces
from motiontheater.databases.check import _Take, check_motion, recipe
from motiontheater.databases.check_feet import STRIDE_SPEED_RANGE, STRIDE_SPEED_SHARE
from motiontheater.databases.check_pace import DROP_EVIDENCE, step_pace
from motiontheater.databases.findings import KINDS as FINDING_KINDS
from motiontheater.databases.findings import SEVERITIES
from motiontheater.feet.footskate import prepare
from mtcore import check as kernel
from variants import with_offset_channels, with_static_root

TAKES = real_files("*/*.amc") + real_files("*/*.bvh")
BVHS = [p for p in TAKES if p.suffix == ".bvh"]
VARIANTS = {
    "as found": lambda take: take,
    "game rig": lambda take: with_static_root(with_offset_channels(take), shift=(250.0, 0.0, -400.0)),
    "z-up": lambda take: with_static_root(take, turn=(90.0, 0.0, 0.0), keep_world=False),
    "in mm": lambda take: take.with_units(length_factor=1000 * take.skeleton.meters_per_unit, length="mm"),
}
TRIALS = 3  # injections of each kind per take and variant
UNITS = {"deg", "m", "m/s", "s", "Hz", "%", ""}


def _variant(path, name, tmp_path, take=None):
    """The take at ``path`` (or ``take``, read from it) as the variant's producer would write it:
    through a BVH file, read back."""
    take = mt.read_take(path) if take is None else take
    if name == "as found":
        return take
    target = tmp_path / f"{path.stem}.bvh"
    mt.write_bvh(VARIANTS[name](take), target)
    return mt.read_take(target)


def _before(finding, base) -> bool:
    """Whether the clean take already had this finding (same kind and joints, frames overlapping)."""
    return any(
        b.kind == finding.kind and b.joints == finding.joints and b.first <= finding.last and finding.first <= b.last
        for b in base
    )


def _touched(motion, steps) -> np.ndarray:
    """The cells (frames, channels) that a recipe's steps may change."""
    mask = np.zeros(motion.values.shape, bool)
    skeleton = motion.skeleton
    for name, options in steps:
        if name == "scale":
            mask[:] = True
            continue
        columns = skeleton.columns_of(options.get("joints"))
        first, last = options.get("frames") or (motion.first_frame, motion.last_frame)
        mask[first - motion.first_frame : last - motion.first_frame + 1, columns] = True
    return mask


@pytest.fixture(scope="module", params=list(VARIANTS))
def injected(request, tmp_path_factory):
    """Per kind: found, missed, false findings, fixed, and frames changed outside the fixes."""
    if not TAKES:
        pytest.skip("the real-file corpus (../shared/data) is absent")
    name = request.param
    tally = collections.defaultdict(collections.Counter)
    rng = np.random.default_rng(26)
    folder = tmp_path_factory.mktemp("variants")
    for path in TAKES if name == "as found" else BVHS:
        take = _variant(path, name, folder)
        base = check_motion(take, str(path))
        for kind in KINDS:
            for _ in range(TRIALS):
                made = inject(take, kind, rng)
                if made is None:
                    continue
                motion, truth = made
                found = check_motion(motion, str(path))
                hit = any(hits(f, truth) for f in found)
                tally[kind]["found" if hit else "missed"] += 1
                for f in found:
                    if not hits(f, truth) and not _before(f, base) and f.kind in KINDS:
                        tally[f.kind]["false"] += 1
                chosen = [f for f in found if f.severity in ("medium", "high")]
                steps = [s for f in chosen for s in f.fix]
                fixed = recipe(found).apply(motion)
                # an artifact that joins a finding the take had (a hold beside a hold) is not the
                # injection's alone to fix
                if hit and not any(hits(f, truth) and _before(f, base) for f in found):
                    kept = any(hits(f, truth) for f in check_motion(fixed, str(path)))
                    tally[kind]["kept" if kept else "fixed"] += 1
                outside = ~_touched(motion, steps)
                same = np.array_equal(fixed.values[outside], motion.values[outside], equal_nan=True)
                tally[kind]["untouched" if same else "touched"] += 1
    return name, tally


@pytest.mark.parametrize("kind", KINDS)
def test_injected_artifacts_are_found_with_precision_and_recall_of_095(injected, kind):
    variant, tally = injected
    counts = tally[kind]
    found, missed, false = counts["found"], counts["missed"], counts["false"]
    assert found + missed > 0, f"{variant}: no take had a place for a {kind}"
    recall = found / (found + missed)
    precision = found / (found + false) if found + false else 1.0
    assert recall >= 0.95 and precision >= 0.95, (variant, kind, dict(counts))


@pytest.mark.parametrize("kind", KINDS)
def test_recipes_remove_the_injected_findings_and_change_no_frame_outside_them(injected, kind):
    variant, tally = injected
    counts = tally[kind]
    assert counts["fixed"] >= 0.95 * (counts["fixed"] + counts["kept"]), (variant, kind, dict(counts))
    assert counts["touched"] == 0, (variant, kind, dict(counts))


@pytest.mark.parametrize("variant", ["as found", "z-up", "in mm"])
def test_frames_taken_out_of_real_takes_are_found_where_the_body_moves(variant, tmp_path):
    """One or two frames taken out at random rows of every real take: where the body moves over
    the missing time more than its noise could (three times the evidence the check asks for), the
    check finds them at that step (recall >= 0.95 at 60 Hz and above; >= 0.8 below,
    where a step holds enough change of acceleration that the steps beside it foretell it less
    well), mostly how many; the frames it finds missing elsewhere the take had missing before
    (precision >= 0.95)."""
    if not TAKES:
        pytest.skip("the real-file corpus (../shared/data) is absent")
    rng = np.random.default_rng(27)
    tally = collections.defaultdict(collections.Counter)
    for path in TAKES if variant == "as found" else BVHS:
        take = _variant(path, variant, tmp_path)
        if take.frames < 40:
            continue
        before = {(f.first, f.last) for f in check_motion(take, str(path)) if f.kind == "dropped"}
        counts = tally["fast" if take.frame_rate >= 60 else "slow"]
        for _ in range(6):
            missing, row = int(rng.integers(1, 3)), int(rng.integers(10, take.frames - 12))
            cut = take.replace(values=np.delete(take.values, range(row, row + missing), axis=0))
            counts["made"] += 1
            if step_pace(cut).moved[row - 1] < 3 * DROP_EVIDENCE:
                continue  # a still body hides a missing frame (and loses nothing by it)
            counts["visible"] += 1
            at = take.first_frame + row - 1  # the step from the frame before the cut to the one after
            found = [f for f in check_motion(cut, str(path)) if f.kind == "dropped"]
            hit = [f for f in found if (f.first, f.last) == (at, at + 1)]
            counts["found" if hit else "missed"] += 1
            counts["counted"] += any(round(f.size * take.frame_rate) == missing for f in hit)
            # a missing frame the take had, a frame either way (its evidence near the threshold)
            shifted = {a - missing * (a > at) + shift for a, _ in before for shift in (-1, 0, 1)}
            counts["false"] += sum(f not in hit and f.first not in shifted for f in found)
    made = sum(c["made"] for c in tally.values())
    assert sum(c["visible"] for c in tally.values()) >= 0.6 * made, tally  # most steps of a take move
    for rates, least in (("fast", 0.95), ("slow", 0.8)):
        counts = tally[rates]
        assert counts["found"] >= least * counts["visible"], (rates, tally)
        assert counts["counted"] >= 0.8 * counts["found"], (rates, tally)  # how many: the pace of two frames missing
        assert counts["false"] <= 0.05 * (counts["found"] + counts["false"]), (rates, tally)


def test_frames_missing_from_smooth_motion_are_found_in_a_take_of_any_length(monkeypatch):
    """A smooth synthetic take has no frame missing; with frames taken out, the check tells each
    cut and no other, also where the take is checked a piece of frames at a time."""
    take = _smooth_take(120.0)
    assert [f for f in check_motion(take) if f.kind == "dropped"] == []
    rows = [40, 90, 91, 150]  # 91: two frames missing at once
    cut = take.replace(values=np.delete(take.values, rows, axis=0))
    want = [(take.first_frame + 39, 1), (take.first_frame + 88, 2), (take.first_frame + 146, 1)]
    for block in (pieces.PIECE_FRAMES, 64, 7):
        monkeypatch.setattr(pieces, "PIECE_FRAMES", block)
        found = [f for f in check_motion(cut) if f.kind == "dropped"]
        assert [(f.first, round(f.size * take.frame_rate)) for f in found] == want, block
        assert all(f.unit == "s" and f.fix == () and f.severity == "low" for f in found)


@pytest.mark.parametrize("path", TAKES, ids=[p.name for p in TAKES])
def test_every_finding_on_a_real_take_names_its_frames_joints_and_units(path):
    take = mt.read_take(path)
    findings = check_motion(take, str(path))
    joints = set(take.skeleton.joint_names)
    for f in findings:
        assert f.take == str(path)
        assert f.kind in FINDING_KINDS and f.severity in SEVERITIES
        assert set(f.joints) <= joints, f
        assert take.first_frame <= f.first <= f.last <= take.last_frame, f
        assert f.unit in UNITS and math.isfinite(f.size), f
        if f.channel is not None:
            joint, dof = f.channel.rsplit(" ", 1)
            assert dof in take.skeleton.dofs(joint), f
        for name, options in f.fix:
            mt.Pipeline.of(name, **options)  # each fix is a step with options it takes
    assert recipe(findings).apply(take).frames == take.frames
    rotations = [(f.kind, f.joints, f.first) for f in findings if f.unit == "deg" and f.kind in ("jump", "spike")]
    assert len(rotations) == len(set(rotations))  # one finding of a joint's rotation, however many channels show it


def test_a_clean_synthetic_take_has_no_finding_above_low():
    """Smooth motion at 120 Hz and 30 Hz: nothing a person would call a problem."""
    for rate in (120.0, 30.0):
        take = _smooth_take(rate)
        assert [f for f in check_motion(take) if f.severity != "low"] == []


def _smooth_take(rate: float) -> mt.Motion:
    cmu = real_files("cmu/01_01.amc")
    if not cmu:
        pytest.skip("the real-file corpus (../shared/data) is absent")
    skeleton = mt.read_take(cmu[0]).skeleton
    t = np.arange(int(4 * rate))[:, None] / rate
    channels = len(skeleton.channels)
    phase = np.linspace(0, 2 * np.pi, channels)[None, :]
    values = 20 * np.sin(2 * np.pi * 0.8 * t + phase)
    values[:, :3] = np.hstack([t * 10, np.full_like(t, 17.0), t * 5])  # a walk at 1 m/s in inch/0.45
    return mt.Motion(skeleton, values, frame_rate=rate)


def _walk_path():
    cmu = real_files("cmu/02_01.amc")
    if not cmu:
        pytest.skip("the real-file corpus (../shared/data) is absent")
    return cmu[0]


def _walk():
    return mt.read_take(_walk_path())


def _legs_found(take, kind):
    return [f for f in check_motion(take) if f.kind == kind]


def test_a_knee_bent_backwards_is_found_where_it_is():
    take = _walk()
    assert _legs_found(take, "knee") == []
    values = take.values.copy()
    (column,) = take.columns("ltibia", ("rx",))
    bend = np.sign(np.median(values[:, column]))  # the way this knee bends
    values[100:110, column] = -bend * 40.0
    (finding,) = _legs_found(take.replace(values=values), "knee")
    assert finding.joints == ("ltibia",) and (finding.first, finding.last) == (101, 110)
    assert 35 < finding.size < 45 and finding.unit == "deg"


def test_feet_in_the_floor_and_a_floor_away_from_zero_are_found_in_metres():
    take = _walk()
    assert _legs_found(take, "penetration") == [] and _legs_found(take, "floor") == []
    (ty,) = take.columns("root", ("ty",))
    metre = 1 / take.skeleton.meters_per_unit
    values = take.values.copy()
    values[200:218, ty] -= 0.15 * metre
    found = _legs_found(take.replace(values=values), "penetration")
    assert found and all(195 <= f.first and f.last <= 225 for f in found), found
    arrays, ground, mpu = prepare(take)
    lowest = np.min(ground.heights(arrays.points)[:, 200:218], axis=(0, 2)) * mpu  # the clean feet there
    assert max(f.size for f in found) == pytest.approx(0.15 - lowest.min(), abs=0.01)
    values = take.values.copy()
    values[:, ty] += 0.5 * metre
    (floor,) = _legs_found(take.replace(values=values), "floor")
    assert floor.severity == "low" and floor.size == pytest.approx(0.5, abs=0.06) and floor.unit == "m"


def test_a_fast_smooth_turn_is_no_high_spike_and_a_pop_as_far_is():
    """LAFAN1's hands at 30 Hz turn 1,800 deg/s through excursions of 100 deg that a person sees
    as a fast wrist: medium at most; a forearm popping 150 deg for two frames (4,500 deg/s) is
    high.  The hand popping as far is medium: its end site has no length, so its turn moves nothing
    drawn (the viewer shows nothing; a skinned mesh would)."""
    lafan = real_files("bvh-producers/bvhTools_test2_lafan1.bvh")
    if not lafan:
        pytest.skip("the real-file corpus (../shared/data/bvh-producers) is absent")
    take = mt.read_take(lafan[0])
    hands = [f for f in check_motion(take) if f.kind == "spike" and f.joints[0] in ("LeftHand", "RightHand")]
    assert hands and max(f.size for f in hands) > 70  # the excursions are found, as big as they are
    assert [f for f in hands if f.severity == "high"] == []
    for joint, severity in (("LeftForeArm", "high"), ("LeftHand", "medium")):
        values = take.values.copy()
        columns = take.columns(joint, take.skeleton.dofs(joint))
        values[600:602, columns[-3]] += 150.0  # its first rotation channel
        found = [f for f in check_motion(take.replace(values=values)) if f.kind == "spike" and f.first in (601, 602)]
        assert [(f.joints, f.severity) for f in found if f.joints == (joint,)] == [((joint,), severity)]


def test_at_30_hz_a_swing_off_its_neighbours_path_is_low_and_a_turn_out_and_back_as_far_medium():
    """LAFAN1's left forearm swings 50 deg from frame 561 to 563, 15 deg off the path between
    them at 562: as far as smooth motion goes at 30 Hz, low; the forearm turned 15 deg out and
    back for one frame where it is slow is a spike a person sees, medium."""
    lafan = real_files("bvh-producers/bvhTools_test2_lafan1.bvh")
    if not lafan:
        pytest.skip("the real-file corpus (../shared/data/bvh-producers) is absent")
    take = mt.read_take(lafan[0])

    def forearm(motion, frame):
        return [
            f for f in check_motion(motion) if f.kind == "spike" and f.joints == ("LeftForeArm",) and f.first == frame
        ]

    swing = forearm(take, 562)
    assert len(swing) == 1 and swing[0].size > 10 and swing[0].severity == "low", swing
    q = take.rotations(local=True, quaternions=True)[:, take.skeleton.joint_names.index("LeftForeArm")]
    turns = np.degrees(2 * np.arccos(np.clip(np.abs(np.sum(q[1:] * q[:-1], axis=1)), -1, 1)))
    row = int(np.argmin(turns[100:-100] + turns[101:-99])) + 101  # the forearm at its stillest
    values = take.values.copy()
    values[row, take.columns("LeftForeArm", take.skeleton.dofs("LeftForeArm"))[0]] += 15.0
    popped = forearm(take.replace(values=values), take.first_frame + row)
    assert [f.severity for f in popped] == ["medium"] and 12 < popped[0].size < 18, popped


@pytest.mark.parametrize("variant", ["as found", "game rig", "z-up"])
def test_an_elbow_bent_backwards_is_found_where_it_is(variant, tmp_path):
    """CMU's elbow is a hinge of one channel (rx); in the game rig and z-up BVH written from it,
    three channels whose axes the check must find for itself."""
    assert _legs_found(_variant(_walk_path(), variant, tmp_path), "elbow") == []
    take = _walk()
    values = take.values.copy()
    (column,) = take.columns("lradius", ("rx",))
    forward = np.sign(np.median(values[:, column]))
    values[100:112, column] = -forward * 35.0
    bent = _variant(_walk_path(), variant, tmp_path, take.replace(values=values))
    (finding,) = _legs_found(bent, "elbow")
    assert finding.joints == ("lradius",) and (finding.first, finding.last) == (101, 112)
    assert 30 < finding.size < 40 and finding.unit == "deg" and finding.severity == "medium"


def test_a_frame_time_written_for_another_rate_is_found_from_the_strides():
    """Every real take as found has no rate finding; written at a quarter or four times its rate,
    each steady walk or run has one in both directions, its range holding the true rate."""
    if not TAKES:
        pytest.skip("the real-file corpus (../shared/data) is absent")
    found = 0
    for path in TAKES:
        take = mt.read_take(path)
        assert [f for f in check_motion(take) if f.kind == "rate"] == [], path
        named = []
        for factor in (0.25, 4.0):
            named += [f for f in check_motion(take.replace(frame_rate=take.frame_rate * factor)) if f.kind == "rate"]
        if named:
            assert len(named) == 2, (path, named)
            for f in named:
                low, high = (f.size * share / STRIDE_SPEED_SHARE for share in STRIDE_SPEED_RANGE)
                assert f.unit == "Hz" and 0.95 * low < take.frame_rate < 1.05 * high, (path, f)  # 2 digits
                assert "retime" in f.detail and f.fix == ()
            found += 1
    assert found >= 10  # the walks and runs of CMU, HDM05, DeepMimic, the BVH sites


def test_retime_sets_the_rate_and_keeps_every_frame():
    take = _walk()
    again = mt.Pipeline.of("retime", rate=30).apply(take)
    assert again.frame_rate == 30.0 and again.frames == take.frames
    np.testing.assert_array_equal(again.values, take.values)
    with pytest.raises(ValueError, match="positive number of frames per second"):
        mt.Pipeline.of("retime", rate=0).apply(take)


def test_the_elbow_check_holds_a_piece_of_frames_at_a_time(monkeypatch):
    """Pieces of 7 frames (a take of any length is checked a piece at a time) find what one
    piece of every frame finds."""
    take = _walk()
    values = take.values.copy()
    (column,) = take.columns("rradius", ("rx",))
    values[200:230, column] = -np.sign(np.median(values[:, column])) * 50.0
    bent = take.replace(values=values)
    whole = [f for f in check_motion(bent, "walk") if f.kind == "elbow"]
    monkeypatch.setattr(pieces, "PIECE_FRAMES", 7)
    assert [f for f in check_motion(bent, "walk") if f.kind == "elbow"] == whole
    assert [(f.joints, f.first, f.last, f.severity) for f in whole] == [(("rradius",), 201, 230, "high")]


@pytest.mark.parametrize("frames", [1, 10])
def test_a_turn_over_and_back_whose_euler_angles_wrap_is_one_spike(frames):
    """A BVH joint turned 170 degrees for one frame, or for 10 (0.42 s at 24 Hz): its Euler
    angles jump by other amounts on the way out and back (they wrap), and the check still calls
    it one spike of those frames, not flips or jumps, which the recipe fills."""
    from scipy.spatial.transform import Rotation

    walk = real_files("bvh/walk01.bvh")
    if not walk:
        pytest.skip("the real-file corpus (../shared/data/bvh) is absent")
    take = mt.read_take(walk[0])
    joint = "LeftForeArm"
    columns = take.columns(joint, take.skeleton.dofs(joint)[-3:])
    order = "".join(take.skeleton.dofs(joint)[-3:]).replace("r", "").upper()
    values = take.values.copy()
    rows = slice(60, 60 + frames)
    turned = Rotation.from_euler(order, values[rows, columns], degrees=True) * Rotation.from_euler(
        "x", 170, degrees=True
    )
    values[rows, columns] = turned.as_euler(order, degrees=True)
    found = check_motion(take.replace(values=values))
    near = [f for f in found if joint in f.joints and 58 <= f.first <= 62 + frames]
    assert [(f.kind, f.first, f.last) for f in near] == [("spike", 61, 60 + frames)]
    assert near[0].size == pytest.approx(170, abs=2) and near[0].severity == "high"
    fixed = recipe(near).apply(take.replace(values=values))
    assert [f for f in check_motion(fixed) if joint in f.joints and 58 <= f.first <= 62 + frames] == []


@pytest.mark.parametrize("path", TAKES, ids=lambda p: p.name)
def test_a_take_of_nan_zeros_or_huge_values_is_checked_without_a_warning(path):
    """What the check says of a broken take is in its findings, not in numpy's warnings."""
    import warnings

    take = mt.read_take(path)
    rng = np.random.default_rng(0)
    broken = {"some NaN": take.values.copy(), "all NaN": np.full_like(take.values, np.nan)}
    broken["some NaN"][rng.random(take.values.shape) < 0.05] = np.nan
    broken["zeros"] = np.zeros_like(take.values)
    broken["huge"] = take.values.copy()
    broken["huge"][: take.frames // 2] = 1e6
    broken["infinite"] = take.values.copy()  # a number too large to write, read as infinity
    broken["infinite"][:, 0] = np.inf
    broken["infinite"][rng.random(take.values.shape) < 0.01] = -np.inf
    for name, values in broken.items():
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            findings = check_motion(take.replace(values=values))
        assert all(f.kind in FINDING_KINDS for f in findings), name


@pytest.mark.parametrize("frames", [1, 3, 20])
def test_a_joint_of_two_angles_turned_over_is_one_spike_of_its_frames(frames):
    """CMU's thumbs and hands have two angles (rx rz): an rz that crosses 90 deg and comes back
    180 deg on turns the thumb over (no other pair of angles gives that rotation).  The check
    finds one high spike of exactly the turned frames, none on the good frames beside them, and
    its recipe puts the thumb back."""
    take = mt.read_take(real_files("cmu/131_04-dance.amc")[0] if real_files("cmu/131_04-dance.amc") else _walk_path())
    joint, first = "lthumb", 400
    (rz,) = take.columns(joint, ("rz",))
    values = take.values.copy()
    values[first - 1 : first - 1 + frames, rz] += 180.0
    turned = take.replace(values=values)
    near = [
        f for f in check_motion(turned) if joint in f.joints and first - 3 <= f.last and f.first <= first + frames + 2
    ]
    assert [(f.kind, f.first, f.last, f.severity) for f in near] == [("spike", first, first + frames - 1, "high")]
    assert near[0].size == pytest.approx(180, abs=5)
    fixed = recipe(near).apply(turned)
    assert [
        f for f in check_motion(fixed) if joint in f.joints and first - 3 <= f.last and f.first <= first + frames + 2
    ] == []


def test_a_turn_the_joints_below_turn_back_is_told_and_not_filled():
    """A thigh turned 180 deg about its own bone for a few frames, the knee turned back by as
    much: the angles jump, nothing drawn moves (a person sees nothing): medium, as angles that
    are wrong for anyone who edits or retargets them, and no recipe fills the thigh alone (that
    would put the leg out).  The same turn without the knee's is high, and filled."""
    from scipy.spatial.transform import Rotation

    walk = real_files("bvh/walk01.bvh")
    if not walk:
        pytest.skip("the real-file corpus (../shared/data/bvh) is absent")
    take = mt.read_take(walk[0])
    skeleton = take.skeleton
    thigh, knee = "LeftUpLeg", "LeftLeg"
    axis = (
        skeleton.rest_positions()[skeleton.joint_names.index(knee)]
        - skeleton.rest_positions()[skeleton.joint_names.index(thigh)]
    )
    twist = Rotation.from_rotvec(np.pi * axis / np.linalg.norm(axis))
    rows = slice(40, 44)
    for undone, severity in ((True, "medium"), (False, "high")):
        values = take.values.copy()
        for joint, turn in ((thigh, twist), (knee, twist.inv())) if undone else ((thigh, twist),):
            dofs = [d for d in skeleton.dofs(joint) if d in ("rx", "ry", "rz")]
            columns = take.columns(joint, tuple(dofs))
            order = "".join(d[1] for d in dofs).upper()
            rotation = Rotation.from_euler(order, values[rows, columns], degrees=True)
            values[rows, columns] = (rotation * turn if joint == thigh else turn * rotation).as_euler(
                order, degrees=True
            )
        turned = take.replace(values=values)
        moved = np.abs(turned.positions() - take.positions()).max()
        assert (moved < 1e-6) == undone
        thighs = [f for f in check_motion(turned) if f.joints == (thigh,) and 38 <= f.first <= 45]
        assert thighs and {f.severity for f in thighs} == {severity}, thighs
        assert all(bool(f.fix) != undone for f in thighs)


def test_a_rig_of_a_few_bones_has_no_unit_finding():
    """A chain of four bones (sinusoidal.bvh) is no person: its size tells nothing of its unit."""
    chain = real_files("bvh/sinusoidal.bvh")
    if not chain:
        pytest.skip("the real-file corpus (../shared/data/bvh) is absent")
    assert [f for f in check_motion(mt.read_take(chain[0])) if f.kind == "unit"] == []


@pytest.mark.parametrize(
    ("turn", "axis", "severity"),
    [
        (None, None, None),
        ((90.0, 0.0, 0.0), "z", "low"),
        ((180.0, 0.0, 0.0), "-y", "high"),
        ((0.0, 0.0, 90.0), "-x", "medium"),
    ],
)
def test_a_take_that_does_not_stand_along_y_is_told(turn, axis, severity):
    """walk01 (y-up) under a static joint turned so that it stands along z (as z-up exporters
    write it: low, motiontheater reads it standing), upside down (high) or along x (medium)."""
    walk = real_files("bvh/walk01.bvh")
    if not walk:
        pytest.skip("the real-file corpus (../shared/data/bvh) is absent")
    take = mt.read_take(walk[0])
    turned = with_static_root(take, turn=turn, keep_world=False) if turn else take
    found = [f for f in check_motion(turned) if f.kind == "up"]
    if axis is None:
        assert found == []
    else:
        assert [(f.severity, f.unit) for f in found] == [(severity, "%")]
        assert ("upside down" if axis == "-y" else f"along {axis}") in found[0].detail
        assert found[0].size == pytest.approx(100.0)


def test_a_flip_near_gimbal_lock_says_how_near_and_one_far_from_it_does_not():
    """A joint's Euler triple turned to the other triple of the same rotation over 40 frames is a
    medium flip; where its middle angle nears the lock (+-90 deg here) the finding says how near,
    as for lafan1's shoulders, and elsewhere it says nothing of it."""
    take = _walk()
    order, _, columns = _Take(take, "walk").triples["lhumerus"]
    assert order[0] != order[2]  # Tait-Bryan: the lock is at +-90
    for middle, near in ((30.0, False), (88.0, True)):
        values = take.values.copy()
        values[:, columns[1]] = middle  # the middle angle held, the others as captured
        flipped = values.copy()
        rows = slice(200, 240)
        flipped[rows, columns[0]] += 180.0
        flipped[rows, columns[1]] = 180.0 - middle
        flipped[rows, columns[2]] += 180.0
        flips = [
            f for f in check_motion(take.replace(values=flipped)) if f.kind == "flip" and f.joints == ("lhumerus",)
        ]
        assert [(f.first, f.last, f.severity) for f in flips] == [(201, 240, "medium")], middle
        assert ("near gimbal lock: the middle angle comes within 2 deg of it" in flips[0].detail) == near, flips[0]


def test_events_by_kind_are_those_of_each_kind_in_their_order(rng):
    """ChannelEvents.by_kind: every kind's events and sizes, in the pass's order, as a mask of
    each kind picks them (a kind with none gets none)."""
    values = np.cumsum(rng.normal(size=(300, 6)), axis=0)
    values[40:60, 1] = values[40, 1]  # frozen
    values[100, 2] += 50.0  # a spike
    values[150:, 3] += 30.0  # a step
    values[200:205, 4] = np.nan  # a gap
    values[250] = values[249]  # a repeated row
    found = kernel.channel_events(values, 5.0, 5.0, 10)
    kinds = found.by_kind()
    assert list(kinds) == sorted(kernel.KINDS)
    for code in kernel.KINDS:
        mask = found.events[:, 3] == code
        np.testing.assert_array_equal(kinds[code][0], found.events[mask])
        np.testing.assert_array_equal(kinds[code][1], found.sizes[mask])
        assert len(kinds[code][0]), kernel.KINDS[code]  # each made above
    empty = kernel.channel_events(np.arange(300.0)[:, None], 5.0, 5.0, 10).by_kind()  # a steady ramp
    assert all(e.shape == (0, 5) and s.shape == (0,) for e, s in empty.values())
