"""The exception family of spherewarp.

Every error raised on purpose at the public boundary derives from
:class:`SpherewarpError`; subclasses are also :class:`ValueError`,
:class:`TypeError` or :class:`OSError` where that fits, so callers can catch
either. The command-line interface turns any of them into one line on stderr
and a non-zero exit status.

Advice for the Python caller and for the command line: a message that tells
the caller what to do says it in Python terms (``overwrite=True``,
``convert_dtype(pixels, np.uint8)``). Where the command line has its own way
(an option such as ``--overwrite``), the error also carries ``cli=`` -- the
whole message as the command line should show it -- and ``spherewarp``'s
``main()`` prints :attr:`SpherewarpError.cli_message` instead of ``str(exc)``.
So one exception serves both, and no CLI error shows Python code.

Examples
--------
>>> err = OutputExistsError("'a.png' exists; pass overwrite=True to replace it",
...                         cli="'a.png' exists; pass --overwrite to replace it")
>>> str(err)
"'a.png' exists; pass overwrite=True to replace it"
>>> err.cli_message
"'a.png' exists; pass --overwrite to replace it"
>>> InvalidValueError("bad").cli_message    # no CLI wording: the message itself
'bad'
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
    """Base class of every error spherewarp raises on purpose.

    Parameters
    ----------
    *args
        As for :class:`Exception`; the first is the message.
    cli : str, optional
        The message as the command line shows it, naming CLI options instead
        of Python arguments (see the module documentation).
    """

    def __init__(self, *args: object, cli: str | None = None) -> None:
        super().__init__(*args)
        self._cli = cli

    @property
    def cli_message(self) -> str:
        """The message for the command line: ``cli=`` if given, else ``str(self)``."""
        return self._cli if getattr(self, "_cli", None) else str(self)


class InvalidValueError(SpherewarpError, ValueError):
    """An argument has the right type but a value that cannot be used."""


class InvalidTypeError(SpherewarpError, TypeError):
    """An argument has a type that cannot be used."""


class ImageFormatError(SpherewarpError, OSError):
    """An image file cannot be read or written in the requested form."""


class OutputExistsError(SpherewarpError, FileExistsError):
    """The output file exists and overwriting was not asked for."""
