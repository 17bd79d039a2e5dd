"""Rendering: the pull-back renderer, cached maps, anti-aliasing and the samplers.

* :func:`warp` / :func:`push`: render one image through a map (fast compiled
  path by default, NumPy reference path with ``method="reference"``);
* :class:`WarpMap`: build a pull-back once, apply it to every video frame;
* :mod:`~spherewarp.render.antialias`: adaptive anti-aliasing from the map's
  magnification; :mod:`~spherewarp.render.fast`: the compiled kernels and how a
  map family adds its own.
"""

from .cache import WarpMap
from .sampling import INTERPOLATIONS, sample
from .warp import METHODS, as_image, check_equirect, push, warp

__all__ = [
    "INTERPOLATIONS",
    "METHODS",
    "WarpMap",
    "as_image",
    "check_equirect",
    "push",
    "sample",
    "warp",
]
