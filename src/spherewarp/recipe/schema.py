"""The JSON Schema of the recipe format, built from the effect table.

The package ships it as ``recipe.schema.json`` (``python -m
spherewarp.recipe.schema`` prints it; a test checks the shipped file is the
same). The schema says the shape of a recipe for editors and other tools; the
library's own validation (:class:`~spherewarp.recipe.Recipe`) says more (which
parameters go together, keyframe order, the maps' own limits).

Examples
--------
>>> s = json_schema()
>>> s["properties"]["spherewarp"]
{'const': 1}
"""

from __future__ import annotations

import json
from typing import Any

from ..grids import GRIDS
from . import params as P
from .effects import EFFECTS
from .recipe import FORMAT_VERSION
from .tracks import EASINGS

__all__ = ["json_schema", "spec_schema"]

_TRACK = {"$ref": "#/$defs/track"}


def _number(spec: P.Real) -> dict[str, Any]:
    out: dict[str, Any] = {"type": "number"}
    for key, name in (
        ("gt", "exclusiveMinimum"),
        ("ge", "minimum"),
        ("lt", "exclusiveMaximum"),
        ("le", "maximum"),
    ):
        if getattr(spec, key) is not None:
            out[name] = getattr(spec, key)
    return out


_DISK = {
    "type": "array",
    "prefixItems": [
        {"type": "number"},
        {"type": "number", "minimum": -90, "maximum": 90},
        {"type": "number", "exclusiveMinimum": 0, "maximum": 180},
    ],
    "minItems": 3,
    "maxItems": 3,
}


def _real_or_track() -> dict[str, Any]:
    return {"oneOf": [{"type": "number"}, _TRACK]}


def spec_schema(spec: P.Spec) -> dict[str, Any]:
    """The JSON Schema of one parameter."""
    from .effects import _Cells, _Seam

    if isinstance(spec, _Seam):
        return {"oneOf": [{"const": "auto"}, {"type": "number"}]}
    if isinstance(spec, _Cells):
        item = {"type": "integer", "minimum": 1, "maximum": 64}
        return {"type": "array", "items": item, "minItems": 2, "maxItems": 2}
    if isinstance(spec, P.File):
        return {"type": "string", "minLength": 1, "maxLength": 4096}
    if isinstance(spec, P.Generators):
        disk = {"$ref": "#/$defs/disk"}
        return {
            "type": "array",
            "maxItems": 64,
            "items": {
                "oneOf": [
                    {
                        "type": "object",
                        "required": ["disk", "to"],
                        "additionalProperties": False,
                        "properties": {"disk": disk, "to": disk, "twist": _real_or_track()},
                    },
                    {
                        "type": "object",
                        "required": ["disk", "matrix"],
                        "additionalProperties": False,
                        "properties": {"disk": disk, "matrix": spec_schema(P.Matrix())},
                    },
                ]
            },
        }
    if isinstance(spec, P.Targets):
        colour = {"type": "string", "minLength": 1, "maxLength": 40}
        return {
            "type": "array",
            "minItems": 1,
            "maxItems": 64,
            "items": {
                "oneOf": [
                    {
                        "type": "object",
                        "required": ["colour", "to"],
                        "additionalProperties": False,
                        "properties": {"colour": colour, "to": {"$ref": "#/$defs/disk"}},
                    },
                    {
                        "type": "object",
                        "required": ["colour", "zoom"],
                        "additionalProperties": False,
                        "properties": {
                            "colour": colour,
                            "zoom": {"oneOf": [{"type": "number", "exclusiveMinimum": 1}, _TRACK]},
                        },
                    },
                ]
            },
        }
    if isinstance(spec, P.RealOrAuto):
        return {"oneOf": [{"const": "auto"}, _number(spec), _TRACK]}
    if isinstance(spec, P.Real):
        return {"oneOf": [_number(spec), _TRACK]}
    if isinstance(spec, P.Integer):
        out: dict[str, Any] = {"type": "integer"}
        if spec.ge is not None:
            out["minimum"] = spec.ge
        if spec.le is not None:
            out["maximum"] = spec.le
        return out
    if isinstance(spec, P.Flag):
        return {"type": "boolean"}
    if isinstance(spec, P.Choice):
        return {"enum": list(spec.choices)}
    if isinstance(spec, P.Text):
        return {"type": "string", "minLength": 1, "maxLength": spec.max_length}
    if isinstance(spec, P.Point):
        return {"$ref": "#/$defs/point"}
    if isinstance(spec, P.Points):
        out = {
            "type": "array",
            "items": {"$ref": "#/$defs/point"},
            "minItems": spec.n or spec.n_min,
        }
        if spec.n is not None:
            out["maxItems"] = spec.n
        return out
    if isinstance(spec, P.Matrix):
        return {"type": "array", "items": {"$ref": "#/$defs/complex"}, "minItems": 4, "maxItems": 4}
    raise TypeError(f"no schema for {type(spec).__name__}")  # pragma: no cover


