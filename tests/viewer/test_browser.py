"""The page in a real headless browser: Playwright driving Debian's chromium, with
SwiftShader's software WebGL (``--use-angle=swiftshader``).

Skipped, with the reason, when the ``playwright`` package or a chromium is missing
(CI installs both). One browser for the module: each start costs seconds.
"""

from __future__ import annotations

import base64
import io
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from spherewarp.coords import pixel_from_lonlat_deg
from spherewarp.io.images import read_image
from spherewarp.recipe import Recipe
from spherewarp.viewer.server import ViewerServer

W, H = 256, 128
ARGS = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]


def find_chromium() -> str | None:
    """Debian's chromium (Playwright cannot download its own browser here)."""
    for name in (os.environ.get("SPHEREWARP_CHROMIUM"), "/usr/bin/chromium", "chromium"):
        if name and (shutil.which(name) or (os.path.isfile(name) and os.access(name, os.X_OK))):
            return shutil.which(name) or name
    return None


@pytest.fixture(scope="module")
def browser():
    sync_api = pytest.importorskip(
        "playwright.sync_api", reason="the 'playwright' package is not installed (test extra)"
    )
    exe = find_chromium()
    if exe is None:
        pytest.skip("no chromium found (apt-get install chromium, or set SPHEREWARP_CHROMIUM)")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=exe, args=ARGS)
        yield b
        b.close()


@pytest.fixture(scope="module")
def mask_file(tmp_path_factory):
    """A Schottky mask, red around (0, 0) and blue around (100, 50): a file the server
    is started with (``--mask``), as a recipe from the page may name no other."""
    mask = np.zeros((64, 128, 3), np.uint8)
    mask[24:40, 56:72] = (255, 0, 0)
    mask[8:20, 96:112] = (0, 0, 255)
    path = tmp_path_factory.mktemp("masks") / "mask.png"
    Image.fromarray(mask).save(path)
    return path


@pytest.fixture(scope="module")
def served(mask_file):
    srv = ViewerServer(None, None, masks=[mask_file])
    yield srv
    srv.close()


def load(pg, url: str) -> None:
    """Open the page at ``url`` and wait until it is ready (no error)."""
    pg.goto(url)
    pg.wait_for_function(
        "window.spherewarp && (window.spherewarp.ready || window.spherewarp.error)"
    )
    assert pg.evaluate("window.spherewarp.error") is None


@pytest.fixture(scope="module")
def page(browser, served):
    pg = browser.new_page(viewport={"width": 1000, "height": 600})
    load(pg, served.url + f"?view=flat&size={W}x{H}")
    yield pg
    pg.close()


def shown(page) -> np.ndarray:
    """The canvas as the page shows it (RGB, float)."""
    url = page.evaluate("document.getElementById('view').toDataURL('image/png')")
    im = Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))).convert("RGB")
    return np.asarray(im).astype(np.float64)


def set_recipe(page, recipe) -> None:
    page.evaluate(
        "r => { window.spherewarp.setRecipe(r); return window.spherewarp.settle(); }", recipe
    )


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    mse = float(np.mean((a - b) ** 2))
    return math_inf() if mse == 0 else 10 * np.log10(255.0**2 / mse)


def math_inf() -> float:
    return float("inf")


def cpu(served, recipe) -> np.ndarray:
    out = Recipe.from_dict({**recipe, "view": {"size": [W, H]}}).render(
        read_image(served.image_path)
    )
    return np.asarray(getattr(out, "pixels", out))[..., :3].astype(np.float64)


#: a recipe for every effect with a compiled stage (Schottky: see test_schottky)
RECIPES = {
    "rotate": [{"rotate": {"yaw": 30, "pitch": 10}}],
    "zoom": [{"zoom": {"at": [20, 10], "factor": 3}}],
    "mobius": [
        {"mobius": {"from": [[0, 0], [90, 0], [0, 90]], "to": [[30, 15], [90, 0], [0, 90]]}}
    ],
    "power": [{"power": {"n": 3}}],
    "exp": [{"exp": {"lam": 4}}],
    "lattes": [{"lattes": {"alpha": "1+i"}}],
    "lattes-hex": [{"lattes": {"alpha": "2", "lattice": "hex"}}],
    "droste": [{"droste": {"center": [0, 0], "inner_radius": 20}}],
    "droste-twisted": [{"droste": {"center": [0, 0], "inner_radius": 20, "twist": True}}],
    # the seam (lon 180) through the middle, and a map that shrinks at the pole
    "seam": [{"rotate": {"yaw": 180}}],
    "pole": [{"zoom": {"at": [0, 88], "factor": 0.25}}],
    "composed": [{"zoom": {"at": [-40, 20], "factor": 2}}, {"power": {"n": 2}}],
    # expression maps: GLSL made from the expression's tree (spherewarp.viewer.glsl)
    "expr-poly": [{"map": {"expr": "z**3 + 0.5*z"}}],
    "expr-mobius": [{"map": {"expr": "(z - 1)/(z + 1)", "chart": "front"}}],
    "expr-functions": [{"map": {"expr": "exp(i*pi*z/4) + sqrt(z)*0.1 - tanh(z)/(2+2i)"}}],
    "expr-trig": [{"map": {"expr": "sin(z)/2 + cosh(z/3) + log(z + 3)/4", "look_at": [30, 10]}}],
    "expr-composed": [
        {"zoom": {"at": [10, 5], "factor": 2}},
        {"map": {"expr": "1/z**2 + conj(z)/8"}},
    ],
}


@pytest.mark.parametrize("name", list(RECIPES))
def test_flat_view_equals_the_python_renderer(page, served, name):
    recipe = {"spherewarp": 1, "steps": RECIPES[name]}
    set_recipe(page, recipe)
    got = shown(page)
    assert got.shape == (H, W, 3)
    value = psnr(got, cpu(served, recipe))
    print(f"{name}: PSNR {value:.2f} dB")
    assert value >= 35, f"{name}: PSNR {value:.2f} dB"


@pytest.mark.parametrize(
    "expr",
    ["__import__('os').system('id')", "z.real", "z) + vec2(1.0", "exp(" * 60 + "z" + ")" * 60],
)
def test_a_hostile_expression_is_refused(page, expr):
    """The server refuses it with the parser's line; the page keeps its picture."""
    set_recipe(page, {"spherewarp": 1, "steps": [{"map": {"expr": "z**2"}}]})
    before = shown(page)
    set_recipe(page, {"spherewarp": 1, "steps": [{"map": {"expr": expr}}]})
    text = page.text_content("#status")
    assert text.startswith("recipe: ") and "expression" in text, text
    assert page.evaluate("window.spherewarp.S.stages.codes") == [64]
    page.evaluate("window.spherewarp.draw()")
    assert np.array_equal(shown(page), before)


