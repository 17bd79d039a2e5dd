"""The viewer's server, against a running instance: the API and every security case."""

from __future__ import annotations

import http.client
import io
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from spherewarp.recipe import Recipe
from spherewarp.viewer.server import MAX_BODY, STATIC_DIR, ViewerServer


def _snapshot(root: Path) -> dict[str, float]:
    return {str(p): p.stat().st_mtime_ns for p in root.rglob("*")}


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    d = tmp_path_factory.mktemp("view")
    img = d / "pano.png"
    rng = np.random.default_rng(1)
    Image.fromarray(rng.integers(0, 255, (32, 64, 3), dtype=np.uint8)).save(img)
    (d / "secret.txt").write_text("do not serve")
    srv = ViewerServer(img, None)
    yield srv, d
    srv.close()


def _req(srv, method, path, body=None, headers=None):
    c = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=10)
    h = {"Host": f"127.0.0.1:{srv.port}"}
    h.update(headers or {})
    c.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
    for k, v in h.items():
        c.putheader(k, v)
    if body is not None:
        c.putheader("Content-Length", str(len(body)))
    c.endheaders()
    if body is not None:
        c.send(body)
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, data, r


def test_state_and_assets(served):
    srv, _ = served
    status, data, _ = _req(srv, "GET", "/api/state")
    state = json.loads(data)
    assert status == 200
    assert state["image"] == {"width": 64, "height": 32, "name": "pano.png", "video": False}
    assert state["rate"] is None
    assert "#define STAGE_MOBIUS 1" in state["glsl_header"]
    assert state["stages"]["codes"] == []  # no steps: no stages
    assert "#define STAGE_EXPRESSION 64" in state["glsl_header"]
    status, data, r = _req(srv, "GET", "/image")
    assert status == 200 and r.getheader("Content-Type") == "image/png"
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    status, data, _ = _req(srv, "GET", "/testpattern")
    assert status == 200 and data[:4] == b"\x89PNG"
    status, data, _ = _req(srv, "GET", "/")
    assert status == 200 and data == (STATIC_DIR / "index.html").read_bytes()


def test_stages_of_a_posted_recipe(served):
    srv, _ = served
    recipe = {
        "spherewarp": 1,
        "steps": [{"power": {"n": 2}}, {"zoom": {"at": [10, 20], "factor": 2}}],
    }
    origin = {"Origin": f"http://127.0.0.1:{srv.port}", "Content-Type": "application/json"}
    status, data, _ = _req(srv, "POST", "/api/stages", json.dumps(recipe).encode(), origin)
    assert status == 200, data
    assert 2 in json.loads(data)["stages"]["codes"]
    # an expression map: the shader-only stage 64 and its GLSL, made from the tree (its
    # numbers go in the row, never into the GLSL text)
    expr = {"spherewarp": 1, "steps": [{"map": {"expr": "z**2 + 0.25/z"}}]}
    status, data, _ = _req(srv, "POST", "/api/stages", json.dumps(expr).encode(), origin)
    assert status == 200
    st = json.loads(data)["stages"]
    assert st["codes"] == [64] and "expr0" in st["glsl"] and "0.25" not in st["glsl"]
    assert st["rows"][0][:1] == [0.0] and 0.25 in st["rows"][0]
    # hostile expressions: a 400 with the expression parser's line, nothing compiled
    for bad in ("__import__('os').system('id')", "z.real", "z; }", "exp(" * 60 + "z" + ")" * 60):
        body = json.dumps({"spherewarp": 1, "steps": [{"map": {"expr": bad}}]}).encode()
        status, data, _ = _req(srv, "POST", "/api/stages", body, origin)
        assert status == 400, bad
        err = json.loads(data)["error"]
        assert err.startswith("recipe: ") and "\n" not in err, err
    # a map with no compiled stage at all (the exact Lattès map): the page is told why
    exact = {"spherewarp": 1, "steps": [{"lattes": {"alpha": "1+i", "exact": True}}]}
    status, data, _ = _req(srv, "POST", "/api/stages", json.dumps(exact).encode(), origin)
    assert status == 200
    assert json.loads(data)["stages"]["codes"] is None