def json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of recipe format version 1."""
    number_or_track = {"oneOf": [{"type": "number"}, _TRACK]}
    steps = []
    for name, effect in EFFECTS.items():
        body = {
            "type": "object",
            "description": effect.summary,
            "properties": {k: spec_schema(s) for k, s in effect.params.items()},
            "additionalProperties": False,
        }
        required = [k for k, s in effect.params.items() if s.required]
        if required:
            body["required"] = required
        steps.append(
            {
                "type": "object",
                "properties": {name: body},
                "required": [name],
                "additionalProperties": False,
            }
        )
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://spherewarp.invalid/recipe.schema.json",
        "title": "spherewarp recipe",
        "type": "object",
        "required": ["spherewarp", "steps"],
        "additionalProperties": False,
        "properties": {
            "spherewarp": {"const": FORMAT_VERSION},
            "inputs": {"type": "array", "items": {"type": "string"}},
            "duration": {"type": "number", "exclusiveMinimum": 0, "maximum": 86400},
            "loop": {"type": "boolean"},
            "steps": {"type": "array", "items": {"$ref": "#/$defs/step"}},
            "view": {
                "type": "object",
                "additionalProperties": False,
                "properties": {
                    "size": {
                        "type": "array",
                        "items": {"type": "integer", "minimum": 1},
                        "minItems": 2,
                        "maxItems": 2,
                    },
                    "projection": {"enum": list(GRIDS)},
                    "look_at": {"$ref": "#/$defs/point"},
                    "roll": {"type": "number", "minimum": -360, "maximum": 360},
                    "fov": {"type": "number", "exclusiveMinimum": 0, "maximum": 360},
                },
            },
            "options": {
                "type": "object",
                "additionalProperties": False,
                "properties": {
                    "interp": {"enum": ["bilinear", "bicubic", "nearest"]},
                    "supersample": {"type": "integer", "minimum": 1, "maximum": 16},
                    "antialias": {
                        "oneOf": [
                            {"enum": ["auto", "area", "adaptive", "none"]},
                            {"type": "integer", "minimum": 1, "maximum": 16},
                        ]
                    },
                    "background": {"type": ["string", "null"]},
                    "tonemap": {"enum": ["aces", "reinhard", "clip"]},
                    "exposure": {"type": "number", "minimum": -20, "maximum": 20},
                },
            },
        },
        "$defs": {
            "step": {"oneOf": steps},
            "disk": _DISK,
            "track": {
                "type": "object",
                "required": ["keyframes"],
                "additionalProperties": False,
                "properties": {
                    "keyframes": {
                        "type": "array",
                        "minItems": 1,
                        "items": {
                            "type": "array",
                            "prefixItems": [
                                {"type": "number"},
                                {"oneOf": [{"type": "number"}, {"$ref": "#/$defs/plainpoint"}]},
                            ],
                            "minItems": 2,
                            "maxItems": 2,
                        },
                    },
                    "easing": {"enum": list(EASINGS)},
                },
            },
            "plainpoint": {
                "type": "array",
                "prefixItems": [
                    {"type": "number"},
                    {"type": "number", "minimum": -90, "maximum": 90},
                ],
                "minItems": 2,
                "maxItems": 2,
            },
            "point": {
                "oneOf": [
                    {
                        "type": "array",
                        "prefixItems": [
                            number_or_track,
                            {"oneOf": [{"type": "number", "minimum": -90, "maximum": 90}, _TRACK]},
                        ],
                        "minItems": 2,
                        "maxItems": 2,
                    },
                    _TRACK,
                ]
            },
            "complex": {
                "oneOf": [
                    {"type": "number"},
                    _TRACK,
                    {"type": "array", "items": number_or_track, "minItems": 2, "maxItems": 2},
                ]
            },
        },
    }


def schema_text() -> str:
    """The schema as the shipped file holds it."""
    return json.dumps(json_schema(), indent=2, ensure_ascii=False) + "\n"


if __name__ == "__main__":  # pragma: no cover
    print(schema_text(), end="")