@pytest.mark.parametrize("where", ["flat", "right panel"])
def test_drag_moves_the_point_under_the_cursor(page, served, tmp_path, where):
    """Also in the right panel of two (the sphere view, and the flat one beside it)."""
    base = {"spherewarp": 1, "steps": [{"zoom": {"at": [30, 10], "factor": 1.5}}]}
    set_recipe(page, base)
    pins = [[-120.0, 40.0], [100.0, -30.0]]
    page.evaluate("p => { window.spherewarp.S.pins = p; }", pins)
    x0 = 0
    if where == "right panel":
        page.click("#v-sphere")
        page.select_option("#side", "flat")
        x0 = W
    box = page.locator("#view").bounding_box()
    assert round(box["width"]) == W + x0  # one CSS pixel a canvas pixel
    a, b = (100.0, 60.0), (140.0, 45.0)  # canvas pixels (of the panel)
    page.mouse.move(box["x"] + x0 + a[0], box["y"] + a[1])
    page.mouse.down()
    for k in range(1, 6):
        page.mouse.move(
            box["x"] + x0 + a[0] + (b[0] - a[0]) * k / 5,
            box["y"] + a[1] + (b[1] - a[1]) * k / 5,
        )
    page.mouse.up()
    page.evaluate("window.spherewarp.settle()")
    if where == "right panel":
        shown_right = shown(page)[:, W:]
        page.click("#v-flat")
        page.select_option("#side", "")
        assert np.array_equal(shown(page), shown_right)  # the same picture, alone
    with page.expect_download() as dl:
        page.click("#save")
    saved = tmp_path / "saved.json"
    dl.value.save_as(saved)
    new = Recipe.load(saved)
    old = Recipe.from_dict(base)
    inv = new.map_at(0).as_mobius().inverse()
    lonlat_a = [a[0] / W * 360 - 180, 90 - a[1] / H * 180]
    # the source point under the cursor at the press is now under the cursor's release
    src = old.map_at(0).apply_lonlat(np.array(lonlat_a))
    moved = pixel_from_lonlat_deg(inv.apply_lonlat(src), W, H)
    err = np.hypot((moved[0] - b[0] + W / 2) % W - W / 2, moved[1] - b[1])
    print(f"drag error ({where}) {err:.3f} px")
    assert err <= 2.0
    for pin in pins:
        at = pixel_from_lonlat_deg(
            inv.apply_lonlat(old.map_at(0).apply_lonlat(np.array(pin))), W, H
        )
        want = pixel_from_lonlat_deg(np.array(pin), W, H)
        assert np.hypot((at[0] - want[0] + W / 2) % W - W / 2, at[1] - want[1]) <= 2.0
    if where == "right panel":
        return  # the replay: the flat case
    # the saved recipe replayed by 'spherewarp render' gives the image the page showed
    out = tmp_path / "replay.png"
    cmd = [sys.executable, "-m", "spherewarp", "render", str(saved), str(served.image_path)]
    subprocess.run([*cmd, "-o", str(out), "--size", f"{W}x{H}"], check=True, capture_output=True)
    replay = np.asarray(Image.open(out).convert("RGB")).astype(np.float64)
    value = psnr(shown(page), replay)
    print(f"drag replay PSNR {value:.2f} dB")
    assert value >= 35


def test_views_url_and_undo(page):
    set_recipe(page, {"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": 2}}]})
    set_recipe(page, {"spherewarp": 1, "steps": [{"power": {"n": 2}}]})
    q = page.evaluate("new URLSearchParams(location.search).get('recipe')")
    assert json.loads(q)["steps"] == [{"power": {"n": 2}}]
    page.click("#undo")
    page.evaluate("window.spherewarp.settle()")
    assert page.evaluate("window.spherewarp.S.recipe.steps") == [
        {"zoom": {"at": [0, 0], "factor": 2}}
    ]
    page.click("#redo")
    page.evaluate("window.spherewarp.settle()")
    for view in ("sphere", "planet", "flat"):
        page.click(f"#v-{view}")
        img = shown(page)
        assert np.isfinite(img).all() and img.std() > 10, view
        assert page.evaluate("new URLSearchParams(location.search).get('view')") == view
    # Ctrl + wheel: a conformal zoom at the cursor (a zoom step, not a field of view)
    box = page.locator("#view").bounding_box()
    page.mouse.move(box["x"] + 64, box["y"] + 32)
    page.keyboard.down("Control")
    page.mouse.wheel(0, -100)
    page.keyboard.up("Control")
    page.evaluate("window.spherewarp.settle()")
    last = page.evaluate("window.spherewarp.S.recipe.steps.at(-1)")
    assert last["zoom"]["at"] == [-90, 45] and last["zoom"]["factor"] > 1
    # the test pattern overlay, pulled back by the same map
    before = shown(page)
    page.locator("#overlay").fill("1")
    page.wait_for_function("window.spherewarp.S.overlay === 1")
    page.evaluate("window.spherewarp.draw()")
    assert np.abs(shown(page) - before).mean() > 5
    page.locator("#overlay").fill("0")
    page.wait_for_function("window.spherewarp.S.overlay === 0")
    page.click("#copy")
    assert "spherewarp render recipe.json courtyard.png -o out.png --size 256x128" in (
        page.input_value("#cli")
    )


def test_schottky_stage(page, served):
    """No recipe effect makes a Schottky group yet: its packed stages go to the page
    directly, as the server packs a recipe's."""
    from spherewarp.maps import Schottky
    from spherewarp.render import warp
    from spherewarp.viewer.server import packed_stages

    class _One:  # packed_stages takes anything with map_at
        def __init__(self, m):
            self.m = m

        def map_at(self, t):
            return self.m

    m = Schottky.from_disk_pairs([((0, 0, 20), (180, 0, 20)), ((90, 30, 25), (-90, -30, 25))])
    st = packed_stages(_One(m))
    assert 6 in st["codes"]
    page.evaluate("st => window.spherewarp.setStages(st)", st)
    out = warp(read_image(served.image_path), m, output_shape=(H, W))
    want = np.asarray(getattr(out, "pixels", out))[..., :3].astype(np.float64)
    value = psnr(shown(page), want)
    print(f"schottky: PSNR {value:.2f} dB")
    assert value >= 35


def test_masked_schottky_stage(page, served, mask_file):
    """The exact disks of a mask (``schottky_mask``): the labels go to the page once, as a
    texture."""
    path = mask_file
    targets = [
        {"colour": "#ff0000", "to": [180, 0, 20]},
        {"colour": "#0000ff", "to": [-80, -40, 15]},
    ]
    recipe = {"spherewarp": 1, "steps": [{"schottky": {"mask": str(path), "targets": targets}}]}
    set_recipe(page, recipe)
    assert 7 in page.evaluate("window.spherewarp.S.stages.codes")
    value = psnr(shown(page), cpu(served, recipe))
    print(f"schottky_mask: PSNR {value:.2f} dB")
    assert value >= 35


def canvas_png(page, which: str) -> np.ndarray:
    url = page.evaluate(f"document.getElementById('{which}').toDataURL('image/png')")
    im = Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))).convert("RGBA")
    return np.asarray(im).astype(np.float64)


