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
Branched maps (:mod:`spherewarp.maps.branched`, :mod:`spherewarp.maps.expression`)
    :class:`Power` (z^n and roots about any two branch points), :class:`ExpMap`
    (the paper's exp variant), :class:`ExpressionMap` (a formula in z);
    :func:`splitscreen` (k panoramas on the k sheets of a branched cover).
Droste (:mod:`spherewarp.maps.droste`, :mod:`spherewarp.effects.droste`)
    :class:`Droste`, :class:`TwistedDroste`; frames from corners, masks or radii.
Elliptic and rational maps (:mod:`spherewarp.maps.elliptic`, :mod:`spherewarp.maps.rational`)
    :class:`Lattes`, :class:`Rational`, :func:`fit_rational`; Weierstrass p and
    Schwarz-Christoffel in :mod:`spherewarp.special`; Peirce's quincuncial
    projection in :mod:`spherewarp.grids.peirce`; toroidal images in
    :mod:`spherewarp.effects.torus`.
Effects (:mod:`spherewarp.effects`)
    the workflows round the maps: Droste's frames, split-screen's seams, the torus.
The map protocol (:mod:`spherewarp.maps.base`)
    :class:`SphereMap`, :class:`PullBack`, :class:`Composite`,
    :func:`map_from_dict`, :func:`map_from_json`.
Output grids (:mod:`spherewarp.grids`)
    :func:`make_grid` (little planet, rectilinear, fisheye, equisolid, cube maps, Peirce,
    torus; ``warp(..., grid=)``), :func:`from_grid` (such a picture back to the sphere).
Images (:mod:`spherewarp.io`)
    :func:`read_image`, :func:`write_image`.
Recipes (:mod:`spherewarp.recipe`)
    :class:`Recipe` (load, save, validate, ``at(t)``, ``render``): the
    serialisable render request, with tracks over time; :class:`RecipeError`.
Test pattern (:mod:`spherewarp.testpattern`)
    :func:`make_test_pattern`.
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
    "Power": "spherewarp.maps.branched",
    "ExpMap": "spherewarp.maps.branched",
    "ExpressionMap": "spherewarp.maps.expression",
    "Droste": "spherewarp.maps.droste",
    "TwistedDroste": "spherewarp.maps.droste",
    "Lattes": "spherewarp.maps.elliptic",
    "Rational": "spherewarp.maps.rational",
    "fit_rational": "spherewarp.maps.rational",
    "splitscreen": "spherewarp.effects.splitscreen",
    "make_test_pattern": "spherewarp.testpattern",
    "make_grid": "spherewarp.grids",
    "from_grid": "spherewarp.grids",
    "Recipe": "spherewarp.recipe",
    "RecipeError": "spherewarp.recipe",
}

__all__ = [
    "ImageFormatError",
    "InvalidTypeError",
    "InvalidValueError",
    "OutputExistsError",
    "SpherewarpError",
    "__version__",
    "warp",
    "push",
    "Mobius",
    "SphereMap",
    "PullBack",
    "Composite",
    "map_from_dict",
    "map_from_json",
    "read_image",
    "write_image",
    "Power",
    "ExpMap",
    "ExpressionMap",
    "Droste",
    "TwistedDroste",
    "Lattes",
    "Rational",
    "fit_rational",
    "splitscreen",
    "make_test_pattern",
    "make_grid",
    "from_grid",
    "Recipe",
    "RecipeError",
]

if TYPE_CHECKING:  # pragma: no cover
    from .effects.splitscreen import splitscreen
    from .grids import from_grid, make_grid
    from .io import read_image, write_image
    from .maps.base import Composite, PullBack, SphereMap, map_from_dict, map_from_json
    from .maps.branched import ExpMap, Power
    from .maps.droste import Droste, TwistedDroste
    from .maps.elliptic import Lattes
    from .maps.expression import ExpressionMap
    from .maps.mobius import Mobius
    from .maps.rational import Rational, fit_rational
    from .recipe import Recipe, RecipeError
    from .render.warp import push, warp
    from .testpattern import make_test_pattern


def __getattr__(name: str) -> Any:
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            return version("spherewarp")
        except PackageNotFoundError:  # pragma: no cover - not installed
            return "0+unknown"
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'spherewarp' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
