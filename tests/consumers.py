"""Other programs' readers of what we write, as oracles: Blender (headless) and three.js in
headless Chromium.  Each gives the world positions of the bones it built from a file, per frame,
in the file's own axes (glTF's +Y up; Blender's Z-up scene turned back), so that a test compares
them with our forward kinematics.  A test skips, with the reason, where a program is absent."""

import base64
import json
import os
import shutil
import subprocess
import textwrap
from pathlib import Path

import numpy as np
import pytest

BLENDER = shutil.which("blender")
BROWSER = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)
DRIVER = shutil.which("chromedriver")
THREE = Path("/usr/share/javascript/three")

needs_blender = pytest.mark.skipif(BLENDER is None, reason="no Blender here (Debian: apt-get install blender)")
needs_three = pytest.mark.skipif(
    BROWSER is None or DRIVER is None or not (THREE / "three.min.js").exists(),
    reason="no Chromium with chromedriver or no three.js here "
    "(Debian: apt-get install chromium chromium-driver libjs-three)",
)

_BLENDER_SCRIPT = textwrap.dedent(
    """
    import bpy, json, sys
    import numpy
    numpy.bool = bool  # Debian's Blender 3.4 glTF importer still uses this alias, gone in numpy 1.24
    import builtins
    _open = builtins.open
    def open_without_u(file, mode="r", *args, **kwargs):  # its BVH importer opens with "rU", gone in Python 3.11
        return _open(file, mode.replace("U", ""), *args, **kwargs)
    builtins.open = open_without_u
    jobs = json.load(open(sys.argv[sys.argv.index("--") + 1]))
    results = []
    for path, times, rate in jobs:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = bpy.context.scene
        kind = path.rsplit(".", 1)[-1].lower()
        try:
            if kind in ("glb", "gltf"):
                bpy.ops.import_scene.gltf(filepath=path)
            elif kind == "fbx":
                bpy.ops.import_scene.fbx(filepath=path)
            else:
                # quaternion keys: its default Euler keys are taken from float32 matrices in each
                # bone's own axes, which loses up to 2.4 mm on frames near gimbal lock there
                bpy.ops.import_anim.bvh(
                    filepath=path, update_scene_fps=True, update_scene_duration=True, rotate_mode="QUATERNION"
                )
        except Exception as e:
            results.append(f"error: {e}")
            continue
        fps = rate or scene.render.fps / scene.render.fps_base
        armature = next(o for o in scene.objects if o.type == "ARMATURE")
        bones = armature.pose.bones
        frames = []
        start = 1 if kind == "bvh" else 0  # the BVH importer puts the first frame at scene frame 1
        for t in times:
            frame = start + t * fps
            scene.frame_set(int(frame // 1), subframe=frame % 1)
            world = armature.matrix_world
            frames.append([list(world @ b.head) for b in bones])
        results.append({"names": [b.name for b in bones], "frames": frames})
    print("POSITIONS" + json.dumps(results))
    """
)


def run_blender(script: str, *args: str, timeout: float = 1200) -> subprocess.CompletedProcess:
    """Headless Blender running ``script`` with ``args`` after ``--``.  Its Python finds its
    standard library from the python on PATH: a virtualenv's or pyenv's there would hide the
    system's packages (numpy, which its glTF add-on needs), so PATH holds the system's only."""
    env = {**os.environ, "PATH": "/usr/local/bin:/usr/bin:/bin"}
    return subprocess.run(
        [BLENDER, "-b", "--factory-startup", "--python-expr", script, "--", *args],
        check=False,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )


def blender_positions(jobs, tmp_path):
    """For each (path, times) or (path, times, rate) of ``jobs``: {bone name: (len(times), 3)}
    world positions of the bones Blender imports from the file (glTF, FBX or BVH), at ``times``
    seconds from its first frame, in the file's axes (Blender's Z-up scene turned back to Y-up:
    x, z, -y).  ``rate``: the frames per second the times count in, where Blender's scene rate
    is not the take's (its BVH importer keys frame i at scene frame 1 + i, and rounds the scene's
    rate: 30 Hz for a Frame Time of 0.033333).  One Blender for all: it takes a second or two
    to start."""
    listing = tmp_path / "blender-jobs.json"
    listing.write_text(
        json.dumps([[str(job[0]), [float(t) for t in job[1]], job[2] if len(job) > 2 else None] for job in jobs])
    )
    result = run_blender(_BLENDER_SCRIPT, str(listing))
    line = next((x for x in result.stdout.splitlines() if x.startswith("POSITIONS")), None)
    assert line is not None, f"Blender failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    out = []
    for (path, *_), found in zip(jobs, json.loads(line[len("POSITIONS") :])):
        assert not isinstance(found, str), f"Blender could not import {path}: {found}"
        frames = np.array(found["frames"])  # (times, bones, 3), Blender's axes
        frames = np.stack([frames[..., 0], frames[..., 2], -frames[..., 1]], axis=-1)
        out.append({name: frames[:, i] for i, name in enumerate(found["names"])})
    return out


