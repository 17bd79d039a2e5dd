"""Fuzz: hostile files and values end in one error (or a correct result), in bounded memory.

Seeded, a few hundred cases, a few seconds. Most cases run in one child process
(``python tests/test_fuzz.py``) that calls the library in-process under
``RLIMIT_AS``, so a runaway allocation fails there instead of eating the
machine; it reports its cases and its peak resident memory
(``resource.getrusage``) as JSON. Every case must return a result or raise a
:class:`~spherewarp.errors.SpherewarpError` (never another exception), within
a few seconds. The same child then runs ``spherewarp info`` (``cli.main``)
in-process on every image case with fds 1 and 2 captured: one
``spherewarp: error:`` line and nothing on stdout, or a report and
``spherewarp: warning:`` lines only, never a codec library's own output. A
handful of real command lines (fresh processes) check the same from outside.

The cases: truncations and byte mutations of small files in every format
(PNG 8/16-bit, JPEG, TIFF 8/16/float, WebP, EXR), header "bombs" declaring
huge sizes, multi-part EXR, hostile XMP in UTF-8, UTF-16BE and UTF-16LE (DTDs,
entities, hostile GPano numbers), a GPano canvas larger than the pixel limit,
hostile map JSON, devices, FIFOs and a directory as input.
"""

from __future__ import annotations

import io
import json
import os
import random
import struct
import subprocess
import sys
import tempfile
import threading
import zlib
from pathlib import Path

import pytest

SEED = 20261202
#: the pixel limit the in-process cases read with (the base files are 64 x 32)
MAX_PIXELS = 4_000_000
#: the child's address-space limit and the peak-memory bound checked
ADDRESS_SPACE = 3 << 30
MAX_RSS_GROWTH_MB = 300
CASE_SECONDS = 10

GPANO = "http://ns.google.com/photos/1.0/panorama/"


# -- the cases (built in the child) ----------------------------------------------------


def _xmp(width: str = "64", height: str = "32", *, dtd: str = "", decl: str = "") -> str:
    return (
        f'{decl}{dtd}<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF '
        'xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">'
        f'<rdf:Description xmlns:GPano="{GPANO}" GPano:ProjectionType="equirectangular" '
        f'GPano:FullPanoWidthPixels="{width}" GPano:FullPanoHeightPixels="{height}" '
        f'GPano:CroppedAreaImageWidthPixels="64" GPano:CroppedAreaImageHeightPixels="32"/>'
        "</rdf:RDF></x:xmpmeta>"
    )


def _base_files(d: Path) -> dict[str, bytes]:
    import numpy as np

    from spherewarp.io import write_image

    rng = np.random.default_rng(SEED)
    px8 = rng.integers(0, 256, (32, 64, 3), dtype=np.uint8)
    out = {}
    specs = [
        ("p8.png", px8),
        ("p16.png", px8.astype(np.uint16) * 257),
        ("j.jpg", px8),
        ("t8.tif", px8),
        ("t16.tif", px8.astype(np.uint16) * 257),
        ("tf.tif", px8.astype(np.float32) / 255),
        ("w.webp", px8),
        ("e.exr", px8.astype(np.float32) / 255),
    ]
    for name, px in specs:
        out[name] = write_image(d / name, px, overwrite=True).read_bytes()
    # a multi-part EXR: part 0 is small, the others add up past the limit
    sizes = [(32, 64), (1024, 2048), (1024, 2048)]
    out["multi.exr"] = write_multipart_exr(d / "multi.exr", sizes).read_bytes()
    return out


def write_multipart_exr(path: Path, sizes: list[tuple[int, int]]) -> Path:
    """An RGB OpenEXR file with one zero part of each (height, width) in ``sizes``."""
    import numpy as np
    import OpenEXR

    parts = []
    for k, (h, w) in enumerate(sizes):
        header = {
            "compression": OpenEXR.ZIP_COMPRESSION,
            "type": OpenEXR.scanlineimage,
            "dataWindow": ((0, 0), (w - 1, h - 1)),
            "displayWindow": ((0, 0), (63, 31)),
        }
        plane = np.zeros((h, w), np.float32)
        parts.append(OpenEXR.Part(header, {"R": plane, "G": plane, "B": plane}, f"p{k}"))
    OpenEXR.File(parts).write(str(path))
    return path


