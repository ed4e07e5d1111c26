"""Curves (motiontheater plot) and animations (motiontheater render): files checked by content."""

import io
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.cli import main
from variants import with_static_root

pytest.importorskip("matplotlib", reason="matplotlib is not installed (pip install 'motiontheater[plot]')")
Image = pytest.importorskip("PIL.Image", reason="pillow is not installed (pip install 'motiontheater[plot]')")

from motiontheater.views.plot import figure, plot
from motiontheater.views.render import render


def walk(frames: int = 60, rate: float = 30.0) -> mt.Motion:
    """A small ASF skeleton whose legs swing and whose root moves forward."""
    skeleton = mt.Skeleton(
        bones=(
            mt.Bone("lfemur", direction=(0, -1, 0), length=8.0, dofs=("rx", "ry", "rz")),
            mt.Bone("ltibia", direction=(0, -1, 0), length=8.0, dofs=("rx",)),
            mt.Bone("rfemur", direction=(0, -1, 0), length=8.0, dofs=("rx", "ry", "rz")),
            mt.Bone("spine", direction=(0, 1, 0), length=10.0, dofs=("rx", "rz")),
        ),
        hierarchy=(("root", ("lfemur", "rfemur", "spine")), ("lfemur", ("ltibia",))),
        units=(("mass", "1.0"), ("length", "0.45"), ("angle", "deg")),
    )
    t = np.arange(frames) / rate
    values = np.zeros((frames, len(skeleton.channels)))
    values[:, 1] = 16.0
    values[:, 2] = 20 * t
    values[:, 6] = 30 * np.sin(2 * np.pi * t)
    values[:, 9] = 20 + 20 * np.sin(2 * np.pi * t)
    values[:, 10] = -30 * np.sin(2 * np.pi * t)
    return mt.Motion(skeleton, values, frame_rate=rate)


def image(data: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB")).astype(int)


def test_figure_holds_the_channels_of_each_take():
    before = walk()
    after = before.mean(size=9)
    fig = figure([before, after], joints=["lfemur", "spine"], names=["before", "after"])
    axes = fig.get_axes()
    assert [a.get_ylabel().split("\n")[0] for a in axes] == [
        "lfemur rx",
        "lfemur ry",
        "lfemur rz",
        "spine rx",
        "spine rz",
    ]
    lines = axes[0].get_lines()
    assert [line.get_label() for line in lines] == ["before", "after"]
    np.testing.assert_array_equal(lines[0].get_xdata(), np.arange(1, 61))
    np.testing.assert_array_equal(lines[0].get_ydata(), before.channel("lfemur", "rx"))
    np.testing.assert_array_equal(lines[1].get_ydata(), after.channel("lfemur", "rx"))
    assert "degrees" in axes[0].get_ylabel()


def test_a_bvh_root_is_plotted_by_its_own_name(data_dir):
    walk01 = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    fig = figure([walk01, walk01.median(size=5)], joints=["Hips"])
    axes = fig.get_axes()
    assert [a.get_ylabel().split("\n")[0] for a in axes][:3] == ["Hips Xposition", "Hips Yposition", "Hips Zposition"]
    for ax, dof in zip(axes, walk01.skeleton.dofs("root")):
        assert len(ax.get_lines()) == 2  # it drew empty panels: the root is called root inside
        np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), walk01.channel("root", dof))


def test_compared_takes_are_aligned_in_time_and_framed():
    fast = walk(120, 60.0)
    slow = walk(60, 30.0)
    fig = figure([fast, slow], joints=["lfemur"], dofs=["rx"], frames=(11, 100))
    (ax,) = fig.get_axes()
    a, b = ax.get_lines()
    assert ax.get_xlim() == (11, 100)
    assert a.get_xdata()[0] == 11 and a.get_xdata()[-1] == 100
    # the 30 Hz take's frame k is the 60 Hz take's frame 1 + 2k
    np.testing.assert_array_equal(b.get_xdata(), 1 + 2 * np.arange(5, 50))


@pytest.mark.parametrize("fmt", ["png", "svg", "pdf"])
def test_plot_writes_valid_files(tmp_path, fmt):
    target = tmp_path / f"fig.{fmt}"
    before = walk()
    plot([before, before.median(size=5)], target, joints=["lfemur", "ltibia"], dpi=100)
    data = target.read_bytes()
    if fmt == "png":
        picture = image(data)
        assert picture.shape == (round((0.9 + 1.8 * 4) * 100), 800, 3)  # four panels of 1.8 in, 8 in wide
        ink = (picture.sum(axis=2) < 600).mean()
        assert 0.01 < ink < 0.5  # curves and labels, not a blank or a black page
        assert ((picture[..., 0] > 180) & (picture[..., 1] < 80)).any()  # the compared take in red
    elif fmt == "svg":
        root = ET.fromstring(data)
        assert root.tag.endswith("svg")
        assert len(root.findall(".//{http://www.w3.org/2000/svg}path")) > 20
    else:
        assert data.startswith(b"%PDF-") and data.rstrip().endswith(b"%%EOF")


def test_plot_refuses_bad_requests(tmp_path):
    motion = walk()
    with pytest.raises(ValueError, match="format"):
        plot([motion], tmp_path / "fig.jpg", joints=["lfemur"])
    with pytest.raises(ValueError, match="frames 0..10"):
        plot([motion], tmp_path / "fig.png", joints=["lfemur"], frames=(0, 10))
    with pytest.raises(ValueError, match="none of the dofs"):
        plot([motion], tmp_path / "fig.png", joints=["ltibia"], dofs=["rz"])
    with pytest.raises(mt.UnknownNameError, match="nose"):
        plot([motion], tmp_path / "fig.png", joints=["nose"])
    assert not list(tmp_path.iterdir())


