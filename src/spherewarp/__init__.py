"""spherewarp: conformal edits of spherical (360°) images.

An equirectangular image is a picture of the sphere; the sphere is the
Riemann sphere by stereographic projection; conformal maps of it give effects
that ordinary image editors cannot. Every effect is a map ``S`` from output
points to input points, and one renderer pulls the image back through it.

API index
---------
Rendering
    :func:`warp` (pull back by a map), :func:`push` (push forward by an
    invertible map).
Möbius maps (:mod:`spherewarp.maps.mobius`)
    :class:`Mobius`: ``rotation``, ``from_yaw_pitch_roll``, ``rotation_to``,
    ``zoom``, ``zoom_between``, ``translation``, ``from_points``; ``@`` is
    composition (f after g), ``inverse``, ``power``, ``fixed_points``,
    ``classify``.
The map protocol (:mod:`spherewarp.maps.base`)
    :class:`SphereMap`, :class:`PullBack`, :class:`Composite`,
    :func:`map_from_dict`, :func:`map_from_json`.
Images (:mod:`spherewarp.io`)
    :func:`read_image`, :func:`write_image`.
Coordinates (:mod:`spherewarp.coords`)
    pixel, lon/lat, unit vectors, CP^1 pairs and the Riemann sphere.
Errors (:mod:`spherewarp.errors`)
    :class:`SpherewarpError` and its subclasses.

Examples
--------
>>> import numpy as np
>>> import spherewarp as sw
>>> img = np.zeros((64, 128, 3), np.uint8)
>>> out = sw.warp(img, sw.Mobius.from_yaw_pitch_roll(yaw=30, pitch=10))
>>> out.shape, out.dtype
((64, 128, 3), dtype('uint8'))
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .errors import (
    ImageFormatError,
    InvalidTypeError,
    InvalidValueError,
    OutputExistsError,
    SpherewarpError,
)

try:
    from importlib.metadata import version as _version

    __version__ = _version("spherewarp")
except Exception:  # pragma: no cover - not installed
    __version__ = "0+unknown"

# Public names loaded on first use, so that `import spherewarp` (and the CLI) start fast.
_LAZY = {
    "warp": "spherewarp.render.warp",
    "push": "spherewarp.render.warp",
    "Mobius": "spherewarp.maps.mobius",
    "SphereMap": "spherewarp.maps.base",
    "PullBack": "spherewarp.maps.base",
    "Composite": "spherewarp.maps.base",
    "map_from_dict": "spherewarp.maps.base",
    "map_from_json": "spherewarp.maps.base",
    "read_image": "spherewarp.io",
    "write_image": "spherewarp.io",
}

__all__ = [
    "ImageFormatError",
    "InvalidTypeError",
    "InvalidValueError",
    "OutputExistsError",
    "SpherewarpError",
    "__version__",
    *_LAZY,
]

if TYPE_CHECKING:  # pragma: no cover
    from .io import read_image, write_image
    from .maps.base import Composite, PullBack, SphereMap, map_from_dict, map_from_json
    from .maps.mobius import Mobius
    from .render.warp import push, warp


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'spherewarp' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