def test_side_by_side_and_pin_markers(page, served, tmp_path):
    recipe = {"spherewarp": 1, "steps": [{"zoom": {"at": [20, 10], "factor": 2}}]}
    set_recipe(page, recipe)
    pins = [[-100.0, 30.0], [30.0, -20.0]]  # the second one in the sphere view too
    page.evaluate("p => { window.spherewarp.S.pins = p; window.spherewarp.draw(); }", pins)
    want = cpu(served, recipe)
    try:
        for side in ("sphere", "original", "planet"):
            page.select_option("#side", side)
            assert page.evaluate("new URLSearchParams(location.search).get('side')") == side
            got = shown(page)
            assert got.shape == (H, 2 * W, 3)
            value = psnr(got[:, :W], want)  # the left panel is still the flat view
            assert value >= 35, (side, value)
            right = got[:, W:]
            if side == "original":  # the image unedited
                value = psnr(right, cpu(served, {"spherewarp": 1, "steps": []}))
                print(f"side by side, original: PSNR {value:.2f} dB")
                assert value >= 35
            else:
                assert right.std() > 10, side
            # the pins are marked where they are, in each edited panel
            marks = canvas_png(page, "marks")
            assert marks.shape[:2] == (H, 2 * W)
            views = ["flat", None if side == "original" else side]
            checked = 0
            for k, view in enumerate(views):
                for pin in pins:
                    at = view and page.evaluate(
                        "([p, v]) => window.spherewarp.lonLatToPixel(p[0], p[1], v)", [pin, view]
                    )
                    if not at or not (2 <= at[0] < W - 2 and 2 <= at[1] < H - 2):
                        continue  # not in this panel
                    x, y = int(round(at[0])) + k * W, int(round(at[1]))
                    ring = marks[max(0, y - 7) : y + 8, max(0, x - 7) : x + 8, 3]
                    assert ring.max() > 200, (side, view, pin)
                    checked += 1
            assert checked >= (2 if side == "original" else 3), side
            (tmp_path / f"side-{side}.png").write_bytes(page.screenshot())
        # flat pin markers, computed here, not by the page's own projection
        for pin in pins:
            x, y = pixel_from_lonlat_deg(np.array(pin), W, H)
            ring = marks[int(y) - 7 : int(y) + 8, int(x) - 7 : int(x) + 8, 3]
            assert ring.max() > 200
        # each view's marks are placed by the inverse of its pixel -> (lon, lat)
        for view in ("flat", "sphere", "planet"):
            back = page.evaluate(
                """v => [[30, 40], [200, 100], [128, 64]].map(
                    ([x, y]) => window.spherewarp.lonLatToPixel(
                        ...window.spherewarp.pixelToLonLat(x, y, v), v))""",
                view,
            )
            assert np.allclose(back, [[30, 40], [200, 100], [128, 64]], atol=1e-6), view
    finally:
        page.select_option("#side", "")
    assert shown(page).shape == (H, W, 3)
    assert page.evaluate("new URLSearchParams(location.search).get('side')") is None


def replay(served, page, tmp_path) -> float:
    """PSNR of the page's flat view against 'spherewarp render' of the recipe it holds."""
    saved = tmp_path / "page.json"
    saved.write_text(json.dumps(page.evaluate("window.spherewarp.S.recipe")))
    out = tmp_path / "replay.png"
    cmd = [sys.executable, "-m", "spherewarp", "render", str(saved), str(served.image_path)]
    subprocess.run([*cmd, "-o", str(out), "--size", f"{W}x{H}"], check=True, capture_output=True)
    replay = np.asarray(Image.open(out).convert("RGB")).astype(np.float64)
    return psnr(shown(page), replay)


def lonlat_of(x: float, y: float) -> list[float]:
    return [x / W * 360 - 180, 90 - y / H * 180]


def wait_steps(page, n: int) -> None:
    page.wait_for_function(f"window.spherewarp.S.recipe.steps.length === {n}")
    page.evaluate("window.spherewarp.settle()")


def test_droste_frame_by_four_clicks(page, served, tmp_path):
    set_recipe(page, {"spherewarp": 1, "steps": [{"rotate": {"yaw": 10}}]})
    box = page.locator("#view").bounding_box()
    page.click("#m-droste")
    corners = [(110, 50), (148, 52), (146, 80), (112, 78)]  # round the frame, canvas pixels
    for x, y in corners:
        page.mouse.click(box["x"] + x, box["y"] + y)
    wait_steps(page, 2)
    step = page.evaluate("window.spherewarp.S.recipe.steps[1]")
    assert list(step) == ["droste"]
    assert np.allclose(step["droste"]["frame"], [lonlat_of(x, y) for x, y in corners], atol=1e-4)
    value = replay(served, page, tmp_path)
    print(f"droste frame by clicks: replay PSNR {value:.2f} dB")
    assert value >= 35
    # in the sphere view: the corners are the directions of the pixels clicked (the
    # shader's camera, written again here)
    page.click("#v-sphere")
    try:
        set_recipe(page, {"spherewarp": 1, "steps": []})
        page.evaluate("window.spherewarp.S.look = [20, 10, 90]; window.spherewarp.draw()")
        page.click("#m-droste")
        for x, y in corners:
            page.mouse.click(box["x"] + x, box["y"] + y)
        wait_steps(page, 1)
        got = page.evaluate("window.spherewarp.S.recipe.steps[0].droste.frame")
    finally:
        page.click("#v-flat")
    yaw, pitch, k = np.radians(20), np.radians(10), np.tan(np.radians(45))
    f = np.array([np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw), np.sin(pitch)])
    r = np.array([-np.sin(yaw), np.cos(yaw), 0])
    u = np.array([-np.sin(pitch) * np.cos(yaw), -np.sin(pitch) * np.sin(yaw), np.cos(pitch)])
    for (x, y), corner in zip(corners, got, strict=True):
        d = f + k * (2 * x - W) / W * r - k * (2 * y - H) / W * u
        want = np.degrees([np.arctan2(d[1], d[0]), np.arctan2(d[2], np.hypot(d[0], d[1]))])
        assert np.allclose(corner, want, atol=1e-4), (corner, want)
    # corners out of order: the server's line, and the recipe stays as it was
    set_recipe(page, {"spherewarp": 1, "steps": [{"rotate": {"yaw": 10}}, step]})
    page.click("#m-droste")
    for x, y in [corners[0], corners[2], corners[1], corners[3]]:
        page.mouse.click(box["x"] + x, box["y"] + y)
    page.wait_for_function("document.getElementById('status').className === 'bad'")
    assert "not in order" in page.text_content("#status")
    assert len(page.evaluate("window.spherewarp.S.recipe.steps")) == 2


