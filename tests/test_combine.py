"""The motion combiner: the thesis's worked example and cases, properties, bad requests."""

import warnings

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.editing.combine import combine, plan
from twins import combine as twin
from twins import rotations as euler_twin


@pytest.fixture(scope="module")
def take(data_dir):
    return mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))


def frames_of(take, first, last, number_from=None):
    """Frames first..last of the take as a motion numbered from number_from (default: first)."""
    return take.replace(values=take.values[first - 1 : last], first_frame=number_from or first)


def test_thesis_worked_example(take):
    """Fig. 4.17: old 45..150, new file 1..113, cut 50..113, scale 50..140, b = 5."""
    old, new = frames_of(take, 45, 150), frames_of(take, 1001, 1113, 1)
    p = plan(old, new, cut=(50, 113), scale=(50, 140), blend=5)
    assert p.piece == (50, 140) and p.source == (47, 113)
    start = p.borders[0]
    assert (start.side, start.window, start.step) == ("start", (45, 55), 1 / 12)
    piece_frames = p.frames[p.weight > 0]
    assert (piece_frames.min(), piece_frames.max()) == (45, 140)  # the piece runs over 45..140
    x = p.new_row + new.first_frame
    assert x[p.frames == 45][0] == 47 and x[p.frames == 140][0] == 113
    assert x[p.frames == 46][0] == 47 and x[p.frames == 49][0] == 49  # 47.2 -> 47, 49.3 -> 49
    weights = p.weight[(p.frames >= 45) & (p.frames <= 55)]
    np.testing.assert_allclose(weights, np.arange(1, 12) / 12)


def test_thesis_worked_example_with_frames_missing(take):
    """The file holds only 48..113: b_start = 46.5 -> 47 is missing, the nearest is 48, b_new = 3."""
    old, new = frames_of(take, 45, 150), frames_of(take, 1048, 1113, 48)
    p = plan(old, new, cut=(50, 113), scale=(50, 140), blend=5)
    start = p.borders[0]
    assert (start.left, start.right, start.window, start.step) == (3, 5, (47, 55), 1 / 10)
    assert p.source == (48, 113)


def test_blend_at_the_end(take):
    """A piece inside the old motion blends at both ends; at g2 from new to old."""
    old, new = frames_of(take, 1, 300), frames_of(take, 1001, 1200, 1)
    p = plan(old, new, cut=(101, 150), scale=(101, 150), blend=4)
    end = p.borders[1]
    assert (end.side, end.frame, end.window, end.step) == ("end", 150, (146, 154), 1 / 10)
    w = p.weight[(p.frames >= 146) & (p.frames <= 154)]
    np.testing.assert_allclose(w, 1 - np.arange(1, 10) / 10)
    assert (np.diff(w) < 0).all()
    result = combine(old, new, cut=(101, 150), scale=(101, 150), blend=4, rotation_blend="linear")
    np.testing.assert_array_equal(result.values[p.frames == 155][0], old.values[154])
    np.testing.assert_array_equal(result.values[p.frames == 145][0], new.values[144])


def test_blend_into_a_gap(take):
    """Old 1..100, piece laid onto 151..200: the gap 101..150 is a transition with b > 0, held with b = 0."""
    old, new = frames_of(take, 1, 100), frames_of(take, 1001, 1100, 1)
    held = plan(old, new, cut=(1, 50), scale=(151, 200), blend=0)
    assert held.gap == (101, 150)
    g = (held.frames >= 101) & (held.frames <= 150)
    assert (held.weight[g] == 0).all() and (held.old_row[g] == 99).all()
    smooth = plan(old, new, cut=(1, 50), scale=(151, 200), blend=3)
    np.testing.assert_allclose(smooth.weight[g], np.arange(1, 51) / 51)
    assert (smooth.new_row[g] == 0).all()  # towards the piece's first pose
    result = combine(old, new, cut=(1, 50), scale=(151, 200), blend=3)
    assert result.first_frame == 1 and result.frames == 200
    np.testing.assert_array_equal(result.values[199], new.values[49])


@pytest.mark.parametrize(
    "options",
    [
        dict(cut=(50, 113), scale=(50, 140), blend=5),
        dict(cut=(10, 60), scale=(120, 140), blend=2),
        dict(cut=(1, 40), scale=(200, 280), blend=0, interpolate=True),
        dict(cut=(1, 40), blend=0, discard_old=True),
    ],
)
def test_outside_blends_every_frame_is_exactly_old_or_source(take, options):
    old, new = frames_of(take, 45, 250), frames_of(take, 1001, 1113, 1)
    p = plan(old, new, **{k: v for k, v in options.items() if k != "interpolate"})
    result = combine(old, new, rotation_blend="linear", **options)
    pure_old, pure_new = p.weight == 0, (p.weight == 1)
    if not options.get("discard_old"):
        np.testing.assert_array_equal(result.values[pure_old], old.values[p.old_row[pure_old]])
    if not options.get("interpolate"):
        np.testing.assert_array_equal(result.values[pure_new], new.values[p.new_row[pure_new]])
    blends = p.weight[(p.weight > 0) & (p.weight < 1)]
    assert len(blends) == sum(b.left + b.right + 1 for b in p.borders if b.window) + (
        len(range(p.gap[0], p.gap[1] + 1)) if p.gap and p.blend else 0
    )


