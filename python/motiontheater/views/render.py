"""Animations of skeletons for reports and issue threads: GIF (matplotlib and pillow, the
``plot`` extra) or MP4 (also ffmpeg on the PATH).

The camera is the viewer page's: a perspective view from above and to the
side, its distance set by the skeleton's size, following the body over the
floor (``follow=True``) or fixed on the whole take.  The take's up axis is
drawn up (a z-up export stands, as a y-up one does).  The first
take is drawn solid, compared takes ghosted over it at the same time from
each take's start.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import tempfile
from collections.abc import Callable, Sequence

import numpy as np

from .._io import Source, output
from .._optional import require
from ..feet.upright import take_up
from ..model.motion import Motion
from ..model.rig import body_view

FORMATS = ("gif", "mp4")
MAX_GIF_FRAMES = 1500  # a minute at 25 fps; pillow holds every frame of a GIF until it writes it
_COLOURS = ("#1f4e9c", "#c0392b", "#2e8b57", "#8e44ad", "#b8860b")


class _Camera:
    """A perspective camera looking at ``target`` from yaw / pitch (radians) at ``distance``."""

    def __init__(self, size: tuple[int, int], distance: float, yaw: float = 0.7, pitch: float = 0.28):
        self.width, self.height = size
        self.distance, self.yaw, self.pitch = distance, yaw, pitch
        self.focal = self.height / 2 / math.tan(math.radians(45) / 2)
        self.near = 0.02 * distance

    def look_at(self, target: np.ndarray) -> None:
        cp = math.cos(self.pitch)
        offset = self.distance * np.array([cp * math.sin(self.yaw), math.sin(self.pitch), cp * math.cos(self.yaw)])
        self.eye = target + offset
        forward = -offset / np.linalg.norm(offset)
        right = np.cross(forward, [0.0, 1.0, 0.0])
        right /= np.linalg.norm(right)
        self.basis = np.stack([right, np.cross(right, forward), forward])  # rows: x, y, depth

    def segments(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Screen segments (n, 2, 2) of world segments a -> b (n, 3), cut at the near plane;
        segments wholly behind it or holding NaN are dropped."""
        ca, cb = (a - self.eye) @ self.basis.T, (b - self.eye) @ self.basis.T
        keep = np.isfinite(ca).all(axis=1) & np.isfinite(cb).all(axis=1)
        keep &= (ca[:, 2] > self.near) | (cb[:, 2] > self.near)
        ca, cb = ca[keep], cb[keep]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.clip((self.near - ca[:, 2]) / (cb[:, 2] - ca[:, 2]), 0.0, 1.0)[:, None]
        cut = ca + s * (cb - ca)
        ca = np.where((ca[:, 2] < self.near)[:, None], cut, ca)
        cb = np.where((cb[:, 2] < self.near)[:, None], cut, cb)
        return np.stack([self._screen(ca), self._screen(cb)], axis=1)

    def points(self, p: np.ndarray) -> np.ndarray:
        """Screen points (m, 2) of the world points (n, 3) in front of the camera."""
        c = (p - self.eye) @ self.basis.T
        return self._screen(c[np.isfinite(c).all(axis=1) & (c[:, 2] > self.near)])

    def _screen(self, c: np.ndarray) -> np.ndarray:
        return np.column_stack(
            [self.width / 2 + self.focal * c[:, 0] / c[:, 2], self.height / 2 - self.focal * c[:, 1] / c[:, 2]]
        )


def _frame_times(motion: Motion, fps: float, frames: tuple[int, int] | None) -> np.ndarray:
    """Indices of the first take's frames shown at ``fps`` over ``frames`` (frame numbers)."""
    first, last = motion.first_frame, motion.first_frame + motion.frames - 1
    lo, hi = frames if frames is not None else (first, last)
    if not (first <= lo <= hi <= last):
        raise ValueError(f"frames {lo}..{hi} must lie within the take's frames {first}..{last}, first <= last")
    seconds = (hi - lo) / motion.frame_rate
    count = math.floor(seconds * fps + 1e-9) + 1
    return (lo - first) + np.minimum(np.rint(np.arange(count) / fps * motion.frame_rate).astype(int), hi - lo)


