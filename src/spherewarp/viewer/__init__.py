"""The browser viewer and editor (``spherewarp view``).

:mod:`.server` serves the page bundled in ``static/`` (built from the npm
sources in the repository's ``viewer/`` folder), the image it was started
with, and a small JSON API: the recipe's map as packed compiled stages (the
rows :func:`spherewarp.render.fast.kernel_spec` gives the CPU kernels), the
GLSL ``#define`` lines of the stage table, and full-resolution renders with
the Python renderer.
"""

from __future__ import annotations

from .server import STATIC_DIR, ViewerServer, packed_stages

__all__ = ["STATIC_DIR", "ViewerServer", "packed_stages"]