def test_c_loop_equals_numpy_and_python_twins(take):
    old, new = frames_of(take, 45, 250), frames_of(take, 1001, 1113, 1)
    p = plan(old, new, cut=(20, 90), scale=(100, 200), blend=6, interpolate=True)
    selected = np.zeros(62, np.uint8)
    selected[old.columns("lfemur") + old.columns("root")] = 1
    from mtcore.combine import combine_frames

    got = combine_frames(
        old.values, new.values, p.old_row, p.new_row, p.weight, next_row=p.next_row, ramp=p.ramp, selected=selected
    )
    rows = (p.old_row, p.new_row, p.weight)
    ramps = dict(next_row=p.next_row, ramp=p.ramp, selected=selected)
    np.testing.assert_array_equal(got, twin.combine_frames(old.values, new.values, *rows, **ramps))
    lists = [a.tolist() for a in rows]
    ramps = {k: None if v is None else v.tolist() for k, v in ramps.items()}
    np.testing.assert_array_equal(
        got, np.array(twin.python_combine(old.values.tolist(), new.values.tolist(), *lists, **ramps))
    )


def test_unselected_joints_are_bit_identical(take):
    old, new = frames_of(take, 1, 300), frames_of(take, 1001, 1300, 1)
    result = combine(old, new, cut=(20, 120), scale=(50, 200), blend=5, joints=["lhumerus", "lradius"])
    chosen = set(old.columns("lhumerus") + old.columns("lradius"))
    others = [c for c in range(62) if c not in chosen]
    np.testing.assert_array_equal(result.values[:, others], old.values[:, others])
    assert not np.array_equal(result.values[:, sorted(chosen)], old.values[:, sorted(chosen)])


def test_interpolation_replaces_repeats_with_ramps(take):
    old, new = frames_of(take, 1, 300), frames_of(take, 1001, 1300, 1)
    stepped = combine(old, new, cut=(1, 30), scale=(101, 190), discard_old=True)
    ramped = combine(old, new, cut=(1, 30), scale=(101, 190), discard_old=True, interpolate=True)
    column = old.columns("lfemur", "rx")[0]
    assert (np.diff(stepped.values[:, column]) == 0).sum() >= 50  # scaled 3x: two repeats per source frame
    assert (np.diff(ramped.values[:-1, column]) == 0).sum() == 0  # the last frame has nothing to ramp to
    p = plan(old, new, cut=(1, 30), scale=(101, 190), discard_old=True)
    starts = np.r_[True, np.diff(p.new_row) != 0]  # where each source frame first appears: exact
    np.testing.assert_array_equal(ramped.values[starts, column], new.values[p.new_row[starts], column])


@pytest.mark.parametrize("mode", ["literal", "ground"])
def test_preserve_keeps_the_root_continuous(take, mode):
    old, new = frames_of(take, 1, 300), frames_of(take, 1501, 1800, 1)
    result = combine(old, new, cut=(1, 100), scale=(101, 200), preserve=mode)
    root = result.values[:, result.columns("root", ("tx", "ty", "tz"))]
    ground = [0, 2] if mode == "ground" else [0, 1, 2]
    for border in (100, 200):  # g1 - 1 and g1; g2 and g2 + 1
        i = border - result.first_frame
        step = np.abs(root[i + 1, ground] - root[i, ground])
        assert step.max() < 1e-9, (border, step)
    if mode == "ground":
        headings = _headings(result)
        for border in (100, 200):
            i = border - result.first_frame
            assert abs(np.angle(np.exp(1j * (headings[i + 1] - headings[i])))) < 1e-9
        # the piece moves rigidly: its own steps keep their ground-plane lengths
        raw = new.values[:100][:, new.columns("root", ("tx", "tz"))]
        moved = result.values[100:200][:, result.columns("root", ("tx", "tz"))]
        np.testing.assert_allclose(
            np.linalg.norm(np.diff(moved, axis=0), axis=1), np.linalg.norm(np.diff(raw, axis=0), axis=1), atol=1e-9
        )