def _png_chunk(ctype: bytes, payload: bytes) -> bytes:
    crc = zlib.crc32(ctype + payload) & 0xFFFFFFFF
    return struct.pack(">I", len(payload)) + ctype + payload + struct.pack(">I", crc)


def _header_bombs(base: dict[str, bytes]) -> dict[str, bytes]:
    """Files whose headers declare far more pixels than they hold."""
    png = base["p8.png"]
    ihdr = bytearray(png[16:29])
    ihdr[0:8] = struct.pack(">II", 100_000, 100_000)
    bombs = {"bomb.png": png[:8] + _png_chunk(b"IHDR", bytes(ihdr)) + png[33:]}
    jpg = bytearray(base["j.jpg"])
    sof = jpg.find(b"\xff\xc0")
    jpg[sof + 5 : sof + 9] = struct.pack(">HH", 60_000, 60_000)
    bombs["bomb.jpg"] = bytes(jpg)
    webp = bytearray(base["w.webp"])
    assert webp[12:16] == b"VP8X"  # what write_image writes (it carries the XMP)
    webp[24:30] = b"\xff" * 6  # a 16777216 x 16777216 canvas
    bombs["bomb.webp"] = bytes(webp)
    return bombs


def jpeg_with_xmp(packet: bytes, shape: tuple[int, int] = (32, 64)) -> bytes:
    """A black JPEG of ``shape`` (height, width) carrying the XMP ``packet`` as given."""
    import numpy as np
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.zeros((*shape, 3), np.uint8)).save(buf, "JPEG", xmp=packet)
    return buf.getvalue()


def _xmp_packets() -> dict[str, bytes]:
    """XMP packets, hostile and not, in UTF-8, UTF-16BE and UTF-16LE."""
    entity = '<!DOCTYPE x [<!ENTITY fw "512">]>'
    bomb = '<!DOCTYPE x [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;">]>'
    external = '<!DOCTYPE x [<!ENTITY e SYSTEM "file:///etc/passwd">]>'
    texts = {
        "plain": _xmp(),
        "entity": _xmp("&fw;", dtd=entity),
        "bomb": _xmp("&b;", dtd=bomb),
        "external": _xmp("&e;", dtd=external),
        "doctype-only": _xmp(dtd="<!DOCTYPE x>"),
        "not-xml": "<x:xmpmeta <<<",
    }
    for value in ["inf", "Infinity", "-inf", "nan", "1e999", "9" * 5000, "1e308"]:
        texts[f"num-{value[:8]}"] = _xmp(value)
    for value in [str(10**30), str(2**62), "-64", "64.5", "0x40", "", " 64 "]:
        texts[f"num-{value[:8]}-h"] = _xmp("64", value or "")
    packets = {}
    for name, text in texts.items():
        packets[f"{name}.utf8"] = text.encode("utf-8")
        decl = '<?xml version="1.0" encoding="UTF-16"?>'
        packets[f"{name}.utf16be"] = (decl + text).encode("utf-16-be")
        packets[f"{name}.utf16le"] = (decl + text).encode("utf-16-le")
    return packets


def _map_documents(rng: random.Random) -> list[str]:
    """Hostile map JSON: missing and wrong fields, huge numbers, deep nesting."""
    from spherewarp.maps import Lattes, Mobius, Power

    valid = [
        Mobius.zoom((30, 10), 2.0).to_dict(),
        Power(2).to_dict(),
        Lattes(2).to_dict(),
        {"kind": "expression", "expr": "z**2"},
        {"kind": "droste", "center": [0, 0], "rho": 0.1, "scale": 8},
        {"kind": "composite", "maps": [Power(2).to_dict(), Mobius.zoom((0, 0), 2).to_dict()]},
    ]
    hostile_values = [
        None, True, "x", "1e999", [], {}, [[1]], 1e308, -1e308, 10**30, 2**62, 0, -1,
        "__import__('os')", {"kind": "mobius"},
    ]  # fmt: skip
    docs = [json.dumps(v) for v in valid]
    for v in valid:
        for key in v:
            if key == "kind":
                continue
            short = {k: x for k, x in v.items() if k != key}
            docs.append(json.dumps(short))
            for value in rng.sample(hostile_values, 5):
                docs.append(json.dumps({**v, key: value}))
    docs += [
        '{"kind": "os.system", "command": "true"}',
        '{"kind": "power", "exponent": ' + "9" * 5000 + "}",
        '{"kind": "power", "exponent": 1e999}',
        '{"kind": "power", "exponent": Infinity}',
        '{"kind": "power", "exponent": NaN}',
        "[" * 100_000 + "]" * 100_000,
        '{"kind": "composite", "maps": ' + '[{"kind": "composite", "maps": ' * 5000 + "[]"
        + "}]" * 5000 + "}",
        '{"kind": "mobius", "matrix": [[1e308, 1e308], [1e308, -1e308]]}',
        '{"kind": "mobius", "matrix": [[5e-324, 0], [0, 1]]}',
        "not json",
        "",
        '"just a string"',
    ]  # fmt: skip
    return docs


