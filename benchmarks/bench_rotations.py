"""Speed of the fused rotation interpolation (mt_interpolate_euler) against the chains of kernel calls it replaced.

Run: python -m pytest benchmarks/bench_rotations.py
Issue 11 asks SLERP blending and interpolation to "get faster: report before/after figures".  On
cmu/01_01 (11 joints with three rotation channels): the interpolators over frames 100..2700 (the
2599 frames between the keys, 28,589 rotations), the same as kernel calls alone, and a combine with
blend 40 over a 120,000-frame motion (01_01 tiled; its cross-fades are 162 frames of 11 joints).
The references, measured in the same run:

- "814c4eb": the rotation kernels of commit 814c4eb (main before the fused kernel), built from git,
  called as interpolate and the combiner's SLERP blends called them there: per Euler convention,
  Euler to matrices to quaternions, mt_slerp (or rotation vectors and mt_interpolate_rotvecs), back
  to matrices and Euler angles, then mt_unroll_euler or numpy's nearest turns;
- "ae1be65": the same kernels (rotation.c did not change between the two commits) called joint by
  joint, as interpolate did at ae1be65.

Each reference's result is checked against ours first (1e-9 degrees).
"""

import importlib
import math
import os
import subprocess
from contextlib import nullcontext
from pathlib import Path
from unittest import mock

import cffi
import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA
from motiontheater import interpolate
from motiontheater.editing.combine import combine, plan
from mtcore import rotations as rot

combine_module = importlib.import_module("motiontheater.editing.combine")  # the package's `combine` is the function
ROOT = Path(__file__).resolve().parents[1]
PREVIOUS = "814c4eb"
FAST = dict(rounds=20, iterations=1, warmup_rounds=2)
KEYS = (100, 2700)
METHODS = ("slerp", "expmap", "aligned_expmap")
WHO = ("mtcore", PREVIOUS, "ae1be65")
COMBINE = dict(cut=(1_000, 100_000), scale=(5_000, 110_000), blend=40)
TILED = 120_000
CDEF = """
int mt_euler_to_matrices(const double *, size_t, const int *, size_t, int, double, double *);
int mt_matrices_to_euler(const double *, size_t, const int *, int, double, double *);
int mt_matrices_to_quaternions(const double *, size_t, double *);
int mt_quaternions_to_matrices(const double *, size_t, double *);
int mt_quaternions_to_rotvecs(const double *, size_t, double *);
int mt_rotvecs_to_quaternions(const double *, size_t, double *);
int mt_unroll_euler(const double *, size_t, size_t, size_t, int, double, double *);
int mt_slerp(const double *, const double *, const double *, size_t, double *);
int mt_interpolate_rotvecs(const double *, const double *, const double *, size_t, int, double *);
"""


