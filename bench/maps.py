"""Maps for the anti-aliasing benchmark that the package may not ship yet.

The exp variant and a Droste map come from the package when it has them
(``spherewarp.maps.branched.ExpMap``, ``spherewarp.effects.droste``); otherwise the
small stand-ins below implement the paper's formulas directly.
"""

from __future__ import annotations

import numpy as np

from spherewarp import coords
from spherewarp.maps import Mobius, SphereMap
from spherewarp.maps.base import vectorize_plane_function


class ExpVariant(SphereMap):
    """``S(z) = -exp(-lam (1 + z)/(1 - z))`` in the default chart (the paper's exp variant)."""

    kind = "bench-exp"

    def __init__(self, lam: float = 4.0):
        self.lam = float(lam)
        self._pull = vectorize_plane_function(self._s)

    def _s(self, z: np.ndarray) -> np.ndarray:
        return -np.exp(-self.lam * (1 + z) / (1 - z))

    def pull_cp1(self, zw: np.ndarray) -> np.ndarray:
        return self._pull(zw)

    def local_scale(self, zw: np.ndarray) -> np.ndarray:
        z = coords.plane_from_cp1(zw)
        with np.errstate(all="ignore"):
            s = self._s(z)
            ds = s * (-2 * self.lam) / (1 - z) ** 2
            out = np.abs(ds) * (1 + np.abs(z) ** 2) / (1 + np.abs(s) ** 2)
        return np.nan_to_num(out, nan=1e6, posinf=1e6)

    def params(self) -> dict:
        return {"lam": self.lam}


class DrosteCircle(SphereMap):
    """Straight Droste with a round hole: ``zeta -> zeta / scale**k``, into the annulus
    ``r0 <= |zeta| < r0 scale``.

    ``zeta`` is a chart with ``centre`` at 0 and its antipode at infinity.
    """

    kind = "bench-droste"

    def __init__(self, centre=(0.0, 0.0), r0: float = 0.25, scale: float = 3.0):
        self.chart = Mobius.rotation_to(centre, (0.0, 90.0))  # centre -> zenith (z = 0)
        self.r0 = float(r0)
        self.scale = float(scale)

    def _k(self, zeta: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore"):
            return np.floor(np.log(np.abs(zeta) / self.r0) / np.log(self.scale))

    def pull_cp1(self, zw: np.ndarray) -> np.ndarray:
        zeta = coords.plane_from_cp1(self.chart.pull_cp1(zw))
        k = np.clip(np.nan_to_num(self._k(zeta), nan=0.0, neginf=-60, posinf=60), -60, 60)
        out = coords.cp1_from_plane(np.where(np.isfinite(zeta), zeta / self.scale**k, np.inf))
        return self.chart.inverse().pull_cp1(out)

    def local_scale(self, zw: np.ndarray) -> np.ndarray:
        zeta = coords.plane_from_cp1(self.chart.pull_cp1(zw))
        k = np.clip(np.nan_to_num(self._k(zeta), nan=0.0, neginf=-60, posinf=60), -60, 60)
        f = self.scale ** (-k)
        with np.errstate(all="ignore"):
            a2 = np.abs(zeta) ** 2
            out = f * (1 + a2) / (1 + f * f * a2)
        return np.nan_to_num(out, nan=1.0, posinf=1e6)

    def params(self) -> dict:
        return {"r0": self.r0, "scale": self.scale}


def exp_map(lam: float = 4.0) -> tuple[SphereMap, str]:
    try:
        from spherewarp.maps.branched import ExpMap

        return ExpMap(lam), "spherewarp.maps.branched.ExpMap"
    except Exception:
        return ExpVariant(lam), "bench.maps.ExpVariant"


def droste_map(scale: float = 3.0) -> tuple[SphereMap, str]:
    try:
        from spherewarp.effects.droste import droste_map as dm
        from spherewarp.effects.droste import hole_from_radius

        return dm(hole_from_radius((0, 0), 25), scale), "spherewarp.effects.droste.droste_map"
    except Exception:
        return DrosteCircle((0.0, 0.0), 0.22, scale), "bench.maps.DrosteCircle"