def _image_cases(d: Path, rng: random.Random) -> list[tuple[str, Path]]:
    base = _base_files(d)
    files: dict[str, bytes] = {}
    for name, data in base.items():
        files[name] = data
        cuts = sorted({rng.randrange(1, len(data)) for _ in range(12)} | {8, 16, 64})
        for cut in cuts:
            files[f"cut{cut}-{name}"] = data[:cut]
        for k in range(14):
            buf = bytearray(data)
            for _ in range(rng.randint(1, 8)):
                # half of the flips land in the header, where sizes and offsets are
                at = rng.randrange(min(len(buf), 200)) if rng.random() < 0.5 else None
                buf[at if at is not None else rng.randrange(len(buf))] = rng.randrange(256)
            files[f"mut{k}-{name}"] = bytes(buf)
    files.update(_header_bombs(base))
    for name, packet in _xmp_packets().items():
        files[f"xmp-{name}.jpg"] = jpeg_with_xmp(packet)
    # a 64 x 32 JPEG that declares a 30000 x 15000 panorama around it
    files["canvas.jpg"] = jpeg_with_xmp(_xmp("30000", "15000").encode())
    cases = []
    for name, data in files.items():
        p = d / "cases" / name
        p.parent.mkdir(exist_ok=True)
        p.write_bytes(data)
        cases.append((name, p))
    return cases


def endless_writer(fifo: Path, stop: threading.Event) -> None:
    """Write zeros into ``fifo`` until ``stop`` is set or the reader goes."""
    try:
        with open(fifo, "wb") as fh:
            while not stop.is_set():
                fh.write(b"\0" * 65536)
    except OSError:
        pass


