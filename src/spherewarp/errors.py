"""The exception family of spherewarp.

Every error raised on purpose at the public boundary derives from
:class:`SpherewarpError`; subclasses are also :class:`ValueError`,
:class:`TypeError` or :class:`OSError` where that fits, so callers can catch
either. The command-line interface turns any of them into one line on stderr
and a non-zero exit status.
"""

from __future__ import annotations

__all__ = [
    "SpherewarpError",
    "InvalidValueError",
    "InvalidTypeError",
    "ImageFormatError",
    "OutputExistsError",
]


class SpherewarpError(Exception):
    """Base class of every error spherewarp raises on purpose."""


class InvalidValueError(SpherewarpError, ValueError):
    """An argument has the right type but a value that cannot be used."""


class InvalidTypeError(SpherewarpError, TypeError):
    """An argument has a type that cannot be used."""


class ImageFormatError(SpherewarpError, OSError):
    """An image file cannot be read or written in the requested form."""


class OutputExistsError(SpherewarpError, FileExistsError):
    """The output file exists and overwriting was not asked for."""