def test_schottky_disks_by_dragging(page, served, tmp_path):
    set_recipe(page, {"spherewarp": 1, "steps": []})
    box = page.locator("#view").bounding_box()

    def disk(c, edge):
        page.mouse.move(box["x"] + c[0], box["y"] + c[1])
        page.mouse.down()
        for k in range(1, 4):
            page.mouse.move(
                box["x"] + c[0] + (edge[0] - c[0]) * k / 3,
                box["y"] + c[1] + (edge[1] - c[1]) * k / 3,
            )
        page.mouse.up()

    page.click("#m-schottky")
    disk((64, 64), (76, 64))  # D_x round (-90, 0), 16.875 degrees
    disk((192, 64), (192, 74))  # D_X round (90, 0), 14.0625 degrees
    wait_steps(page, 1)
    gen = page.evaluate("window.spherewarp.S.recipe.steps[0].schottky.generators")
    assert len(gen) == 1
    assert np.allclose(gen[0]["disk"], [-90, 0, 12 / W * 360], atol=1e-4)
    assert np.allclose(gen[0]["to"], [90, 0, 10 / H * 180], atol=1e-4)
    # a second pair joins the same step
    page.click("#m-schottky")
    disk((128, 20), (128, 30))
    disk((128, 108), (136, 108))
    page.wait_for_function("window.spherewarp.S.recipe.steps[0].schottky.generators.length == 2")
    page.evaluate("window.spherewarp.settle()")
    assert len(page.evaluate("window.spherewarp.S.recipe.steps")) == 1
    value = replay(served, page, tmp_path)
    print(f"schottky disks by dragging: replay PSNR {value:.2f} dB")
    assert value >= 35


FPS = 4


def write_video(path, frames) -> None:
    """A WebM (VP9, BT.601 tagged) of the frames, FPS a second."""
    import av

    with av.open(str(path), "w") as c:
        s = c.add_stream("libvpx-vp9", rate=FPS)
        s.width, s.height = frames[0].shape[1], frames[0].shape[0]
        s.pix_fmt = "yuv420p"
        s.options = {"crf": "4", "b": "0", "deadline": "good", "cpu-used": "8"}
        for a in frames:
            f = av.VideoFrame.from_ndarray(a, format="rgb24")
            for p in s.encode(f):
                c.mux(p)
        for p in s.encode():
            c.mux(p)


def decoded(path) -> list[np.ndarray]:
    import av

    with av.open(str(path)) as c:
        return [f.to_ndarray(format="rgb24") for f in c.decode(video=0)]


@pytest.fixture(scope="module")
def video(tmp_path_factory, served):
    """8 frames of the sample panorama, turning 45 degrees a frame (256x128, 2 s)."""
    base = np.asarray(Image.open(served.image_path).convert("RGB").resize((256, 128)))
    frames = [np.roll(base, 32 * k, axis=1) for k in range(8)]
    path = tmp_path_factory.mktemp("video") / "turn.webm"
    write_video(path, frames)
    return path


def test_video_plays_warped(browser, video, tmp_path):
    """'spherewarp view VIDEO': the page plays the video (range requests) with the effect
    live; paused at a frame's time it shows that frame warped, as 'spherewarp render'."""
    srv = ViewerServer(video, None)
    pg = browser.new_page(viewport={"width": 1000, "height": 600})
    try:
        load(pg, srv.url + f"?view=flat&size={W}x{H}")
        # it plays: the time and the picture change
        pg.evaluate("window.spherewarp.S.video.play()")
        n0 = pg.evaluate("window.spherewarp.S.frames")
        how = "v => [v.paused, v.readyState, v.networkState, v.currentTime, v.error]"
        # four frame times seen (it loops: not "later than", which a wrap would miss)
        seen_times = """(() => {
            const seen = (window.seenTimes = window.seenTimes || new Set());
            seen.add(window.spherewarp.S.videoTime);
            return seen.size >= 4;
        })()"""
        try:
            pg.wait_for_function(seen_times, timeout=60000)
        except Exception:
            raise AssertionError(pg.evaluate(f"({how})(window.spherewarp.S.video)")) from None
        assert pg.evaluate("window.spherewarp.S.frames") > n0
        # an animated recipe: its time is the video's
        factor = {"keyframes": [[0, 1], [2, 3]]}
        recipe = {"spherewarp": 1, "steps": [{"zoom": {"at": [20, 10], "factor": factor}}]}
        set_recipe(pg, recipe)
        frames = decoded(video)
        seen = []
        for k in (2, 5):
            t = pg.evaluate("t => window.spherewarp.seek(t)", (k + 0.5) / FPS)
            assert abs(t - (k + 0.5) / FPS) < 1e-3
            got = shown(pg)
            r = Recipe.from_dict({**recipe, "view": {"size": [W, H]}})
            out = r.render(frames[k], t=k / FPS)  # the recipe at the frame's time
            want = np.asarray(getattr(out, "pixels", out))[..., :3].astype(np.float64)
            value = psnr(got, want)
            print(f"video frame {k} warped: PSNR {value:.2f} dB")
            assert value >= 35
            seen.append(got)
        assert np.abs(seen[0] - seen[1]).mean() > 10  # two frames, not one
        # "Render full resolution" (the video's own size here): the frame shown
        with pg.expect_download(timeout=120000) as dl:
            pg.click("#render")
        out = tmp_path / "full.png"
        dl.value.save_as(out)
        full = np.asarray(Image.open(out).convert("RGB")).astype(np.float64)
        value = psnr(seen[1], full)
        print(f"video frame 5, render full resolution: PSNR {value:.2f} dB")
        assert value >= 35
        (tmp_path / "video.png").write_bytes(pg.screenshot())
        # "Copy as command": 'spherewarp video', the recipe at each frame's time
        pg.click("#copy")
        text = pg.input_value("#cli")
        assert text.endswith(
            f"spherewarp video turn.webm -o out.mp4 --size {W}x{H} recipe recipe.json"
        )
        shutil.copy(video, tmp_path / "turn.webm")
        env = {**os.environ, "PATH": f"{os.path.dirname(sys.executable)}:{os.environ['PATH']}"}
        subprocess.run(["bash", "-c", text], cwd=tmp_path, env=env, check=True, capture_output=True)
        made = decoded(tmp_path / "out.mp4")
        assert len(made) == len(frames)
        value = psnr(seen[1], made[5].astype(np.float64))
        print(f"video frame 5 vs the copied command's video (x264): PSNR {value:.2f} dB")
        assert value >= 35  # the page against an encoded video (x264, crf 18)
    finally:
        pg.close()
        srv.close()


# -- the recipe's marks: frames and disks over the picture, dragged to edit ------------------

#: a Droste frame (clicked in the flat view), a round Droste hole, a Schottky pair across
#: the seam and one near the pole
MARKED = {
    "spherewarp": 1,
    "steps": [
        {
            "droste": {
                "frame": [lonlat_of(x, y) for x, y in [(110, 50), (148, 52), (146, 80), (112, 78)]]
            }
        },
        {"droste": {"center": [-100, -20], "inner_radius": 12}},
        {
            "schottky": {
                "generators": [
                    {"disk": [175, 10, 15], "to": [-60, 30, 12]},
                    {"disk": [30, 70, 10], "to": [60, -60, 10]},
                ]
            }
        },
    ],
}