def _headings(motion):
    """About +y, by the numpy twin: independent of the C conversions that ground preserving uses."""
    m = euler_twin.matrices(np.radians(motion.values[:, motion.columns("root", ("rx", "ry", "rz"))]), "xyz")
    return np.arctan2(m[:, 0, 2], m[:, 2, 2])


def test_blend_and_preserve_warn_and_preserve(take):
    old, new = frames_of(take, 1, 300), frames_of(take, 1501, 1800, 1)
    with pytest.warns(UserWarning, match="blend and preserve exclude each other"):
        result = combine(old, new, cut=(1, 100), scale=(101, 200), blend=5, preserve="literal")
    assert set(np.unique(plan(old, new, cut=(1, 100), scale=(101, 200)).weight)) == {0.0, 1.0}
    assert result.frames == 300


def test_slerp_blends_stay_on_the_shorter_arc(take):
    """Linear Euler blending through ±180 swings the long way round; SLERP does not."""
    old, new = frames_of(take, 1, 100), frames_of(take, 1001, 1100, 1)
    values = old.values.copy()
    values[:, old.columns("lfemur", "rz")[0]] = 179.0
    old = old.replace(values=values)
    values = new.values.copy()
    values[:, new.columns("lfemur", ("rx", "ry", "rz"))] = [0.0, 0.0, -179.0]
    values[:, new.columns("lfemur", ("rx", "ry"))] = old.values[0, old.columns("lfemur", ("rx", "ry"))]
    new = new.replace(values=values)
    linear = combine(old, new, cut=(1, 30), scale=(41, 70), blend=5, rotation_blend="linear")
    slerp = combine(old, new, cut=(1, 30), scale=(41, 70), blend=5)
    column = old.columns("lfemur", "rz")[0]
    window = slice(36 - 1, 46)
    assert np.abs(linear.values[window, column]).min() < 90  # through zero: the long way
    assert (np.abs(np.abs(slerp.values[window, column]) - 180) < 1.5).all()


@pytest.mark.parametrize(
    "kwargs,message",
    [
        (dict(cut=(0, 500)), r"cut=\(0, 500\) is outside the new motion's frames 1..113"),
        (dict(cut=(50, 20)), r"cut=\(50, 20\) is outside"),
        (dict(scale=(90, 90)), r"scale=\(90, 90\) needs its first frame before its last"),
        (dict(scale=(90, 10)), r"scale=\(90, 10\)"),
        (dict(joints=["tail"]), "joints: no joint 'tail'"),
        (dict(blend=-1), "blend must be a depth of 0 frames or more, got -1"),
        (dict(preserve="heading"), "preserve must be one of"),
        (dict(rotation_blend="cubic"), "rotation_blend must be one of"),
        (dict(cut="1-10"), "cut must be a pair of frame numbers"),
    ],
)
def test_bad_requests_name_the_argument(take, kwargs, message):
    old, new = frames_of(take, 45, 150), frames_of(take, 1001, 1113, 1)
    with pytest.raises(ValueError, match=message):
        combine(old, new, **kwargs)


def test_a_motion_of_another_skeleton(take, data_dir):
    other = mt.read_amc(data_dir / "edge" / "test.amc", mt.read_asf(data_dir / "edge" / "test.asf"))
    with pytest.raises(ValueError, match="new: a motion of another skeleton"):
        combine(take, other)


def test_inputs_untouched(take):
    old, new = frames_of(take, 45, 150), frames_of(take, 1001, 1113, 1)
    before = old.values.copy(), new.values.copy()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        combine(old, new, cut=(50, 113), scale=(50, 140), blend=5)
    np.testing.assert_array_equal(old.values, before[0])
    np.testing.assert_array_equal(new.values, before[1])


class NoC:
    """Stands in for the C library: any use fails the test."""

    def __getattr__(self, name):
        raise AssertionError(f"{name} called before the arguments were checked")


