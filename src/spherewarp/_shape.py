"""Image and grid shapes given by callers: two whole numbers, checked in one place."""

from __future__ import annotations

import numbers
from typing import Any


def whole_pair(shape: Any) -> tuple[int, int]:
    """``(height, width)`` as two ints: integers, or floats with no fractional part.

    A float such as 10.5 or a bool is refused (``int()`` truncated 10.5 to 10, and
    ``True`` passed as 1), as is anything that is not a pair.

    Raises
    ------
    TypeError, ValueError
        For the caller to turn into its own error, naming the argument.

    Examples
    --------
    >>> whole_pair((128, 256.0)), whole_pair([3, 6])
    ((128, 256), (3, 6))
    >>> whole_pair((10.5, 20))
    Traceback (most recent call last):
    ...
    ValueError: expected whole numbers, got 10.5
    """
    a, b = shape
    return _whole(a), _whole(b)


def _whole(v: Any) -> int:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise TypeError(f"expected whole numbers, got {v!r}")
    if isinstance(v, numbers.Integral):
        return int(v)
    f = float(v)
    if not f.is_integer():
        raise ValueError(f"expected whole numbers, got {v!r}")
    return int(f)
