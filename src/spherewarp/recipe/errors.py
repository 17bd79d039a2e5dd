"""The recipe error: a bad field, named by its path."""

from __future__ import annotations

from ..errors import InvalidValueError

__all__ = ["RecipeError"]


class RecipeError(InvalidValueError):
    """A recipe that cannot be used; the message starts with the path of the bad field.

    Parameters
    ----------
    path : str
        Where in the recipe: ``"steps[1].zoom.factor"`` (empty for the whole text).
    message : str
        What was expected and what was found.
    cli : str, optional
        The message as the command line shows it (naming CLI options), if it differs.

    Examples
    --------
    >>> err = RecipeError("steps[1].zoom.factor", "expected a number > 0, got -1")
    >>> str(err)
    'steps[1].zoom.factor: expected a number > 0, got -1'
    >>> err.path
    'steps[1].zoom.factor'
    """

    def __init__(self, path: str, message: str, *, cli: str | None = None) -> None:
        where = f"{path}: " if path else ""
        super().__init__(where + message, cli=None if cli is None else where + cli)
        self.path = path
        self.detail = message
        self.cli_detail = message if cli is None else cli
