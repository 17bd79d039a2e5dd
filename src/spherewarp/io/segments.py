"""360° video in segments: render pieces that can be resumed, spread and joined.

:func:`render_segmented` renders a video as :func:`~spherewarp.io.video.render_video`
does, but in GOP-aligned segments of a few seconds (each one its own encode, so each
starts on a keyframe), into a work directory beside the output, ``OUT.parts/``:

* ``manifest.json`` names the input (its path, size and modification time), a hash
  of everything that decides the pixels (the recipe or effect and the encoder
  options: ``identity``), the segments' boundaries (frame indices and presentation
  times) and the segments done;
* each segment is written atomically (``seg-00003.mp4``), so a half-written one is
  never joined, and is added to the manifest once whole;
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
"spherewarp[dask]"``), which read the input and write the segments by path: the input
and ``OUT.parts/`` must be reachable at the same path from every worker (checked
before any work). Dask reruns a dead worker's segment elsewhere.

Examples
--------
>>> plan_segments([0, 512, 1024, 1536, 2048], frames_per_segment=2)
[(0, 2), (2, 4), (4, 5)]
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import InvalidValueError, SpherewarpError
from .atomic import atomic_file, write_text
from .spherical import Spherical, write_spherical
from .video import (
    FrameMap,
    Settings,
    VideoInfo,
    _check_output,
    _open,
    _video_stream,
    copy_streams,
    muxer,
    output_spherical,
    pipeline,
    prepare,
)

__all__ = [
    "DEFAULT_SEGMENT_SECONDS",
    "ManifestMismatch",
    "SegmentJob",
    "check_workers",
    "dask_client",
    "frame_times",
    "join",
    "parts_dir",
    "plan_segments",
    "render_segment",
    "render_segmented",
    "resume_hint",
]

#: seconds of video a segment holds by default
DEFAULT_SEGMENT_SECONDS = 10.0
_MANIFEST = "manifest.json"
_VERSION = 1
_PART_FORMAT = "mp4"  # keeps every pts and dts (an edit list for a B-frame delay)

#: the line an interrupt adds (the CLI prints it), while a segmented render runs
resume_hint: str | None = None


class ManifestMismatch(SpherewarpError):
    """``--resume`` found a work directory made for another input or other options."""


def parts_dir(output: str | os.PathLike[str]) -> Path:
    """The work directory of ``output``: ``OUT.parts`` beside it.

    Examples
    --------
    >>> parts_dir("out/tour.mp4").as_posix()
    'out/tour.mp4.parts'
    """
    output = Path(output)
    return output.with_name(output.name + ".parts")


def frame_times(input: str | os.PathLike[str]) -> tuple[list[int], Fraction]:
    """The presentation times of the frames of ``input``'s first video stream (in its time
    base, sorted: presentation order) and the time base; read from the packets, nothing is
    decoded."""
    path = Path(input)
    with _open(path) as c:
        vin = _video_stream(c, path)
        pts = [p.pts for p in c.demux(vin) if p.pts is not None and p.size]
        return sorted(pts), vin.time_base


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


def render_segment(
    job: SegmentJob, progress: Callable[[int], None] | None = None
) -> tuple[int, int, int]:
    """Render one segment to ``job.part`` atomically; return ``(index, frames, bytes)``.

    ``progress(frames_done_in_this_segment)`` after each frame.
    """
    import av

    _set_threads(job.threads if job.threads is not None else _dask_threads())
    s = job.settings
    make_plan = s.plan_maker(job.planar)
    done = 0
    with atomic_file(job.part, overwrite=True) as tmp:
        src = _open(Path(job.input))
        try:
            vin = src.streams.video[0]
            vin.thread_type = "AUTO"
            rate = vin.average_rate or vin.guessed_rate or Fraction(24)
            with av.open(str(tmp), "w", format=_PART_FORMAT) as dst:
                vout = dst.add_stream(s.codec, rate=rate, options=s.options)
                vout.height, vout.width = s.size
                vout.pix_fmt = s.out_pix
                vout.time_base = vin.time_base
                vout.codec_context.time_base = vin.time_base
                vout.thread_type = "AUTO"
                if job.index > 0:
                    src.seek(job.start_pts, stream=vin, backward=True, any_frame=False)

                def frames() -> Iterator[Any]:
                    for item in src.decode(vin):
                        if item.pts is None or item.pts < job.start_pts:
                            continue
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
                    frames(), warp, lambda f: dst.mux(vout.encode(f)),
                    lambda: dst.mux(vout.encode(None)),
                )  # fmt: skip
        finally:
            src.close()
        if done != job.frames:
            raise RuntimeError(
                f"segment {job.index} of '{job.input}' gave {done} frames, expected {job.frames}"
            )
        size = os.path.getsize(tmp)
    return job.index, done, size


# -- the manifest -------------------------------------------------------------------------


def _input_identity(input: Path) -> dict[str, Any]:
    st = os.stat(input)
    return {"path": os.path.abspath(input), "size": st.st_size, "mtime_ns": st.st_mtime_ns}


def _digest(identity: str) -> str:
    return hashlib.sha256(identity.encode("utf-8")).hexdigest()


@dataclass
class _Manifest:
    path: Path
    data: dict[str, Any] = field(default_factory=dict)

    def save(self) -> None:
        write_text(self.path, json.dumps(self.data, indent=1) + "\n", overwrite=True)

    def done(self, index: int) -> bool:
        entry = self.data["done"].get(str(index))
        if entry is None:
            return False
        part = self.path.parent / entry["file"]
        return part.is_file() and part.stat().st_size == entry["bytes"]

    def mark(self, index: int, size: int) -> None:
        self.data["done"][str(index)] = {"file": _part_name(index), "bytes": size}
        self.save()


def _part_name(index: int) -> str:
    return f"seg-{index:05d}.{_PART_FORMAT}"


def _open_manifest(
    work: Path,
    input: Path,
    identity: str,
    pts: list[int],
    ranges: list[tuple[int, int]],
    resume: bool,
) -> _Manifest:
    """The manifest to render by: the one found with ``resume`` (refused if it was made for
    another input or other options), else a fresh one (old parts removed)."""
    data = {
        "spherewarp_segments": _VERSION,
        "input": _input_identity(input),
        "options": _digest(identity),
        "frames": len(pts),
        "segments": [
            {
                "index": i,
                "start": a,
                "end": b,
                "start_pts": pts[a],
                "end_pts": pts[b] if b < len(pts) else None,
            }
            for i, (a, b) in enumerate(ranges)
        ],  # fmt: skip
        "done": {},
    }
    m = _Manifest(work / _MANIFEST, data)
    if resume and m.path.is_file():
        try:
            found = json.loads(m.path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            found = {}
        for key, what in (
            ("input", f"another input (not '{input}' as it is now)"),
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
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    m.save()
    return m


# -- running the segments ------------------------------------------------------------------


def _worker_init() -> None:
    """A pool process ignores SIGINT: the client stops it (a Ctrl-C reaches the whole
    process group, and a traceback from each process would break the one-line rule)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _run_local(
    jobs: list[SegmentJob],
    n: int,
    on_done: Callable[[tuple[int, int, int]], None],
    on_frame: Callable[[int, int], None],
) -> None:
    if n <= 1:
        for job in jobs:
            result = render_segment(job, lambda k, i=job.index: on_frame(i, k))
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
        pending = {pool.submit(render_segment, job) for job in jobs}
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
    """Run on each worker: the paths it cannot read (or write)."""
    bad = [p for p in paths if not os.access(p, os.R_OK)]
    return bad + [p for p in writable if not os.access(p, os.W_OK)]


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
                "at the same path on every worker (a shared file system)"
            )


