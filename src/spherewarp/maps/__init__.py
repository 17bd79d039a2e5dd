"""Conformal maps of the sphere, one family a module.

See :mod:`spherewarp.maps.base` for the map protocol every effect follows.
"""

from .base import Composite, PullBack, SphereMap, map_from_dict, map_from_json, register_map
from .mobius import Mobius, as_cp1_point

__all__ = [
    "Composite",
    "Mobius",
    "PullBack",
    "SphereMap",
    "as_cp1_point",
    "map_from_dict",
    "map_from_json",
    "register_map",
]
