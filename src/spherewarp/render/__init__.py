"""Rendering: the pull-back renderer and the samplers."""

from .sampling import INTERPOLATIONS, sample
from .warp import as_image, check_equirect, push, warp

__all__ = ["INTERPOLATIONS", "as_image", "check_equirect", "push", "sample", "warp"]