def test_stages_of_an_animated_recipe_say_where_its_marks_are(served):
    """An animated recipe's reply has its steps at ``?t`` (the recipe's own tracks
    evaluated: a loop's time wraps round), where the page draws its marks."""
    srv, _ = served
    center = {"keyframes": [[0, [-100, -20]], [2, [20, 10]]], "easing": "smoothstep"}
    radius = {"keyframes": [[0, 10], [2, 30]]}
    recipe = {
        "spherewarp": 1,
        "duration": 2,
        "loop": True,
        "steps": [{"droste": {"center": center, "inner_radius": radius}}],
    }
    r = Recipe.from_dict(recipe)
    for t, tt in ((0.5, 0.5), (3.25, 1.25)):
        status, data, _ = _req(srv, "POST", f"/api/stages?t={t}", json.dumps(recipe).encode())
        assert status == 200, data
        at = json.loads(data)["at"]
        assert at["time"] == tt
        got = at["steps"][0]["droste"]
        want = r.step_values(0, t)
        assert np.allclose(got["center"], want["center"])
        assert got["inner_radius"] == want["inner_radius"]
        assert not np.allclose(got["center"], [-100, -20])
    # a recipe with no tracks: no "at" (the page draws it as it is)
    still = {"spherewarp": 1, "steps": [{"droste": {"center": [0, 0], "inner_radius": 9}}]}
    data = json.loads(_req(srv, "POST", "/api/stages", json.dumps(still).encode())[1])
    assert "at" not in data


@pytest.mark.parametrize(
    "path",
    [
        "/../secret.txt",
        "/assets/../../secret.txt",
        "/%2e%2e/secret.txt",
        "/assets/%2e%2e/%2e%2e/%2e%2e/secret.txt",
        "/%2E%2E%2Fsecret.txt",
        "/..%2f..%2fserver.py",
        "/..%5c..%5cserver.py",
        "/server.py",
        "/%00index.html",
        "//etc/passwd",
    ],
)
def test_path_traversal(served, path):
    srv, d = served
    before = _snapshot(d)
    status, data, _ = _req(srv, "GET", path)
    assert status in (400, 404), (path, status)
    assert b"do not serve" not in data and b"import" not in data
    assert _snapshot(d) == before


@pytest.mark.parametrize("host", ["evil.example:80", "evil.example", "127.0.0.1:1", ""])
def test_dns_rebinding(served, host):
    srv, _ = served
    for path in ("/", "/api/state", "/image"):
        status, _, _ = _req(srv, "GET", path, headers={"Host": host})
        assert status == 403, (host, path)


def test_cross_origin(served):
    srv, d = served
    before = _snapshot(d)
    body = json.dumps({"spherewarp": 1, "steps": []}).encode()
    for hdr in ({"Origin": "http://evil.example"}, {"Sec-Fetch-Site": "cross-site"}):
        assert _req(srv, "GET", "/api/state", headers=hdr)[0] == 403
        assert _req(srv, "POST", "/api/render", body, hdr)[0] == 403
        assert _req(srv, "POST", "/api/stages", body, hdr)[0] == 403
    assert _snapshot(d) == before
    assert not srv.jobs


def test_oversized_body(served):
    srv, d = served
    before = _snapshot(d)
    # the length is refused before the body is read (the server then closes the
    # connection: a client still sending gets a broken pipe, so only a little is sent)
    big = {"Content-Length": str(MAX_BODY + 1)}
    for path in ("/api/render", "/api/stages"):
        c = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=10)
        c.putrequest("POST", path, skip_host=True, skip_accept_encoding=True)
        c.putheader("Host", f"127.0.0.1:{srv.port}")
        for k, v in big.items():
            c.putheader(k, v)
        c.endheaders()
        c.send(b"x" * 1000)
        r = c.getresponse()
        assert r.status == 413 and "over the limit" in json.loads(r.read())["error"]
        c.close()
    assert _snapshot(d) == before and not srv.jobs


