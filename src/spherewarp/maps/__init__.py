"""Conformal maps of the sphere, one family a module.

See :mod:`spherewarp.maps.base` for the map protocol every effect follows.
"""

from .base import Composite, PullBack, SphereMap, map_from_dict, map_from_json, register_map
from .branched import ExpMap, LogMap, Power, chart_for_branch_points
from .droste import Droste, TwistedDroste
from .elliptic import Lattes
from .expression import ExpressionMap, FunctionMap
from .mobius import Mobius, as_cp1_point
from .rational import Rational, RationalFit, fit_rational

__all__ = [
    "Composite",
    "Droste",
    "ExpMap",
    "ExpressionMap",
    "FunctionMap",
    "Lattes",
    "LogMap",
    "Mobius",
    "Power",
    "PullBack",
    "Rational",
    "RationalFit",
    "SphereMap",
    "TwistedDroste",
    "as_cp1_point",
    "chart_for_branch_points",
    "fit_rational",
    "map_from_dict",
    "map_from_json",
    "register_map",
]
