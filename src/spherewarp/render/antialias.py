"""Anti-aliasing from the map's derivative: how each output pixel is filtered.

``antialias="auto"`` (the default) is one of two filters (:func:`resolve_auto`):

* ``"area"`` for a map that shrinks the input somewhere (a zoom, a downscale,
  the branched, exp, Droste and Lattès maps): every pixel is the average of
  the input's bilinear surface over the pixel's footprint, what a heavily
  supersampled render converges to. The footprint is the map's Jacobian in
  the input's chart (:func:`area_footprints`; the compiled renderer computes
  the same); footprints whose axes are up to about 1.5 input pixels
  (:data:`AREA_SPLIT` with the tolerance) are one closed-form area tap (4 x 4
  taps of tent * box), longer ones are split along their axes and each part
  pulled back through the map.
* ``"adaptive"`` for a map that shrinks nowhere (a rotation, an enlargement):
  there it is one bilinear tap a pixel, as sharp as the input allows and
  what the peers (ffmpeg's v360) do.

The area filter is what matches a supersampled reference render: it averages
every pixel, including those the map enlarges, where a single tap differs
from the average of the surface over the pixel (``bench/aa_profile.py``
measures it). A rotation is left sharp because nothing needs filtering there.

``"adaptive"`` (also a mode of its own, and :class:`~spherewarp.render.cache.WarpMap`'s
``auto``: its samples can be cached) supersamples only where a pixel's footprint
covers more than one input pixel. A conformal map magnifies a small disc by
its local scale ``s`` (the spherical magnification,
:meth:`~spherewarp.maps.SphereMap.local_scale`) and turns it, without
shearing it. An output pixel of an equirectangular image of size
``W_out x H_out`` at latitude ``lat`` spans ``2 pi cos(lat) / W_out`` by
``pi / H_out`` radians, so its pre-image in the input spans ``s`` times that,
which is

* ``nx = s cos(lat) (2 pi / W_out) / rho`` input pixels along the image of
  the output's rows, and
* ``ny = s (pi / H_out) / rho`` input pixels along the image of its columns,

with ``rho = min(pi / H_in, 2 pi / W_in)`` the angular size of an input pixel.
Since the map is conformal these two numbers hold whatever the rotation. A
bilinear tap is a fine filter for a footprint up to about one input pixel;
beyond that the pixel is supersampled on a ``ceil(nx - tol) x ceil(ny - tol)``
grid (capped), and only there.

The magnification says nothing where the map jumps (the seams between the
copies of a Droste image): an output pixel there straddles points far apart
in the input. :func:`jump_mask` finds them by comparing the distance between
the source points of neighbouring pixels with what the magnification allows,
and those pixels get ``JUMP_SAMPLES x JUMP_SAMPLES`` samples, in both modes. The
compiled renderer makes the same test in its kernel (for maps with a stage in
:data:`spherewarp.render.fast.JUMP_KINDS`), and cached maps
(:class:`~spherewarp.render.cache.WarpMap`) call :func:`jump_mask`, so all
three paths treat the same pixels.

The equirectangular input is oversampled along its rows near its poles
(``rho`` is the size of a pixel at the equator), so in ``"adaptive"`` a footprint
there is not made smaller by the input's tiny pole pixels: the sampling rate
follows the sphere, not the chart. The area filter follows the chart, as a
supersampled render does.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidValueError

__all__ = [
    "AREA_SPLIT",
    "AUTO_DENSITY",
    "AUTO_MAX",
    "AUTO_TOLERANCE",
    "JUMP_SAMPLES",
    "area_footprints",
    "footprint_factors",
    "jump_mask",
    "one_tap_pixels",
    "parse_antialias",
    "resolve_auto",
    "sample_counts",
    "subsample_offsets",
]

#: samples per input pixel of footprint, per axis
AUTO_DENSITY = 1.0
#: ``ceil(AUTO_DENSITY * footprint - AUTO_TOLERANCE)`` samples per axis: a footprint up to
#: ``(1 + AUTO_TOLERANCE) / AUTO_DENSITY`` input pixels gets a single bilinear sample
AUTO_TOLERANCE = 0.1
#: at most this many samples per axis and output pixel in ``antialias="auto"``
AUTO_MAX = 8
#: largest uniform supersampling accepted
MAX_UNIFORM = 32
#: samples per axis, in ``"auto"``, for pixels on a jump of the map (a seam of a Droste map)
JUMP_SAMPLES = 4
#: in ``"area"``, a footprint whose axis is longer than this many input pixels is split along
#: it into ``ceil(length / AREA_SPLIT - AUTO_TOLERANCE)`` parts (one area tap holds a box of
#: up to 2 x 2 input pixels, and a turned part of ``sqrt 2`` fits in one)
AREA_SPLIT = math.sqrt(2.0)
#: in ``"area"``, a pixel whose footprint's box in the input's chart is at most this many
#: input pixels a side (bounded from the magnification ``s``: ``s * max(kx cos(lat), ky) <=
#: AREA_ONE_TAP * cos(lat_src)``, see :func:`one_tap_pixels`) takes one bilinear tap instead
#: of 4x4 taps and a footprint. Not 1 (every pixel that does not shrink): the box average of
#: the bilinear surface over a footprint of 0.5 to 1 input pixels is what heavy supersampling
#: gives, and a single tap there was 2.4 dB (0.5) to 8.2 dB (1) further from 16x16 on a zoom by
#: 2.5 of forest.png (bench/speed.py), and on the stripes of tests/render/test_antialias.py
#: (a zoom by 6) the RMS error grew by 7% at 0.2 and 74% at 0.35; at 0.1 nothing changes
AREA_ONE_TAP = 0.1
#: in ``"area"`` (compiled), a footprint that needs splitting but whose box is at most this
#: many input pixels high (a sliver along the rows: the footprints near the input's poles,
#: where the chart stretches the rows) is one exact tap of its whole box instead of parts
#: pulled back through the map: the rows' averages from prefix sums (:data:`AREA_SLIVER_ROWS`).
#: 0 turns it off. On the exp variant (forest.png, 1024x512, against 16x16 supersampling)
#: the sliver taps lose 0.4 dB against the parts they replace, and the parts' wide taps (boxes
#: over 2 input pixels exact up to 4, no longer clamped to 2) gain 0.2 dB: 58.92 dB with both,
#: against 59.12 for the clamped parts alone, at 0.53x the time of the exact parts and 0.8x
#: that of the clamped ones (2048x1024 interior.png, one thread, CPU time)
AREA_SLIVER_BOX = 0.25
#: the input rows whose prefix sums the sliver taps read: those with ``cos(lat)`` under this
#: (3% of the rows; their sums are built per render, 12 MiB for a 4096x2048 RGB input: 0.25
#: took 140 ms and 62 MiB there, 18% of the time of a zoom's area filter, and gained the exp
#: variant 3% of its time but lost it 0.2 dB)
AREA_SLIVER_ROWS = 0.05
#: a sliver tap only where the chart bends the footprint by at most this many input rows (a
#: straight piece of the sphere near a pole is an arc in the chart; parts follow it)
AREA_SLIVER_BEND = 0.05
#: what ``"area"`` renders as with interpolations other than bilinear (the area filter
#: averages the bilinear surface): uniform supersampling, which the area filter approximates
AREA_FALLBACK = ("uniform", 4)


def parse_antialias(antialias: str | int | None, supersample: int | None = None) -> tuple[str, int]:
    """Normalise the anti-aliasing options to ``(mode, n)``.

    ``mode`` is ``"none"``, ``"auto"``, ``"area"``, ``"adaptive"`` or ``"uniform"``
    (``n x n`` samples a pixel); :func:`resolve_auto` turns ``"auto"`` into one of
    the others for a given map. ``supersample`` is the older option for uniform supersampling:
    a value above 1 wins over ``antialias``; 1 (its old default) or None
    leave the choice to ``antialias``.

    Examples
    --------
    >>> parse_antialias("AUTO"), parse_antialias("none"), parse_antialias(4), parse_antialias("3")
    (('auto', 0), ('none', 1), ('uniform', 4), ('uniform', 3))
    >>> parse_antialias("area"), parse_antialias("adaptive")
    (('area', 0), ('adaptive', 0))
    >>> parse_antialias("auto", supersample=1), parse_antialias("none", supersample=2)
    (('auto', 0), ('uniform', 2))
    """
    if supersample is not None:
        if (
            isinstance(supersample, bool)
            or not isinstance(supersample, (int, np.integer))
            or not (1 <= supersample <= MAX_UNIFORM)
        ):
            raise InvalidValueError(
                f"expected supersample to be an integer 1..{MAX_UNIFORM}, got {supersample!r}"
            )
        if supersample > 1:
            return ("uniform", int(supersample))
    if antialias is None:
        return ("none", 1)
    if isinstance(antialias, str):
        name = antialias.strip().lower()
        if name == "auto":
            return ("auto", 0)
        if name == "adaptive":
            return ("adaptive", 0)
        if name in ("none", "off", "no"):
            return ("none", 1)
        if name == "area":
            return ("area", 0)
        if name.isdigit():
            antialias = int(name)
    if (
        isinstance(antialias, (int, np.integer))
        and not isinstance(antialias, bool)
        and 1 <= antialias <= MAX_UNIFORM
    ):
        n = int(antialias)
        return ("none", 1) if n == 1 else ("uniform", n)
    raise InvalidValueError(
        f"expected antialias to be 'auto', 'area', 'adaptive', 'none' or an integer "
        f"1..{MAX_UNIFORM}, "
        f"got {antialias!r}"
    )


def footprint_factors(in_shape: tuple[int, int], out_shape: tuple[int, int]) -> tuple[float, float]:
    """``(kx, ky)``: input pixels spanned by an output pixel per unit of magnification.

    Along the output's rows the span is ``s * kx * cos(lat)``, along its
    columns ``s * ky`` (see the module docstring).

    Examples
    --------
    >>> footprint_factors((512, 1024), (256, 512))
    (2.0, 2.0)
    """
    h_in, w_in = in_shape
    h_out, w_out = out_shape
    rho = min(math.pi / h_in, 2 * math.pi / w_in)
    return (2 * math.pi / w_out) / rho, (math.pi / h_out) / rho


def sample_counts(
    scale: NDArray[np.floating],
    lat_out: NDArray[np.floating],
    factors: tuple[float, float],
    tol: float = AUTO_TOLERANCE,
    cap: int = AUTO_MAX,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Samples per axis ``(nx, ny)`` for pixels of magnification ``scale`` at ``lat_out``.

    Examples
    --------
    >>> nx, ny = sample_counts(np.array([1.0, 3.0, 3.0]), np.radians([0.0, 0.0, 60.0]), (1.0, 1.0))
    >>> nx.tolist(), ny.tolist()
    ([1, 3, 2], [1, 3, 3])
    """
    kx, ky = factors
    s = np.asarray(scale, dtype=np.float64)
    cl = np.cos(np.asarray(lat_out, dtype=np.float64))
    nx = np.clip(np.ceil(s * kx * cl - tol), 1, cap).astype(np.int64)
    ny = np.clip(np.ceil(s * ky - tol), 1, cap).astype(np.int64)
    return nx, ny


