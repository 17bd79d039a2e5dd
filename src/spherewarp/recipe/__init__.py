"""Recipes: the serialisable render request.

A recipe is versioned JSON data -- the effects a render applies, each with the
parameters its command takes, in order, plus the output view, the render
options and, for an animation, tracks over time. The command line writes and
replays recipes, the API runs them, and an animation evaluates one per frame.
A recipe is data: reading one never runs code.

.. code-block:: json

    {
      "spherewarp": 1,
      "inputs": ["room.jpg"],
      "duration": 2.0,
      "loop": false,
      "steps": [
        {"rotate": {"yaw": 30}},
        {"zoom": {"at": [-163, 5], "factor": {"keyframes": [[0, 1], [2, 4]],
                                              "easing": "geometric"}}}
      ],
      "view": {"size": [2048, 1024]},
      "options": {"interp": "bilinear", "supersample": 1, "antialias": "auto"}
    }

Fields
------
``spherewarp``
    The format version (1); a newer version is refused.
``inputs``
    The file names the recipe was made from (for the record; ``render`` takes
    the panoramas to apply it to). A step that renders from several images (a
    ``splitscreen``, a ``droste`` with ``images`` > 1) takes that many, in order:
    ``Recipe.render([a, b])``, ``spherewarp render R.json A B``.
``steps``
    A list of ``{EFFECT: {PARAMETER: value, ...}}``, applied in order; see
    :data:`~spherewarp.recipe.effects.EFFECTS`. Parameters are named as the
    command's options, ``-`` written ``_`` (``--look-at`` is ``look_at``).
``duration``, ``loop``
    Seconds, and whether time wraps round (``t`` modulo ``duration``).
``view``
    ``size`` ``[W, H]``; ``projection``, ``look_at``, ``fov`` are reserved for
    the output grids and checked loosely.
``options``
    ``interp``, ``supersample``, ``antialias``, ``background``.

Time and constant speed
-----------------------
Any number, or a point's coordinates, may be a track (:mod:`.tracks`). A
rotation whose ``angle`` (or ``yaw``) track is linear in time turns at constant
speed: rotations about one axis form a one-parameter group, ``R(a) = R(1)^a``.
A zoom's ``factor`` grows at constant speed (``M^t``) on the ``geometric``
easing, which interpolates ``log(factor)``; the ``linear`` easing interpolates
the factor itself (1 to 4 passes 2.5 half-way). A Droste loop is a ``phase``
track from 0 to 1 over the duration with ``loop: true``; so is a Schottky loop.

Pictures of their own
---------------------
A ``splitscreen``, a ``droste`` step with several ``images`` or a ``view`` of
``log``/``log-output``, ``peirce`` and ``torus`` render their own picture (the
effect's ``render``), so such a step is the recipe's only step; the flat ones
(log plane, Peirce square, torus) take no output grid and carry no GPano. File
names (a ``mask``) are read relative to the recipe file's directory.
"""

from __future__ import annotations

from .effects import EFFECTS, Effect
from .errors import RecipeError
from .recipe import FORMAT_VERSION, Frame, Recipe, Step
from .tracks import EASINGS, Track

__all__ = [
    "EASINGS",
    "EFFECTS",
    "FORMAT_VERSION",
    "Effect",
    "Frame",
    "Recipe",
    "RecipeError",
    "Step",
    "Track",
]
