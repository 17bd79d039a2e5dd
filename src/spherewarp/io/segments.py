"""360° video in segments: render pieces that can be resumed, spread and joined.

:func:`render_segmented` renders a video as :func:`~spherewarp.io.video.render_video`
does, but in GOP-aligned segments of a few seconds (each one its own encode, so each
starts on a keyframe), into a work directory beside the output, ``OUT.parts/``:

* ``manifest.json`` names the input (its path, size and modification time), a hash
  of everything that decides the pixels (the recipe or effect and the encoder
  options: ``identity``), the segments' boundaries (frame indices and presentation
  times) and the segments done;
* each segment is written atomically (``seg-00003-1a2b3c4d.mp4``: its index and the
  first digits of ``identity``'s hash; in the output's own kind of container, which holds
  its codec: ``.mkv`` for a Matroska or WebM output, ``.mov`` for a MOV one), so a
  half-written one is never joined, nor one that a task of an earlier render (of a client
  killed with other options) writes late, and is added to the manifest once whole;
* when all are done they are joined without re-encoding (PyAV remuxes their
  packets), the input's audio (and other copyable streams) is muxed back with its
  packets as they are, the spherical metadata is written, the output is moved into
  place atomically and the work directory is removed.

Every frame keeps its presentation time, so the frame count and the timestamps are a
one-piece render's. ``resume=True`` continues from the finished segments of an
interrupted render (SIGINT, SIGKILL, a client crash): the joined output is
byte-identical to an uninterrupted one. A manifest made for another input or other
options is refused.

Segments are rendered in this process (``jobs=1``), on a local process pool
(``jobs=N``: each process renders with its share of the cores), or on the workers of
a Dask distributed scheduler (``dask="tcp://host:8786"``; ``pip install
"spherewarp[dask]"``), which read the input and write the segments by path or fsspec
URL (:mod:`spherewarp.io.remote`): the input and ``OUT.parts/`` must be reachable by
the same name from every worker (checked before any work). Dask reruns a dead
worker's segment elsewhere.

:func:`run_segments` is the runner itself, for any render cut into frame ranges
(:class:`Segmented`): :func:`render_segmented` runs a video through it, and
``spherewarp animate ... -o OUT.mp4`` an animation of a still
(:mod:`spherewarp.cli._video_out`).

Examples
--------
>>> plan_segments([0, 512, 1024, 1536, 2048], frames_per_segment=2)
[(0, 2), (2, 4), (4, 5)]
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import re
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ImageFormatError, InvalidValueError, SpherewarpError
from . import remote
from .atomic import atomic_file, unwritable_error, write_text
from .remote import is_url
from .spherical import Spherical, write_spherical
from .video import (
    COLORS_UNSPECIFIED,
    FrameMap,
    Settings,
    VideoInfo,
    _check_output,
    _open,
    _video_stream,
    add_video_stream,
    copy_streams,
    encode,
    frames_from,
    keep_metadata,
    muxer,
    output_spherical,
    pipeline,
    prepare,
    whole,
)

__all__ = [
    "DEFAULT_SEGMENT_SECONDS",
    "ManifestMismatch",
    "SegmentJob",
    "check_times",
    "check_workers",
    "dask_client",
    "frame_times",
    "join",
    "local_name",
    "mux_options",
    "part_suffix",
    "parts_dir",
    "plan_segments",
    "refuse_existing",
    "release_memory",
    "render_segment",
    "render_segmented",
    "resume_hint",
    "run_segments",
    "segment_frames",
    "Segmented",
]

#: seconds of video a segment holds by default
DEFAULT_SEGMENT_SECONDS = 10.0
_MANIFEST = "manifest.json"
_VERSION = 1
#: the extension of the segments of an output of each muxer: its own container, which holds
#: its codec (MP4 holds no utvideo, nor MOV's qtrle in MP4...); an MP4/MOV part keeps every pts
#: and dts (an edit list for a B-frame delay), a Matroska one milliseconds, which the join
#: replaces with the input's times
_PART_SUFFIX = {"mp4": ".mp4", "mov": ".mov", "matroska": ".mkv", "webm": ".mkv"}
_SEG = r"seg-\d{5,}(?:-[0-9a-f]{8})?\.(?:mp4|mov|mkv)"
#: the names spherewarp writes in a work folder, and so may remove: the manifest, the
#: segments, their temporary files (a local one's: :func:`~spherewarp.io.atomic.temp_name`,
#: and a temporary file's own, from a writer that writes atomically too; a URL's:
#: :func:`~spherewarp.io.remote.put_atomic`) and a worker's probe (``--dask``)
_OURS = re.compile(
    rf"manifest\.json|{_SEG}|\.+(?:manifest\.json|seg-\d{{5,}})[^/]*\.spherewarp-\d+-"
    r"[0-9a-f]{8}\.tmp[^/]*|\.spherewarp-probe-[0-9a-f]{8}"
)

#: the line an interrupt adds (the CLI prints it), while a segmented render runs
resume_hint: str | None = None


class ManifestMismatch(SpherewarpError):
    """``--resume`` found a work directory made for another input or other options."""


def parts_dir(output: str | os.PathLike[str]) -> Any:
    """The work directory of ``output``: ``OUT.parts`` beside it.

    Examples
    --------
    >>> parts_dir("out/tour.mp4").as_posix()
    'out/tour.mp4.parts'
    >>> parts_dir("ftp://host/out/tour.mp4")
    'ftp://host/out/tour.mp4.parts'
    """
    if is_url(output):
        return f"{output}.parts"
    output = Path(output)
    return output.with_name(output.name + ".parts")


def frame_times(input: str | os.PathLike[str]) -> tuple[list[int], Fraction]:
    """The presentation times of the frames of ``input``'s first video stream (in its time
    base, sorted: presentation order) and the time base; read from the packets, nothing is
    decoded. A packet read short (a truncated file's last) is no frame: it is left out, with
    a warning (:func:`~spherewarp.io.video.whole`)."""
    path = input if is_url(input) else Path(input)
    with _open(path) as c:
        vin = _video_stream(c, path)
        packets = [p for p in c.demux(vin) if p.pts is not None and p.size]
        kept = [p.pts for p in whole(packets)]
        if len(kept) < len(packets):
            warnings.warn(
                f"'{input}' ends early (truncated?): its last frame is cut short and left out; "
                f"the {len(kept)} whole frames are rendered",
                stacklevel=2,
            )
        return sorted(kept), vin.time_base


def segment_frames(seconds: float | None, rate: float) -> int:
    """The frames a segment of ``seconds`` (None: :data:`DEFAULT_SEGMENT_SECONDS`) holds at
    ``rate`` frames a second: one at least.

    Raises
    ------
    InvalidValueError
        For ``seconds`` that is not a finite number above 0 (nan, inf).

    Examples
    --------
    >>> segment_frames(0.5, 24), segment_frames(None, 30000 / 1001), segment_frames(1e-9, 24)
    (12, 300, 1)
    """
    seconds = DEFAULT_SEGMENT_SECONDS if seconds is None else float(seconds)
    if not (math.isfinite(seconds) and seconds > 0):
        raise InvalidValueError(
            f"--segment {seconds!r}: expected a finite number of seconds above 0 (e.g. 10)"
        )
    return max(1, min(2**62, round(seconds * float(rate))))


def check_times(pts: list[int], time_base: Fraction, input: Any) -> None:
    """Refuse frames of ``input`` that share a presentation time (``pts``: sorted, in
    ``time_base``): every frame keeps its time, and no encoder or container takes two frames
    at one time (x264's decode times stopped rising: an internal 'Invalid argument').

    Examples
    --------
    >>> check_times([0, 1, 2], Fraction(1, 24), "in.mp4")
    >>> check_times([0, 1, 1, 2], Fraction(1, 24), "in.mp4")
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: 'in.mp4' has two frames at one time (0.0416667 s, \
frames 1 and 2); re-time it first (e.g. ffmpeg -i IN -fps_mode cfr OUT.mp4)
    """
    for k in range(1, len(pts)):
        if pts[k] == pts[k - 1]:
            raise InvalidValueError(
                f"'{input}' has two frames at one time ({float(pts[k] * time_base):g} s, "
                f"frames {k - 1} and {k}); re-time it first (e.g. ffmpeg -i IN -fps_mode cfr "
                "OUT.mp4)"
            )


def plan_segments(pts: list[int], frames_per_segment: int) -> list[tuple[int, int]]:
    """Cut ``len(pts)`` frames into ``[start, end)`` frame ranges of ``frames_per_segment``."""
    n, step = len(pts), max(1, int(frames_per_segment))
    return [(a, min(a + step, n)) for a in range(0, n, step)]


@dataclass
class SegmentJob:
    """One segment to render: all a worker needs, by value (picklable; sent to a process
    pool or a Dask worker). ``frame_map`` must pickle (a module-level class, not a closure,
    for a process pool)."""

    input: str
    part: str
    index: int
    start_pts: int
    end_pts: int | None
    frames: int
    frame_map: FrameMap
    settings: Settings
    planar: bool = True
    threads: int | None = None


def _set_threads(threads: int | None) -> None:
    """Render with ``threads`` numba threads in this thread (a worker's share of the cores)."""
    if not threads:
        return
    import numba

    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))


def _dask_threads() -> int | None:
    """Inside a Dask worker: its cores divided by its task threads; else None."""
    import sys

    if "distributed" not in sys.modules:  # not in a worker (and no 1.5 s import to find out)
        return None
    try:
        from distributed import get_worker

        w = get_worker()
    except (ImportError, ValueError):
        return None
    n = getattr(getattr(w, "state", None), "nthreads", None) or getattr(w, "nthreads", 1)
    return max(1, (os.cpu_count() or 1) // max(1, int(n)))


#: the last frame plan made, for the next segment of the same render in this process:
#: ``[settings, key, plan]`` (dropped with the settings: a plan holds ~100 MB at 4K)
_KEPT: list[Any] = []


def _kept_plan(s: Settings, key: tuple[Any, ...], make_plan: Callable[..., Any]) -> Any:
    """The frame plan of ``key`` (``(inverse map, build options, pixel format, planar)``)
    for the render of ``s``: made once, and kept for its next segments (which this
    process renders one after the other, with the same map object for a static effect)."""
    import weakref

    if _KEPT and _KEPT[0]() is s and _KEPT[1][0] is key[0] and _KEPT[1][1:] == key[1:]:
        return _KEPT[2]
    plan = make_plan(key[0], key[1], key[2])
    if not (_KEPT and _KEPT[0]() is s):  # once a render (a timed map makes a plan a frame)
        weakref.finalize(s, _KEPT.clear)
    _KEPT[:] = [weakref.ref(s), key, plan]
    return plan


#: glibc's ``malloc_trim`` once looked up: the function, or False where the C library has none
_TRIM: list[Any] = []


def release_memory() -> None:
    """Give the heap's free memory back to the system (glibc's ``malloc_trim(0)``; nothing
    where the C library has no such function), after a segment.

    Each segment has its own decoder, encoder and threads; glibc keeps much of what they
    free (4K frame buffers, above its dynamic mmap threshold, land in its arenas, and are
    kept there, fragmented) and the next segment's buffers do not all fit in it: without
    this, a 3840x1920 render's resident memory between segments grows by ~100 MiB over the
    first 10-30 segments and its peak by ~130 MiB (``bench/README.md``).
    """
    if not _TRIM:
        try:
            import ctypes

            _TRIM.append(ctypes.CDLL("libc.so.6").malloc_trim)
        except (OSError, AttributeError):  # not glibc (macOS, Windows, musl)
            _TRIM.append(False)
    if _TRIM[0]:
        _TRIM[0](0)


def render_segment(
    job: SegmentJob, progress: Callable[[int], None] | None = None
) -> tuple[int, int, int]:
    """Render one segment to ``job.part`` atomically; return ``(index, frames, bytes)``.

    ``progress(frames_done_in_this_segment)`` after each frame. Gives the memory the
    segment freed back to the system when it ends (:func:`release_memory`).
    """
    try:
        return _render_segment(job, progress)
    finally:
        release_memory()


def _render_segment(
    job: SegmentJob, progress: Callable[[int], None] | None = None
) -> tuple[int, int, int]:
    import av

    _set_threads(job.threads if job.threads is not None else _dask_threads())
    s = job.settings
    make_plan = s.plan_maker(job.planar)
    done = 0
    with writing_part(job.part) as tmp:
        src = _open(job.input)
        opened = [src]

        def reopen() -> Any:
            opened.append(_open(job.input))
            return opened[-1]

        try:
            vin = src.streams.video[0]
            vin.thread_type = "AUTO"
            rate = vin.average_rate or vin.guessed_rate or Fraction(24)
            with av.open(str(tmp), "w", format=muxer(local_name(job.part))) as dst:
                vout = add_video_stream(
                    dst, s.codec, rate, s.options, s.size, s.out_pix, vin.time_base,
                    s.color_range, s.colors,
                )  # fmt: skip

                def frames() -> Iterator[Any]:
                    # from the keyframe before the segment (robust to a seek landing after it)
                    for item in frames_from(src, job.start_pts, job.index > 0, reopen):
                        if job.end_pts is not None and item.pts >= job.end_pts:
                            break
                        yield item

                plan: list[Any] = [None, None]  # the map, its plan

                def warp(item: Any) -> Any:
                    nonlocal done
                    inverse, opts = job.frame_map(float(item.pts * item.time_base))
                    if plan[1] is None or plan[0] is not inverse:
                        key = (inverse, opts, item.format.name, job.planar)
                        plan[:] = [inverse, _kept_plan(s, key, make_plan)]
                    frame = plan[1].apply(item)
                    frame.pts, frame.time_base = item.pts, item.time_base
                    done += 1
                    if progress is not None:
                        progress(done)
                    return frame

                # decode, warp and encode at once (three threads, a few frames between)
                pipeline(
                    frames(), warp, lambda f: dst.mux(encode(vout, f)),
                    lambda: dst.mux(encode(vout, None)),
                )  # fmt: skip
        finally:
            for c in opened:
                c.close()
        if done != job.frames:  # damaged data the decoder gave no frame for
            raise ImageFormatError(
                f"cannot read '{job.input}': its segment {job.index} decodes to {done} frames, "
                f"not the {job.frames} its packets hold (damaged data?); re-encode it first "
                "(e.g. ffmpeg -i IN -c:v libx264 OUT.mp4)"
            )
        size = os.path.getsize(tmp)
    return job.index, done, size


@contextlib.contextmanager
def writing_part(part: str) -> Iterator[Path]:
    """Yield a temporary file to write the segment ``part`` to; put it in place whole when the
    block ends normally (a half-written segment is never found by its name); a URL's is
    written locally, then uploaded and moved into place (:func:`~spherewarp.io.remote.put_atomic`).
    """
    if not is_url(part):
        with atomic_file(part, overwrite=True) as tmp:
            yield tmp
        return
    folder = remote.local_copy_dir()
    try:
        tmp = Path(folder) / _part_name(0, suffix=_suffix(part))
        yield tmp
        remote.put_atomic(tmp, part, fresh=True)
    finally:
        remote.remove_local(folder)


# -- the manifest -------------------------------------------------------------------------


def _input_identity(input: str | Path) -> dict[str, Any]:
    if is_url(input):
        return remote.identity(input)
    st = os.stat(input)
    return {"path": os.path.abspath(input), "size": st.st_size, "mtime_ns": st.st_mtime_ns}


def _digest(identity: str) -> str:
    return hashlib.sha256(identity.encode("utf-8")).hexdigest()


class _Folder:
    """The work directory: a local folder, or a URL (:mod:`spherewarp.io.remote`)."""

    def __init__(self, where: Path | str) -> None:
        self.where = where
        self.url = is_url(where)

    def __str__(self) -> str:
        return str(self.where)

    def file(self, name: str) -> Any:
        """The path (or URL) of ``name`` in the folder, absolute: as workers are given it."""
        return remote.child(self.where, name) if self.url else os.path.abspath(self.where / name)

    def size(self, name: str) -> int | None:
        if self.url:
            return remote.size(self.file(name))
        p = self.where / name
        return p.stat().st_size if p.is_file() else None

    def read(self, name: str) -> str | None:
        try:
            if self.url:
                return remote.read_text(self.file(name))
            return (self.where / name).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return None

    def write(self, name: str, text: str) -> None:
        if self.url:
            remote.write_atomic(self.file(name), text.encode("utf-8"))
        else:
            write_text(self.where / name, text, overwrite=True)

    def make(self) -> None:
        if self.url:
            remote.make_folder(self.where)
        else:  # beside the output, in its folder: a missing folder is refused, as for a still
            self.where.mkdir(exist_ok=True)

    def names(self) -> list[str] | None:
        """The names of what the folder holds; None when nothing is there.

        Raises
        ------
        NotADirectoryError
            When a file is there.
        """
        if self.url:
            return remote.names(self.where)
        if not os.path.lexists(self.where):
            return None
        if not self.where.is_dir():
            raise NotADirectoryError(20, "Not a directory", str(self.where))
        return os.listdir(self.where)

    def remove(self) -> None:
        """Remove the files spherewarp writes here (:data:`_OURS`), then the folder if that
        leaves it empty: whatever else is there (put there by someone else, meanwhile) stays."""
        try:
            names = self.names() or []
        except OSError:
            return
        ours = [n for n in names if _OURS.fullmatch(n)]
        if self.url:
            if len(ours) == len(names):
                remote.remove_tree(self.where)
            return
        for name in ours:
            with contextlib.suppress(OSError):
                (self.where / name).unlink()
        with contextlib.suppress(OSError):
            self.where.rmdir()

    def remove_dead_temporaries(self) -> None:
        """Remove the temporary files here of processes that no longer run (a local folder's):
        what the pool processes were writing when they were stopped (terminated, they leave
        their temporary files behind)."""
        from .atomic import _alive

        if self.url or os.name != "posix":
            return
        with contextlib.suppress(OSError):
            for name in os.listdir(self.where):
                pids = [int(p) for p in re.findall(r"\.spherewarp-(\d+)-[0-9a-f]{8}\.tmp", name)]
                if pids and _OURS.fullmatch(name) and not any(_alive(p) for p in pids):
                    with contextlib.suppress(OSError):
                        (self.where / name).unlink()

    def check_ours(self, output: Path | str) -> None:
        """Refuse a work folder that spherewarp did not make: a file, or a folder holding
        anything but a spherewarp manifest and the files spherewarp writes beside it
        (:data:`_OURS`). Nothing there, or an empty folder, is fine.

        Raises
        ------
        InvalidValueError
            Naming the folder and what to do (remove it, or choose another -o).
        """
        try:
            names = self.names()
        except NotADirectoryError:
            raise InvalidValueError(
                f"-o {output}: '{self}' is not a spherewarp work folder (it is a file), so it "
                "is left as it is; remove it, or choose another -o"
            ) from None
        if not names:
            return
        foreign = sorted(n for n in names if not _OURS.fullmatch(n))
        if foreign:
            listed = ", ".join(f"'{n}'" for n in foreign[:3])
            more = f" and {len(foreign) - 3} more" if len(foreign) > 3 else ""
            what = f"{listed}{more}: not written by spherewarp"
        elif _MANIFEST in names:
            if _is_manifest(self.read(_MANIFEST)):
                return
            what = f"a {_MANIFEST} that is not a spherewarp manifest"
        elif any(n.startswith("seg-") for n in names):
            what = f"segment files but no {_MANIFEST}"
        else:
            return  # only temporary files of ours (a render stopped before its manifest)
        raise InvalidValueError(
            f"-o {output}: '{self}' is not a spherewarp work folder (it holds {what}), so it "
            "is left as it is; remove it, or choose another -o"
        )


def _is_manifest(text: str | None) -> bool:
    """Whether ``text`` is a spherewarp manifest (JSON with its version key)."""
    try:
        data = json.loads(text) if text is not None else None
    except ValueError:
        return False
    return isinstance(data, dict) and "spherewarp_segments" in data


@dataclass
class _Manifest:
    folder: _Folder
    data: dict[str, Any] = field(default_factory=dict)
    suffix: str = ".mp4"  # the segments' (:func:`part_suffix`)

    def save(self) -> None:
        self.folder.write(_MANIFEST, json.dumps(self.data, indent=1) + "\n")

    def done(self, index: int) -> bool:
        entry = self.data["done"].get(str(index))
        if entry is None or entry["file"] != self.part(index):  # another container's: again
            return False
        return self.folder.size(entry["file"]) == entry["bytes"]

    def part(self, index: int) -> str:
        """The file name of segment ``index`` of this render."""
        return _part_name(index, self.data["options"], self.suffix)

    def mark(self, index: int, size: int) -> None:
        self.data["done"][str(index)] = {"file": self.part(index), "bytes": size}
        self.save()


def _part_name(index: int, options: str = "", suffix: str = ".mp4") -> str:
    tag = f"-{options[:8]}" if options else ""
    return f"seg-{index:05d}{tag}{suffix}"


def part_suffix(output: str | os.PathLike[str]) -> str:
    """The extension of the segments of ``output`` (a path or a URL): a container that holds
    whatever codec the output's does (Matroska for ``.mkv`` and ``.webm``, MOV for ``.mov``).

    Examples
    --------
    >>> part_suffix("a.mp4"), part_suffix("a.m4v"), part_suffix("a.webm"), part_suffix("a.MOV")
    ('.mp4', '.mp4', '.mkv', '.mov')
    """
    return _PART_SUFFIX[muxer(local_name(output))]


def _open_manifest(
    work: _Folder,
    source: Any,
    name: str,
    identity: str,
    segments: list[dict[str, Any]],
    resume: bool,
    suffix: str = ".mp4",
) -> _Manifest:
    """The manifest to render by: the one found with ``resume`` (refused if it was made for
    another input or other options), else a fresh one (old parts removed). ``source``
    describes the input (``name`` names it in messages), ``segments`` the boundaries,
    ``suffix`` the segments' extension (:func:`part_suffix`)."""
    data = {
        "spherewarp_segments": _VERSION,
        "input": source,
        "options": _digest(identity),
        "frames": segments[-1]["end"] if segments else 0,
        "segments": segments,
        "done": {},
    }
    m = _Manifest(work, data, suffix)
    text = work.read(_MANIFEST) if resume else None
    if text is not None:
        try:
            found = json.loads(text)
        except ValueError:
            found = {}
        for key, what in (
            ("input", f"another input (not '{name}' as it is now)"),
            ("options", "other options (another effect, recipe or encoder setting)"),
            ("segments", "other segment boundaries (another --segment)"),
        ):
            if found.get(key) != data[key]:
                raise ManifestMismatch(
                    f"--resume: '{work}' holds a render of {what}; rerun without --resume "
                    "to start over"
                )
        m.data["done"] = dict(found.get("done", {}))
        return m
    work.remove()
    work.make()
    m.save()
    return m


# -- running the segments ------------------------------------------------------------------


def _worker_init() -> None:
    """A pool process ignores SIGINT and SIGHUP: the client stops it (a Ctrl-C, or a closed
    terminal's hang-up, reaches the whole process group, and a traceback from each process
    would break the one-line rule)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_IGN)


#: ``render(job, progress) -> (index, frames, bytes)``: renders one segment (module level, so
#: that a process pool or a Dask worker imports it)
Render = Callable[..., tuple[int, int, int]]


def _run_local(
    jobs: list[Any],
    n: int,
    on_done: Callable[[tuple[int, int, int]], None],
    on_frame: Callable[[int, int], None],
    render: Render = render_segment,
) -> None:
    if n <= 1:
        for job in jobs:
            result = render(job, lambda k, i=job.index: on_frame(i, k))
            on_done(result)
        return
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    threads = max(1, (os.cpu_count() or 1) // n)
    for job in jobs:
        job.threads = threads
    pool = ProcessPoolExecutor(
        max_workers=n, mp_context=multiprocessing.get_context("spawn"), initializer=_worker_init
    )
    clean = False
    try:
        pending = {pool.submit(render, job) for job in jobs}
        while pending:
            finished, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
            for f in finished:
                on_done(f.result())
        clean = True
    finally:
        if not clean:
            _stop_pool(pool)
        pool.shutdown(wait=True, cancel_futures=True)


def _stop_pool(pool: Any) -> None:
    """End a pool's processes now (an interrupt or an error): cancel what waits, terminate
    what runs, and wait for them, so that no process (and no semaphore) outlives us."""
    processes = list(getattr(pool, "_processes", {}).values())
    for p in processes:
        try:
            p.terminate()
        except (OSError, AttributeError):
            pass
    for p in processes:
        try:
            p.join(5)
        except (OSError, AttributeError, AssertionError):
            pass


DASK_INSTALL = 'install Dask for --dask: pip install "spherewarp[dask]"'


def dask_client(address: str) -> Any:
    """A ``distributed.Client`` on the scheduler at ``address`` (one clear line when Dask is
    missing or the scheduler cannot be reached)."""
    try:
        from distributed import Client
    except ImportError:
        raise InvalidValueError(f"--dask: {DASK_INSTALL}") from None
    try:
        return Client(address, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise InvalidValueError(
            f"--dask {address}: cannot reach the scheduler ({exc}); start one with "
            "'dask scheduler' and workers with 'dask worker ADDRESS'"
        ) from None


def _can_reach(paths: list[str], writable: list[str]) -> list[str]:
    """Run on each worker: the paths (or URLs) it cannot read (or write)."""
    bad = [p for p in paths if not is_url(p) and not os.access(p, os.R_OK)]
    bad += [p for p in writable if not is_url(p) and not os.access(p, os.W_OK)]
    urls = [p for p in paths if is_url(p)], [p for p in writable if is_url(p)]
    if urls[0] or urls[1]:
        try:
            bad += remote.reachable(*urls)
        except InvalidValueError:  # no fsspec on this worker
            bad += urls[0] + urls[1]
    return bad


def check_workers(client: Any, read: list[str], write: list[str] = ()) -> None:
    """Refuse to start when a worker cannot read an input (or write the work directory) by
    the path the client gives: every worker must reach the same paths."""
    found = client.run(_can_reach, list(read), list(write))
    if not found:
        raise InvalidValueError("--dask: the scheduler has no workers; start some with "
                                "'dask worker ADDRESS'")  # fmt: skip
    for worker, bad in sorted(found.items()):
        if bad:
            raise InvalidValueError(
                f"--dask: worker {worker} cannot reach '{bad[0]}'; inputs and outputs must be "
                "at the same path (or URL) on every worker (a shared file system, or a URL "
                "that every worker reaches with fsspec installed)"
            )


def _run_dask(
    jobs: list[Any],
    client: Any,
    on_done: Callable[[tuple[int, int, int]], None],
    render: Render = render_segment,
) -> None:
    from distributed import as_completed

    futures = [client.submit(render, job, pure=False, key=f"spherewarp-seg-{job.index}-"
                             f"{os.urandom(4).hex()}") for job in jobs]  # fmt: skip
    try:
        for f in as_completed(futures):
            on_done(f.result())
    finally:
        for f in futures:
            if not f.done():
                f.cancel()


# -- the whole render ----------------------------------------------------------------------


class _Frames:
    """Frames done across the segments, for ``progress(done, total)``."""

    def __init__(self, total: int, progress: Callable[[int, int], None] | None) -> None:
        self.total, self.progress = total, progress
        self.whole = 0  # frames of finished segments
        self.partial: dict[int, int] = {}

    def frame(self, index: int, k: int) -> None:
        self.partial[index] = k
        self._tell()

    def segment(self, index: int, frames: int) -> None:
        self.partial.pop(index, None)
        self.whole += frames
        self._tell()

    def _tell(self) -> None:
        if self.progress is not None:
            self.progress(self.whole + sum(self.partial.values()), self.total)


def render_segmented(
    input: str | os.PathLike[str],
    output: str | os.PathLike[str],
    frame_map: FrameMap,
    *,
    identity: str = "",
    resume: bool = False,
    jobs: int = 1,
    dask: str | Any | None = None,
    segment_seconds: float = DEFAULT_SEGMENT_SECONDS,
    codec: str | None = None,
    crf: float | None = None,
    preset: str | None = None,
    pix_fmt: str | None = None,
    overwrite: bool = False,
    force: bool = False,
    spherical: bool | Callable[[Spherical], Spherical | None] = True,
    progress: Callable[[int, int], None] | None = None,
    stereo: str | None = None,
    grid: Any = None,
    out_shape: tuple[int, int] | None = None,
    planar: bool = True,
    on_client: Callable[[list[float]], None] | None = None,
) -> VideoInfo:
    """Render ``input`` to ``output`` in segments (see the module documentation).

    The parameters after ``segment_seconds`` are :func:`~spherewarp.io.video.render_video`'s.

    Parameters
    ----------
    input, output : path or str
        The video to read and the file to write: paths, or fsspec URLs
        (``ftp://host/in.mp4``; :mod:`spherewarp.io.remote`), whose 360° metadata is not
        read (pass ``stereo`` for a stereo input).
    identity : str
        Everything that decides the pixels, as text (the effect and its options, the
        recipe's contents, the encoder options): a manifest made with another is refused
        by ``resume``.
    resume : bool
        Continue from the finished segments in ``OUT.parts/`` (else start afresh).
    jobs : int
        Local processes rendering segments (1: this process).
    dask : str or distributed.Client, optional
        Render the segments on this Dask scheduler's workers instead.
    segment_seconds : float
        Seconds of video a segment holds.
    on_client : callable, optional
        Called with every frame's time (seconds) when the segments are rendered
        elsewhere (``jobs > 1``, ``dask``), so the client sees what ``frame_map`` would
        have seen (e.g. the pose a timed recipe gives the metadata).

    Returns
    -------
    VideoInfo
        The input's description.

    Examples
    --------
    >>> import tempfile, sys; sys.path.insert(0, "tests")
    >>> from videoclip import make_clip
    >>> from spherewarp.maps import Mobius
    >>> d = Path(tempfile.mkdtemp())
    >>> clip = make_clip(d / "in.mp4", frames=12)
    >>> turn = Mobius.from_yaw_pitch_roll(30, 0, 0).inverse()
    >>> info = render_segmented(clip, d / "out.mp4", lambda t: (turn, {}), segment_seconds=0.25)
    >>> len(frame_times(d / "out.mp4")[0]), (d / "out.mp4.parts").exists()
    (12, False)
    """
    input = input if is_url(input) else Path(input)
    output = output if is_url(output) else Path(output)
    target = local_name(output)  # what the extension says (a URL's too)
    _check_output(target)
    refuse_existing(output, overwrite)
    s = prepare(input, target, codec, crf, preset, pix_fmt, stereo, grid, out_shape, force)
    pts, tb = frame_times(input)
    if not pts:
        raise InvalidValueError(f"'{input}' has no video frames")
    check_times(pts, tb, input)
    rate = float(s.info.rate or 24)
    ranges = plan_segments(pts, segment_frames(segment_seconds, rate))
    full = (
        f"{identity}\n{s.codec} {s.out_pix} {sorted(s.options.items())} {s.size} {s.layout} "
        f"{planar}"
    ) + (f" range {s.color_range}" if s.color_range else "")  # a full-range output's parts
    if s.colors != COLORS_UNSPECIFIED:  # parts tagged (and converted) with the input's colours
        full += f" colors {s.colors}"
    if s.rgb.startswith("rgba"):  # parts warped with their alpha
        full += f" {s.rgb}"

    source = input if is_url(input) else os.path.abspath(input)

    def job(i: int, part: str) -> SegmentJob:
        a, b = ranges[i]
        return SegmentJob(
            input=source, part=part, index=i, start_pts=pts[a],
            end_pts=pts[b] if b < len(pts) else None, frames=b - a, frame_map=frame_map,
            settings=s, planar=planar,
        )  # fmt: skip

    def join_parts(parts: list[Path], tmp: Path) -> None:
        join(parts, input, tmp, muxer(target), times=pts, time_base=tb)  # the input's times
        write_spherical(tmp, output_spherical(s.info, s.layout, s.grid, spherical))

    def after(elsewhere: bool) -> None:
        if on_client is not None and elsewhere:
            on_client([float(p * tb) for p in pts])

    segments = [
        {"index": i, "start": a, "end": b, "start_pts": pts[a],
         "end_pts": pts[b] if b < len(pts) else None}
        for i, (a, b) in enumerate(ranges)
    ]  # fmt: skip
    plan = Segmented(
        output=output, source=_input_identity(input), name=str(input), identity=full,
        segments=segments, job=job, render=render_segment, join=join_parts,
        reads=[source], after=after,
    )  # fmt: skip
    run_segments(plan, resume=resume, jobs=jobs, dask=dask, overwrite=overwrite,
                 progress=progress)  # fmt: skip
    return s.info


@dataclass
class Segmented:
    """A render in segments, as :func:`run_segments` runs it (a video's, an animation's).

    Attributes
    ----------
    output : Path
        The file to write; the segments go to :func:`parts_dir` of it.
    source : object
        What the segments are made from, as JSON (the input's path, size and time): a
        manifest made from another is refused by ``resume``.
    name : str
        The input, as messages name it.
    identity : str
        Everything else that decides the pixels, as text.
    segments : list of dict
        The segments' boundaries, in order, each with its ``start`` and ``end`` frame
        indices (``[start, end)``) and whatever else locates it.
    job : callable
        ``job(index, part)``: what ``render`` needs to render segment ``index`` into the
        file ``part`` (picklable: sent to a process pool or a Dask worker).
    render : callable
        ``render(job, progress) -> (index, frames, bytes)`` (module level).
    join : callable
        ``join(parts, tmp)``: write the output from the finished parts (in order) to
        ``tmp``, metadata included; ``tmp`` is then moved into place.
    reads : list of str
        What every worker must read (checked before any work with ``dask``).
    after : callable, optional
        ``after(elsewhere)``, before the join; ``elsewhere``: the segments were rendered
        in other processes.
    """

    output: Path
    source: Any
    name: str
    identity: str
    segments: list[dict[str, Any]]
    job: Callable[[int, str], Any]
    render: Render
    join: Callable[[list[Path], Path], None]
    reads: list[str]
    after: Callable[[bool], None] | None = None


def run_segments(
    plan: Segmented,
    *,
    resume: bool = False,
    jobs: int = 1,
    dask: str | Any | None = None,
    overwrite: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """Render ``plan``'s missing segments (in this process, on ``jobs`` local processes or on
    the ``dask`` scheduler's workers), then join them into ``plan.output`` atomically and
    remove the work directory (see the module documentation; the parameters are
    :func:`render_segmented`'s).

    Examples
    --------
    See :func:`render_segmented`, which runs a video through it.
    """
    global resume_hint
    output = plan.output
    work = _Folder(parts_dir(output))
    with _writing(output):
        work.check_ours(output)  # someone else's folder is never emptied
    client = None
    if dask is not None:
        client = dask_client(dask) if isinstance(dask, str) else dask
        with _writing(output):
            work.make()
        check_workers(client, plan.reads, [work.where if work.url else os.path.abspath(work.where)])
    ranges = [(g["start"], g["end"]) for g in plan.segments]
    with _writing(output):
        manifest = _open_manifest(
            work, plan.source, plan.name, plan.identity, plan.segments, resume,
            part_suffix(output),
        )  # fmt: skip
    todo = [
        plan.job(i, work.file(manifest.part(i))) for i in range(len(ranges)) if not manifest.done(i)
    ]
    counter = _Frames(ranges[-1][1] if ranges else 0, progress)
    counter.whole = sum(b - a for i, (a, b) in enumerate(ranges) if manifest.done(i))
    counter._tell()

    def finished(result: tuple[int, int, int]) -> None:
        index, frames, size = result
        manifest.mark(index, size)
        counter.segment(index, frames)

    resume_hint = f"rerun with --resume to continue from the finished segments in '{work}'"
    try:
        if client is not None:
            _run_dask(todo, client, finished, plan.render)
        else:
            try:
                _run_local(todo, jobs, finished, counter.frame, plan.render)
            except BaseException:
                work.remove_dead_temporaries()  # of the pool's processes, stopped mid-segment
                raise
        if plan.after is not None:
            plan.after(client is not None or jobs > 1)
        parts = [work.file(manifest.part(i)) for i in range(len(ranges))]
        _write_output(output, overwrite, lambda tmp: plan.join(parts, tmp))
        resume_hint = None
    finally:
        if client is not None and isinstance(dask, str):
            client.close()
    work.remove()


@contextlib.contextmanager
def _writing(output: Path | str) -> Iterator[None]:
    """Turn an OSError of the block (making the work folder, writing its manifest) into the
    error that names ``output``, as a still's does (:func:`~spherewarp.io.atomic.unwritable_error`:
    ``cannot write 'OUT': reason``), not the work folder the user never named."""
    try:
        yield
    except OSError as exc:
        if is_url(output):
            raise ImageFormatError(f"cannot write '{output}': {exc.strerror or exc}") from exc
        raise unwritable_error(Path(output), exc) from exc


def _write_output(output: Path | str, overwrite: bool, write: Callable[[Path], None]) -> None:
    """``write(tmp)`` a local temporary file, then put it in place as ``output`` atomically (a
    URL's: uploaded, then moved)."""
    if not is_url(output):
        with atomic_file(output, overwrite=overwrite) as tmp:
            write(tmp)
        return
    folder = remote.local_copy_dir()
    try:
        tmp = Path(folder) / ("output" + _suffix(output))
        write(tmp)
        remote.put_atomic(tmp, output)
    finally:
        remote.remove_local(folder)


def local_name(output: str | os.PathLike[str]) -> Path:
    """``output`` as a path, a URL's as a file name of the same extension (what picks the
    container and the encoder, as a local path's does).

    Examples
    --------
    >>> local_name("ftp://host/out/tour.mkv"), local_name("out/tour.mp4")
    (PosixPath('output.mkv'), PosixPath('out/tour.mp4'))
    """
    return Path("output" + _suffix(output)) if is_url(output) else Path(output)


def refuse_existing(output: str | os.PathLike[str], overwrite: bool) -> None:
    """Refuse an existing ``output`` (a path or a URL) unless ``overwrite``, in one line."""
    if overwrite:
        return
    if remote.exists(output) if is_url(output) else os.path.lexists(output):
        from .atomic import exists_error

        raise exists_error(output)


def _suffix(path: Path | str) -> str:
    """The extension of a path or a URL's path."""
    return Path(str(path).split("?", 1)[0]).suffix


def _packets(container: Any, streams: list[Any]) -> Iterator[Any]:
    for packet in container.demux(streams):
        if packet.dts is not None or packet.pts is not None:
            yield packet


def _video_packets(parts: list[Any]) -> Iterator[tuple[int, Any]]:
    """``(part index, packet)`` for the video packets of the parts, in order."""
    for i, part in enumerate(parts):
        with _open(part) as c:
            for packet in _packets(c, [c.streams.video[0]]):
                if packet.size:
                    yield i, packet


def _retime(
    parts: list[Any], times: list[int] | None, time_base: Fraction
) -> tuple[list[list[int]], list[int], list[int]]:
    """The times to give the parts' video packets: ``(ranks, pts, dts)``.

    ``ranks[i][j]``: where the ``j``-th packet of part ``i`` (in decode order) comes in the
    part's presentation order; the ``k``-th frame of the output (in presentation order) is
    at ``pts[k]`` (``times``, or the parts' own times when None); the ``g``-th packet of the
    output (in decode order) has the decode time ``dts[g]``.

    The decode times are made anew for the whole output: each part's encoder made its own
    from its own frames, so a part whose frames follow a gap (a variable frame rate) began
    with a decode time (its first frame's time less its B-frame delay) before the previous
    part's last, which MP4 refuses. ``dts[g] = pts[g - D]`` (``D`` the largest reordering
    in any part; the first ``D`` a frame interval apart before ``pts[0]``) rises strictly
    with ``g`` and is never after the packet's presentation time.
    """
    ranks: list[list[int]] = []
    own: list[int] = []
    for part in parts:
        with _open(part) as c:
            packets = [(p.pts, p.time_base) for p in _packets(c, [c.streams.video[0]]) if p.size]
        if any(t is None for t, _ in packets):
            raise RuntimeError(f"the segment '{part}' has a video packet without a time")
        found = [t * base for t, base in packets]
        order = sorted(range(len(found)), key=lambda j: (found[j], j))
        rank = [0] * len(found)
        for r, j in enumerate(order):
            rank[j] = r
        ranks.append(rank)
        own += [round(found[j] / time_base) for j in order]
    pts = own if times is None else list(times)
    if len(own) != len(pts):
        raise RuntimeError(f"the segments hold {len(own)} frames, expected {len(pts)}")
    if any(b <= a for a, b in zip(pts, pts[1:], strict=False)):
        raise RuntimeError("the frames' times do not rise")
    delay = max((j - r for rank in ranks for j, r in enumerate(rank)), default=0)
    step = pts[1] - pts[0] if len(pts) > 1 else 1
    dts = [pts[0] - (delay - g) * step for g in range(min(delay, len(pts)))]
    dts += pts[: len(pts) - len(dts)]
    return ranks, pts, dts


def mux_options(format: str, time_base: Fraction) -> dict[str, str]:
    """The muxer options that keep the times of a video stream in ``time_base`` exactly: an
    MP4/MOV file's movie time scale (1000 by default, in which its edit lists hold a start
    that is not 0: a frame at 1/12 s came back at 0.083 s) is the time base's denominator.

    Examples
    --------
    >>> mux_options("mp4", Fraction(1001, 30000)), mux_options("matroska", Fraction(1, 1000))
    ({'movie_timescale': '30000'}, {})
    """
    if format not in ("mp4", "mov") or not 0 < time_base.denominator < 2**31:
        return {}
    return {"movie_timescale": str(time_base.denominator)}


def _when(packet: Any) -> Fraction:
    t = packet.dts if packet.dts is not None else packet.pts
    return t * packet.time_base


def join(
    parts: list[Path],
    input: Path | None,
    output: Path,
    format: str,
    end: float | None = None,
    *,
    times: list[int] | None = None,
    time_base: Fraction | None = None,
) -> None:
    """Join the segment files ``parts`` (in order) into ``output`` without re-encoding, with
    the copyable streams of ``input`` (its audio; None: no input) muxed back, packets as
    they are (up to ``end`` seconds when given: the rest is left out).

    ``times`` (in ``time_base``, default the input's video time base, else the first part's):
    the presentation times of the output's frames, in order; the parts' video packets, part
    after part and each part's in presentation order, are given these exactly. (A part's MP4
    file holds its start in its edit list in milliseconds: a part starting at 0.5005 s came
    back at 0.5 s.) The decode times are made anew so that they rise across the parts
    (:func:`_retime`); the packets' data are untouched.
    """
    import heapq

    import av

    with _open(parts[0]) as first, contextlib.ExitStack() as stack:
        src = None if input is None else stack.enter_context(_open(input))
        template = first.streams.video[0]
        vin = None if src is None else src.streams.video[0]
        tb = time_base or (template.time_base if vin is None else vin.time_base)
        ranks, pts, dts = _retime(parts, times, tb)
        offsets = [0]
        for rank in ranks:
            offsets.append(offsets[-1] + len(rank))
        with av.open(str(output), "w", format=format, options=mux_options(format, tb)) as dst:
            # opaque: the part's codec parameters as they are (not an encoder looked up by
            # its decoder's name: libdav1d, an AV1 part's, is no encoder)
            vout = dst.add_stream_from_template(template, opaque=True)
            # the part's tag, valid in the output (a part is in its kind of container): PyAV
            # clears it, and Matroska then refuses rawvideo (its tag says the pixel format)
            vout.codec_context.codec_tag = template.codec_context.codec_tag
            vout.time_base = tb
            # the stream's frame rate (Matroska's DefaultDuration; else the time base's:
            # 12288 fps for a 12 fps MP4 input), the input's as FFmpeg guesses it
            rate = None if vin is None else vin.average_rate or vin.guessed_rate
            vout.codec_context.framerate = rate or 1 / tb
            copies = {} if src is None else copy_streams(src, dst, vin)
            if src is not None:
                keep_metadata(src, dst, vin, vout, copies, end)
            others = [] if src is None else [s for s in src.streams if s.index in copies]

            def video() -> Iterator[tuple[Fraction, int, int, Any]]:
                for g, (i, p) in enumerate(_video_packets(parts)):
                    k = offsets[i] + ranks[i][g - offsets[i]]  # its frame, in the output
                    if k + 1 < len(pts):
                        duration = pts[k + 1] - pts[k]
                    else:  # the last frame: as long as its part says
                        duration = round((p.duration or 0) * p.time_base / tb) or None
                    p.pts, p.dts, p.time_base = pts[k], dts[g], tb
                    p.duration = duration
                    yield dts[g] * tb, 0, g, p

            def rest() -> Iterator[tuple[Fraction, int, int, Any]]:
                if others:
                    for k, p in enumerate(_packets(src, others)):
                        if end is not None and p.pts is not None and p.pts * p.time_base > end:
                            return
                        yield _when(p), 1, k, p

            for _, source, _, packet in heapq.merge(video(), rest(), key=lambda x: x[:3]):
                packet.stream = vout if source == 0 else copies[packet.stream_index]
                dst.mux(packet)
