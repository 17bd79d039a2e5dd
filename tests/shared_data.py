"""The shared panoramas' folder for the tests (``bench/data.py`` says where it is)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

_spec = importlib.util.spec_from_file_location(
    "_spherewarp_bench_data", Path(__file__).resolve().parents[1] / "bench" / "data.py"
)
_data = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_data)

SHARED_PANORAMAS: Path = _data.SHARED_PANORAMAS
