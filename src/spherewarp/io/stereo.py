"""Stereoscopic 360° frames, and the warp of one frame planned once for many.

A stereo panorama holds one equirectangular picture for each eye, one above
the other (``"top-bottom"``, the left eye on top) or side by side
(``"left-right"``, the left eye on the left). A map of the sphere applies to
each eye's half on its own: :class:`FramePlan` plans it once for the half's
size (:class:`~spherewarp.render.WarpMap`) and samples both halves through it,
keeping the layout.

:class:`FramePlan` also takes an output grid (a view that is not the plain
panorama: a little planet, a flat view, a cube map...), which each eye is
rendered into.

Examples
--------
>>> import numpy as np
>>> from spherewarp.maps import Mobius
>>> frame = np.zeros((64, 64, 3), np.uint8)       # two 64x32 eyes, one above the other
>>> frame[:32, :16] = 200; frame[32:, 32:48] = 100
>>> plan = FramePlan(Mobius.from_yaw_pitch_roll(90, 0, 0), (64, 64), stereo="tb")
>>> out = plan.apply(frame)
>>> out.shape, eye_shape((64, 64), "top-bottom")
((64, 64, 3), (32, 64))
>>> bool(np.array_equal(out[:32], np.roll(frame[:32], -16, axis=1)))  # each eye turned alone
True
>>> bool(np.array_equal(out[32:], np.roll(frame[32:], -16, axis=1)))
True
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidValueError
from ..maps.base import SphereMap

__all__ = [
    "STEREO_MODES",
    "FramePlan",
    "eye_shape",
    "eyes",
    "frame_shape",
    "is_panorama",
    "parse_stereo",
    "resolve_grid",
]

#: the layouts, as :class:`~spherewarp.io.spherical.Spherical` names them
STEREO_MODES = ("mono", "top-bottom", "left-right")
_ALIASES = {
    "mono": "mono",
    "tb": "top-bottom",
    "top-bottom": "top-bottom",
    "ou": "top-bottom",
    "sbs": "left-right",
    "lr": "left-right",
    "left-right": "left-right",
}
GridArg = Any  # a Grid, a callable (eye height, width) -> Grid, or None


def parse_stereo(name: str) -> str:
    """The layout called ``name``: ``mono``, ``tb`` (``top-bottom``) or ``sbs`` (``left-right``).

    Examples
    --------
    >>> parse_stereo("TB"), parse_stereo("sbs"), parse_stereo("mono")
    ('top-bottom', 'left-right', 'mono')
    """
    key = str(name).strip().lower()
    if key not in _ALIASES:
        raise InvalidValueError(
            f"unknown stereo layout {name!r}; expected tb (top-bottom), sbs (left-right) or mono",
            cli=f"--stereo {name!r}: expected tb (top-bottom), sbs (left-right) or mono",
        )
    return _ALIASES[key]


def eye_shape(shape: tuple[int, ...], stereo: str) -> tuple[int, int]:
    """(height, width) of one eye's picture in a frame of ``shape``.

    Examples
    --------
    >>> eye_shape((1920, 1920), "top-bottom"), eye_shape((960, 3840), "left-right")
    ((960, 1920), (960, 1920))
    """
    h, w = int(shape[0]), int(shape[1])
    stereo = parse_stereo(stereo)
    if stereo == "top-bottom":
        if h % 2:
            raise InvalidValueError(f"a top-bottom stereo frame needs an even height, got {h}")
        return (h // 2, w)
    if stereo == "left-right":
        if w % 2:
            raise InvalidValueError(f"a left-right stereo frame needs an even width, got {w}")
        return (h, w // 2)
    return (h, w)


def frame_shape(eye: tuple[int, int], stereo: str) -> tuple[int, int]:
    """(height, width) of a frame holding two eyes of ``eye`` in ``stereo`` (or one, mono).

    Examples
    --------
    >>> frame_shape((960, 1920), "top-bottom")
    (1920, 1920)
    """
    stereo = parse_stereo(stereo)
    h, w = int(eye[0]), int(eye[1])
    return {"top-bottom": (2 * h, w), "left-right": (h, 2 * w)}.get(stereo, (h, w))


def eyes(pixels: NDArray, stereo: str) -> list[NDArray]:
    """Views of each eye's half of ``pixels`` (left eye first; one view, mono).

    Examples
    --------
    >>> [e.shape for e in eyes(np.zeros((4, 16)), "sbs")]
    [(4, 8), (4, 8)]
    """
    stereo = parse_stereo(stereo)
    h, w = eye_shape(pixels.shape, stereo)
    if stereo == "top-bottom":
        return [pixels[:h], pixels[h:]]
    if stereo == "left-right":
        return [pixels[:, :w], pixels[:, w:]]
    return [pixels]


class FramePlan:
    """The warp of a frame (both eyes of a stereo one), planned once and applied to many.

    Parameters
    ----------
    inverse_map : SphereMap
        The map from output points to input points (one sheet).
    shape : (height, width)
        The input frame's size (both eyes together for stereo).
    stereo : str
        ``"mono"``, ``"top-bottom"``/``"tb"`` or ``"left-right"``/``"sbs"``.
    grid : Grid or callable, optional
        The output grid of each eye, or ``grid(eye_shape) -> Grid``; None: an
        equirectangular eye of ``out_shape``.
    out_shape : (height, width), optional
        One eye's output size without a grid (default: the input eye's).
    force : bool
        Accept an eye that is not 2:1.
    lazy : bool
        Make only the render plan (:attr:`plan`) now, and the
        :class:`~spherewarp.render.WarpMap` (its source coordinates) when :meth:`apply`
        first needs it (for :class:`~spherewarp.io.planes.PlaneTaps`, which needs the plan).
    **options
        :meth:`~spherewarp.render.WarpMap.build`'s (``interp``, ``antialias``,
        ``supersample``).

    Attributes
    ----------
    stereo : str
    eye_in, eye_out : (height, width)
        One eye's input and output sizes.
    out_shape : (height, width)
        The output frame's size.
    grid : Grid or None
    plan : Plan or None
        The render plan of an eye (None with a grid).
    """

    def __init__(
        self,
        inverse_map: SphereMap,
        shape: tuple[int, int],
        *,
        stereo: str = "mono",
        grid: GridArg = None,
        out_shape: tuple[int, int] | None = None,
        force: bool = False,
        lazy: bool = False,
        **options: Any,
    ) -> None:
        self.stereo = parse_stereo(stereo)
        self.eye_in = eye_shape(shape, self.stereo)
        self.grid = resolve_grid(grid, self.eye_in)
        if self.grid is not None and getattr(self.grid, "is_identity", False):
            # the plain panorama: no grid; an asked-for size (a chroma plane's) comes first
            out_shape = self.grid.shape if out_shape is None else out_shape
            self.grid = None
        self.inverse_map = inverse_map
        self.options = dict(options)
        self.force = force
        self.plan: Any = None
        self._wm: Any = None
        if self.grid is not None:
            self.eye_out = tuple(int(v) for v in self.grid.shape)
            # TODO(lead): switch to WarpMap.build(..., grid=self.grid) once the `plan` branch
            # (a WarpMap with an output grid) is merged; until then each frame is rendered
            # into the grid by spherewarp.warp (grids/render.py).
            from ..render.warp import check_equirect

            check_equirect(np.empty((*self.eye_in, 1), np.uint8), force=force, name="each eye")
        else:
            from ..render import WarpMap

            self.eye_out = tuple(out_shape) if out_shape is not None else self.eye_in
            h, w = self.eye_in
            plain = inverse_map.n_sheets <= 1 and (force or w == 2 * h)  # WarpMap's checks
            if lazy and plain:  # only the render plan; the WarpMap when apply first needs it
                from ..render.plan import Options, plan

                self.plan = plan(
                    inverse_map, None, self.eye_in, self.eye_out, Options(**self.options)
                )
            else:
                self._wm = WarpMap.build(
                    inverse_map, self.eye_in, self.eye_out, force=force, **self.options
                )
                self.plan = self._wm.plan
        self.out_shape = frame_shape(self.eye_out, self.stereo)  # type: ignore[arg-type]

    @property
    def _map(self) -> Any:
        """The :class:`~spherewarp.render.WarpMap` of an eye (None with a grid), built on first
        use for a ``lazy`` plan."""
        if self._wm is None and self.grid is None:
            from ..render import WarpMap

            self._wm = WarpMap.build(
                self.inverse_map, self.eye_in, self.eye_out, force=self.force, **self.options
            )
        return self._wm

    @staticmethod
    def output_shape(
        eye: tuple[int, int],
        stereo: str,
        grid: Any = None,
        out_shape: tuple[int, int] | None = None,
    ) -> tuple[int, int]:
        """The output frame's (height, width) for an input eye of ``eye`` (``grid`` resolved,
        see :func:`resolve_grid`), as :attr:`out_shape` will be.

        Examples
        --------
        >>> FramePlan.output_shape((32, 64), "sbs", out_shape=(16, 32))
        (16, 64)
        """
        shape = grid.shape if grid is not None else (out_shape or eye)
        return frame_shape(tuple(shape), stereo)  # type: ignore[arg-type]

    def apply(self, pixels: NDArray, out: NDArray | None = None, background: Any = None) -> NDArray:
        """Warp ``pixels`` (H, W[, C]): each eye through the plan, in the input's layout;
        ``background``: the value of pixels the map leaves undefined (default 0)."""
        img = pixels if pixels.ndim == 3 else pixels[..., None]
        if out is None:
            out = np.empty((*self.out_shape, img.shape[2]), img.dtype)
        for src, dst in zip(eyes(img, self.stereo), eyes(out, self.stereo), strict=True):
            if self._map is not None and dst.flags.c_contiguous:
                self._map.apply(src, out=dst, background=background)
            elif self._map is not None:
                dst[...] = self._map.apply(src, background=background)
            else:
                from ..render import warp

                kwargs = {k: v for k, v in self.options.items() if k != "threads"}
                dst[...] = warp(
                    src, self.inverse_map, grid=self.grid, force=True, background=background,
                    **kwargs,
                )  # fmt: skip
        return out if pixels.ndim == 3 else out[..., 0]


def resolve_grid(grid: GridArg, eye: tuple[int, int]) -> Any:
    """``grid``, or ``grid(eye)`` when it is a callable (None: no grid)."""
    if grid is None:
        return None
    if callable(grid) and not hasattr(grid, "directions_at"):
        grid = grid(eye)
    return grid


def is_panorama(grid: Any) -> bool:
    """Whether frames rendered into ``grid`` are equirectangular panoramas (None: yes)."""
    return grid is None or bool(getattr(grid, "panorama", False))