@pytest.mark.parametrize(
    ("body", "line"),
    [
        (b"{not json", "not JSON"),
        (b'{"spherewarp": 1, "steps": [{"zooom": {}}]}', "unknown effect 'zooom'"),
        (b'{"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": -2}}]}', "factor"),
        (b"\xff\xfe", "UTF-8"),
    ],
)
def test_malformed_recipe(served, body, line):
    srv, d = served
    before = _snapshot(d)
    for path in ("/api/render", "/api/stages"):
        status, data, _ = _req(srv, "POST", path, body)
        assert status == 400
        assert line in json.loads(data)["error"]
    assert _snapshot(d) == before and not srv.jobs


def test_render_job(served):
    srv, d = served
    before = _snapshot(d)
    recipe = {"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": 2}}]}
    status, data, _ = _req(srv, "POST", "/api/render", json.dumps(recipe).encode())
    assert status == 200
    job = json.loads(data)["job"]
    for _ in range(300):
        st = json.loads(_req(srv, "GET", f"/api/render/{job}")[1])
        if st["done"]:
            break
        time.sleep(0.1)
    assert st["started"] and st["done"] and st["error"] is None and st["progress"] == 1.0
    status, data, r = _req(srv, "GET", f"/api/render/{job}/file")
    assert status == 200 and "attachment" in r.getheader("Content-Disposition")
    assert data[:4] == b"\x89PNG"
    assert _snapshot(d) == before  # written in the server's own temporary folder
    assert _req(srv, "GET", "/api/render/nope")[0] == 404


def test_cli_view_prints_url_and_warns(tmp_path):
    env = dict(os.environ)
    cmd = [sys.executable, "-m", "spherewarp", "view", "--no-browser", "--host", "0.0.0.0"]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = p.stdout.readline()
        assert line.startswith("spherewarp view: http://0.0.0.0:")
    finally:
        p.terminate()
        _, err = p.communicate(timeout=10)
    assert "warning: listening on 0.0.0.0, not loopback" in err
    # the names it answers to (any other Host is refused)
    assert "host names 0.0.0.0, 127.0.0.1, localhost" in err and "Traceback" not in err


def test_cli_view_on_another_loopback_address_does_not_warn(tmp_path):
    """127.0.0.2 is loopback (127.0.0.0/8): no "not loopback" warning (it had one), and
    the server answers to its own name only."""
    cmd = [sys.executable, "-m", "spherewarp", "view", "--no-browser", "--host", "127.0.0.2"]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = p.stdout.readline()
        assert line.startswith("spherewarp view: http://127.0.0.2:"), line
    finally:
        p.terminate()
        _, err = p.communicate(timeout=10)
    assert "warning" not in err, err
    srv = ViewerServer(None, None, host="127.0.0.2")
    try:
        assert srv.host_names == ["127.0.0.2"]
    finally:
        srv.close()


