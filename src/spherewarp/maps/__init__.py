"""Conformal maps of the sphere, one family a module.

See :mod:`spherewarp.maps.base` for the map protocol every effect follows.
"""

from .base import Composite, PullBack, SphereMap, map_from_dict, map_from_json, register_map
from .branched import ExpMap, LogMap, Power, chart_for_branch_points
from .droste import Droste, TwistedDroste
from .expression import ExpressionMap, FunctionMap
from .mobius import Mobius, as_cp1_point

__all__ = [
    "Composite",
    "Droste",
    "ExpMap",
    "ExpressionMap",
    "FunctionMap",
    "LogMap",
    "Mobius",
    "Power",
    "PullBack",
    "SphereMap",
    "TwistedDroste",
    "as_cp1_point",
    "chart_for_branch_points",
    "map_from_dict",
    "map_from_json",
    "register_map",
]