def render(
    takes: Sequence[Motion],
    target: Source,
    *,
    format: str | None = None,
    fps: float = 25.0,
    size: tuple[int, int] = (480, 360),
    frames: tuple[int, int] | None = None,
    names: Sequence[str] | None = None,
    follow: bool = True,
    up: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> int:
    """Write an animation of the takes' skeletons and return the number of frames written.

    ``format`` is "gif" or "mp4" (default: the target's suffix); MP4 needs
    ffmpeg on the PATH.  ``fps`` frames per second of animation sample the
    first take in real time (the nearest frame to each instant) over
    ``frames`` (first, last frame numbers; default all).  ``size`` is
    (width, height) in pixels (even numbers for MP4).  ``names`` label the
    takes in the corner.  ``up`` is the axis that points up ("y", "z",
    "-y", ...; default: the first take's, found from its frames, see
    :func:`~motiontheater.feet.upright.take_up`): it is drawn up.
    Takes are drawn as their bodies (:func:`~motiontheater.model.rig.body_view`):
    the camera follows the joint that travels, and no bone is drawn from a
    static joint above it.  ``progress(done, total)`` is called after each
    frame.  A path is written atomically.
    """
    if format is None:
        suffix = os.path.splitext(os.fspath(target) if isinstance(target, (str, os.PathLike)) else "")[1]
        format = suffix.lstrip(".").lower()
    if format not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(FORMATS)} (or a target ending in one), got {format!r}")
    if not takes:
        raise ValueError("give at least one take to render")
    if not (isinstance(fps, (int, float)) and 0 < fps <= 100):
        raise ValueError(f"fps must be a number of frames per second in (0, 100], got {fps!r}")
    width, height = (int(v) for v in size)
    if not (16 <= width <= 4096 and 16 <= height <= 4096):
        raise ValueError(f"size must be between 16x16 and 4096x4096 pixels, got {width}x{height}")
    if format == "mp4":
        if width % 2 or height % 2:
            raise ValueError(f"MP4 needs an even width and height, got {width}x{height}")
        if shutil.which("ffmpeg") is None:
            raise RuntimeError("writing MP4 needs ffmpeg on the PATH (e.g. apt-get install ffmpeg); or write a .gif")
    require("matplotlib", "plot", "rendering animations")
    require("PIL", "plot", "rendering animations")
    labels = list(names) if names is not None else [f"take {i + 1}" for i in range(len(takes))]
    if len(labels) != len(takes):
        raise ValueError(f"give one name per take ({len(takes)}), got {len(labels)}")
    for motion, label in zip(takes, labels):
        if motion.frames == 0:
            raise ValueError(f"{label} has no frames to render")
    shown = _frame_times(takes[0], fps, frames)
    if format == "gif" and len(shown) > MAX_GIF_FRAMES:
        raise ValueError(
            f"a GIF of {len(shown)} frames is too long (at most {MAX_GIF_FRAMES}, held in memory until written): "
            "choose fewer frames, a lower fps, or write .mp4"
        )
    turn = take_up(takes[0], up).turn
    pictures = _pictures([body_view(m).motion for m in takes], labels, shown, (width, height), follow, turn)
    total = len(shown)

    def counted():
        for done, picture in enumerate(pictures, 1):
            yield picture
            if progress is not None:
                progress(done, total)

    if format == "gif":
        _write_gif(counted(), target, fps)
    else:
        _write_mp4(counted(), target, fps, (width, height))
    return total


