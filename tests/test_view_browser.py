"""The viewer page in a real headless Chromium, driven by selenium and chromedriver.

Skipped, with the reason, only where no Chromium with its driver (Debian: apt-get install chromium
chromium-driver) or no selenium is installed.
"""

import base64
import io
import shutil
import sys
import time

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.views.viewer import write_page
from variants import with_offset_channels, with_static_root

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed (pip install selenium)")
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.actions.wheel_input import ScrollOrigin
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select, WebDriverWait

BROWSER = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)
DRIVER = shutil.which("chromedriver")
pytestmark = pytest.mark.skipif(
    BROWSER is None or DRIVER is None,
    reason="no Chromium with chromedriver here (Debian: apt-get install chromium chromium-driver)",
)


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    from selenium.webdriver.chrome.service import Service

    downloads = tmp_path_factory.mktemp("downloads")
    options = webdriver.ChromeOptions()
    options.binary_location = BROWSER
    for flag in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1280,800"):
        options.add_argument(flag)
    options.add_experimental_option("prefs", {"download.default_directory": str(downloads)})
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    driver.execute_cdp_cmd("Browser.setDownloadBehavior", {"behavior": "allow", "downloadPath": str(downloads)})
    driver.downloads = downloads
    yield driver
    driver.quit()


def cmu(data_dir, kind="amc"):
    if kind == "bvh":
        return mt.read_bvh(data_dir / "cmu" / "01_01.bvh")
    return mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))


def open_page(browser, tmp_path, takes, **options):
    """Write the page of the takes, open it from disk and wait until it is interactive."""
    path = tmp_path / "page.html"
    write_page(takes, path, **options)
    browser.get_log("browser")  # drop what earlier pages logged
    browser.get(path.as_uri())
    WebDriverWait(browser, 30).until(
        lambda d: d.execute_script(
            "return document.body.dataset.ready === '1' || !document.getElementById('error').hidden"
        )
    )
    error = browser.find_element(By.ID, "error")
    assert not error.is_displayed(), error.text
    return browser


def console_errors(browser):
    return [e for e in browser.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]


def frame_shown(browser) -> int:
    return int(browser.execute_script("return document.body.dataset.frame"))


def settle(browser) -> None:
    """Return after two animation frames: the page has drawn what the last input changed."""
    browser.execute_async_script(
        "const done = arguments[arguments.length - 1]; requestAnimationFrame(() => requestAnimationFrame(() => done()));"
    )


def wait_frame(browser, frame: int) -> None:
    """Wait until the page shows this frame number (it draws on the next animation frame)."""
    WebDriverWait(browser, 5).until(lambda d: frame_shown(d) == frame)


def screenshot(browser):
    image = pytest.importorskip("PIL.Image", reason="pillow is not installed")
    return np.asarray(image.open(io.BytesIO(browser.get_screenshot_as_png())).convert("RGB")).astype(int)


def joints_on_screen(browser, k=0):
    """Page pixel (x, y) of every joint of take k at the current frame as the page draws it (None
    for a joint it does not draw)."""
    return browser.execute_script(
        """
        const r = document.getElementById('view3d').getBoundingClientRect(), dpr = window.devicePixelRatio || 1;
        return mtView.drawn(arguments[0]).map((s) => (s ? [r.left + s[0] / dpr, r.top + s[1] / dpr] : null));""",
        k,
    )