def sphere_pixel(lonlat, look) -> tuple[float, float] | None:
    """The sphere view's pixel of a direction (the shader's camera, written again here)."""
    yaw, pitch, k = np.radians(look[0]), np.radians(look[1]), np.tan(np.radians(look[2] / 2))
    f = np.array([np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw), np.sin(pitch)])
    r = np.array([-np.sin(yaw), np.cos(yaw), 0])
    u = np.array([-np.sin(pitch) * np.cos(yaw), -np.sin(pitch) * np.sin(yaw), np.cos(pitch)])
    lon, lat = np.radians(lonlat)
    d = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    if d @ f <= 0:
        return None
    nx, ny = (d @ r) / (k * (d @ f)), -(d @ u) / (k * (d @ f))
    return (nx + 1) * W / 2, (ny * W + H) / 2


def handle_value(recipe, path):
    v = recipe["steps"]
    for key in path:
        v = v[key]
    return v


def test_recipe_marks_in_every_view_and_the_toggle(page, served, tmp_path):
    set_recipe(page, MARKED)
    page.evaluate("window.spherewarp.S.look = [160, 10, 100]")
    try:
        for side in ("", "sphere", "planet", "original"):
            page.select_option("#side", side)
            pos = page.evaluate("window.spherewarp.markPositions()")
            marks = canvas_png(page, "marks")
            (tmp_path / f"marks-{side or 'flat'}.png").write_bytes(page.screenshot())
            assert {p["panel"] for p in pos} == ({0} if side in ("", "original") else {0, 1})
            for p in pos:
                at = handle_value(MARKED, p["path"])
                x, y = p["x"] - p["panel"] * W, p["y"]
                if p["panel"] == 0:  # flat: the Python side's projection
                    want = pixel_from_lonlat_deg(np.array(at[:2], float), W, H)
                    dx = (x - want[0] + W / 2) % W - W / 2
                    assert np.hypot(dx, y - want[1]) <= 1.0, (p, want)
                elif side == "sphere":
                    want = sphere_pixel(at[:2], [160, 10, 100])
                    assert want is not None and np.hypot(x - want[0], y - want[1]) <= 1.0
                # a mark is drawn there (the overlay is opaque round it)
                xi, yi = int(round(p["x"])), int(round(p["y"]))
                ring = marks[max(0, yi - 5) : yi + 6, max(0, xi - 5) : xi + 6, 3]
                assert ring.max() > 200, p
            # all six disk centres, two frame corners... in the flat panel
            assert sum(p["panel"] == 0 for p in pos) == 4 + 1 + 4
        page.select_option("#side", "")
        # a disk across the seam: no line across the whole panel (the polyline is split)
        marks = canvas_png(page, "marks")
        row = int(round(pixel_from_lonlat_deg(np.array([175.0, 10.0]), W, H)[1]))
        assert (marks[row, 60:200, 3] > 0).sum() < 40
        # the picture is the same with the marks and without, and still the renderer's
        with_marks = shown(page)
        page.uncheck("#show-marks")
        assert page.evaluate("new URLSearchParams(location.search).get('marks')") == "0"
        assert page.evaluate("window.spherewarp.markPositions()") == []
        assert canvas_png(page, "marks")[..., 3].max() == 0  # nothing over the picture
        page.evaluate("window.spherewarp.draw()")
        assert np.array_equal(shown(page), with_marks)
        value = psnr(with_marks, cpu(served, MARKED))
        print(f"marked recipe: PSNR {value:.2f} dB")
        assert value >= 35
    finally:
        page.select_option("#side", "")
        if not page.is_checked("#show-marks"):
            page.check("#show-marks")
    assert page.evaluate("new URLSearchParams(location.search).get('marks')") is None
    assert canvas_png(page, "marks")[..., 3].max() > 200


def drag_to(page, box, a, b) -> None:
    page.mouse.move(box["x"] + a[0], box["y"] + a[1])
    page.mouse.down()
    for k in range(1, 6):
        page.mouse.move(
            box["x"] + a[0] + (b[0] - a[0]) * k / 5, box["y"] + a[1] + (b[1] - a[1]) * k / 5
        )
    page.mouse.up()


def test_dragging_marks_edits_the_recipe(page, served, tmp_path):
    corners = [(110, 50), (148, 52), (146, 80), (112, 78)]
    base = {
        "spherewarp": 1,
        "steps": [
            {"rotate": {"yaw": 10}},
            {"droste": {"frame": [lonlat_of(x, y) for x, y in corners]}},
        ],
    }
    set_recipe(page, base)
    box = page.locator("#view").bounding_box()
    pos = {tuple(p["path"]): p for p in page.evaluate("window.spherewarp.markPositions()")}
    c = pos[(1, "droste", "frame", 1)]
    assert np.hypot(c["x"] - 148, c["y"] - 52) <= 1e-6
    drag_to(page, box, (c["x"], c["y"]), (156.0, 44.0))
    page.wait_for_function("document.getElementById('status').textContent === 'mark moved'")
    frame = page.evaluate("window.spherewarp.S.recipe.steps[1].droste.frame")
    got = pixel_from_lonlat_deg(np.array(frame[1], float), W, H)
    assert np.hypot(got[0] - 156, got[1] - 44) <= 2.0, got
    assert np.allclose(frame[0], lonlat_of(*corners[0]))
    value = replay(served, page, tmp_path)
    print(f"droste corner dragged: replay PSNR {value:.2f} dB")
    assert value >= 35
    (tmp_path / "dragged.png").write_bytes(page.screenshot())
    # undo takes it back
    page.click("#undo")
    page.evaluate("window.spherewarp.settle()")
    assert page.evaluate("window.spherewarp.S.recipe") == base
    # a corner dragged across the frame (out of order): the server's line, nothing changes
    pos = {tuple(p["path"]): p for p in page.evaluate("window.spherewarp.markPositions()")}
    c = pos[(1, "droste", "frame", 0)]
    drag_to(page, box, (c["x"], c["y"]), (150.0, 82.0))
    # the drop's line (the live preview of the drag may show the server's line first)
    page.wait_for_function(
        "document.getElementById('status').textContent.startsWith('moving the mark')"
    )
    assert page.evaluate("document.getElementById('status').className") == "bad"
    page.evaluate("window.spherewarp.settle()")
    assert page.evaluate("window.spherewarp.S.recipe") == base
    # a Schottky disk's centre: moved, its radius kept
    pair = {
        "spherewarp": 1,
        "steps": [{"schottky": {"generators": [{"disk": [-90, 0, 15], "to": [90, 0, 12]}]}}],
    }
    set_recipe(page, pair)
    page.evaluate("window.spherewarp.settle()")
    pos = {tuple(p["path"]): p for p in page.evaluate("window.spherewarp.markPositions()")}
    c = pos[(0, "schottky", "generators", 0, "disk")]
    drag_to(page, box, (c["x"], c["y"]), (c["x"] - 10, c["y"] - 12))
    page.wait_for_function("document.getElementById('status').textContent === 'mark moved'")
    disk = page.evaluate("window.spherewarp.S.recipe.steps[0].schottky.generators[0].disk")
    got = pixel_from_lonlat_deg(np.array(disk[:2], float), W, H)
    assert np.hypot(got[0] - (c["x"] - 10), got[1] - (c["y"] - 12)) <= 2.0
    assert disk[2] == 15
    (tmp_path / "disk").mkdir()
    value = replay(served, page, tmp_path / "disk")
    print(f"schottky disk dragged: replay PSNR {value:.2f} dB")
    assert value >= 35


