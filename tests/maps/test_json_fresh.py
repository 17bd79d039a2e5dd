"""Conformance: every registered map kind reads back from JSON in a fresh interpreter.

A map's JSON is only useful if ``map_from_json`` can rebuild it in a process that
has imported nothing but ``spherewarp``: a kind whose module the registry does not
import on demand (``spherewarp.maps.MAP_MODULES``) reads back in the process that
wrote it and nowhere else. This test writes one example of every registered kind
here and reads them all back in one fresh ``python`` process.

A new map kind needs an entry in :data:`EXAMPLES` (the test says so); a kind that
cannot be read back by design goes in :data:`NOT_READABLE`.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from collections.abc import Callable

import numpy as np

from spherewarp import coords
from spherewarp.maps import (
    MAP_MODULES,
    ExpMap,
    ExpressionMap,
    Lattes,
    LogMap,
    Mobius,
    Power,
    Rational,
    Schottky,
    SphereMap,
    map_from_json,
)
from spherewarp.maps.base import _REGISTRY
from spherewarp.maps.sheeted import SheetedCover


def _droste(twist: bool) -> SphereMap:
    from spherewarp.demo import PICTURE, PICTURE_FRAME
    from spherewarp.effects.droste import droste_map, hole_from_corners

    hole = hole_from_corners(PICTURE_FRAME, PICTURE)
    return droste_map(hole, 8.0 if twist else None, twist=twist)


#: kind -> a function building one example of it
EXAMPLES: dict[str, Callable[[], SphereMap]] = {
    "mobius": lambda: Mobius.zoom((-163, 5), 3.0),
    "composite": lambda: Mobius.zoom((-163, 5), 3.0) @ Power(2),
    "power": lambda: Power(3, branch_points=((10, 20), (190, -20))),
    "exp": lambda: ExpMap(4.0),
    "log": lambda: LogMap(4.0),
    "expression": lambda: ExpressionMap("z**3 + 0.5*z"),
    "droste": lambda: _droste(twist=False),
    "twisted_droste": lambda: _droste(twist=True),
    "lattes": lambda: Lattes("2+1j", "square"),
    "rational": lambda: Rational([1, 0, 1], [2, 0]),
    "schottky": lambda: Schottky.from_disk_pairs([((-163, 5, 12), (17, -5, 25))], phase=0.5),
    "sheeted_cover": lambda: SheetedCover(
        Power(4), 2, seam=30.0, view=Mobius.from_yaw_pitch_roll(10, 20)
    ),
}

#: kinds whose JSON describes the map but cannot rebuild it (a Python callable)
NOT_READABLE = {"function"}

_READ_BACK = """
import json, sys
from spherewarp import map_from_json
for text in json.load(sys.stdin):
    print(map_from_json(text).to_json())
"""


def _registered_kinds() -> set[str]:
    for name in MAP_MODULES:
        importlib.import_module(name)
    return set(_REGISTRY) - {k for k in _REGISTRY if k.startswith("test-")}


def test_every_registered_kind_has_an_example():
    missing = _registered_kinds() - set(EXAMPLES) - NOT_READABLE
    assert not missing, f"add an example of map kind(s) {sorted(missing)} to EXAMPLES"


def test_examples_are_of_their_kind():
    for kind, build in EXAMPLES.items():
        assert build().kind == kind


def test_every_kind_reads_back_in_a_fresh_interpreter():
    kinds = sorted(_registered_kinds() & set(EXAMPLES))
    maps = [EXAMPLES[k]() for k in kinds]
    texts = [m.to_json() for m in maps]
    done = subprocess.run(
        [sys.executable, "-c", _READ_BACK],
        input=json.dumps(texts),
        capture_output=True,
        text=True,
        timeout=300,
        env=dict(os.environ),
    )
    assert done.returncode == 0, done.stderr
    back = done.stdout.splitlines()
    assert len(back) == len(texts)
    lon, lat = np.meshgrid(np.linspace(-179, 179, 13), np.linspace(-85, 85, 7))
    zw = coords.cp1_from_lonlat(np.radians(np.stack([lon, lat], axis=-1)))
    for kind, m, again in zip(kinds, maps, back, strict=True):
        rebuilt = map_from_json(again)
        assert rebuilt.kind == kind
        want, got = m.pull(zw), rebuilt.pull(zw)
        np.testing.assert_allclose(
            coords.xyz_from_cp1(got.points), coords.xyz_from_cp1(want.points), atol=1e-9
        )
        for field in ("sheet", "valid"):
            a, b = getattr(want, field), getattr(got, field)
            assert (a is None) == (b is None), (kind, field)
            if a is not None:
                np.testing.assert_array_equal(a, b)
