"""Tolerances of the test suite, in one place.

Geometry is float64 throughout, so coordinate and map checks use absolute
tolerances near machine precision. Images keep their dtype, so image checks
use a table per dtype: ``ROUNDING[dtype]`` is the largest difference between
two renders of the same samples that differ only in arithmetic rounding (one
level for integer images, float32 rounding of values in [0, 1] otherwise).

Fix the test data rather than loosening these.
"""

from __future__ import annotations

import numpy as np

#: coordinate round trips (radians, unit vectors, pixels relative to the image size)
COORDS = 1e-12
#: relative error of plane (chart) values and of the chart formula
PLANE_REL = 1e-12
#: chordal distance between two points of the sphere (|det| of unit pairs) after a few maps
POINTS = 1e-11
#: entries of products of a few SL(2, C) matrices of norm <~ 10
MATRIX = 1e-11
#: the finite-difference local scale of the base class against an exact derivative
FINITE_DIFFERENCE_REL = 1e-6

#: full-scale value of an image of each dtype
FULL_SCALE = {
    np.dtype(np.uint8): 255.0,
    np.dtype(np.uint16): 65535.0,
    np.dtype(np.float32): 1.0,
    np.dtype(np.float64): 1.0,
}

#: same samples, different arithmetic: max abs difference, in the image's units
ROUNDING = {
    np.dtype(np.uint8): 1.0,
    np.dtype(np.uint16): 1.0,
    np.dtype(np.float32): 2e-6,
    np.dtype(np.float64): 2e-6,  # the samplers compute in float32
}

#: interpolating a smooth (linear in xyz) image of height 64: max abs error, full scale 1
#: (measured: nearest 0.0122, bilinear 3.0e-4, bicubic 1.1e-6 in float32, 1.6e-5 in uint16)
SMOOTH_INTERPOLATION = {"nearest": 0.02, "bilinear": 1e-3, "bicubic": 1e-4}
#: float bicubic, clamped to its four nearest samples (no ringing of HDR steps): at a smooth
#: extremum the clamp gives the nearest samples' extreme, as bilinear does (measured 2.1e-4)
SMOOTH_CLAMPED_BICUBIC = 3e-4

#: a Möbius render against the float64 reference of the paper's formulas (uint8 levels)
REFERENCE_MEAN_LEVELS = 0.5
REFERENCE_MAX_LEVELS = 3.0

#: spherewarp against ffmpeg v360, both bilinear, after a 4x4 box filter
V360_PSNR_DB = 36.0

#: magnification measured on a rendered image, relative
MEASURED_SCALE_REL = 0.05


def full_scale(dtype: np.dtype | type) -> float:
    """Full-scale value of an image dtype (255 for uint8, 1.0 for floats)."""
    return FULL_SCALE[np.dtype(dtype)]


def rounding(dtype: np.dtype | type) -> float:
    """Tolerance for two renders of the same samples, in the image's units."""
    return ROUNDING[np.dtype(dtype)]