def test_dragging_a_mark_in_the_sphere_panel(page):
    """The right panel (the sphere view beside the flat one): the corner goes to the
    direction of the pixel where the mouse was released (the shader's camera)."""
    corners = [(110, 50), (148, 52), (146, 80), (112, 78)]
    base = {"spherewarp": 1, "steps": [{"droste": {"frame": [lonlat_of(*c) for c in corners]}}]}
    set_recipe(page, base)
    look = [10, 5, 100]
    page.evaluate(f"window.spherewarp.S.look = {look}")
    page.select_option("#side", "sphere")
    try:
        box = page.locator("#view").bounding_box()
        pos = page.evaluate("window.spherewarp.markPositions()")
        c = next(p for p in pos if p["panel"] == 1 and p["path"] == [0, "droste", "frame", 2])
        want = sphere_pixel(lonlat_of(*corners[2]), look)
        assert np.hypot(c["x"] - W - want[0], c["y"] - want[1]) <= 1.0
        to = (c["x"] + 9, c["y"] + 7)
        drag_to(page, box, (c["x"], c["y"]), to)
        page.wait_for_function("document.getElementById('status').textContent === 'mark moved'")
        got = page.evaluate("window.spherewarp.S.recipe.steps[0].droste.frame[2]")
        at = sphere_pixel(got, look)
        assert np.hypot(at[0] + W - to[0], at[1] - to[1]) <= 2.0, (at, to)
    finally:
        page.select_option("#side", "")


def test_marks_hidden_by_the_url_on_load(browser, served):
    """``?marks=0``: the page starts with the checkbox off and nothing on the marks layer
    (the picture as ever); ticking the box shows them and drops the parameter."""
    from urllib.parse import quote

    pg = browser.new_page(viewport={"width": 1000, "height": 600})
    try:
        load(pg, served.url + f"?view=flat&size={W}x{H}&marks=0&recipe={quote(json.dumps(MARKED))}")
        pg.evaluate("window.spherewarp.settle()")
        assert pg.evaluate("window.spherewarp.S.recipe") == MARKED
        assert not pg.is_checked("#show-marks")
        assert pg.evaluate("window.spherewarp.markPositions()") == []
        marks = canvas_png(pg, "marks")
        assert marks.shape[:2] == (H, W) and marks[..., 3].max() == 0
        assert pg.evaluate("new URLSearchParams(location.search).get('marks')") == "0"
        assert psnr(shown(pg), cpu(served, MARKED)) >= 35
        pg.check("#show-marks")
        assert pg.evaluate("new URLSearchParams(location.search).get('marks')") is None
        assert len(pg.evaluate("window.spherewarp.markPositions()")) == 4 + 1 + 4
        assert canvas_png(pg, "marks")[..., 3].max() > 200
    finally:
        pg.close()


def test_dragging_a_disk_rim_changes_its_radius(page, served, tmp_path):
    """A Schottky disk's rim, dragged: its radius (the centre kept), checked by the server
    and undone as a centre's move; the marks drawn again round the new rim."""
    pair = {
        "spherewarp": 1,
        "steps": [{"schottky": {"generators": [{"disk": [-90, 0, 15], "to": [90, 0, 12]}]}}],
    }
    set_recipe(page, pair)
    box = page.locator("#view").bounding_box()
    rim = pixel_from_lonlat_deg(np.array([-75.0, 0.0]), W, H)  # the rim's east point
    to = pixel_from_lonlat_deg(np.array([-67.5, 0.0]), W, H)  # 22.5 degrees from the centre
    drag_to(page, box, tuple(rim), tuple(to))
    page.wait_for_function(
        "document.getElementById('status').textContent === 'disk radius changed'"
    )
    gen = page.evaluate("window.spherewarp.S.recipe.steps[0].schottky.generators[0]")
    disk = gen["disk"]
    assert disk[:2] == [-90, 0]
    assert abs(disk[2] - 22.5) <= 0.5, disk
    assert gen["to"] == [90, 0, 12]
    # the rim is drawn where it now is, and not where it was
    marks = canvas_png(page, "marks")
    new_rim = pixel_from_lonlat_deg(np.array([-90 + disk[2], 0.0]), W, H)
    xi, yi = int(round(new_rim[0])), int(round(new_rim[1]))
    assert marks[yi - 2 : yi + 3, xi - 2 : xi + 3, 3].max() > 200
    xi = int(round(rim[0]))
    assert marks[yi - 2 : yi + 3, xi - 1 : xi + 2, 3].max() == 0
    value = replay(served, page, tmp_path)
    print(f"schottky disk radius dragged: replay PSNR {value:.2f} dB")
    assert value >= 35
    # undo takes it back; a radius dragged to nothing: the server's line, nothing changes
    page.click("#undo")
    page.evaluate("window.spherewarp.settle()")
    assert page.evaluate("window.spherewarp.S.recipe") == pair
    centre = pixel_from_lonlat_deg(np.array([-90.0, 0.0]), W, H)
    drag_to(page, box, tuple(rim), tuple(centre))
    # the drop's line (the live preview of the drag may show the server's line first)
    page.wait_for_function(
        "document.getElementById('status').textContent.startsWith('moving the mark')"
    )
    assert page.evaluate("document.getElementById('status').className") == "bad"
    page.evaluate("window.spherewarp.settle()")
    assert page.evaluate("window.spherewarp.S.recipe") == pair