def canvas_picture(browser):
    """The 3D view's own pixels (rows, columns, RGB), in the canvas pixels mtView.drawn gives."""
    image = pytest.importorskip("PIL.Image", reason="pillow is not installed")
    url = browser.execute_script("return document.getElementById('view3d').toDataURL('image/png')")
    png = base64.b64decode(url.split(",", 1)[1])
    return np.asarray(image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def drawn_points(browser, k=0) -> np.ndarray:
    """Canvas pixels (n, 2) of the joints of take k the page draws at the shown frame."""
    return np.array([s for s in browser.execute_script("return mtView.drawn(arguments[0])", k) if s is not None])


def inked(picture, x, y, radius=2):
    """Whether any pixel within radius of (x, y) is not the white background."""
    x, y = round(x), round(y)
    patch = picture[max(0, y - radius) : y + radius + 1, max(0, x - radius) : x + radius + 1]
    return bool((patch.sum(axis=2) < 3 * 235).any())


@pytest.mark.parametrize("kind", ["amc", "bvh"])
def test_real_take_opens_and_its_skeleton_is_drawn(browser, data_dir, tmp_path, kind):
    motion = cmu(data_dir, kind)
    open_page(browser, tmp_path, [motion], names=[f"01_01.{kind}"])
    assert console_errors(browser) == []
    # the page's forward kinematics reproduce Motion.positions()
    expected = motion.positions()
    for frame in (0, 1, 777, motion.frames - 1):
        got = np.array(browser.execute_script("return mtView.positions(0, arguments[0])", frame))
        np.testing.assert_allclose(got.reshape(-1, 3), expected[frame], rtol=0, atol=1e-9)
    picture = screenshot(browser)
    points = joints_on_screen(browser)
    assert len(points) == len(motion.skeleton.joint_names)
    assert all(inked(picture, x, y) for x, y in points)
    # and the test could fail: the corners of the 3D view are background
    box = browser.find_element(By.ID, "view3d").rect
    assert not inked(picture, box["x"] + box["width"] - 6, box["y"] + 30)


VARIETY = real_files("*/*.bvh") + real_files("edge/*.amc") + real_files("hdm05/HDM_bd_squat1Reps_003_120.amc")


@pytest.mark.parametrize("path", VARIETY, ids=ids(VARIETY))
def test_every_kind_of_file_opens(browser, tmp_path, path):
    """Every real BVH (every producer: orders, odd names, z-up, game rigs, a one-frame rest pose), a
    non-CMU ASF, HDM05: no console error, the page's forward kinematics, and the figure in view at
    its first, middle and last frame with the camera following it."""
    if path.suffix == ".bvh":
        motion = mt.read_bvh(path)
    else:
        motion = mt.read_amc(path, mt.read_asf(mt.skeleton_path_for(path)))
    open_page(browser, tmp_path, [motion], names=[path.name])
    assert console_errors(browser) == []
    expected = motion.positions()
    for frame in sorted({0, motion.frames // 2, motion.frames - 1}):
        got = np.array(browser.execute_script("return mtView.positions(0, arguments[0])", frame))
        np.testing.assert_allclose(got.reshape(-1, 3), expected[frame], rtol=1e-12, atol=1e-9)
        assert_in_view(browser, frame)
    play_and_look(browser)
    assert console_errors(browser) == []
    assert not browser.find_element(By.ID, "error").is_displayed()


def assert_in_view(browser, index, least=0.2):
    """At frame index, every drawn joint of the first take lies on the canvas and the figure spans at
    least ``least`` of the canvas's height (not a tiny far-away figure)."""
    browser.execute_script("mtView.seek(arguments[0])", index)
    settle(browser)
    width, height = browser.execute_script("const c = document.getElementById('view3d'); return [c.width, c.height]")
    shown = browser.execute_script("return mtView.drawn(0)")
    points = np.array([s for s in shown if s is not None])
    assert len(points), f"frame {index}: no joint drawn"
    assert (points >= 0).all() and (points[:, 0] <= width).all() and (points[:, 1] <= height).all(), (
        f"frame {index}: joints off the {width}x{height} canvas: {points.min(axis=0)} .. {points.max(axis=0)}"
    )
    assert np.ptp(points, axis=0).max() >= least * height, f"frame {index}: the figure is {np.ptp(points, axis=0)}"


def play_and_look(browser):
    """Play a moment and pause (the drawing of frames in between runs too)."""
    browser.execute_script("mtView.play()")
    time.sleep(0.3)
    browser.execute_script("mtView.pause()")


def standing_frame(motion: mt.Motion, up: int) -> tuple[int, float]:
    """The frame at which the figure is tallest for its width along the coordinate axis ``up`` (its
    producer's), and that height over width."""
    positions = motion.positions()
    across = [a for a in range(3) if a != up]
    tall = np.ptp(positions[:, :, up], axis=1)
    wide = np.ptp(positions[:, :, across], axis=1).max(axis=1)
    ratio = tall / wide
    best = int(np.nanargmax(ratio))
    return best, float(ratio[best])


def drawn_extent(browser) -> tuple[float, float]:
    points = drawn_points(browser)
    return tuple(np.ptp(points, axis=0))


Z_UP_FILES = real_files("bvh/zombie.bvh") + real_files("bvh-producers/*.bvh")
Z_UP_FILES = [p for p in Z_UP_FILES if p.name in {"zombie.bvh", "video2bvh_cxk.bvh", "pybvh_bvh_example.bvh"}]


@pytest.mark.parametrize("path", Z_UP_FILES, ids=ids(Z_UP_FILES))
def test_a_z_up_file_stands_upright(browser, tmp_path, path):
    """Real z-up files (their producers' frame): at the frame where the figure stands tallest along
    z, the drawn figure is taller than wide, with its top joint above its bottom one on screen."""
    motion = mt.read_bvh(path)
    assert_stands(browser, tmp_path, motion, 2, path.name)


def test_a_take_turned_z_up_by_its_exporter_stands_upright(browser, data_dir, tmp_path):
    """walk01 under a static root that turns it a quarter about x, as a z-up exporter writes it: it
    stands as walk01 does, on the same pixels when the two are compared; told it is y-up (--up y),
    it lies on the floor."""
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    take = with_static_root(walk, turn=(90.0, 0.0, 0.0), keep_world=False)
    assert_stands(browser, tmp_path, take, 2, "walk01 z-up")
    tall = drawn_extent(browser)[1]
    # compared with walk01 as it is, each stands on its own up axis: drawn on the same pixels
    open_page(browser, tmp_path, [take, walk])
    browser.execute_script("mtView.seek(arguments[0])", standing_frame(take, 2)[0])
    settle(browser)
    turned, plain = (browser.execute_script("return mtView.drawn(arguments[0])", k) for k in (0, 1))
    assert turned[0] is None  # the static root
    np.testing.assert_allclose(np.array(turned[1:], float), np.array(plain, float), atol=1e-6)
    open_page(browser, tmp_path, [take], up="y")
    assert browser.execute_script("return mtView.state.takes[0].up") == "y"
    browser.execute_script("mtView.seek(arguments[0])", standing_frame(take, 2)[0])
    settle(browser)
    wide_lying, tall_lying = drawn_extent(browser)
    assert tall_lying < wide_lying and tall_lying < tall / 2  # the test could fail: lying, it is drawn flat


def assert_stands(browser, tmp_path, motion, up, name):
    frame, ratio = standing_frame(motion, up)
    assert ratio > 1.5, f"{name}: no frame stands along its up axis (best {ratio:.2f} at {frame})"
    open_page(browser, tmp_path, [motion], names=[name])
    assert browser.execute_script("return mtView.state.takes[0].up") == "z"
    browser.execute_script("mtView.seek(arguments[0])", frame)
    settle(browser)
    wide, tall = drawn_extent(browser)
    assert tall > wide, f"{name} at frame {frame + 1}: drawn {wide:.0f} wide, {tall:.0f} tall"
    shown = browser.execute_script("return mtView.drawn(0)")
    drawn = [j for j, s in enumerate(shown) if s is not None]
    heights = motion.positions()[frame, drawn, up]
    top, bottom = (shown[drawn[f(heights)]] for f in (np.nanargmax, np.nanargmin))
    assert top[1] < bottom[1]  # head up: canvas y grows downwards
    assert console_errors(browser) == []


def shifted(motion: mt.Motion, dx: float, dz: float) -> mt.Motion:
    """The take moved over the floor (dx, dz in its units): its root's position channels shifted."""
    values = motion.values.copy()
    tx, _, tz = (motion.columns("root")[motion.skeleton.root.order.index(d)] for d in ("tx", "ty", "tz"))
    values[:, tx] += dx
    values[:, tz] += dz
    return motion.replace(values=values)


def game_rigs():
    """Travelling takes laid out as game studios write them (six channels on every joint, a static
    root), and a real game rig's bind pose."""
    walk, lafan = real_files("bvh/walk01.bvh"), real_files("bvh-producers/bvhTools_test2_lafan1.bvh")
    geno = real_files("bvh-producers/lafan1-resolved_Geno_bind.bvh")
    cases = []
    if walk:
        take = with_offset_channels(mt.read_bvh(walk[0]))
        cases.append(pytest.param(lambda: with_static_root(shifted(take, 4000.0, -2500.0)), id="walk01-far-away"))
        cases.append(pytest.param(lambda: with_static_root(take, shift=(-3000.0, 0.0, 5000.0)), id="walk01-far-root"))
    if lafan:
        cases.append(
            pytest.param(lambda: with_static_root(with_offset_channels(mt.read_bvh(lafan[0]))), id="lafan1-take")
        )
    if geno:
        cases.append(pytest.param(lambda: mt.read_bvh(geno[0]), id="lafan1-resolved-Geno-bind"))
    return cases


@pytest.mark.parametrize("make", game_rigs())
def test_the_camera_keeps_a_travelling_game_rig_in_view(browser, tmp_path, make):
    """The camera follows the body (the joint that travels), not the static root; no bone or point is
    drawn from the static root: nothing of the figure's colour lies outside the drawn joints."""
    motion = make()
    open_page(browser, tmp_path, [motion])
    names = motion.skeleton.joint_names
    static = motion.skeleton.root.name == "Reference"
    assert browser.execute_script("return mtView.state.takes[0].body") == names.index("Hips" if static else "root")
    skeleton, hidden = motion.skeleton, {"root"} if static else set()
    drawn_bones = [[skeleton.parent(j), j] for j in names[1:] if skeleton.parent(j) not in hidden]
    assert browser.execute_script("return mtView.bones(0)") == drawn_bones
    assert browser.find_element(By.ID, "joint-name").text == ("Hips" if static else motion.skeleton.root.name)
    for index in sorted({0, motion.frames // 2, motion.frames - 1}):
        assert_in_view(browser, index, least=0.3)
        picture, points = canvas_picture(browser), drawn_points(browser)
        lo, hi = np.floor(points.min(axis=0)).astype(int) - 8, np.ceil(points.max(axis=0)).astype(int) + 8
        blue = (picture[..., 2] - picture[..., 0] > 60) & (picture[..., 2] > 100)
        blue[max(lo[1], 0) : hi[1], max(lo[0], 0) : hi[0]] = False
        assert not blue.any(), f"frame {index + 1}: the figure's colour away from its joints"
    play_and_look(browser)
    assert console_errors(browser) == []


def test_play_advances_the_frame_and_the_picture(browser, data_dir, tmp_path):
    open_page(browser, tmp_path, [cmu(data_dir)])
    first = frame_shown(browser)
    before = browser.execute_script("return document.getElementById('view3d').toDataURL()")
    browser.find_element(By.ID, "b-play").click()
    WebDriverWait(browser, 10).until(lambda d: frame_shown(d) >= first + 30)
    browser.find_element(By.ID, "b-play").click()
    assert browser.execute_script("return mtView.state.playing") is False
    after = browser.execute_script("return document.getElementById('view3d').toDataURL()")
    assert after != before
    stats = browser.execute_script("return mtView.state.stats")
    assert stats["playTicks"] > 0
    assert console_errors(browser) == []


def test_keys_step_and_jump(browser, data_dir, tmp_path):
    motion = cmu(data_dir)
    open_page(browser, tmp_path, [motion])
    body = browser.find_element(By.TAG_NAME, "body")
    body.send_keys(Keys.ARROW_RIGHT)
    wait_frame(browser, 2)
    body.send_keys(Keys.SHIFT, Keys.ARROW_RIGHT)
    wait_frame(browser, 12)
    body.send_keys(Keys.ARROW_LEFT)
    wait_frame(browser, 11)
    body.send_keys(Keys.END)
    wait_frame(browser, motion.frames)
    body.send_keys("r")
    assert browser.execute_script("return mtView.state.reverse") is True
    body.send_keys(" ")
    WebDriverWait(browser, 10).until(lambda d: frame_shown(d) < motion.frames - 20)  # playing backwards
    body.send_keys(" ")
    body.send_keys(Keys.HOME)
    wait_frame(browser, 1)
    state = "return [mtView.state.speed, mtView.state.loop, mtView.state.follow]"
    assert browser.execute_script(state) == [1, True, True]
    body.send_keys("d", "l", "f")
    assert browser.execute_script(state) == [2, False, False]
    assert browser.find_element(By.ID, "b-speed").get_attribute("aria-pressed") == "true"
    body.send_keys(Keys.ARROW_RIGHT * 4, "[")
    body.send_keys(Keys.SHIFT, Keys.ARROW_RIGHT)
    body.send_keys("]")
    assert browser.find_element(By.ID, "e-from").get_attribute("value") == "5"
    assert browser.find_element(By.ID, "e-to").get_attribute("value") == "15"
    body.send_keys("?")
    assert browser.find_element(By.ID, "help").is_displayed()
    body.send_keys(Keys.ESCAPE)
    assert not browser.find_element(By.ID, "help").is_displayed()


def test_orbit_zoom_and_pan_move_the_camera(browser, data_dir, tmp_path):
    open_page(browser, tmp_path, [cmu(data_dir)])
    view = browser.find_element(By.ID, "view3d")
    camera = "return document.getElementById('view3d').toDataURL()"
    pictures = [browser.execute_script(camera)]
    ActionChains(browser).move_to_element(view).click_and_hold().move_by_offset(80, 30).release().perform()
    settle(browser)
    pictures.append(browser.execute_script(camera))
    before = joints_on_screen(browser)
    ActionChains(browser).scroll_from_origin(ScrollOrigin.from_element(view), 0, 300).perform()  # zoom out
    settle(browser)
    after = joints_on_screen(browser)
    spread = lambda points: np.ptp(np.array(points), axis=0).max()
    assert spread(after) < spread(before)
    ActionChains(browser).move_to_element(view).key_down(Keys.SHIFT).click_and_hold().move_by_offset(
        50, 0
    ).release().key_up(Keys.SHIFT).perform()
    settle(browser)
    moved = joints_on_screen(browser)
    shift = np.array(moved).mean(axis=0) - np.array(after).mean(axis=0)
    assert abs(shift[0] - 50) < 10 and abs(shift[1]) < 10  # panned with the pointer
    pictures.append(browser.execute_script(camera))
    assert len(set(pictures)) == 3


def test_tree_collapses(browser, data_dir, tmp_path):
    open_page(browser, tmp_path, [cmu(data_dir)])
    femur = browser.find_element(By.CSS_SELECTOR, ".jname[data-name='lfemur']")
    foot = browser.find_element(By.CSS_SELECTOR, ".jname[data-name='lfoot']")
    assert foot.is_displayed()
    femur.find_element(By.XPATH, "preceding-sibling::button").click()
    assert not foot.is_displayed() and femur.is_displayed()
    femur.find_element(By.XPATH, "preceding-sibling::button").click()
    assert foot.is_displayed()


def test_one_hour_take_opens_decimated(browser, data_dir, tmp_path):
    take = cmu(data_dir)
    hour = take.replace(values=np.tile(take.values, (432_000 // take.frames + 1, 1))[:432_000])
    open_page(browser, tmp_path, [hour], names=["hour.amc"])
    note = browser.find_element(By.ID, "note")
    assert note.is_displayed() and "1 frame in 15 of its 432,000 is shown (8 Hz)" in note.text
    assert not browser.find_element(By.ID, "editor").is_displayed()
    assert browser.execute_script("return mtView.state.takes[0].frames") == 28_800
    browser.execute_script("mtView.seek(28_799)")
    wait_frame(browser, 432_000 - 14)  # the last frame kept: 1 + 28,799 x 15
    got = np.array(browser.execute_script("return mtView.positions(0, 28799)")).reshape(-1, 3)
    np.testing.assert_allclose(got, hour.replace(values=hour.values[-15:-14]).positions()[0], atol=1e-9)
    assert console_errors(browser) == []


def test_selecting_a_joint_shows_its_values_and_rotation(browser, data_dir, tmp_path):
    motion = cmu(data_dir)
    open_page(browser, tmp_path, [motion])
    browser.find_element(By.CSS_SELECTOR, ".jname[data-name='lfemur']").click()
    field = browser.find_element(By.ID, "frame")
    field.send_keys(Keys.CONTROL, "a")
    field.send_keys("1234", Keys.ENTER)
    wait_frame(browser, 1234)
    assert browser.find_element(By.ID, "joint-name").text == "lfemur"
    cells = browser.find_elements(By.CSS_SELECTOR, "#channels td[data-dof]")
    shown = {c.get_attribute("data-dof"): float(c.get_attribute("data-value")) for c in cells}
    expected = {dof: motion.values[1233, col] for dof, col in zip(("rx", "ry", "rz"), motion.columns("lfemur"))}
    assert shown == expected  # exactly the stored values
    for cell in cells:
        assert float(cell.text) == pytest.approx(float(cell.get_attribute("data-value")), rel=1e-7)
    from mtcore.rotations import quaternions_to_rotvecs

    q = motion.rotations(local=True, quaternions=True)[1233, motion.skeleton.joint_names.index("lfemur")]
    got = browser.execute_script("return JSON.parse(document.getElementById('axis-angle').dataset.rotvec)")
    np.testing.assert_allclose(got, quaternions_to_rotvecs(q), atol=1e-9)
    assert "\u00b0 about (" in browser.find_element(By.ID, "axis-angle").text


def test_clicking_a_joint_in_the_view_selects_it(browser, data_dir, tmp_path):
    motion = cmu(data_dir)
    open_page(browser, tmp_path, [motion])
    j = motion.skeleton.joint_names.index("lhand")
    x, y = joints_on_screen(browser)[j]
    view = browser.find_element(By.ID, "view3d").rect
    ActionChains(browser).move_to_element_with_offset(
        browser.find_element(By.ID, "view3d"), x - view["x"] - view["width"] / 2, y - view["y"] - view["height"] / 2
    ).click().perform()
    assert browser.find_element(By.ID, "joint-name").text == "lhand"


def curve_x(browser, frame_index):
    """Page x of a frame index on the curves."""
    return browser.execute_script(
        """const t = mtView.state.takes[0], c = document.getElementById('curves'), r = c.getBoundingClientRect();
        const dpr = window.devicePixelRatio || 1, left = 56, right = 10;
        const T = Math.max(...mtView.state.takes.map(k => (k.frames - 1) * k.step / k.frameRate));
        return r.left + left + (r.width - left - right) * (arguments[0] * t.step / t.frameRate) / T;""",
        frame_index,
    )


def drag_on_curves(browser, a, b):
    curves = browser.find_element(By.ID, "curves")
    rect = curves.rect
    y = rect["height"] / 2 - rect["height"] / 2 + 20  # near the top of the plot, inside it
    xa, xb = (curve_x(browser, i) - rect["x"] - rect["width"] / 2 for i in (a, b))
    ActionChains(browser).move_to_element_with_offset(
        curves, xa, y - rect["height"] / 2 + 20
    ).click_and_hold().move_by_offset((xb - xa) / 2, 0).move_by_offset((xb - xa) / 2, 0).release().perform()


def test_curves_seek_on_click(browser, data_dir, tmp_path):
    open_page(browser, tmp_path, [cmu(data_dir)])
    curves = browser.find_element(By.ID, "curves")
    rect = curves.rect
    x = curve_x(browser, 1500) - rect["x"] - rect["width"] / 2
    ActionChains(browser).move_to_element_with_offset(curves, x, 0).click().perform()
    WebDriverWait(browser, 5).until(lambda d: abs(frame_shown(d) - 1501) <= 3)  # a pixel is about 3 frames wide


def test_compared_takes_are_overlaid_and_aligned(browser, data_dir, tmp_path):
    motion = cmu(data_dir)
    smooth = motion.median(size=9)
    open_page(browser, tmp_path, [motion, smooth], names=["01_01.amc", "median 9"])
    legend = browser.find_element(By.ID, "legend").text
    assert "01_01.amc" in legend and "median 9" in legend
    browser.execute_script("mtView.select('rhumerus'); mtView.seek(600)")
    wait_frame(browser, 601)
    cells = browser.find_elements(By.CSS_SELECTOR, "#channels td[data-take='1']")
    expected = smooth.values[600, smooth.columns("rhumerus")]
    assert [float(c.get_attribute("data-value")) for c in cells] == list(expected)
    # the ghost skeleton is drawn at the same time
    picture = screenshot(browser)
    assert sum(inked(picture, x, y) for x, y in joints_on_screen(browser, 1)) >= 25
    assert console_errors(browser) == []


def test_footplants_are_marked_on_the_feet_and_the_timeline(browser, data_dir, tmp_path):
    motion = cmu(data_dir)
    flags = np.zeros(motion.frames, bool)
    flags[:200] = True
    open_page(browser, tmp_path, [motion], contacts=[{"ltoes": flags}])
    browser.execute_script("mtView.seek(100)")
    wait_frame(browser, 101)
    settle(browser)
    picture = screenshot(browser)
    j = motion.skeleton.joint_names.index("ltoes")
    x, y = joints_on_screen(browser)[j]
    green = (picture[..., 1] > 120) & (picture[..., 0] < 80) & (picture[..., 2] < 110)
    assert green[int(y) - 3 : int(y) + 4, int(x) - 3 : int(x) + 4].any()
    # on the timeline strip under the curves: inked where planted, blank after
    rect = browser.find_element(By.ID, "curves").rect
    strip_y = int(rect["y"] + rect["height"] - 7)
    xa, xb = curve_x(browser, 100), curve_x(browser, 1500)
    assert inked(picture, xa, strip_y, 1) and not inked(picture, xb, strip_y, 1)
    browser.execute_script("mtView.seek(1000)")
    wait_frame(browser, 1001)
    settle(browser)
    picture = screenshot(browser)
    x, y = joints_on_screen(browser)[j]
    green = (picture[..., 1] > 120) & (picture[..., 0] < 80) & (picture[..., 2] < 110)
    assert not green[int(y) - 3 : int(y) + 4, int(x) - 3 : int(x) + 4].any()


def green_near(picture, x, y, radius=3) -> bool:
    """Whether the footplant green is drawn within radius pixels of (x, y)."""
    patch = picture[round(y) - radius : round(y) + radius + 1, round(x) - radius : round(x) + radius + 1]
    return bool(((patch[..., 1] > 120) & (patch[..., 0] < 80) & (patch[..., 2] < 110)).any())


def test_detected_footplants_are_shown_on_the_feet_the_clock_and_the_timeline(browser, data_dir, tmp_path):
    """motiontheater view --plants on a real walk: at a frame where the left foot stands, its heel
    (marked at the ankle: CMU has no heel joint) and ball are green, listed beside the clock and
    inked on their timeline rows; in its swing, none of it."""
    from motiontheater.cli import main
    from motiontheater.feet.footskate import contacts_of, prepare

    take = data_dir / "cmu" / "07_05-walk.amc"
    motion = mt.read_amc(take, mt.read_asf(data_dir / "cmu" / "07-walk.asf"))
    arrays, ground, mpu = prepare(motion)
    masks = contacts_of(None, motion, arrays, ground, mpu).masks(arrays.legs)  # (legs, frames, heel and ball)
    labels = ["lfoot heel", "lfoot ball", "rfoot heel", "rfoot ball"]
    out = tmp_path / "walk.html"
    assert main(["view", str(take), "--no-open", "--plants", "-o", str(out)]) == 0
    browser.get_log("browser")
    browser.get(out.as_uri())
    WebDriverWait(browser, 30).until(lambda d: d.execute_script("return document.body.dataset.ready === '1'"))
    names = motion.skeleton.point_names
    ankle, ball = names.index("ltibia"), names.index("lfoot")  # an ASF bone's point is where it ends
    positions = motion.positions()
    # frames 5 or more from a change of the left foot's plants (a pixel on the timeline holds two frames)
    margin = np.ones(9, int)
    standing = np.flatnonzero(np.convolve(masks[0].all(axis=1).astype(int), margin, "same") == 9)
    swinging = np.flatnonzero(np.convolve(masks[0].any(axis=1).astype(int), margin, "same") == 0)
    assert len(standing) and len(swinging)
    # in the swing, the frame where the left foot is farthest from the right one: no ring of the right foot near it
    apart = np.linalg.norm(positions[swinging, ankle] - positions[swinging, names.index("rtibia")], axis=1)
    cases = ((int(standing[len(standing) // 2]), True), (int(swinging[np.argmax(apart)]), False))
    rect = browser.find_element(By.ID, "curves").rect
    for (index, planted), (other, other_planted) in zip(cases, cases[::-1]):
        browser.execute_script("mtView.seek(arguments[0])", index)
        wait_frame(browser, index + motion.first_frame)
        settle(browser)
        shown = [label for label, flags in zip(labels, masks.transpose(0, 2, 1).reshape(4, -1)) if flags[index]]
        assert browser.find_element(By.ID, "planted").text == "planted: " + (", ".join(shown) or "none")
        assert ("lfoot heel" in shown and "lfoot ball" in shown) == planted
        picture = screenshot(browser)
        on_screen = joints_on_screen(browser)
        assert green_near(picture, *on_screen[ankle]) == planted
        assert green_near(picture, *on_screen[ball]) == planted
        for row in (0, 1):  # the left foot's rows under the curves, at the other frame (the playhead is at this one)
            y = rect["y"] + rect["height"] - 7 * (4 - row) + 0.5
            assert inked(picture, curve_x(browser, other), y, 1) == other_planted
    # the clock's list changes on the very frame a plant starts
    start = int(np.flatnonzero(np.diff(masks[0, :, 0].astype(int)) == 1)[0]) + 1
    for index in (start - 1, start):
        browser.execute_script("mtView.seek(arguments[0])", index)
        wait_frame(browser, index + motion.first_frame)
        assert ("lfoot heel" in browser.find_element(By.ID, "planted").text) == (index == start)
    assert console_errors(browser) == []


def apply_recipe(text: str, motion: mt.Motion, tmp_path) -> mt.Motion:
    """The recipe applied by the command line (motiontheater apply) to the take, read back."""
    from motiontheater.cli import main

    recipe, take = (
        tmp_path / "steps.toml",
        tmp_path / ("take.bvh" if motion.skeleton.convention == "bvh" else "take.amc"),
    )
    recipe.write_text(text, encoding="utf-8")
    mt.write_take(motion, take)
    if take.suffix == ".amc":
        mt.write_asf(motion.skeleton, take.with_suffix(".asf"))
    out = take.with_name("out" + take.suffix)
    assert main(["apply", str(take), "--recipe", str(recipe), "-o", str(out)]) == 0
    return mt.read_take(out, take.with_suffix(".asf") if take.suffix == ".amc" else None)


def previewed(browser, shape):
    return np.array(browser.execute_script("return mtView.values(0)"), float).reshape(shape)


STACKS = {
    "euler": [dict(kind="euler", first=300, last=420, joints=["lfemur", "ltibia"])],
    "slerp": [dict(kind="slerp", first=100, last=260, joints=None)],
    "expmap": [dict(kind="expmap", first=1000, last=1200, joints=["root", "rhumerus", "rradius"])],
    "aligned_expmap": [dict(kind="aligned_expmap", first=2000, last=2700, joints=None)],
    "median3": [dict(kind="median3", first=1, last=900, joints=None)],
    "median": [dict(kind="median", first=50, last=1600, joints=None, size=9)],
    "mean": [dict(kind="mean", first=400, last=2751, joints=["root", "lowerback"], size=7)],
    "binomial": [dict(kind="binomial", first=1, last=2751, joints=None, size=5)],
    "stacked": [
        dict(kind="median3", first=1, last=2751, joints=None),
        dict(kind="slerp", first=500, last=700, joints=["lhumerus"]),
        dict(kind="binomial", first=600, last=900, joints=["lhumerus", "lradius"], size=7),
        dict(kind="aligned_expmap", first=880, last=1400, joints=None),
    ],
}


@pytest.mark.parametrize("kind", ["amc", "bvh", "radians"])
@pytest.mark.parametrize("stack", list(STACKS))
def test_recipe_from_the_page_gives_the_previewed_motion(browser, data_dir, tmp_path, kind, stack):
    motion = cmu(data_dir, "bvh" if kind == "bvh" else "amc")
    if kind == "radians":
        motion = motion.to_radians()
    names = {"lfemur": "LeftUpLeg", "ltibia": "LeftLeg", "rhumerus": "RightArm", "rradius": "RightForeArm"}
    names |= {"root": "root", "lhumerus": "LeftArm", "lradius": "LeftForeArm", "lowerback": "LowerBack"}
    steps = STACKS[stack]
    if kind == "bvh":
        steps = [dict(s, joints=None if s["joints"] is None else [names[j] for j in s["joints"]]) for s in steps]
    open_page(browser, tmp_path, [motion])
    for step in steps:
        browser.execute_script("mtView.addStep(arguments[0])", step)
    recipe = browser.execute_script("return mtView.recipe()")
    assert recipe.count("[[step]]") == len(steps)
    expected = apply_recipe(recipe, motion, tmp_path).values
    got = previewed(browser, motion.values.shape)
    assert np.abs(got - expected).max() <= 1e-6
    assert not np.array_equal(expected, motion.values)  # the steps did something
    assert console_errors(browser) == []


def test_preview_over_missing_and_infinite_samples(browser, data_dir, tmp_path):
    """NaN and inf in the frames edited: the page's steps treat them as the package's do."""
    motion = cmu(data_dir)
    values = motion.values.copy()
    femur, humerus = motion.columns("lfemur"), motion.columns("rhumerus")
    values[300:304, femur[0]] = np.nan  # a gap inside a filtered range
    values[310, femur[1]] = np.inf
    values[500, humerus] = np.nan  # a key of an interpolation
    values[200:220, humerus[2]] = np.nan  # a gap at the start of a range
    motion = motion.replace(values=values)
    open_page(browser, tmp_path, [motion])
    steps = [
        dict(kind="median", first=290, last=330, joints=["lfemur"], size=5),
        dict(kind="mean", first=200, last=260, joints=["rhumerus"], size=7),
        dict(kind="binomial", first=280, last=320, joints=None, size=5),
        dict(kind="median3", first=290, last=320, joints=None),
        dict(kind="slerp", first=480, last=500, joints=["rhumerus"]),
    ]
    for step in steps:
        browser.execute_script("mtView.addStep(arguments[0])", step)
    expected = mt.Pipeline.from_toml(browser.execute_script("return mtView.recipe()")).apply(motion).values
    got = np.array(
        browser.execute_script(
            "return mtView.values(0).map(v => Number.isNaN(v) ? 'nan' : v === Infinity ? 'inf' : v === -Infinity ? '-inf' : v)"
        )
    )
    got = got.astype(float).reshape(motion.values.shape)
    assert np.array_equal(np.isnan(got), np.isnan(expected)) and np.array_equal(np.isinf(got), np.isinf(expected))
    finite = np.isfinite(expected)
    assert np.array_equal(got[~finite & ~np.isnan(expected)], expected[~finite & ~np.isnan(expected)])
    assert np.abs(got[finite] - expected[finite]).max() <= 1e-6
    assert console_errors(browser) == []


def test_editing_through_the_controls(browser, data_dir, tmp_path):
    motion = cmu(data_dir)
    open_page(browser, tmp_path, [motion], names=["01_01.amc"])
    browser.find_element(By.CSS_SELECTOR, ".jname[data-name='rfemur']").click()
    drag_on_curves(browser, 400, 700)
    first = int(browser.find_element(By.ID, "e-from").get_attribute("value"))
    last = int(browser.find_element(By.ID, "e-to").get_attribute("value"))
    assert abs(first - 401) <= 3 and abs(last - 701) <= 3
    Select(browser.find_element(By.ID, "e-kind")).select_by_value("slerp")
    browser.find_element(By.ID, "e-add").click()
    Select(browser.find_element(By.ID, "e-kind")).select_by_value("binomial")
    size = browser.find_element(By.ID, "e-size")
    size.clear()
    size.send_keys("7")
    Select(browser.find_element(By.ID, "e-joints")).select_by_value("subtree")
    browser.find_element(By.ID, "e-add").click()
    recipe = browser.find_element(By.ID, "recipe").get_attribute("value")
    parsed = tomllib.loads(recipe)["step"]
    assert parsed[0] == {"run": "slerp", "frames": [first, last], "joints": ["rfemur"]}
    assert parsed[1] == {
        "run": "binomial",
        "size": 7,
        "frames": [first, last],
        "joints": ["rfemur", "rtibia", "rfoot", "rtoes"],
    }
    expected = apply_recipe(recipe, motion, tmp_path).values
    assert np.abs(previewed(browser, motion.values.shape) - expected).max() <= 1e-6
    # a bad step is refused with a message and changes nothing
    size.clear()
    size.send_keys("4")
    browser.find_element(By.ID, "e-add").click()
    assert "odd" in browser.find_element(By.ID, "e-message").text
    assert browser.find_element(By.ID, "recipe").get_attribute("value") == recipe
    # the recipe downloads as a file
    browser.find_element(By.ID, "e-download").click()
    target = browser.downloads / "01_01.recipe.toml"
    WebDriverWait(browser, 10).until(lambda d: target.exists())
    assert target.read_text(encoding="utf-8") == recipe
    # removing a step updates the preview
    browser.find_element(By.CSS_SELECTOR, "#stack li:last-child button").click()
    recipe = browser.find_element(By.ID, "recipe").get_attribute("value")
    assert recipe.count("[[step]]") == 1
    assert np.abs(previewed(browser, motion.values.shape) - apply_recipe(recipe, motion, tmp_path).values).max() <= 1e-6


def test_edits_on_a_game_rig_name_its_own_joints(browser, data_dir, tmp_path):
    """Drawn from its body, a game rig is still edited as the take it is: the recipe names its joints
    (the static root too), and motiontheater apply gives the motion previewed."""
    motion = with_static_root(with_offset_channels(mt.read_bvh(data_dir / "bvh" / "walk01.bvh")), shift=(50, 0, 80))
    open_page(browser, tmp_path, [motion])
    browser.find_element(By.CSS_SELECTOR, ".jname[data-name='root']").click()  # the still root is listed, as Reference
    assert browser.find_element(By.ID, "joint-name").text == "Reference"
    steps = [
        dict(kind="slerp", first=20, last=60, joints=["Hips", "LeftUpLeg"]),
        dict(kind="binomial", first=1, last=101, joints=None, size=5),
    ]
    for step in steps:
        browser.execute_script("mtView.addStep(arguments[0])", step)
    recipe = browser.execute_script("return mtView.recipe()")
    assert tomllib.loads(recipe)["step"][0]["joints"] == ["Hips", "LeftUpLeg"]
    expected = apply_recipe(recipe, motion, tmp_path).values
    got = previewed(browser, motion.values.shape)
    assert np.abs(got - expected).max() <= 1e-6 and not np.array_equal(expected, motion.values)
    assert console_errors(browser) == []


def test_long_take_names_leave_the_joint_values_in_view(browser, tmp_path, data_dir):
    """HDM05's take names are long: the selected joint's table cuts them short (whole on hover) and
    its values stay inside the side panel, with no sideways scrolling."""
    folder = data_dir / "hdm05"
    names = ["HDM_bd_elbowToKnee1RepsLelbowStart_005_120.amc", "HDM_bd_jogLeftCircle4StepsRstart_001_120.amc"]
    skeleton = mt.read_asf(folder / "HDM_bd.asf")
    takes = [mt.read_amc(folder / name, skeleton) for name in names]
    open_page(browser, tmp_path, takes, names=names)
    side, right, scroll, client, titles = browser.execute_script(
        """const side = document.getElementById('side');
        const cells = [...document.querySelectorAll('#channels td.v')].map(c => c.getBoundingClientRect().right);
        const heads = [...document.querySelectorAll('#channels td.take')].map(c => c.title);
        return [side.getBoundingClientRect().right, Math.max(...cells), side.scrollWidth, side.clientWidth, heads];"""
    )
    assert right <= side and scroll <= client, (right, side, scroll, client)
    assert titles == names