def test_cli_view_bad_recipe_is_one_line(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"spherewarp": 1, "steps": [{"zooom": {}}]}')
    before = _snapshot(tmp_path)
    p = subprocess.run(
        [sys.executable, "-m", "spherewarp", "view", "--no-browser", "--recipe", str(bad)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr.strip().splitlines() == [
        "spherewarp: error: steps[0]: unknown effect 'zooom' (did you mean 'zoom'?)"
    ]
    assert _snapshot(tmp_path) == before


def _mask_recipe(mask: str) -> dict:
    targets = [{"colour": "#ff0000", "to": [180, 0, 20]}]
    return {"spherewarp": 1, "steps": [{"schottky": {"mask": mask, "targets": targets}}]}


def test_masks_only_the_files_it_was_started_with(tmp_path):
    """A recipe from the page may name only the masks the server was started with (its
    --recipe's, and --mask): any other file, readable or not, existing or not, is a 403
    before it is looked at, and nothing derived from it goes back."""
    d = tmp_path / "work"
    d.mkdir()
    mask = np.zeros((32, 64, 3), np.uint8)
    mask[12:20, 28:36] = (255, 0, 0)
    for name in ("mask.png", "beside.png", "extra.png"):
        Image.fromarray(mask).save(d / name)
    outside = tmp_path / "outside.png"
    Image.fromarray(mask).save(outside)
    (d / "link.png").symlink_to(outside)
    (d / "r.json").write_text(json.dumps(_mask_recipe("mask.png")))
    srv = ViewerServer(None, d / "r.json", masks=[d / "extra.png"])
    try:
        before = _snapshot(tmp_path)
        for ok in ("mask.png", str(d / "mask.png"), str(d / "extra.png"), "../work/mask.png"):
            status, data, _ = _req(
                srv, "POST", "/api/stages", json.dumps(_mask_recipe(ok)).encode()
            )
            assert status == 200, (ok, data)
            key = json.loads(data)["stages"]["labels"][0]["key"]
            assert _req(srv, "GET", f"/api/labels/{key}")[0] == 200
        for bad in (
            "beside.png",  # beside the recipe, but not named by it
            str(outside),
            "link.png",  # a link beside it, to a file outside
            "/etc/passwd",
            "/etc/no-such-file",  # no "not found": the answer says nothing of other files
            "~/.ssh/id_rsa",
        ):
            for path in ("/api/stages", "/api/render"):
                body = json.dumps(_mask_recipe(bad)).encode()
                status, data, _ = _req(srv, "POST", path, body)
                assert status == 403, (bad, path, data)
                err = json.loads(data)["error"]
                assert "is not a file this viewer was started with" in err, err
                assert "not found" not in err
        # the droste mask too
        droste = {"spherewarp": 1, "steps": [{"droste": {"center": [0, 0], "mask": "/etc/passwd"}}]}
        assert _req(srv, "POST", "/api/stages", json.dumps(droste).encode())[0] == 403
        assert not srv.jobs and _snapshot(tmp_path) == before
    finally:
        srv.close()
    # a server started without a recipe or --mask reads no mask at all
    srv = ViewerServer(None, None)
    try:
        body = json.dumps(_mask_recipe(str(d / "mask.png"))).encode()
        assert _req(srv, "POST", "/api/stages", body)[0] == 403
    finally:
        srv.close()


def test_the_pages_recipe_names_its_masks_by_absolute_path(tmp_path):
    """A --recipe naming its mask relative to its folder: the page gets the mask by its
    absolute path, so a recipe it saves elsewhere renders there (it failed: "not found"),
    and the server still takes it (the same file) and nothing else."""
    d = tmp_path / "rdir"
    d.mkdir()
    mask = np.zeros((32, 64, 3), np.uint8)
    mask[12:20, 28:36] = (255, 0, 0)
    Image.fromarray(mask).save(d / "mask.png")
    Image.fromarray(mask).save(tmp_path / "other.png")
    (d / "r.json").write_text(json.dumps(_mask_recipe("mask.png")))
    srv = ViewerServer(None, d / "r.json")
    try:
        recipe = json.loads(_req(srv, "GET", "/api/state")[1])["recipe"]
        assert recipe["steps"][0]["schottky"]["mask"] == str((d / "mask.png").resolve())
        assert _req(srv, "POST", "/api/stages", json.dumps(recipe).encode())[0] == 200
        other = _mask_recipe(str(tmp_path / "other.png"))
        assert _req(srv, "POST", "/api/stages", json.dumps(other).encode())[0] == 403
    finally:
        srv.close()
    saved = tmp_path / "downloads"
    saved.mkdir()
    (saved / "recipe.json").write_text(json.dumps(recipe))
    pano = saved / "pano.png"
    Image.fromarray(np.zeros((32, 64, 3), np.uint8)).save(pano)
    cmd = [sys.executable, "-m", "spherewarp", "render", "recipe.json", "pano.png", "-q"]
    p = subprocess.run([*cmd, "-o", "out.png"], cwd=saved, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert (saved / "out.png").is_file()


def test_label_cache_is_a_locked_lru():
    import threading

    from spherewarp.viewer.server import LabelCache

    cache = LabelCache(4)

    def work(k: int) -> None:
        for i in range(300):
            cache.update({f"{k}-{i}": i})
            cache.get(f"{k}-{i - 1}")
            assert len(cache) <= 4

    threads = [threading.Thread(target=work, args=(k,)) for k in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(cache) == 4
    for k in "abcd":
        cache.update({k: k})
    assert cache.get("a") == "a"  # now the most recently used
    cache.update({"e": "e"})
    assert cache.get("a") == "a" and cache.get("b") is None  # the least recently used went


def test_video_with_range_requests(tmp_path):
    """'spherewarp view VIDEO': the server serves that file with byte ranges (the page's
    video element seeks with them), and nothing else beside it."""
    import av

    path = tmp_path / "clip.webm"
    with av.open(str(path), "w") as c:
        s = c.add_stream("libvpx-vp9", rate=2)
        s.width, s.height, s.pix_fmt = 64, 32, "yuv420p"
        for k in range(3):
            a = np.full((32, 64, 3), 40 * k, np.uint8)
            for p in s.encode(av.VideoFrame.from_ndarray(a, format="rgb24")):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    (tmp_path / "secret.txt").write_text("do not serve")
    whole = path.read_bytes()
    srv = ViewerServer(path, None)
    try:
        state = json.loads(_req(srv, "GET", "/api/state")[1])
        assert state["image"] == {"width": 64, "height": 32, "name": "clip.webm", "video": True}
        assert state["rate"] == 2
        status, data, r = _req(srv, "GET", "/image")  # the first frame
        assert status == 200 and data[:4] == b"\x89PNG"
        status, data, r = _req(srv, "GET", "/video")
        assert status == 200 and data == whole and r.getheader("Accept-Ranges") == "bytes"
        assert r.getheader("Content-Type") == "video/webm"
        n = len(whole)
        for rng, (a, b) in [
            ("bytes=0-99", (0, 99)),
            ("bytes=100-", (100, n - 1)),
            ("bytes=-50", (n - 50, n - 1)),
            (f"bytes=10-{n + 500}", (10, n - 1)),
        ]:
            status, data, r = _req(srv, "GET", "/video", headers={"Range": rng})
            assert status == 206 and data == whole[a : b + 1], rng
            assert r.getheader("Content-Range") == f"bytes {a}-{b}/{n}"
        # one range outside the file: 416, with the file's length
        for bad in (f"bytes={n}-", f"bytes={n + 10}-{n + 20}", "bytes=-0"):
            status, data, r = _req(srv, "GET", "/video", headers={"Range": bad})
            assert status == 416, bad
            assert r.getheader("Content-Range") == f"bytes */{n}"
            assert "do not serve" not in data.decode()
        # a Range that is not one byte range is ignored (RFC 9110): the whole file
        for odd in ("junk", "bytes=5-2", "bytes=0-1,5-6", "items=0-1", "bytes=x-", "bytes=+1-2"):
            status, data, r = _req(srv, "GET", "/video", headers={"Range": odd})
            assert status == 200 and data == whole, odd
            assert r.getheader("Content-Range") is None
        for path_ in (
            "/video/../secret.txt",
            "/secret.txt",
            "/clip.webm",
            "/video%2f..%2fsecret.txt",
        ):
            assert _req(srv, "GET", path_)[0] == 404, path_
        assert _req(srv, "GET", "/video", headers={"Host": "evil.example"})[0] == 403
        # "render full resolution" of the frame at ?t= (a bad t: 400, no job)
        body = json.dumps({"spherewarp": 1, "steps": []}).encode()
        for bad in ("-1", "nan", "abc", "1e9"):
            status, data, _ = _req(srv, "POST", f"/api/render?t={bad}", body)
            assert status == 400 and "t: expected a time" in json.loads(data)["error"], bad
        assert not srv.jobs
        from spherewarp.viewer.server import video_frame

        assert video_frame(path, 1.2)[0, 0, 0] > video_frame(path, 0.7)[0, 0, 0] > 20
    finally:
        srv.close()
    # an image server has no /video
    srv = ViewerServer(None, None)
    try:
        assert _req(srv, "GET", "/video")[0] == 404
    finally:
        srv.close()


def test_cli_view_bad_video_is_one_line(tmp_path):
    bad = tmp_path / "bad.mp4"
    bad.write_text("not a video")
    p = subprocess.run(
        [sys.executable, "-m", "spherewarp", "view", "--no-browser", str(bad)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert p.returncode != 0 and p.stdout == "" and "Traceback" not in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1
    assert "not a video file" in p.stderr


def test_file_of_a_failed_render_says_it_failed(served):
    """The file of a render that failed is refused with the render's error, not as a
    render still running."""
    from spherewarp.errors import InvalidValueError

    srv, _ = served

    class Failing:  # a recipe that fails as it renders
        def render(self, image, t=0.0, progress=None):
            raise InvalidValueError("zoom: factor too large for this image")

    job = srv.start_render(Failing())
    for _ in range(300):
        st = json.loads(_req(srv, "GET", f"/api/render/{job}")[1])
        if st["done"]:
            break
        time.sleep(0.1)
    assert st["error"] == "InvalidValueError: zoom: factor too large for this image"
    status, data, _ = _req(srv, "GET", f"/api/render/{job}/file")
    assert status == 422, data
    assert json.loads(data)["error"] == f"the render failed: {st['error']}"
    del srv.jobs[job]  # the module's other tests see no jobs


class _Held:
    """A recipe whose render waits for ``gate`` (to hold the render worker)."""

    def __init__(self, gate=None):
        self.gate = gate

    def render(self, image, t=0.0, progress=None):
        if self.gate is not None:
            assert self.gate.wait(30)
        return np.zeros((4, 8, 3), np.uint8)


def _wait_done(srv, key):
    for _ in range(300):
        if srv.jobs[key].done:
            return
        time.sleep(0.05)
    raise AssertionError("the render did not finish")


@pytest.fixture()
def own_server(tmp_path):
    img = tmp_path / "pano.png"
    Image.fromarray(np.zeros((32, 64, 3), np.uint8)).save(img)
    srv = ViewerServer(img, None)
    yield srv
    srv.close()


def test_renders_queue_and_a_full_queue_is_refused(own_server):
    """Renders run one at a time; past MAX_QUEUED waiting ones a new one gets 429 (the
    page may not start 50 full-resolution renders at once), and once they are done
    the next is taken."""
    import threading

    from spherewarp.viewer import server

    srv = own_server
    gate = threading.Event()
    first = srv.start_render(_Held(gate))
    for _ in range(100):  # the worker took it: it runs, the rest wait
        if srv.jobs[first].started:
            break
        time.sleep(0.02)
    waiting = [srv.start_render(_Held(gate)) for _ in range(server.MAX_QUEUED)]
    assert srv.jobs[first].started and not any(srv.jobs[k].started for k in waiting)
    recipe = {"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": 2}}]}
    status, data, r = _req(srv, "POST", "/api/render", json.dumps(recipe).encode())
    assert status == 429 and r.getheader("Retry-After") == "5"
    assert "renders are waiting" in json.loads(data)["error"]
    assert len(srv.jobs) == 1 + server.MAX_QUEUED
    gate.set()
    for k in [first, *waiting]:
        _wait_done(srv, k)
        assert srv.jobs[k].error is None and srv.jobs[k].path.is_file()
    status, data, _ = _req(srv, "POST", "/api/render", json.dumps(recipe).encode())
    assert status == 200


def test_old_renders_and_their_files_are_forgotten(own_server, monkeypatch):
    """Only MAX_JOBS renders are kept: the oldest finished one goes, with its file,
    so a long session's server does not grow without end."""
    from spherewarp.viewer import server

    monkeypatch.setattr(server, "MAX_JOBS", 2)
    srv = own_server
    keys = []
    for _ in range(3):
        keys.append(srv.start_render(_Held()))
        _wait_done(srv, keys[-1])
    files = sorted(srv.tmp.iterdir())
    assert list(srv.jobs) == keys[1:]
    assert files == sorted(srv.jobs[k].path for k in keys[1:])
    assert _req(srv, "GET", f"/api/render/{keys[0]}/file")[0] == 404
    assert _req(srv, "GET", f"/api/render/{keys[2]}/file")[0] == 200


def test_an_unexpected_error_is_a_500_and_one_line(own_server, monkeypatch, capfd):
    """A bug in a handler answers 500 with a JSON error (not a connection dropped
    without a reply) and says one line on stderr, no traceback."""
    srv = own_server

    def broken(self):
        raise KeyError("oops")

    monkeypatch.setattr(ViewerServer, "state", broken)
    status, data, r = _req(srv, "GET", "/api/state")
    assert status == 500 and r.getheader("Connection") == "close"
    assert json.loads(data) == {"error": "internal error: KeyError"}
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "KeyError: 'oops'" in err and "Traceback" not in err
    assert _req(srv, "GET", "/image")[0] == 200  # and it goes on serving


def _hdr_pano(d: Path) -> Path:
    from spherewarp.io.images import write_image

    rng = np.random.default_rng(5)
    px = (rng.random((32, 64, 3)) ** 2 * 4).astype(np.float32)  # linear light, up to 4
    path = d / "hdr.exr"
    write_image(path, px, gpano=None)
    return path


def _cli_render(d: Path, recipe: dict, image: Path) -> np.ndarray:
    (d / "r.json").write_text(json.dumps(recipe))
    out = d / "cli.png"
    cmd = [sys.executable, "-m", "spherewarp", "render", str(d / "r.json"), str(image)]
    p = subprocess.run(
        [*cmd, "-o", str(out), "-q", "--overwrite"], capture_output=True, text=True, timeout=120
    )
    assert p.returncode == 0, p.stderr
    return _read16(out.read_bytes())


def _read16(data: bytes) -> np.ndarray:
    """A PNG's samples as they are (Pillow reads 16-bit RGB as 8 bits)."""
    from spherewarp.io.images import read_image

    with tempfile.TemporaryDirectory() as d:
        (Path(d) / "a.png").write_bytes(data)
        return np.asarray(read_image(Path(d) / "a.png").pixels).astype(np.float64)


def _psnr(a: np.ndarray, b: np.ndarray, peak: float) -> float:
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(peak**2 / mse)


@pytest.mark.parametrize("options", [{}, {"tonemap": "reinhard", "exposure": 1.5}])
def test_hdr_renders_and_shows_as_the_command_writes_it(tmp_path, options):
    """An HDR (float) input: "render full resolution" writes a PNG (it failed: "PNG
    cannot store float32 pixels"), tone-mapped to 16 bits with the recipe's tone map
    and exposure as ``spherewarp render`` does; ``/image`` is the command's render of
    no steps, tone-mapped the same way (it was clipped), in 8 bits."""
    image = _hdr_pano(tmp_path)
    recipe = {"spherewarp": 1, "steps": [{"zoom": {"at": [10, 5], "factor": 2}}]}
    if options:
        recipe["options"] = options
    start = tmp_path / "start.json"
    start.write_text(json.dumps({"spherewarp": 1, "steps": [], "options": options}))
    srv = ViewerServer(image, start)
    try:
        status, data, _ = _req(srv, "POST", "/api/render", json.dumps(recipe).encode())
        job = json.loads(data)["job"]
        for _ in range(1200):  # the first render may compile the renderer
            if srv.jobs[job].done:
                break
            time.sleep(0.1)
        assert srv.jobs[job].done and srv.jobs[job].error is None
        status, data, _ = _req(srv, "GET", f"/api/render/{job}/file")
        assert status == 200
        served_render = _read16(data)
        shown = np.asarray(Image.open(io.BytesIO(_req(srv, "GET", "/image")[1])))
    finally:
        srv.close()
    cli = _cli_render(tmp_path, recipe, image)
    assert served_render.shape == cli.shape and cli.max() > 255  # both 16-bit
    assert _psnr(served_render, cli, 65535) > 60
    identity = _cli_render(tmp_path, {"spherewarp": 1, "steps": [], "options": options}, image)
    assert shown.dtype == np.uint8
    assert _psnr(shown.astype(np.float64), identity / 257, 255) > 45


def test_a_failed_render_does_not_name_the_servers_folder(own_server):
    class Failing:
        def render(self, image, t=0.0, progress=None):
            raise OSError(f"cannot write '{own_server.tmp / 'x.png'}'")

    job = own_server.start_render(Failing())
    _wait_done(own_server, job)
    assert own_server.jobs[job].error == "OSError: cannot write 'x.png'"