class Previous:
    """The rotation kernels of commit PREVIOUS, in the sequences of calls that the fused kernel replaced."""

    def __init__(self, library: Path):
        self.ffi = cffi.FFI()
        self.ffi.cdef(CDEF)
        self.lib = self.ffi.dlopen(str(library))

    def _call(self, name: str, *args) -> None:
        converted = [
            self.ffi.from_buffer("double[]", a)
            if isinstance(a, np.ndarray)
            else self.ffi.new("int[]", a)
            if isinstance(a, list)
            else a
            for a in args
        ]
        assert getattr(self.lib, name)(*converted) == 0, name

    def quaternions(self, angles: np.ndarray, order: str, extrinsic: bool, degrees: bool) -> np.ndarray:
        angles = np.ascontiguousarray(angles, dtype=float)
        n, codes = angles.size // 3, ["xyz".index(a) for a in order]
        m, q = np.empty(angles.shape[:-1] + (3, 3)), np.empty(angles.shape[:-1] + (4,))
        self._call("mt_euler_to_matrices", angles, n, codes, 3, not extrinsic, math.pi / 180 if degrees else 1.0, m)
        self._call("mt_matrices_to_quaternions", m, n, q)
        return q

    def euler(self, q: np.ndarray, order: str, extrinsic: bool, degrees: bool) -> np.ndarray:
        n, codes = q.size // 4, ["xyz".index(a) for a in order]
        m, angles = np.empty(q.shape[:-1] + (3, 3)), np.empty(q.shape[:-1] + (3,))
        self._call("mt_quaternions_to_matrices", q, n, m)
        self._call("mt_matrices_to_euler", m, n, codes, not extrinsic, math.pi / 180 if degrees else 1.0, angles)
        return angles

    def blend(self, k0: np.ndarray, k1: np.ndarray, t: np.ndarray, method: str) -> np.ndarray:
        """The quaternions between the keys' quaternions (broadcast against t (frames, 1))."""
        shape = np.broadcast_shapes(k0.shape[:-1], t.shape)
        out = np.empty(shape + (4,))
        t = np.ascontiguousarray(np.broadcast_to(t, shape))
        if method == "slerp":
            k0, k1 = (np.ascontiguousarray(np.broadcast_to(k, shape + (4,))) for k in (k0, k1))
            self._call("mt_slerp", k0, k1, t, t.size, out)
            return out
        v0, v1 = (np.empty(k.shape[:-1] + (3,)) for k in (k0, k1))
        self._call("mt_quaternions_to_rotvecs", np.ascontiguousarray(k0), k0.size // 4, v0)
        self._call("mt_quaternions_to_rotvecs", np.ascontiguousarray(k1), k1.size // 4, v1)
        v0, v1 = (np.ascontiguousarray(np.broadcast_to(v, shape + (3,))) for v in (v0, v1))
        v = np.empty(shape + (3,))
        self._call("mt_interpolate_rotvecs", v0, v1, t, t.size, method == "aligned_expmap", v)
        self._call("mt_rotvecs_to_quaternions", v, t.size, out)
        return out

    def interpolate(self, motion: mt.Motion, method: str, frames: tuple[int, int], per_joint: bool) -> mt.Motion:
        """interpolate's rotations as at 814c4eb (whole groups) or ae1be65 (per joint); other channels linear."""
        a, b = frames[0] - motion.first_frame, frames[1] - motion.first_frame
        skeleton, values = motion.skeleton, motion.values.copy()
        groups = skeleton.euler_groups()
        turned = {int(c) for _, _, cols in groups for c in cols.ravel()}
        linear = [c for c in range(values.shape[1]) if c not in turned]
        t = (np.arange(a + 1, b) - a) / (b - a)
        values[a + 1 : b, linear] = values[a, linear] + t[:, None] * (values[b, linear] - values[a, linear])
        degrees = skeleton.angle_unit == "deg"
        fractions = t if per_joint else t[:, None]
        for order, extrinsic, group in groups:
            for cols in group if per_joint else [group]:
                keys = self.quaternions(values[[a, b]][:, cols], order, extrinsic, degrees)
                angles = self.euler(self.blend(keys[0], keys[1], fractions, method), order, extrinsic, degrees)
                path = np.ascontiguousarray(np.concatenate([values[a : a + 1, cols], angles]))
                out = np.empty_like(path)
                inner = path[0].size // 3
                self._call("mt_unroll_euler", path, 1, len(path), inner, order[0] == order[2], 180.0, out)
                values[a + 1 : b, cols] = out[1:]
        return motion.replace(values=values)

    def slerp_blends(self, values: np.ndarray, old: mt.Motion, new: mt.Motion, p, joints) -> None:
        """combine._slerp_blends as at 814c4eb."""
        frames = p.blend_rows
        skeleton = old.skeleton
        u = p.weight[frames, None]
        degrees = skeleton.angle_unit == "deg"
        rows = (slice(None), None, None)
        for order, extrinsic, columns in skeleton.euler_groups(joints):
            a = old.values[p.old_row[frames][rows], columns]
            b = new.values[p.new_row[frames][rows], columns]
            if p.ramp is not None and p.next_row is not None:
                b = b + p.ramp[frames][rows] * (new.values[p.next_row[frames][rows], columns] - b)
            q0, q1 = (self.quaternions(k, order, extrinsic, degrees) for k in (a, b))
            angles = self.euler(self.blend(q0, q1, u, "slerp"), order, extrinsic, degrees)
            where = (frames[rows], columns)
            period = skeleton.period
            values[where] = angles + period * np.round((values[where] - angles) / period)


@pytest.fixture(scope="module")
def previous(tmp_path_factory):
    """The rotation kernels of PREVIOUS, compiled from git into a shared library."""
    build = tmp_path_factory.mktemp("previous")
    try:
        for name in ("rotation.c", "blocks.h", "clones.h", "mtcore.h"):
            shown = subprocess.run(
                ["git", "-C", ROOT, "show", f"{PREVIOUS}:csrc/{name}"], capture_output=True, check=True
            )
            (build / name).write_bytes(shown.stdout)
        command = [os.environ.get("CC", "cc"), "-O3", "-std=c11", "-shared", "-fPIC", "rotation.c", "-o", "old.so"]
        subprocess.run([*command, "-lm"], cwd=build, check=True)
    except (OSError, subprocess.CalledProcessError) as e:
        pytest.skip(f"the rotation kernels of {PREVIOUS} could not be built from git: {e}")
    return Previous(build / "old.so")


@pytest.fixture(scope="module")
def take():
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    return mt.read_amc(DATA / "cmu" / "01_01.amc", mt.read_asf(DATA / "cmu" / "01.asf"))


@pytest.fixture(scope="module")
def tiled(take):
    return take.replace(values=np.tile(take.values, (-(-TILED // take.frames), 1))[:TILED])


def rotations(motion: mt.Motion, frames: int) -> int:
    return frames * sum(len(cols) for _, _, cols in motion.skeleton.euler_groups())


def interpolation(take, previous, who: str, method: str):
    if who == "mtcore":
        return lambda: interpolate(take, method, frames=KEYS)
    return lambda: previous.interpolate(take, method, KEYS, per_joint=who == "ae1be65")


@pytest.mark.parametrize("who", WHO)
@pytest.mark.parametrize("method", METHODS)
def test_interpolate(benchmark, record, take, previous, method, who):
    run = interpolation(take, previous, who, method)
    np.testing.assert_allclose(run().values, interpolation(take, previous, "mtcore", method)().values, atol=1e-9)
    benchmark.pedantic(run, **FAST)
    record(
        f"interpolate {method}, cmu 01_01 frames 100..2700", who, rotations(take, KEYS[1] - KEYS[0] - 1), unit="M rot"
    )


def group_kernels(take, previous, who: str, method: str):
    """The rotations' calls alone, as interpolate makes them: ours one per Euler convention."""
    a, b = (k - take.first_frame for k in KEYS)
    t = (np.arange(a + 1, b) - a) / (b - a)
    (order, extrinsic, cols), *others = take.skeleton.euler_groups()
    assert not others
    first, last = take.values[a, cols], take.values[b, cols]
    if who == "mtcore":
        return lambda: rot.interpolate_euler(
            first, last, t, order, extrinsic=extrinsic, degrees=True, blend=method, start=first
        )

    def chain():
        outs, fractions = [], t if who == "ae1be65" else t[:, None]
        for c in cols if who == "ae1be65" else [cols]:
            keys = previous.quaternions(take.values[[a, b]][:, c], order, extrinsic, True)
            angles = previous.euler(previous.blend(keys[0], keys[1], fractions, method), order, extrinsic, True)
            path = np.ascontiguousarray(np.concatenate([take.values[a : a + 1, c], angles]))
            out = np.empty_like(path)
            previous._call("mt_unroll_euler", path, 1, len(path), path[0].size // 3, False, 180.0, out)
            outs.append(out[1:].reshape(len(t), -1, 3))
        return np.concatenate(outs, axis=1)

    return chain


@pytest.mark.parametrize("who", WHO)
@pytest.mark.parametrize("method", METHODS)
def test_rotation_kernels(benchmark, record, take, previous, method, who):
    run = group_kernels(take, previous, who, method)
    np.testing.assert_allclose(run(), group_kernels(take, previous, "mtcore", method)(), rtol=0, atol=1e-9)
    benchmark.pedantic(run, **FAST)
    frames = KEYS[1] - KEYS[0] - 1
    record(f"rotation calls alone, {method}, 11 joints x {frames} frames", who, rotations(take, frames), unit="M rot")


def blend_stage(tiled, previous, who: str):
    p = plan(tiled, tiled, **COMBINE)
    linear = combine(tiled, tiled, rotation_blend="linear", **COMBINE).values
    stage = combine_module._slerp_blends if who == "mtcore" else previous.slerp_blends
    values = linear.copy()

    # In place, without a fresh copy per round: copying the (120000, 62) values would take most of the time of
    # a stage that writes 162 frames.  Every round does the same work; the first gives the checked result.
    def run():
        stage(values, tiled, tiled, p, tiled.skeleton.joint_names)
        return values

    return run, len(p.blend_rows)


@pytest.mark.parametrize("who", WHO[:2])
def test_combine_blends(benchmark, record, tiled, previous, who):
    run, frames = blend_stage(tiled, previous, who)
    np.testing.assert_allclose(run(), blend_stage(tiled, previous, "mtcore")[0](), rtol=0, atol=1e-9)
    benchmark.pedantic(run, **FAST)
    record(
        f"combine's SLERP blends alone (blend 40: {frames} frames)",
        who,
        rotations(tiled, frames),
        unit="M rot",
    )


@pytest.mark.parametrize("who", WHO[:2])
def test_combine(benchmark, record, tiled, previous, who):
    patched = mock.patch.object(combine_module, "_slerp_blends", previous.slerp_blends)
    with patched if who == PREVIOUS else nullcontext():
        benchmark.pedantic(combine, (tiled, tiled), COMBINE, rounds=5, iterations=1, warmup_rounds=1)
    record(f"combine blend 40, {TILED} frames (01_01 tiled)", who, TILED * tiled.values.shape[1])
