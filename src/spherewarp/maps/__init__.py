"""Conformal maps of the sphere, one family a module.

==============================  =============================================
module                          maps
==============================  =============================================
:mod:`~spherewarp.maps.base`    the map protocol: :class:`SphereMap`,
                                :class:`PullBack`, :class:`Composite`
:mod:`~spherewarp.maps.mobius`  :class:`Mobius` (rotations, zooms, ...)
:mod:`~.branched`               :class:`Power` (z^n, roots), :class:`ExpMap`,
                                :class:`LogMap`
:mod:`~.expression`             :class:`ExpressionMap` (``"z**2 + 1"``),
                                :class:`FunctionMap` (a Python callable)
:mod:`~.droste`                 :class:`Droste`, :class:`TwistedDroste`
:mod:`~.rational`               :class:`Rational`, :func:`fit_rational`
:mod:`~.elliptic`               :class:`Lattes`
:mod:`~.schottky`               :class:`Schottky`
:mod:`~.sheeted`                :class:`SheetedCover` (split-screen's map)
==============================  =============================================

Names are imported on first use, so that the command line starts fast.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .base import Composite, PullBack, SphereMap, map_from_dict, map_from_json, register_map
from .mobius import Mobius, as_cp1_point

#: name -> submodule, for the families imported on first use
_LAZY = {
    "ExpMap": "branched",
    "LogMap": "branched",
    "Power": "branched",
    "chart_for_branch_points": "branched",
    "Droste": "droste",
    "TwistedDroste": "droste",
    "Lattes": "elliptic",
    "ExpressionMap": "expression",
    "FunctionMap": "expression",
    "Rational": "rational",
    "Schottky": "schottky",
    "SheetedCover": "sheeted",
    "RationalFit": "rational",
    "fit_rational": "rational",
}

#: every module that registers map kinds, by full name (map_from_dict imports them all when
#: it meets a kind it does not know yet, so that JSON reads back in a fresh interpreter)
MAP_MODULES = (
    "spherewarp.maps.mobius",
    "spherewarp.maps.branched",
    "spherewarp.maps.droste",
    "spherewarp.maps.elliptic",
    "spherewarp.maps.expression",
    "spherewarp.maps.rational",
    "spherewarp.maps.schottky",
    "spherewarp.maps.sheeted",
)

__all__ = [
    "Composite",
    "Mobius",
    "PullBack",
    "SphereMap",
    "as_cp1_point",
    "map_from_dict",
    "map_from_json",
    "register_map",
    "ExpMap",
    "LogMap",
    "Power",
    "chart_for_branch_points",
    "Droste",
    "TwistedDroste",
    "Lattes",
    "ExpressionMap",
    "FunctionMap",
    "Rational",
    "RationalFit",
    "fit_rational",
    "Schottky",
    "SheetedCover",
]

if TYPE_CHECKING:  # pragma: no cover
    from .branched import ExpMap, LogMap, Power, chart_for_branch_points
    from .droste import Droste, TwistedDroste
    from .elliptic import Lattes
    from .expression import ExpressionMap, FunctionMap
    from .rational import Rational, RationalFit, fit_rational
    from .schottky import Schottky
    from .sheeted import SheetedCover


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'spherewarp.maps' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