OLD, NEW = np.zeros((5, 3)), np.ones((4, 3))
BAD_COMBINE = [
    (dict(old=None, new=None), ValueError, "needs an old or a new motion"),
    (dict(old=np.zeros(5)), ValueError, r"old must be two-dimensional of shape \(any, any\), got shape \(5,\)"),
    (dict(new=np.ones((4, 2))), ValueError, r"new must have the 3 channels of old, got shape \(4, 2\)"),
    (
        dict(new=np.ones((4, 3), complex)),
        TypeError,
        r"^new must hold real numbers \(bool, integer or float\), got dtype complex128$",
    ),
    (dict(weight=None), TypeError, "weight must be an array, got None"),
    (dict(weight=[[0.0, 1.0]]), ValueError, "weight must be one-dimensional"),
    (dict(weight=[0.0, 1.5]), ValueError, r"weight must lie in \[0, 1\], got weight\[1\] = 1.5"),
    (dict(weight=[0.0, np.nan]), ValueError, r"got weight\[1\] = nan"),
    (dict(old_row=[0]), ValueError, r"old_row must be one-dimensional of shape \(2,\), got shape \(1,\)"),
    (dict(old_row=[0.0, 1.0]), TypeError, "old_row must hold integers, got dtype float64"),
    (dict(new_row=[0, 9]), ValueError, r"new_row must lie in -1 .. 3, got new_row\[1\] = 9"),
    (dict(old_row=[0, -2]), ValueError, r"old_row must lie in -1 .. 4, got old_row\[1\] = -2"),
    (dict(old_row=[0, -1], weight=[0.0, 0.5]), ValueError, r"output frame 1 \(weight 0.5\) needs a row of old"),
    (dict(new_row=[-1, -1]), ValueError, r"output frame 1 \(weight 1.0\) needs a row of new, but new_row\[1\] is -1"),
    (dict(next_row=[0, 1]), ValueError, "next_row is the row a ramp leads to: pass ramp too"),
    (dict(ramp=[0.0, 2.0]), ValueError, r"ramp must lie in \[0, 1\], got ramp\[1\] = 2.0"),
    (dict(ramp=[0.0, 0.5], next_row=[0, -1]), ValueError, "needs the next row of new"),
    (dict(selected=[1, 0]), ValueError, r"selected must be one-dimensional of shape \(3,\), got shape \(2,\)"),
    (dict(selected=[1, 0, 2]), ValueError, r"selected must lie in 0 .. 1, got selected\[2\] = 2"),
    (dict(selected=None, old_row=None, weight=[1.0, 0.0]), ValueError, "output frame 1 .* needs a row of old"),
    (dict(offset_channels=[0, 3]), ValueError, r"offset_channels must lie in 0 .. 2, got offset_channels\[1\] = 3"),
    (
        dict(offset_channels=[0], offsets=np.zeros((2, 2))),
        ValueError,
        r"offsets must be two-dimensional of shape \(any, 1\)",
    ),
    (
        dict(offset_channels=[0], offsets=np.zeros((2, 1)), offset_row=[0, 2]),
        ValueError,
        r"offset_row must lie in -1 .. 1",
    ),
    (dict(workers=0), ValueError, "workers must be"),
]


@pytest.mark.parametrize("change, exc, message", BAD_COMBINE)
def test_combine_frames_checks_every_argument_before_any_c_call(monkeypatch, change, exc, message):
    import mtcore.combine

    args = {**dict(old=OLD, new=NEW, old_row=[0, 1], new_row=[0, 0], weight=[0.0, 1.0]), **change}
    monkeypatch.setattr(mtcore.combine, "lib", NoC())
    with pytest.raises(exc, match=message):
        mtcore.combine.combine_frames(**args)


def test_c_loop_checks_every_row_it_reads():
    """The C loop does not trust its caller either: rows out of range and weights out of [0, 1]."""
    from mtcore._cdata import c_array
    from mtcore._mtcore import ffi, lib
    from mtcore.combine import combine_frames

    def status(new_row, weight, old_row=(0, 1)):
        out = np.empty((2, 3))
        rows = [np.array(r, np.int64) for r in (old_row, new_row)]
        return lib.mt_combine(
            c_array(OLD), 5, c_array(NEW), 4, 3, 2, c_array(rows[0], "long long[]"), c_array(rows[1], "long long[]"),
            ffi.NULL, ffi.NULL, c_array(np.array(weight)), c_array(np.ones(3, np.uint8), "unsigned char[]"),
            c_array(np.full(2, -1, np.int64), "long long[]"), ffi.NULL, 0, ffi.NULL, 0, 0, 2, c_array(out),
        )  # fmt: skip

    assert status([0, 9], [1.0, 1.0]) == lib.MT_EINVAL  # new row 9 of 4
    assert status([0, 0], [0.0, 0.5], old_row=(0, -1)) == lib.MT_EINVAL  # a blend without an old row
    assert status([0, 0], [0.0, 1.5]) == lib.MT_EINVAL  # a weight above 1
    assert status([0, 0], [0.0, 1.0]) == lib.MT_OK
    np.testing.assert_array_equal(combine_frames(OLD, NEW, [0, 1], [0, 0], [0.0, 1.0]), [[0, 0, 0], [1, 1, 1]])


def test_offset_channels_without_offsets():
    """No offset rows is a valid (empty) table, not a NULL the C loop rejects."""
    from mtcore.combine import combine_frames

    old, new = np.zeros((2, 3)), np.arange(6.0).reshape(2, 3)
    out = combine_frames(old, new, [0, 1], [0, 1], [0.0, 1.0], offset_channels=[0])
    np.testing.assert_array_equal(out, [old[0], new[1]])