def test_marks_follow_keyframes_and_a_drag_sets_a_keyframe(browser, video, tmp_path):
    """An animated recipe over a video: its marks are where the effect is at the frame
    shown (the server's tracks at the video's time); a keyframed centre dragged there gets
    a keyframe at that time (added, then changed), its other keyframes kept."""
    srv = ViewerServer(video, None)
    pg = browser.new_page(viewport={"width": 1000, "height": 600})
    try:
        load(pg, srv.url + f"?view=flat&size={W}x{H}")
        center = {"keyframes": [[0, [-100, -20]], [2, [20, 10]]]}
        radius = {"keyframes": [[0, 10], [2, 20]]}
        recipe = {
            "spherewarp": 1,
            "steps": [{"droste": {"center": center, "inner_radius": radius}}],
        }
        set_recipe(pg, recipe)
        frames = decoded(video)
        k = 5
        t = k / FPS  # the recipe's time at the frame shown
        pg.evaluate("t => window.spherewarp.seek(t)", (k + 0.5) / FPS)
        box = pg.locator("#view").bounding_box()

        def centre_mark():
            pos = pg.evaluate("window.spherewarp.markPositions()")
            (c,) = [p for p in pos if p["path"] == [0, "droste", "center"]]
            return c

        want = Recipe.from_dict(recipe).step_values(0, t)  # [-25, -1.25], radius 16.25
        c = centre_mark()
        at = pixel_from_lonlat_deg(np.array(want["center"], float), W, H)
        assert np.hypot(c["x"] - at[0], c["y"] - at[1]) <= 1.0, (c, at)
        marks = canvas_png(pg, "marks")
        xi, yi = int(round(c["x"])), int(round(c["y"]))
        assert marks[yi - 4 : yi + 5, xi - 4 : xi + 5, 3].max() > 200
        # the hole's circle: radius 16.25 at t, above the centre (not 10, as at t = 0)
        top = pixel_from_lonlat_deg(np.array([want["center"][0], -1.25 + 16.25]), W, H)
        xi, yi = int(round(top[0])), int(round(top[1]))
        assert marks[yi - 1 : yi + 2, xi - 2 : xi + 3, 3].max() > 200
        start = pixel_from_lonlat_deg(np.array([-100.0, -20.0]), W, H)  # the t = 0 centre
        xi, yi = int(round(start[0])), int(round(start[1]))
        assert marks[yi - 4 : yi + 5, xi - 4 : xi + 5, 3].max() == 0
        # dragged at t: a keyframe added there, the first and last kept
        drag_to(pg, box, (c["x"], c["y"]), (c["x"] + 12, c["y"] - 9))
        pg.wait_for_function(
            f"document.getElementById('status').textContent === "
            f"'mark moved (keyframe at t = {t:g} s)'"
        )
        got = pg.evaluate("window.spherewarp.S.recipe.steps[0].droste")
        assert got["inner_radius"] == radius
        kf = got["center"]["keyframes"]
        assert [f[0] for f in kf] == [0, t, 2]
        assert kf[0] == center["keyframes"][0] and kf[2] == center["keyframes"][1]
        moved = pixel_from_lonlat_deg(np.array(kf[1][1], float), W, H)
        assert np.hypot(moved[0] - c["x"] - 12, moved[1] - c["y"] + 9) <= 2.0, moved
        c = centre_mark()  # the mark is where it was dropped
        assert np.hypot(c["x"] - moved[0], c["y"] - moved[1]) <= 1.0
        # the picture is the recipe's at t, as 'spherewarp render' makes it
        edited = pg.evaluate("window.spherewarp.S.recipe")
        out = Recipe.from_dict({**edited, "view": {"size": [W, H]}}).render(frames[k], t=t)
        want_px = np.asarray(getattr(out, "pixels", out))[..., :3].astype(np.float64)
        pg.evaluate("window.spherewarp.settle()")  # the dragged recipe's stages drawn (CI: 11.6 dB)
        value = psnr(shown(pg), want_px)
        print(f"keyframed droste centre dragged at t = {t:g}: PSNR {value:.2f} dB")
        assert value >= 35
        (tmp_path / "keyframed.png").write_bytes(pg.screenshot())
        # dragged again at t: that keyframe changed, none added
        drag_to(pg, box, (c["x"], c["y"]), (c["x"] - 6, c["y"] + 4))
        pg.wait_for_function(
            "window.spherewarp.S.recipe.steps[0].droste.center.keyframes[1][1][0] !== "
            f"{kf[1][1][0]}"
        )
        again = pg.evaluate("window.spherewarp.S.recipe.steps[0].droste.center.keyframes")
        assert [f[0] for f in again] == [0, t, 2]
        # undo, twice: the recipe as it was
        pg.click("#undo")
        pg.click("#undo")
        pg.evaluate("window.spherewarp.settle()")
        assert pg.evaluate("window.spherewarp.S.recipe") == recipe
    finally:
        pg.close()
        srv.close()


def test_what_the_preview_does_not_show_is_said(page):
    """A recipe's view (another projection, a size) and options.interp: the preview shows
    the panorama, bilinear, and says so; "Copy as command" leaves the size to the
    recipe's view (it added the page's --size, against the recipe's)."""
    recipe = {
        "spherewarp": 1,
        "view": {"projection": "rectilinear", "fov": 90, "size": [256, 256]},
        "options": {"interp": "nearest"},
        "steps": [{"rotate": {"yaw": 30}}],
    }
    set_recipe(page, recipe)
    text = page.text_content("#status")
    assert "the render uses the recipe's view (rectilinear, fov 90°, 256x256)" in text, text
    assert 'options.interp "nearest"' in text, text
    page.click("#copy")
    cmd = page.input_value("#cli")
    assert "spherewarp render recipe.json" in cmd and "--size" not in cmd, cmd
    set_recipe(page, {"spherewarp": 1, "steps": [{"rotate": {"yaw": 30}}]})
    assert "the render uses" not in page.text_content("#status")
    page.click("#copy")
    assert f"--size {W}x{H}" in page.input_value("#cli")
    set_recipe(page, {"spherewarp": 1, "steps": []})


def _slider_key(page, recipe, index, key):
    set_recipe(page, recipe)
    page.locator("#params input[type=range]").nth(index).focus()
    page.keyboard.press(key)
    page.evaluate("window.spherewarp.settle()")
    return page.evaluate("window.spherewarp.S.recipe.steps[0]")


def test_sliders_reach_only_values_the_recipe_takes(page):
    """A zoom factor's slider stops above 0 (Home made it -3, which the render refuses);
    power's n moves by whole numbers, skipping 0 (one ArrowRight made it 3.012, which
    the shader cannot preview)."""
    zoom = {"spherewarp": 1, "steps": [{"zoom": {"at": [20, 10], "factor": 3}}]}
    factor = _slider_key(page, zoom, 2, "Home")["zoom"]["factor"]
    assert 0 < factor < 0.1, factor
    Recipe.from_dict({"spherewarp": 1, "steps": [{"zoom": {"at": [20, 10], "factor": factor}}]})
    assert page.get_attribute("#status", "class") != "bad"
    assert _slider_key(page, zoom, 2, "End")["zoom"]["factor"] == pytest.approx(9, abs=0.02)
    power = {"spherewarp": 1, "steps": [{"power": {"n": 3}}]}
    assert _slider_key(page, power, 0, "ArrowRight")["power"]["n"] == 4
    assert page.evaluate("window.spherewarp.S.stages.codes") == [2]  # previewed live
    power = {"spherewarp": 1, "steps": [{"power": {"n": 1}}]}
    assert _slider_key(page, power, 0, "ArrowLeft")["power"]["n"] == -1  # 0: a constant
    set_recipe(page, {"spherewarp": 1, "steps": []})