def _pictures(takes, labels, shown, size, follow, turn):
    """RGB arrays (height, width, 3), one per shown frame of the first take."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    width, height = size
    base = takes[0]
    # only the frames shown: each take's nearest frame to each instant of the first take's
    seconds = np.asarray(shown) / base.frame_rate
    rows = [np.minimum(m.frames - 1, np.rint(seconds * m.frame_rate).astype(int)) for m in takes]
    positions = [m.replace(values=m.values[r]).positions() @ turn.T for m, r in zip(takes, rows)]
    points = positions[0]
    finite = points[np.isfinite(points).all(axis=2)]
    floor = float(finite[:, 1].min()) if len(finite) else 0.0
    rest = base.skeleton.rest_positions() @ turn.T
    extent = np.nanmax(rest, axis=0) - np.nanmin(rest, axis=0)
    camera = _Camera(size, 2.2 * max(float(np.nanmax(extent)), 1e-9))
    centre = (np.nanmin(finite, axis=0) + np.nanmax(finite, axis=0)) / 2 if len(finite) else np.zeros(3)
    height_of_view = (np.nanmin(points[0, :, 1]) + np.nanmax(points[0, :, 1])) / 2
    spacing = 0.5 / base.skeleton.meters_per_unit
    reach = 8 * spacing

    fig = Figure(figsize=(width / 100, height / 100), dpi=100)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, width)
    ax.set_ylim(height, 0)
    ax.set_axis_off()
    grid = LineCollection([], colors="#d8d8d8", linewidths=0.8)
    ax.add_collection(grid)
    bones, joints = [], []
    for k in reversed(range(len(takes))):  # the first take on top
        colour, alpha = _COLOURS[k % len(_COLOURS)], 1.0 if k == 0 else 0.45
        bones.insert(0, ax.add_collection(LineCollection([], colors=colour, linewidths=2.2, alpha=alpha)))
        joints.insert(0, ax.plot([], [], "o", color=colour, markersize=2.5, alpha=alpha)[0])
    caption = ax.text(6, 6, "", va="top", ha="left", fontsize=8, color="#333")
    # each bone's parent point: bones are the points after the root
    parents = [
        np.array([m.skeleton.joint_names.index(m.skeleton.parent(b)) for b in m.skeleton.bone_names]) for m in takes
    ]
    for n, i in enumerate(shown):
        root = points[n, 0]
        target = np.array([root[0], height_of_view, root[2]]) if follow and np.isfinite(root).all() else centre
        camera.look_at(target)
        gx = (
            np.arange(math.floor((target[0] - reach) / spacing), math.ceil((target[0] + reach) / spacing) + 1) * spacing
        )
        gz = (
            np.arange(math.floor((target[2] - reach) / spacing), math.ceil((target[2] + reach) / spacing) + 1) * spacing
        )
        a = np.concatenate(
            [
                np.column_stack([gx, np.full_like(gx, floor), np.full_like(gx, gz[0])]),
                np.column_stack([np.full_like(gz, gx[0]), np.full_like(gz, floor), gz]),
            ]
        )
        b = np.concatenate(
            [
                np.column_stack([gx, np.full_like(gx, floor), np.full_like(gx, gz[-1])]),
                np.column_stack([np.full_like(gz, gx[-1]), np.full_like(gz, floor), gz]),
            ]
        )
        grid.set_segments(camera.segments(a, b))
        for k in range(len(takes)):
            p = positions[k][n]
            bones[k].set_segments(camera.segments(p[parents[k]], p[1:]))
            xy = camera.points(p)
            joints[k].set_data(xy[:, 0], xy[:, 1])
        caption.set_text(f"{labels[0]}   frame {base.first_frame + i}   {seconds[n]:.2f} s")
        canvas.draw()
        yield np.asarray(canvas.buffer_rgba())[:, :, :3].copy()


def _write_gif(pictures, target: Source, fps: float) -> None:
    from PIL import Image

    frames = [Image.fromarray(p).convert("P", palette=Image.Palette.ADAPTIVE, colors=64) for p in pictures]
    with output(target) as f:
        frames[0].save(f, format="GIF", save_all=True, append_images=frames[1:], duration=round(1000 / fps), loop=0)


def _write_mp4(pictures, target: Source, fps: float, size: tuple[int, int]) -> None:
    encoders = subprocess.run(
        ["ffmpeg", "-hide_banner", "-encoders"], check=True, capture_output=True, text=True
    ).stdout
    codec = "libx264" if " libx264 " in encoders else "mpeg4"
    with tempfile.TemporaryDirectory() as scratch:
        path = os.path.join(scratch, "out.mp4")
        command = [
            "ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
            "-s", f"{size[0]}x{size[1]}", "-r", f"{fps:g}", "-i", "-",
            "-c:v", codec, "-pix_fmt", "yuv420p", "-movflags", "+faststart", path,
        ]  # fmt: skip
        with subprocess.Popen(command, stdin=subprocess.PIPE, stderr=subprocess.PIPE) as ffmpeg:
            assert ffmpeg.stdin is not None and ffmpeg.stderr is not None
            try:
                for picture in pictures:
                    ffmpeg.stdin.write(picture.tobytes())
            finally:
                ffmpeg.stdin.close()
            error = ffmpeg.stderr.read().decode(errors="replace").strip()
        if ffmpeg.returncode:
            raise RuntimeError(
                f"ffmpeg failed ({ffmpeg.returncode}): {error.splitlines()[-1] if error else 'no message'}"
            )
        with open(path, "rb") as f, output(target) as out:
            shutil.copyfileobj(f, out)