_THREE_PAGE = """<!doctype html><meta charset="utf-8">
<script src="{three}/three.min.js"></script>
<script src="{three}/examples/js/loaders/GLTFLoader.js"></script>
<script src="{three}/examples/js/loaders/FBXLoader.js"></script>
<script src="{three}/examples/js/loaders/BVHLoader.js"></script>
<script>
function decoded(text) {{
  const bytes = atob(text), out = new Uint8Array(bytes.length);
  for (let i = 0; i < bytes.length; i++) out[i] = bytes.charCodeAt(i);
  return out.buffer;
}}
// The bones a loader built and their world positions at each time: [names, [[x, y, z] per bone] per time]
function sample(root, clip, times) {{
  let bones = [];
  root.traverse(o => {{ if (o.isBone) bones.push(o); }});
  const skinned = [];
  root.traverse(o => {{ if (o.isSkinnedMesh) skinned.push(o); }});
  if (skinned.length) bones = skinned[0].skeleton.bones;
  const mixer = new THREE.AnimationMixer(root);
  const action = mixer.clipAction(clip);
  action.setLoop(THREE.LoopOnce);  // a looping clip is back at its start at its last key
  action.clampWhenFinished = true;
  action.play();
  const frames = [], v = new THREE.Vector3();
  for (const t of times) {{
    mixer.setTime(t);
    root.updateMatrixWorld(true);
    frames.push(bones.map(b => b.getWorldPosition(v).toArray()));
  }}
  return [bones.map(b => b.name), frames];
}}
window.positions = function (kind, text, animation, times, done) {{
  try {{
    const data = decoded(text);
    if (kind === "bvh") {{
      // as three.js's BVH example plays it: the tracks bind to .bones[name] of a skeleton
      const found = new THREE.BVHLoader().parse(new TextDecoder().decode(data));
      const root = new THREE.Group();
      root.add(found.skeleton.bones[0]);
      root.skeleton = found.skeleton;
      const [names, frames] = sample(root, found.clip, times);
      const kept = names.map((n, i) => i).filter(i => names[i] !== "ENDSITE");  // End Sites: unnamed
      done([kept.map(i => names[i]), frames.map(f => kept.map(i => f[i]))]);
    }} else if (kind === "fbx") {{
      const root = new THREE.FBXLoader().parse(data, "");
      done(sample(root, root.animations[animation], times));
    }} else {{
      new THREE.GLTFLoader().parse(data, "", g => done(sample(g.scene, g.animations[animation], times)),
                                   e => done("error: " + e));
    }}
  }} catch (e) {{ done("error: " + e + " " + e.stack); }}
}};
</script>"""


@pytest.fixture(scope="session")
def three_page(tmp_path_factory):
    """A headless Chromium on a page that loads files with three.js's loaders."""
    webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed (pip install selenium)")
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = BROWSER
    for flag in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    driver.set_script_timeout(300)
    page = tmp_path_factory.mktemp("three") / "load.html"
    page.write_text(_THREE_PAGE.format(three=THREE.as_uri()))
    driver.get(page.as_uri())
    yield driver
    driver.quit()


def three_positions(driver, path, times, animation=0):
    """{bone name: (len(times), 3)} world positions of the bones three.js's loader (GLTFLoader,
    FBXLoader or BVHLoader, by the suffix; a BVH's End Sites left out) builds from ``path``, its
    animation ``animation`` at ``times``."""
    suffix = str(path).lower().rsplit(".", 1)[-1]
    kind = suffix if suffix in ("fbx", "bvh") else "gltf"
    text = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    found = driver.execute_async_script(
        "window.positions(arguments[0], arguments[1], arguments[2], arguments[3], arguments[4]);",
        kind,
        text,
        animation,
        list(times),
    )
    assert not isinstance(found, str), found
    names, frames = found
    frames = np.array(frames)
    return {name: frames[:, i] for i, name in enumerate(names)}