def test_a_server_gone_during_a_render_is_said(browser, tmp_path):
    """The server stops while a render runs: the page says the render has no answer (it
    said "rendering 0%" forever, the failed poll an uncaught promise rejection)."""
    import threading

    srv = ViewerServer(None, None)
    gate = threading.Event()
    srv._render = lambda key, job, *rest: (setattr(job, "started", True), gate.wait(30))
    pg = browser.new_page(viewport={"width": 1000, "height": 600})
    errors = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    try:
        load(pg, srv.url + f"?view=flat&size={W}x{H}")
        pg.click("#render")
        pg.wait_for_function("document.getElementById('status').textContent.includes('rendering')")
        # the server gone: its kept-alive connections would still answer in this process
        pg.route("**/api/render/*", lambda route: route.abort("connectionrefused"))
        pg.wait_for_function(
            "document.getElementById('status').textContent.includes('no answer')", timeout=10000
        )
        assert pg.get_attribute("#status", "class") == "bad"
        assert errors == []
    finally:
        gate.set()
        pg.close()
        srv.close()


def test_render_button_is_off_while_its_render_runs_and_a_refusal_stays(browser):
    """The Render button is off while its render runs (eight clicks made eight renders);
    a render the server refuses (429, a full queue: here from another tab) is said and
    stays said (progress of other renders overwrote it)."""
    import threading

    srv = ViewerServer(None, None)
    gate = threading.Event()

    def held(key, job, *rest):
        job.started = True
        gate.wait(30)
        job.error = "stopped by the test"
        job.done = True

    srv._render = held
    pages = [browser.new_page(viewport={"width": 1000, "height": 600}) for _ in range(2)]
    try:
        for pg in pages:
            load(pg, srv.url + f"?view=flat&size={W}x{H}")
        first, second = pages
        first.click("#render")
        first.wait_for_function("document.getElementById('status').textContent.includes('render')")
        assert first.is_disabled("#render")
        for _ in range(4):  # the queue full
            srv.start_render(None)
        second.click("#render")
        second.wait_for_function("document.getElementById('status').className === 'bad'")
        second.wait_for_timeout(1000)
        assert "renders are waiting already" in second.text_content("#status")
        assert second.is_enabled("#render")
        assert first.is_disabled("#render")
        gate.set()
        first.wait_for_function("document.getElementById('status').className === 'bad'")
        assert "stopped by the test" in first.text_content("#status")
        assert first.is_enabled("#render")
    finally:
        gate.set()
        for pg in pages:
            pg.close()
        srv.close()


def test_loading_the_same_recipe_file_again_loads_it(page, tmp_path):
    """Load recipe twice with the same file: the second load is a load too (the file
    input kept the name, so no change came and nothing happened)."""
    path = tmp_path / "r.json"
    path.write_text(json.dumps({"spherewarp": 1, "steps": [{"rotate": {"yaw": 30}}]}))
    set_recipe(page, {"spherewarp": 1, "steps": []})
    for _ in range(2):
        page.set_input_files("#load", str(path))
        page.wait_for_function("window.spherewarp.S.recipe.steps.length === 1")
        page.evaluate("window.spherewarp.settle()")
        set_recipe(page, {"spherewarp": 1, "steps": []})


def test_undo_keys_in_a_text_box_are_the_boxs_own(page):
    """Ctrl+Z while typing in the size box undoes the typing, not the recipe (it took the
    recipe's last step away); outside a text box it is still the recipe's undo."""
    set_recipe(page, {"spherewarp": 1, "steps": []})
    set_recipe(page, {"spherewarp": 1, "steps": [{"rotate": {"yaw": 30}}]})
    page.focus("#size")
    page.keyboard.press("Control+z")
    page.evaluate("window.spherewarp.settle()")
    assert len(page.evaluate("window.spherewarp.S.recipe.steps")) == 1
    page.locator("#size").blur()
    page.focus("#render")
    page.keyboard.press("Control+z")
    page.evaluate("window.spherewarp.settle()")
    assert page.evaluate("window.spherewarp.S.recipe.steps") == []


def test_load_recipe_by_keyboard_and_a_status_read_out(page):
    """Load recipe is a button Tab reaches (its file input was display:none), and it
    opens the file chooser; the status footer is a live region, an error an alert."""
    page.focus("#save")
    page.keyboard.press("Shift+Tab")
    assert page.evaluate("document.activeElement.id") == "load-button"
    # Enter on it clicks the file input (the chooser itself is the browser's)
    page.evaluate("""() => { window.__chose = 0; document.getElementById('load').addEventListener(
        'click', (ev) => { window.__chose++; ev.preventDefault(); }, { once: true }); }""")
    page.keyboard.press("Enter")
    page.wait_for_function("window.__chose === 1")
    set_recipe(page, {"spherewarp": 1, "steps": [{"rotate": {"yaw": 30}}]})
    assert page.get_attribute("#status", "role") == "status"
    assert page.get_attribute("#status", "aria-live") == "polite"
    set_recipe(page, {"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": -1}}]})
    assert page.get_attribute("#status", "role") == "alert"
    set_recipe(page, {"spherewarp": 1, "steps": []})
    assert page.get_attribute("#status", "role") == "status"


def _type_size(page, text):
    page.fill("#size", text)
    page.press("#size", "Enter")
    page.evaluate("window.spherewarp.settle()")
    return page.evaluate("window.spherewarp.S.size"), page.text_content("#status")


def test_size_box_refuses_what_cannot_be_drawn(page):
    """0x0 (the canvas went away), 20000x10000 (the page hung), a width past what the
    GPU draws (cut off), "abc" (silently ignored): refused with the reason, the size
    kept; a good size is taken."""
    gpu = page.evaluate(
        "document.getElementById('view').getContext('webgl2')"
        ".getParameter(WebGL2RenderingContext.MAX_VIEWPORT_DIMS)[0]"
    )
    for bad, why in [
        ("0x0", "expected a width of 1 to"),
        ("20000x10000", "expected a width of 1 to"),
        (f"{min(8192, gpu) + 1}x64", "expected a width of 1 to"),
        ("abc", 'expected WIDTHxHEIGHT, such as 1024x512, got "abc"'),
    ]:
        size, text = _type_size(page, bad)
        assert size == [W, H], bad
        assert why in text and page.get_attribute("#status", "class") == "bad", (bad, text)
        assert page.get_attribute("#size", "aria-invalid") == "true"
        assert page.evaluate("document.getElementById('view').width") == W
    page.select_option("#side", "original")  # two panels: each at most half as wide
    half = min(8192, gpu // 2)
    size, text = _type_size(page, f"{half + 1}x64")
    assert size == [W, H] and "2 panels side by side" in text, text
    page.select_option("#side", "")
    assert _type_size(page, "200x100")[0] == [200, 100]
    assert page.get_attribute("#size", "aria-invalid") is None
    assert "size=200x100" in page.url
    assert _type_size(page, f"{W}x{H}")[0] == [W, H]
