"""Cached maps: plan a pull-back once, apply it to many images.

For video, or any effect whose map does not change from frame to frame, the
decisions and the geometry need not be redone per frame. A :class:`WarpMap`
materialises a render plan (:func:`spherewarp.render.plan.plan`, the one
:func:`~spherewarp.render.warp` makes for the same map and options):

* a one-tap plan (:attr:`~spherewarp.render.plan.Plan.cacheable`: a rotation,
  an enlargement, ``antialias="none"``; on a compiled path) keeps the source
  coordinates of every output pixel (float64, 17 bytes a pixel), computed by
  the kernels that the still computes them with, and :meth:`WarpMap.apply`
  only samples them, with the still's sampler: what OpenCV's ``remap`` and
  ffmpeg's ``v360`` tables do;
* any other plan (the area filter, supersampling, maps with several sheets,
  no numba) is run on every frame, as the still is.

Either way a frame is the still's image, bit for bit.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._shape import whole_pair
from ..errors import InvalidTypeError, InvalidValueError
from ..maps.base import SphereMap
from .plan import Options, Plan, _run_taps, output_buffer, plan, render_straight_alpha
from .warp import _background, as_image

if TYPE_CHECKING:  # pragma: no cover
    from ..grids import Grid

__all__ = ["WarpMap"]


class WarpMap:
    """A planned pull-back: build it once, apply it to every frame.

    ``WarpMap(inverse_map, in_shape, out_shape=None, *, grid=None, interp=...,
    antialias=..., ...)``: the same map, grid and options as
    :func:`~spherewarp.render.warp` takes, for images of ``in_shape``;
    :meth:`apply` then gives exactly ``warp``'s image of each frame.

    Parameters
    ----------
    inverse_map : SphereMap
        The map from output points to input points; one sheet.
    in_shape : (height, width)
        Size of the images the map will be applied to.
    out_shape : (height, width), optional
        Of an equirectangular output (default ``in_shape``); with ``grid``, None or
        the grid's shape.
    grid : spherewarp.grids.Grid, optional
        The output grid (a little planet, a rectilinear or fisheye view, a cube map...);
        default the equirectangular panorama of ``out_shape``.
    interp, antialias, supersample, method, force, threads
        As for :func:`~spherewarp.render.warp` (``antialias="auto"`` is decided as
        there).

    Attributes
    ----------
    plan : Plan
        The render plan (:mod:`spherewarp.render.plan`).
    in_shape, out_shape : (height, width)
        The input size the map was built for, and the output size.
    interp : str
        The interpolation.
    antialias : (mode, n)
        The anti-aliasing, resolved (never ``"auto"``).
    cached : bool
        Whether the source coordinates are kept (else each frame runs the plan).

    Examples
    --------
    >>> from spherewarp.maps import Mobius
    >>> from spherewarp.render import warp
    >>> img = np.random.default_rng(0).integers(0, 255, (32, 64, 3), dtype=np.uint8)
    >>> wm = WarpMap(Mobius.rotation((0, 90), 45), (32, 64))
    >>> bool(np.array_equal(wm.apply(img), np.roll(img, -8, axis=1)))
    True
    >>> zoom = Mobius.zoom((0, 0), 2)
    >>> bool(np.array_equal(WarpMap(zoom, (32, 64)).apply(img), warp(img, zoom)))
    True
    """

    def __init__(
        self,
        inverse_map: SphereMap,
        in_shape: tuple[int, int],
        out_shape: tuple[int, int] | None = None,
        *,
        grid: Grid | None = None,
        interp: str = "bilinear",
        antialias: str | int = "auto",
        supersample: int | None = None,
        method: str = "auto",
        force: bool = False,
        threads: int | None = None,
    ):
        if not isinstance(inverse_map, SphereMap):
            raise InvalidTypeError(
                f"expected a map (a spherewarp.maps.SphereMap), got {type(inverse_map).__name__}"
            )
        if inverse_map.n_sheets > 1:
            raise InvalidValueError(
                f"a cached map samples one input image; this map samples {inverse_map.n_sheets}"
            )
        h_in, w_in = _check_shape(in_shape, "in_shape")
        if w_in != 2 * h_in and not force:
            raise InvalidValueError(
                f"in_shape: expected an equirectangular image with width = 2 x height, got "
                f"{w_in}x{h_in} (force=True treats it as equirectangular anyway)"
            )
        if out_shape is not None:
            out_shape = _check_shape(out_shape, "out_shape", min_width=1)
        options = Options(
            interp=interp, antialias=antialias, supersample=supersample, method=method,
            threads=threads,
        )  # fmt: skip
        self.plan: Plan = plan(inverse_map, grid, (h_in, w_in), out_shape, options)
        self._u: NDArray[np.float64] | None = None
        self._v: NDArray[np.float64] | None = None
        self._ok: NDArray[np.uint8] | None = None
        if self.plan.cacheable:
            h_out, w_out = self.plan.out_shape
            u = np.empty((h_out, w_out))
            v = np.empty((h_out, w_out))
            ok = np.empty((h_out, w_out), np.uint8)
            for r0, r1 in self.plan.bands():
                u[r0:r1], v[r0:r1], ok[r0:r1] = self.plan.source(r0, r1)
            for a in (u, v, ok):
                a.flags.writeable = False
            self._u, self._v, self._ok = u, v, ok

    @classmethod
    def build(
        cls,
        inverse_map: SphereMap,
        in_shape: tuple[int, int],
        out_shape: tuple[int, int] | None = None,
        **options: Any,
    ) -> WarpMap:
        """The same as ``WarpMap(inverse_map, in_shape, out_shape, **options)``."""
        return cls(inverse_map, in_shape, out_shape, **options)

    # -- properties --------------------------------------------------------------------------------
    @property
    def in_shape(self) -> tuple[int, int]:
        return self.plan.in_shape

    @property
    def out_shape(self) -> tuple[int, int]:
        return self.plan.out_shape

    @property
    def interp(self) -> str:
        return self.plan.interp

    @property
    def antialias(self) -> tuple[str, int]:
        return self.plan.antialias

    @property
    def grid(self) -> Grid | None:
        return self.plan.grid

    @property
    def cached(self) -> bool:
        return self._u is not None

    @property
    def n_special(self) -> int:
        """Output pixels whose map is undefined (background) in a cached map."""
        return 0 if self._ok is None else int(np.count_nonzero(self._ok == 0))

    @property
    def nbytes(self) -> int:
        """Memory held by the map's arrays, in bytes."""
        return sum(a.nbytes for a in (self._u, self._v, self._ok) if a is not None)

    def __repr__(self) -> str:
        grid = "" if self.grid is None else f", grid={self.grid.name}"
        return (
            f"WarpMap(in_shape={self.in_shape}, out_shape={self.out_shape}{grid}, "
            f"interp={self.interp!r}, antialias={self.antialias[0]!r}, cached={self.cached}, "
            f"nbytes={self.nbytes / 2**20:.1f} MiB)"
        )

    # -- applying ----------------------------------------------------------------------------------
    def apply(
        self,
        image: ArrayLike,
        *,
        background: ArrayLike | None = None,
        alpha: bool = False,
        out: NDArray | None = None,
        threads: int | None = None,
    ) -> NDArray:
        """Warp one image (a video frame) through the planned map.

        Parameters
        ----------
        image : ndarray (H, W[, C])
            ``(H, W) == in_shape``; uint8, uint16, float32 or float64, 1-4 channels
            (the last of 2 or 4 straight alpha, as for :func:`~spherewarp.render.warp`).
        background, alpha
            As for :func:`~spherewarp.render.warp`.
        out : ndarray, optional
            Where to write the result (shape ``out_shape + (C,)``, or ``C + 1``
            with ``alpha``; the image's dtype; C-contiguous), e.g. to reuse one
            buffer for every frame.
        threads : int, optional
            Worker threads (default: the map's, else all cores).

        Returns
        -------
        ndarray
        """
        img = as_image(image)
        img = img.astype(img.dtype.newbyteorder("="), copy=False)
        h, w, c = img.shape
        if (h, w) != self.in_shape:
            raise InvalidValueError(
                f"expected an image of {self.in_shape[1]}x{self.in_shape[0]} (the map's "
                f"in_shape), got {w}x{h}"
            )
        threads = self.plan.threads if threads is None else threads
        if not self.cached:
            return self.plan.run(img, out=out, background=background, alpha=alpha, threads=threads)
        add_alpha = alpha and c not in (2, 4)
        out = output_buffer(out, (*self.out_shape, c + add_alpha), img.dtype)
        bg = _background(background, c)
        p = self.plan
        if threads != p.threads:
            from dataclasses import replace

            p = replace(p, threads=threads)

        def coords_of(r0: int, r1: int) -> tuple[NDArray, NDArray, NDArray]:
            return self._u[r0:r1], self._v[r0:r1], self._ok[r0:r1]

        def render(ims: list[NDArray], dst: NDArray, b: NDArray, _progress: Any) -> None:
            _run_taps(p, ims[0], dst, b, None, coords_of)

        render_straight_alpha(render, [img], out, bg)  # alpha filtered premultiplied
        return out


def _check_shape(shape: Any, name: str, min_width: int = 2) -> tuple[int, int]:
    try:
        h, w = whole_pair(shape)
    except (TypeError, ValueError):
        raise InvalidValueError(f"{name}: expected (height, width), got {shape!r}") from None
    if h < 1 or w < min_width or h * w > 1 << 30:
        raise InvalidValueError(f"{name}: expected a positive (height, width), got {shape!r}")
    return h, w