def _run_dask(
    jobs: list[SegmentJob],
    client: Any,
    on_done: Callable[[tuple[int, int, int]], None],
) -> None:
    from distributed import as_completed

    futures = [client.submit(render_segment, job, pure=False, key=f"spherewarp-seg-{job.index}-"
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
    global resume_hint
    input, output = Path(input), Path(output)
    _check_output(output)
    if not overwrite and os.path.lexists(output):
        from .atomic import exists_error

        raise exists_error(output)
    s = prepare(input, output, codec, crf, preset, pix_fmt, stereo, grid, out_shape, force)
    pts, tb = frame_times(input)
    if not pts:
        raise InvalidValueError(f"'{input}' has no video frames")
    rate = float(s.info.rate or 24)
    ranges = plan_segments(pts, max(1, round(segment_seconds * rate)))
    work = parts_dir(output)
    client = None
    if dask is not None:
        client = dask_client(dask) if isinstance(dask, str) else dask
        work.mkdir(parents=True, exist_ok=True)
        check_workers(client, [os.path.abspath(input)], [os.path.abspath(work)])
    full = (
        f"{identity}\n{s.codec} {s.out_pix} {sorted(s.options.items())} {s.size} {s.layout} "
        f"{planar}"
    )
    manifest = _open_manifest(work, input, full, pts, ranges, resume)
    todo = []
    for i, (a, b) in enumerate(ranges):
        if manifest.done(i):
            continue
        todo.append(
            SegmentJob(
                input=os.path.abspath(input),
                part=os.path.abspath(work / _part_name(i)),
                index=i,
                start_pts=pts[a],
                end_pts=pts[b] if b < len(pts) else None,
                frames=b - a,
                frame_map=frame_map,
                settings=s,
                planar=planar,
            )  # fmt: skip
        )
    counter = _Frames(len(pts), progress)
    counter.whole = sum(b - a for i, (a, b) in enumerate(ranges) if manifest.done(i))
    counter._tell()

    def finished(result: tuple[int, int, int]) -> None:
        index, frames, size = result
        manifest.mark(index, size)
        counter.segment(index, frames)

    resume_hint = f"rerun with --resume to continue from the finished segments in '{work}'"
    try:
        if client is not None:
            _run_dask(todo, client, finished)
        else:
            _run_local(todo, jobs, finished, counter.frame)
        if on_client is not None and (client is not None or jobs > 1):
            on_client([float(p * tb) for p in pts])
        parts = [work / _part_name(i) for i in range(len(ranges))]
        with atomic_file(output, overwrite=overwrite) as tmp:
            join(parts, input, tmp, muxer(output))
            write_spherical(tmp, output_spherical(s.info, s.layout, s.grid, spherical))
        resume_hint = None
    finally:
        if client is not None and isinstance(dask, str):
            client.close()
    shutil.rmtree(work, ignore_errors=True)
    return s.info


def _packets(container: Any, streams: list[Any]) -> Iterator[Any]:
    for packet in container.demux(streams):
        if packet.dts is not None or packet.pts is not None:
            yield packet


def _video_packets(parts: list[Path]) -> Iterator[Any]:
    import av

    for part in parts:
        with av.open(str(part)) as c:
            yield from _packets(c, [c.streams.video[0]])


def _when(packet: Any) -> Fraction:
    t = packet.dts if packet.dts is not None else packet.pts
    return t * packet.time_base


def join(parts: list[Path], input: Path, output: Path, format: str) -> None:
    """Join the segment files ``parts`` (in order) into ``output`` without re-encoding, with
    the copyable streams of ``input`` (its audio) muxed back, packets as they are."""
    import heapq

    import av

    with av.open(str(parts[0])) as first, _open(input) as src:
        vin = src.streams.video[0]
        with av.open(str(output), "w", format=format) as dst:
            vout = dst.add_stream_from_template(first.streams.video[0])
            vout.time_base = vin.time_base
            copies = copy_streams(src, dst, vin)
            others = [s for s in src.streams if s.index in copies]

            def video() -> Iterator[tuple[Fraction, int, int, Any]]:
                for k, p in enumerate(_video_packets(parts)):
                    yield _when(p), 0, k, p

            def rest() -> Iterator[tuple[Fraction, int, int, Any]]:
                if others:
                    for k, p in enumerate(_packets(src, others)):
                        yield _when(p), 1, k, p

            for _, source, _, packet in heapq.merge(video(), rest(), key=lambda x: x[:3]):
                packet.stream = vout if source == 0 else copies[packet.stream_index]
                dst.mux(packet)