def _run_main(main, argv: list[str]) -> tuple[int | None, str, str]:
    """Run the CLI's main() in-process with fds 1 and 2 captured."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with tempfile.TemporaryFile() as fo, tempfile.TemporaryFile() as fe:
        os.dup2(fo.fileno(), 1)
        os.dup2(fe.fileno(), 2)
        code: int | None = 0
        try:
            main(argv)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
        fo.seek(0)
        fe.seek(0)
        return code, fo.read().decode("utf-8", "replace"), fe.read().decode("utf-8", "replace")


def _child_main() -> None:
    """Run every in-process case; print one JSON report."""
    import resource
    import signal
    import warnings

    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))
    warnings.simplefilter("ignore")

    import numpy as np

    from spherewarp.errors import SpherewarpError
    from spherewarp.io import ImageData, parse_gpano, read_image
    from spherewarp.maps import SphereMap, map_from_json

    rng = random.Random(SEED)
    tmp = Path(tempfile.mkdtemp(prefix="sw-fuzz-"))

    def _alarm(signum, frame):  # noqa: ARG001
        raise TimeoutError("case took too long")

    signal.signal(signal.SIGALRM, _alarm)
    report: dict = {"cases": 0, "bad": [], "checks": {}}

    def case(name: str, func, check=None) -> None:
        report["cases"] += 1
        try:
            signal.alarm(CASE_SECONDS)
            try:
                result = func()
            finally:
                signal.alarm(0)
        except SpherewarpError as exc:
            text = str(exc)
            if "Traceback" in text or not text.strip():
                report["bad"].append([name, f"bad message: {text[:200]!r}"])
            result = exc
        except BaseException as exc:  # noqa: BLE001 - that is what is being looked for
            report["bad"].append([name, f"{type(exc).__name__}: {str(exc)[:200]}"])
            return
        if check is not None:
            verdict = check(result)
            if verdict is not True:
                report["bad"].append([name, f"wrong result: {verdict}"])

    # after imports and the base files: the baseline of the memory measure
    image_cases = _image_cases(tmp, rng)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss

    def is_image(r: object) -> object:
        ok = isinstance(r, ImageData) and r.pixels.ndim == 3 and r.pixels.size > 0
        return True if ok or isinstance(r, SpherewarpError) else r

    checks = {
        # the DTD rule holds in every encoding: no entity ever becomes a value
        **{
            f"xmp-{n}.{e}.jpg": (lambda r: r.gpano is None or repr(r))
            for n in ("entity", "bomb", "external", "doctype-only")
            for e in ("utf8", "utf16be", "utf16le")
        },
        # an ordinary packet is read in all three
        **{
            f"xmp-plain.{e}.jpg": (lambda r: r.gpano is not None or repr(r))
            for e in ("utf8", "utf16be", "utf16le")
        },
        "multi.exr": lambda r: isinstance(r, SpherewarpError) and "part" in str(r) or repr(r),
        "canvas.jpg": lambda r: isinstance(r, SpherewarpError) and "canvas" in str(r) or repr(r),
    }
    for name in ("bomb.png", "bomb.jpg", "bomb.webp"):
        checks[name] = lambda r: isinstance(r, SpherewarpError) and "pixel limit" in str(r) or r
    for name, path in image_cases:
        limit = None if name == "canvas.jpg" else MAX_PIXELS
        check = checks.get(name, is_image)
        case(name, lambda p=path, m=limit: read_image(p, max_pixels=m), check)

    for name, packet in _xmp_packets().items():
        case(f"parse_gpano:{name}", lambda b=packet: parse_gpano(b))

    for k, doc in enumerate(_map_documents(rng)):
        ok_map = lambda r: isinstance(r, (SphereMap, SpherewarpError)) or repr(r)  # noqa: E731
        case(f"map_from_json:{k}:{doc[:60]}", lambda t=doc: map_from_json(t), ok_map)

    refused = lambda r: isinstance(r, SpherewarpError) or repr(r)  # noqa: E731
    for dev in ("/dev/zero", "/dev/urandom", "/dev/null"):
        if os.path.exists(dev):
            case(dev, lambda p=dev: read_image(p), refused)
    case("directory", lambda: read_image(tmp), refused)
    idle = tmp / "idle.fifo"
    os.mkfifo(idle)
    case("fifo without writer", lambda: read_image(idle), refused)
    busy = tmp / "busy.fifo"
    os.mkfifo(busy)
    stop = threading.Event()
    writer = threading.Thread(target=endless_writer, args=(busy, stop), daemon=True)
    writer.start()
    case("fifo with endless writer", lambda: read_image(busy), refused)
    stop.set()
    with open(os.open(busy, os.O_RDONLY | os.O_NONBLOCK), "rb") as fh:  # let the writer out
        fh.read(1 << 20)

    # The command line's own output for every image case, in-process (a fresh process
    # each would take minutes): one error line, or a report and warning lines only.
    from spherewarp.cli import main

    warnings.simplefilter("default")
    for name, path in image_cases:
        report["cases"] += 1
        code, out, err = _run_main(main, ["info", str(path), "--max-pixels", str(MAX_PIXELS)])
        lines = err.splitlines()
        if code == 2:
            ok = len(lines) == 1 and lines[0].startswith("spherewarp: error: ") and not out
        else:
            ok = code == 0 and all(x.startswith("spherewarp: warning: ") for x in lines)
        if not ok:
            report["bad"].append([f"cli info {name}", f"exit {code}: {out[-300:]!r} {err!r}"])

    rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    report["rss_growth_mb"] = (rss1 - rss0) / 1024
    report["peak_rss_mb"] = rss1 / 1024
    report["numpy"] = np.__version__
    print(json.dumps(report))


# -- the tests -------------------------------------------------------------------------


@pytest.fixture(scope="module")
def child_report() -> dict:
    done = subprocess.run(
        [sys.executable, __file__],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_in_process_cases_end_in_a_spherewarp_error_or_a_result(child_report):
    assert child_report["cases"] >= 300, child_report["cases"]
    assert child_report["bad"] == []


def test_memory_stays_bounded(child_report):
    assert child_report["rss_growth_mb"] < MAX_RSS_GROWTH_MB, child_report


# A few real command lines (each a fresh process): one line on stderr, no library noise.


def _hostile_files(d: Path) -> dict[str, Path]:
    rng = random.Random(SEED + 1)
    base = _base_files(d)
    out = {}
    for name in ("p8.png", "j.jpg", "t16.tif", "w.webp", "e.exr"):
        data = base[name]
        out[f"cut-{name}"] = data[: len(data) // 2]
        buf = bytearray(data)
        for _ in range(6):
            buf[rng.randrange(8, min(len(buf), 300))] = rng.randrange(256)
        out[f"mut-{name}"] = bytes(buf)
    out["multi.exr"] = base["multi.exr"]
    out["good.png"] = base["p8.png"]
    out["canvas.jpg"] = jpeg_with_xmp(_xmp("30000", "15000").encode())
    out["entity16.jpg"] = jpeg_with_xmp(
        ('<?xml version="1.0" encoding="UTF-16"?><!DOCTYPE x [<!ENTITY fw "512">]>'
         + _xmp("&fw;")).encode("utf-16-be")
    )  # fmt: skip
    out["inf.jpg"] = jpeg_with_xmp(_xmp("inf").encode())
    paths = {}
    for name, data in out.items():
        paths[name] = d / name
        paths[name].write_bytes(data)
    return paths


@pytest.fixture(scope="module")
def hostile_dir(tmp_path_factory) -> tuple[Path, dict[str, Path]]:
    d = tmp_path_factory.mktemp("hostile")
    return d, _hostile_files(d)


def _cli(*args: object, cwd: Path) -> tuple[int, str, str]:
    env = {k: v for k, v in os.environ.items() if k != "SPHEREWARP_DEBUG"}
    done = subprocess.run(
        [sys.executable, "-m", "spherewarp", *(str(a) for a in args)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=cwd,
        env={**env, "PYTHONIOENCODING": "utf-8"},
        stdin=subprocess.DEVNULL,
    )
    return done.returncode, done.stdout, done.stderr


def _one_error_line(code: int, out: str, err: str) -> None:
    assert code == 2, (code, out, err)
    assert err.startswith("spherewarp: error:") and err.count("\n") == 1, err
    assert out == "", out  # the codec libraries print nothing, on stdout either


@pytest.mark.parametrize(
    "name",
    ["cut-p8.png", "cut-j.jpg", "cut-t16.tif", "cut-w.webp", "cut-e.exr", "mut-e.exr",
     "multi.exr"],
)  # fmt: skip
def test_cli_info_on_broken_files_says_one_line(hostile_dir, name):
    d, files = hostile_dir
    _one_error_line(*_cli("info", files[name], "--max-pixels", MAX_PIXELS, cwd=d))


@pytest.mark.parametrize("name", ["mut-p8.png", "mut-j.jpg", "mut-t16.tif", "mut-w.webp"])
def test_cli_info_on_mutated_files_is_one_line_or_a_report(hostile_dir, name):
    d, files = hostile_dir
    code, out, err = _cli("info", files[name], cwd=d)
    if code == 0:
        assert all(line.startswith("spherewarp: warning: ") for line in err.splitlines()), err
    else:
        _one_error_line(code, out, err)


def test_cli_rotate_refuses_a_declared_canvas_over_the_limit(hostile_dir):
    d, files = hostile_dir
    _one_error_line(*_cli("rotate", files["canvas.jpg"], "--yaw", "10", cwd=d))
    assert not list(d.glob("canvas-rotate*"))


def test_cli_warns_once_for_hostile_xmp(hostile_dir):
    d, files = hostile_dir
    for name in ("entity16.jpg", "inf.jpg"):
        code, out, err = _cli("info", files[name], cwd=d)
        assert code == 0, err
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("spherewarp: warning: "), err
        assert "GPano" in lines[0] and "512" not in out


@pytest.mark.parametrize("source", ["/dev/zero", "fifo"])
def test_cli_refuses_devices_and_fifos(hostile_dir, source):
    d, _ = hostile_dir
    if source == "fifo":
        source = d / "in.fifo"
        if not source.exists():
            os.mkfifo(source)
    _one_error_line(*_cli("info", source, cwd=d))


def test_cli_frame_pattern_is_refused_in_one_line(hostile_dir):
    d, files = hostile_dir
    for pattern in ("f%0999999999d.png", "f{:999999999}.png", "f{0.__class__}.png"):
        code, out, err = _cli(
            "droste",
            files["good.png"],
            "--center",
            "0,0",
            "--inner-radius",
            "20",
            "--frames",
            "2",
            "-o",
            pattern,
            cwd=d,
        )
        _one_error_line(code, out, err)
        assert "frame pattern" in err, err
    assert not list(d.glob("f*.png"))


if __name__ == "__main__":
    _child_main()
