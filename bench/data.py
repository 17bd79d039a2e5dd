"""Where the data that is not bundled lies: the shared CC0 panoramas.

``$SPHEREWARP_PANORAMAS`` if set, else ``shared/data/panoramas`` beside the checkout
(``../shared`` from the repository's root, as on the project's machines), else
``/work/shared/data/panoramas``. Benchmarks fall back to the bundled sample, and tests
skip, where the folder is missing. One place for ``bench/``, ``tools/`` and ``tests/``
(``tests/shared_data.py`` loads this file).

Examples
--------
>>> from bench.data import shared_panoramas
>>> shared_panoramas().name
'panoramas'
"""

from __future__ import annotations

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENV = "SPHEREWARP_PANORAMAS"


def shared_panoramas() -> Path:
    """The folder of the shared panoramas (which may not exist)."""
    env = os.environ.get(ENV)
    if env:
        return Path(env)
    beside = ROOT.parent / "shared" / "data" / "panoramas"
    for path in (beside, Path("/work/shared/data/panoramas")):
        if path.is_dir():
            return path
    return beside


SHARED_PANORAMAS = shared_panoramas()