def subsample_offsets(
    nx: NDArray[np.integer], ny: NDArray[np.integer]
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    """Owner pixel and in-pixel offsets of ``nx[k] x ny[k]`` subsamples of each pixel.

    Subsamples are the centres of an ``nx x ny`` grid on the pixel, in row
    order, pixel after pixel.

    Returns
    -------
    owner : ndarray of int64, shape (total,)
        Index of the pixel each subsample belongs to (non-decreasing).
    ox, oy : ndarray of float64, shape (total,)
        Offsets in ``(0, 1)`` from the pixel's top-left corner.

    Examples
    --------
    >>> owner, ox, oy = subsample_offsets(np.array([1, 2]), np.array([1, 1]))
    >>> owner.tolist(), ox.tolist(), oy.tolist()
    ([0, 1, 1], [0.5, 0.25, 0.75], [0.5, 0.5, 0.5])
    """
    nx = np.asarray(nx, dtype=np.int64)
    ny = np.asarray(ny, dtype=np.int64)
    per = nx * ny
    owner = np.repeat(np.arange(per.size), per)
    start = np.cumsum(per) - per
    m = np.arange(owner.size) - start[owner]
    nxo = nx[owner]
    a = m % nxo
    b = m // nxo
    return owner, (a + 0.5) / nxo, (b + 0.5) / ny[owner]


def jump_mask(
    xyz: NDArray[np.floating],
    scale: NDArray[np.floating],
    lat_out: NDArray[np.floating],
    valid: NDArray[np.bool_] | None,
    rho_in: float,
    out_height: int,
) -> NDArray[np.bool_]:
    """Pixels next to a jump of the map, for rows of an equirectangular output.

    Parameters
    ----------
    xyz : ndarray, shape (rows, W, 3)
        Source points of the pixel centres (unit vectors); the last row is
        only a neighbour of the one above (pass one row more than you need).
    scale : ndarray, shape (rows, W)
        The map's magnification at the pixel centres.
    lat_out : ndarray, shape (rows,)
        Latitude of each row of the output.
    valid : ndarray of bool, shape (rows, W), or None
        Where the map is defined (holes do not make jumps).
    rho_in : float
        Angular size of an input pixel.
    out_height : int
        Rows of the whole output (the step between rows is ``pi / out_height``).

    Returns
    -------
    ndarray of bool, shape (rows - 1, W)
        True for both pixels of a neighbouring pair (in a row, across the
        seam too, or in a column) whose source points are further apart than
        twice what the magnification allows, plus two input pixels.

    Examples
    --------
    >>> lon = np.linspace(-np.pi, np.pi, 16, endpoint=False)
    >>> xyz = np.stack([np.cos(lon), np.sin(lon), 0 * lon], -1)[None].repeat(2, 0)
    >>> xyz[:, 3] = (0.0, 0.0, 1.0)      # one column jumps to the zenith
    >>> jump_mask(xyz, np.ones((2, 16)), np.zeros(2), None, 0.01, 8).astype(int)
    array([[0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]])
    """
    rows, w = scale.shape
    h_step = 2 * np.pi / w * np.cos(np.asarray(lat_out, np.float64))[:, None]
    ok = np.ones(scale.shape, bool) if valid is None else np.asarray(valid, bool)
    # along rows (with the seam): pixel j and j + 1
    d = np.linalg.norm(np.roll(xyz, -1, axis=1) - xyz, axis=-1)
    allow = 2 * np.maximum(scale, np.roll(scale, -1, axis=1)) * h_step + 2 * rho_in
    jump = (d > allow) & ok & np.roll(ok, -1, axis=1)
    mask = jump | np.roll(jump, 1, axis=1)
    # along columns: row i and i + 1
    v_step = np.pi / out_height
    d = np.linalg.norm(xyz[1:] - xyz[:-1], axis=-1)
    allow = 2 * np.maximum(scale[1:], scale[:-1]) * v_step + 2 * rho_in
    vj = (d > allow) & ok[1:] & ok[:-1]
    mask[:-1] |= vj
    mask[1:] |= vj
    return mask[:-1]


def resolve_auto(aa: tuple[str, int], interp: str, shrinks: bool) -> tuple[str, int]:
    """What ``antialias="auto"`` means for one render.

    A map that shrinks the input somewhere (``shrinks``) is rendered with the
    area filter, every pixel averaged over its footprint (``("area", 0)``); one
    that shrinks nowhere (a rotation or an enlargement: no pixel covers more
    than one input pixel) with ``("adaptive", 0)``, which then takes one
    bilinear tap a pixel, as sharp as the input allows. The area filter is
    defined on the bilinear surface, so other interpolations take
    ``"adaptive"`` too. Other modes pass through.

    Examples
    --------
    >>> resolve_auto(("auto", 0), "bilinear", True), resolve_auto(("auto", 0), "bilinear", False)
    (('area', 0), ('adaptive', 0))
    >>> resolve_auto(("auto", 0), "bicubic", True), resolve_auto(("uniform", 4), "bilinear", True)
    (('adaptive', 0), ('uniform', 4))
    """
    if aa[0] != "auto":
        return aa
    return ("area", 0) if shrinks and interp == "bilinear" else ("adaptive", 0)


def one_tap_pixels(
    scale: NDArray[np.floating],
    v: NDArray[np.floating],
    valid: NDArray[np.bool_] | None,
    lat_out: NDArray[np.floating],
    in_shape: tuple[int, int],
    out_shape: tuple[int, int],
) -> NDArray[np.bool_]:
    """Pixels that ``antialias="area"`` renders with one bilinear tap (whole output rows).

    Those whose footprint's box in the input's chart is at most
    :data:`AREA_ONE_TAP` input pixels a side, bounded from the magnification:
    the footprint's axes on the sphere are ``s * kx * cos(lat)`` and ``s * ky``
    equatorial input pixels (:func:`footprint_factors`), and the chart stretches
    the east one by ``1 / cos(lat_src)``. The compiled renderer decides the same.

    Parameters
    ----------
    scale : ndarray, shape (rows, W)
        The map's magnification at the pixel centres.
    v : ndarray, shape (rows, W)
        Source rows of the pixel centres in tap space (input pixel row minus 1/2).
    valid : ndarray of bool, shape (rows, W), or None
    lat_out : ndarray, shape (rows,)
        Latitude of each output row (radians).
    in_shape, out_shape : (height, width)

    Returns
    -------
    ndarray of bool, shape (rows, W)

    Examples
    --------
    At the input's equator seen at its own size: a pixel magnified 20 times takes
    one tap, one shrunk 2 times does not.

    >>> one_tap_pixels(np.array([[0.05, 2.0]]), np.array([[7.5, 7.5]]), None, np.array([0.0]),
    ...                (16, 32), (16, 32)).tolist()
    [[True, False]]
    """
    kx, ky = footprint_factors(in_shape, out_shape)
    s = np.minimum(np.nan_to_num(np.asarray(scale, np.float64), nan=1e9), 1e9)
    ext = np.maximum(kx * np.cos(np.asarray(lat_out, np.float64)), ky)[:, None]
    with np.errstate(invalid="ignore"):
        cs = np.sin(np.pi / in_shape[0] * (np.nan_to_num(np.asarray(v, np.float64)) + 0.5))
        small = s * ext <= AREA_ONE_TAP * cs
    return small if valid is None else small & np.asarray(valid, bool)


def area_footprints(
    u: NDArray[np.floating],
    v: NDArray[np.floating],
    valid: NDArray[np.bool_] | None,
    lat_out: NDArray[np.floating],
    in_shape: tuple[int, int],
    out_shape: tuple[int, int],
    tol: float = AUTO_TOLERANCE,
    cap: int = AUTO_MAX,
    scale: NDArray[np.floating] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """Footprints and parts per axis of ``antialias="area"`` for whole output rows.

    The NumPy counterpart of the compiled renderer's footprints. The
    footprint of a pixel in the input's chart is the Jacobian ``J = (du/dx,
    du/dy, dv/dx, dv/dy)`` (input pixels per output pixel). Its first column
    is the difference of the source coordinates along the row (round the
    seam): the mean of the left and right ones where they agree within a
    factor of 2, else the shorter, so that a jump next door does not count.
    The second column follows because the map is conformal: on the sphere the
    image of the output's north step is the image of its east step turned by
    a right angle and scaled by the ratio of the steps. A pixel whose axis
    ``L`` (a column of ``J``) is long is split along it into
    ``ceil(L / AREA_SPLIT - tol)`` parts (at most ``cap``).

    Neighbour differences can miss a footprint that the magnification says is
    large: where the map repeats itself at the pixel's scale (a Droste map's
    fixed point) or where neighbours are half the input apart (tiny outputs).
    Given the magnification ``scale``, a pixel whose footprint on the sphere is
    under half of what it says (and that is over 2 input pixels) is treated as
    on a jump: a zero footprint (plain taps), as many parts as
    :func:`sample_counts` gives and at least ``JUMP_SAMPLES`` a side.

    Parameters
    ----------
    u, v : ndarray, shape (rows, W)
        Source points of the pixel centres in tap space (input pixel
        coordinates minus 1/2), whole rows of the output.
    valid : ndarray of bool, shape (rows, W), or None
        Where the map is defined; undefined pixels get a zero footprint.
    lat_out : ndarray, shape (rows,)
        Latitude of each row (radians).
    in_shape, out_shape : (height, width)
    tol, cap : float, int
        See above.
    scale : ndarray, shape (rows, W), optional
        The map's magnification at the pixel centres.

    Returns
    -------
    J : ndarray, shape (4, rows, W)
    nx, ny : ndarray of int64, shape (rows, W)
        Parts along the footprint's two axes.

    Examples
    --------
    The identity at half the input's size: every footprint is 2 x 2 input
    pixels, two parts along each axis.

    >>> y, x = np.mgrid[0:4, 0:8] + 0.5
    >>> J, nx, ny = area_footprints(2 * x - 0.5, 2 * y - 0.5, None, np.radians([67.5, 22.5,
    ...     -22.5, -67.5]), (8, 16), (4, 8))
    >>> J[:, 1, 0].round(6).tolist(), int(nx[1, 0]), int(ny[1, 0])
    ([2.0, 0.0, 0.0, 2.0], 2, 2)
    """
    h_in, w_in = in_shape
    h_out, w_out = out_shape
    u = np.asarray(u, np.float64)
    v = np.asarray(v, np.float64)
    ok = np.ones(u.shape, bool) if valid is None else np.asarray(valid, bool)
    u = np.where(ok, u, 0.0)
    v = np.where(ok, v, 0.0)
    half = 0.5 * w_in
    # differences to the left neighbour (round the seam); the right one is the next's
    du_l = u - np.roll(u, 1, axis=1)
    du_l = np.where(du_l > half, du_l - w_in, np.where(du_l < -half, du_l + w_in, du_l))
    dv_l = v - np.roll(v, 1, axis=1)
    if u.shape[1] < 2:
        du_l = np.zeros_like(u)
        dv_l = np.zeros_like(v)
    du_r = np.roll(du_l, -1, axis=1)
    dv_r = np.roll(dv_l, -1, axis=1)
    ll = du_l**2 + dv_l**2
    lr = du_r**2 + dv_r**2
    left = ll <= lr
    near = 4.0 * np.minimum(ll, lr) >= np.maximum(ll, lr)
    du = np.where(near, 0.5 * (du_l + du_r), np.where(left, du_l, du_r))
    dv = np.where(near, 0.5 * (dv_l + dv_r), np.where(left, dv_l, dv_r))
    cs = np.maximum(np.sin(np.pi / h_in * (v + 0.5)), 1e-9)  # cos(latitude) of the source
    q = (w_out / (2.0 * h_out * np.cos(np.asarray(lat_out, np.float64))))[:, None]
    J = np.stack([du, -q * dv / cs, dv, q * du * cs])
    J[:, ~ok] = 0.0
    nx = np.clip(np.ceil(np.hypot(J[0], J[2]) / AREA_SPLIT - tol), 1, cap).astype(np.int64)
    ny = np.clip(np.ceil(np.hypot(J[1], J[3]) / AREA_SPLIT - tol), 1, cap).astype(np.int64)
    if scale is not None:
        kx, ky = footprint_factors(in_shape, out_shape)
        s = np.minimum(np.asarray(scale, np.float64), 1e9)
        ex = s * kx * np.cos(np.asarray(lat_out, np.float64))[:, None]
        missed = ok & (ex > 2.0) & (4.0 * ((du * cs) ** 2 + dv**2) < ex * ex)
        if np.any(missed):
            J[:, missed] = 0.0
            lo = min(JUMP_SAMPLES, cap)
            nx[missed] = np.clip(np.ceil(ex[missed] - tol), lo, cap)
            ny[missed] = np.clip(np.ceil(s[missed] * ky - tol), lo, cap)
    return J, nx, ny