def gif_frames(path, duration: int = 40) -> list[np.ndarray]:
    """The frames of a looping GIF whose frames last ``duration`` ms."""
    with Image.open(path) as gif:
        out = []
        for i in range(gif.n_frames):
            gif.seek(i)
            out.append(np.asarray(gif.convert("RGB")).astype(int))
        assert gif.info["duration"] == duration
        assert gif.info.get("loop") == 0
    return out


def test_render_gif_has_a_frame_per_instant_and_shows_the_walk(tmp_path):
    motion = walk(60, 30.0)  # 1.967 s
    target = tmp_path / "walk.gif"
    written = render([motion], target, fps=25, size=(160, 120))
    frames = gif_frames(target)
    assert written == len(frames) == 50  # 0, 0.04, ..., 1.96 s
    for picture in frames:
        assert picture.shape == (120, 160, 3)
        blue = (picture[..., 2] > 120) & (picture[..., 0] < 90)  # the skeleton's colour
        assert blue.sum() > 30
    assert not np.array_equal(frames[0], frames[12])  # the legs moved


def drawn_extent(picture) -> tuple[int, int]:
    """(height, width) in pixels of what is drawn in the skeleton's colour, below the caption."""
    below = picture[20:]
    rows, columns = np.nonzero((below[..., 2] > 120) & (below[..., 0] < 90))
    return int(np.ptp(rows)), int(np.ptp(columns))


@pytest.mark.parametrize(
    "name,variant",
    [("walk01.bvh", None), ("zombie.bvh", None), ("walk01.bvh", "static root"), ("walk01.bvh", "z-up")],
    ids=["y-up", "z-up (AnimatedDrawings)", "a static root turned above the hips", "turned to stand along z"],
)
def test_a_standing_take_is_drawn_standing_whatever_its_up_axis(data_dir, tmp_path, name, variant):
    take = mt.read_bvh(next(data_dir.glob(f"*/{name}")))
    if variant is not None:  # a z-up studio's frame above the hips, the points where they were or turned with it
        take = with_static_root(take, turn=(90.0, 0.0, 0.0), keep_world=variant == "static root")
    target = tmp_path / "stand.gif"
    render([take], target, fps=5, frames=(1, 2), size=(200, 200), **({"up": "z"} if variant == "z-up" else {}))
    tall, wide = drawn_extent(gif_frames(target, duration=200)[0])
    assert tall > wide, (tall, wide)


def test_render_of_a_range_with_a_compared_take(tmp_path):
    motion = walk(60, 30.0)
    target = tmp_path / "part.gif"
    written = render([motion, motion.mean(size=9)], target, fps=10, frames=(11, 40), size=(120, 90))
    assert written == len(gif_frames(target, 100)) == 10  # frames 11..40 at 30 Hz: 0.967 s


@pytest.mark.skipif(shutil.which("ffmpeg") is None or shutil.which("ffprobe") is None, reason="no ffmpeg here")
def test_render_mp4(tmp_path):
    target = tmp_path / "walk.mp4"
    assert render([walk()], target, fps=20, size=(160, 120)) == 40
    probe = subprocess.run(
        [
            "ffprobe",
            "-v",
            "error",
            "-count_frames",
            "-show_entries",
            "stream=width,height,nb_read_frames",
            "-of",
            "csv=p=0",
            str(target),
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert probe.stdout.strip() == "160,120,40"


def test_render_without_ffmpeg_says_so(tmp_path, monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(RuntimeError, match="MP4 needs ffmpeg"):
        render([walk()], tmp_path / "walk.mp4")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(fps=0), "fps"),
        (dict(size=(8, 8)), "size"),
        (dict(frames=(5, 99)), "frames 5..99"),
        (dict(format="avi"), "format"),
        (dict(fps=100, size=(16, 16), long=True), "1801 frames is too long"),
    ],
)
def test_render_refuses_bad_requests(tmp_path, kwargs, message):
    take = walk(541) if kwargs.pop("long", False) else walk()  # 18 s at 30 Hz
    with pytest.raises(ValueError, match=message):
        render([take], tmp_path / "walk.gif", **kwargs)
    assert not list(tmp_path.iterdir())


def test_cli_plot_and_render(tmp_path, data_dir, capsys):
    take = data_dir / "cmu" / "01_01.amc"
    smooth = tmp_path / "smooth.amc"
    assert main(["filter", "--median", "9", str(take), "-o", str(smooth)]) == 0
    fig = tmp_path / "fig.png"
    args = ["plot", str(take), "--joints", "lfemur,rtibia", "--compare", str(smooth), "--frames", "100:400"]
    assert main([*args, "--asf", str(data_dir / "cmu" / "01.asf"), "-o", str(fig), "--dpi", "50"]) == 0
    assert image(fig.read_bytes()).shape == (round((0.9 + 1.8 * 4) * 50), 400, 3)
    gif = tmp_path / "walk.gif"
    assert main(["render", str(take), "--frames", "1:120", "--fps", "10", "--size", "96x72", "-o", str(gif)]) == 0
    assert len(gif_frames(gif, 100)) == 10
    assert "wrote 10 frames at 10 fps" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["render", str(take), "--size", "96", "-o", str(gif)])
    assert "WIDTHxHEIGHT" in capsys.readouterr().err


@pytest.mark.parametrize("verb", ["plot", "render"])
def test_missing_matplotlib_is_one_line(tmp_path, data_dir, capsys, monkeypatch, verb):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib now raises ImportError
    take = str(data_dir / "cmu" / "01_01.amc")
    args = [verb, take, "-o", str(tmp_path / "out.png" if verb == "plot" else tmp_path / "out.gif")]
    assert main(args + (["--joints", "lfemur"] if verb == "plot" else [])) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert "pip install 'motiontheater[plot]'" in err
