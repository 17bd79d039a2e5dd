"""The recipe library: format, tracks, composition, validation."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from spherewarp import warp
from spherewarp.maps import Mobius
from spherewarp.recipe import EASINGS, EFFECTS, Recipe, RecipeError, Track


def recipe(*steps, **top):
    return Recipe.from_dict({"spherewarp": 1, "steps": list(steps), **top})


def image(h=32, w=64, seed=0):
    return np.random.default_rng(seed).integers(0, 256, (h, w, 3), dtype=np.uint8)


# -- steps build the commands' maps ------------------------------------------------------------
def test_rotate_forms():
    ypr = recipe({"rotate": {"yaw": 30, "pitch": -10, "roll": 5}}).map_at()
    assert ypr == Mobius.from_yaw_pitch_roll(30, -10, 5)
    axis = recipe({"rotate": {"axis": [-163, 5], "angle": 45}}).map_at()
    assert axis == Mobius.rotation((-163, 5), 45).inverse()


def test_zoom_and_center():
    z = recipe({"zoom": {"at": [10, 20], "factor": 3}}).map_at()
    assert z == Mobius.zoom((10, 20), 3).inverse()
    zc = recipe({"zoom": {"at": [10, 20], "factor": 3, "center": True}}).map_at()
    assert zc == (Mobius.rotation_to((10, 20), (0, 0)) @ Mobius.zoom((10, 20), 3)).inverse()


def test_mobius_matrix_and_points():
    m = recipe({"mobius": {"matrix": [1, [0.5, 0], 0, 1]}}).map_at()
    assert m == Mobius([[1, 0.5], [0, 1]]).inverse()
    pts = {"from": [[0, 0], [90, 0], [0, 90]], "to": [[0, 0], [60, 0], [0, 60]]}
    m = recipe({"mobius": pts}).map_at()
    fwd = Mobius.from_points([(0, 0), (90, 0), (0, 90)], [(0, 0), (60, 0), (0, 60)])
    assert m == fwd.inverse()


def test_branched_steps_with_look_at():
    from spherewarp.maps import ExpMap, ExpressionMap, Power

    view = Mobius.from_yaw_pitch_roll(yaw=0, pitch=90)
    assert recipe({"power": {"n": 3, "look_at": [0, 90]}}).map_at() == Power(3) @ view
    assert recipe({"exp": {"lam": 2}}).map_at() == ExpMap(2)
    assert recipe({"map": {"expr": "z**2"}}).map_at() == ExpressionMap("z**2")


def test_lattes_and_droste_steps():
    from spherewarp.effects import droste as dr
    from spherewarp.maps import Lattes

    assert recipe({"lattes": {"alpha": "1+1j"}}).map_at() == Lattes("1+1j", "square")
    d = recipe({"droste": {"center": [0, 0], "inner_radius": 20, "scale": 4}}).map_at()
    assert d == dr.droste_map(dr.hole_from_radius((0, 0), 20), 4.0)


def test_droste_log_view_height_is_checked_at_load():
    """A log view's height out of log_view's bounds is refused when the recipe is read,
    naming view.size (a command's --size), not at render time as a bare 'height'."""
    from spherewarp.recipe import Recipe, RecipeError

    step = {"droste": {"center": [0, 0], "inner_radius": 20, "scale": 4, "view": "log"}}
    with pytest.raises(RecipeError) as info:
        Recipe.from_dict({"spherewarp": 1, "steps": [step], "view": {"size": [100, 1]}})
    assert str(info.value) == "view.size: a Droste log view is 8 to 16384 pixels high, got 1"
    assert info.value.cli_detail.startswith("--size: ")
    Recipe.from_dict({"spherewarp": 1, "steps": [step], "view": {"size": [100, 8]}})


def test_steps_compose_in_order():
    r = recipe({"rotate": {"yaw": 30}}, {"zoom": {"at": [0, 0], "factor": 2}})
    first = Mobius.from_yaw_pitch_roll(30, 0, 0)
    second = Mobius.zoom((0, 0), 2).inverse()
    assert r.map_at() == first @ second
    # applying the steps one after the other gives the same image (up to resampling)
    yy, xx = np.mgrid[0:64, 0:128]
    img = (128 + 100 * np.sin(xx * 2 * np.pi / 128) * np.cos(yy * np.pi / 64)).astype(np.float32)
    once = r.render(img, antialias="none")
    twice = warp(warp(img, first, antialias="none"), second, antialias="none")
    assert np.median(np.abs(once - twice)) < 1


def test_exp_step_supersamples_as_the_command():
    assert recipe({"exp": {}}).at().warp_kwargs["supersample"] == 3
    r = recipe({"exp": {}}, options={"supersample": 1})
    assert r.at().warp_kwargs["supersample"] == 1
    r = recipe({"exp": {}}, options={"antialias": "none"})  # the filter chosen: no default
    assert r.at().warp_kwargs["supersample"] == 1 and r.at().warp_kwargs["antialias"] == "none"


def test_options_and_view_reach_warp():
    r = recipe(
        {"rotate": {"yaw": 10}},
        options={"interp": "bicubic", "antialias": "area", "background": "white"},
        view={"size": [40, 20]},
    )
    f = r.at()
    assert f.warp_kwargs["interp"] == "bicubic" and f.warp_kwargs["antialias"] == "area"
    assert f.background == "white"
    assert r.render(image()).shape == (20, 40, 3)


def test_round_trip(tmp_path):
    data = {
        "spherewarp": 1,
        "duration": 2,
        "steps": [{"zoom": {"at": [0, 0], "factor": {"keyframes": [[0, 1], [2, 4]]}}}],
    }
    r = Recipe.from_dict(data)
    assert Recipe.loads(r.dumps()).to_dict() == data
    p = r.save(tmp_path / "r.json")
    assert Recipe.load(p).to_dict() == data
    with pytest.raises(FileExistsError):
        r.save(p)


# -- time --------------------------------------------------------------------------------------
def test_linear_zoom_track_at_half_way_is_the_plain_zoom():
    track = {"keyframes": [[0, 1], [2, 4]], "easing": "linear"}
    r = recipe({"zoom": {"at": [30, 10], "factor": track}}, duration=2)
    plain = recipe({"zoom": {"at": [30, 10], "factor": 2.5}})
    assert r.map_at(1.0) == plain.map_at()
    img = image()
    assert np.array_equal(r.render(img, t=1.0), plain.render(img))


@pytest.mark.parametrize("easing", sorted(EASINGS))
def test_easing_curves(easing):
    tr = Track([(0.0, 1.0), (1.0, 3.0)], easing)
    us = np.linspace(0, 1, 101)
    vals = np.array([tr(u) for u in us])
    assert vals[0] == 1.0 and (easing == "hold" or vals[-1] == 3.0)
    if easing != "hold":
        assert np.all(np.diff(vals) >= -1e-12)  # monotone between keyframes
    expected = {
        "linear": 1 + 2 * us,
        "hold": np.where(us < 1, 1.0, 3.0),
        "ease-in": 1 + 2 * us**3,
        "ease-out": 1 + 2 * (1 - (1 - us) ** 3),
        "ease-in-out": 1 + 2 * np.where(us < 0.5, 4 * us**3, 1 - (2 - 2 * us) ** 3 / 2),
        "smoothstep": 1 + 2 * (3 * us**2 - 2 * us**3),
        "geometric": 3.0**us,
    }[easing]
    np.testing.assert_allclose(vals, expected, rtol=1e-12)


def test_ease_in_out_is_slow_at_the_ends_and_symmetric():
    tr = Track([(0.0, 0.0), (1.0, 1.0)], "ease-in-out")
    assert tr(0.5) == pytest.approx(0.5)
    assert tr(0.1) < 0.1 * 0.1 and tr(0.9) > 1 - 0.1 * 0.1
    for u in (0.1, 0.2, 0.3, 0.4):
        assert tr(u) + tr(1 - u) == pytest.approx(1.0)


def test_track_holds_outside_its_keyframes_and_tracks_points():
    tr = Track([(1.0, (0.0, 0.0)), (3.0, (20.0, 10.0))])
    assert tr(0.0) == (0.0, 0.0) and tr(9.0) == (20.0, 10.0) and tr(2.0) == (10.0, 5.0)
    r = recipe({"zoom": {"at": {"keyframes": [[0, [0, 0]], [2, [20, 10]]]}, "factor": 2}})
    assert r.step_values(0, 1.0)["at"] == (10.0, 5.0)
    r = recipe({"zoom": {"at": [{"keyframes": [[0, 0], [2, 20]]}, 5], "factor": 2}})
    assert r.step_values(0, 1.0)["at"] == (10.0, 5.0)


def test_spin_turns_by_the_same_angle_between_every_pair_of_frames():
    spin = {"keyframes": [[0, 0], [10, 360]]}
    r = recipe({"rotate": {"axis": [20, 30], "angle": spin}}, duration=10)
    times = r.frame_times(24)
    assert len(times) == 241
    steps = []
    for t0, t1 in zip(times[:-1], times[1:], strict=True):
        d = r.map_at(t1).inverse() @ r.map_at(t0)  # turn from one frame to the next
        assert d.is_rotation()
        steps.append(d)
    for d in steps[1:]:
        assert np.allclose(d.matrix / d.matrix[0, 0], steps[0].matrix / steps[0].matrix[0, 0])
    # 360 degrees in 10 s: 1.5 degrees a frame
    rot = steps[0].to_rotation_matrix()
    assert math.degrees(math.acos((np.trace(rot) - 1) / 2)) == pytest.approx(1.5)


def test_geometric_zoom_flies_at_constant_speed():
    track = {"keyframes": [[0, 1], [2, 16]], "easing": "geometric"}
    r = recipe({"zoom": {"at": [0, 0], "factor": track}}, duration=2)
    times = r.frame_times(10)
    ratios = [
        r.map_at(t1).inverse() @ r.map_at(t0) for t0, t1 in zip(times[:-1], times[1:], strict=True)
    ]
    base = Mobius.zoom((0, 0), 16 ** (1 / 20))
    for m in ratios:
        assert m == base or np.allclose(m.matrix / m.matrix[0, 0], base.matrix / base.matrix[0, 0])


def test_droste_loop_last_frame_flows_into_the_first():
    phase = {"keyframes": [[0, 0], [2, 1]]}
    step = {"droste": {"center": [0, 0], "inner_radius": 20, "scale": 4, "phase": phase}}
    r = recipe(step, duration=2, loop=True)
    times = r.frame_times(12)
    assert len(times) == 24 and times[-1] < 2
    after_last = times[-1] + 1 / 12
    assert (
        r.map_at(after_last) == r.map_at(0.0) or r.map_at(after_last).params == r.map_at(0.0).params
    )
    img = image(64, 128)
    a = r.render(img, t=after_last, antialias="none")
    b = r.render(img, t=0.0, antialias="none")
    assert np.abs(a.astype(int) - b.astype(int)).max() <= 1


def test_a_still_is_not_animated():
    assert not recipe({"rotate": {"yaw": 3}}).animated
    assert recipe({"rotate": {"yaw": {"keyframes": [[0, 0], [1, 3]]}}}).animated


def test_every_effect_has_typed_parameters():
    for name, effect in EFFECTS.items():
        assert effect.params, name
        for pname, spec in effect.params.items():
            assert spec.expected, (name, pname)


# -- validation --------------------------------------------------------------------------------
def steps(text):
    return '{"spherewarp": 1, "steps": [' + text + "]}"


def factor(text):
    return steps('{"zoom": {"at": [0, 0], "factor": ' + text + "}}")


BAD = [
    ("[1, 2]", "expected a JSON object"),
    ('{"steps": []}', "spherewarp: missing"),
    ('{"spherewarp": 2, "steps": []}', "spherewarp: format version 2 is newer"),
    ('{"spherewarp": "1", "steps": []}', "spherewarp: expected the format version 1"),
    ('{"spherewarp": 1}', "steps: expected a list of steps"),
    ('{"spherewarp": 1, "steps": [], "stesp": 1}', "stesp: unknown field"),
    (
        steps('{"zooom": {}}'),
        "steps[0]: unknown effect 'zooom' (did you mean 'zoom'?)",
    ),
    (
        steps('{"rotate": {"yaw": 1}}, {"zoom": {"at": [0, 0], "factor": -1}}'),
        "steps[1].zoom.factor: expected a number >= 1e-09 and <= 1e+09, got -1",
    ),
    (
        steps('{"zoom": {"at": [0, 0], "factr": 2}}'),
        "steps[0].zoom.factr: unknown parameter of zoom (did you mean 'factor'?)",
    ),
    (steps('{"zoom": {"at": [0, 0]}}'), "steps[0].zoom.factor: missing"),
    (
        factor('"2"'),
        "steps[0].zoom.factor: expected a number",
    ),
    (
        factor("NaN"),
        "expected finite numbers, got NaN",
    ),
    (factor("Infinity"), "got Infinity"),
    (
        steps('{"zoom": {"at": [0, 95], "factor": 2}}'),
        "steps[0].zoom.at[1]: expected a number >= -90 and <= 90, got 95",
    ),
    (
        factor('{"keyframes": [[1, 2], [0, 3]]}'),
        "steps[0].zoom.factor.keyframes[1][0]: keyframes out of order",
    ),
    (
        factor('{"keyframes": [[0, 2]], "easing": "ease"}'),
        "steps[0].zoom.factor.easing: expected one of",
    ),
    (
        steps('{"rotate": {"yaw": 1, "axis": [0, 0], "angle": 3}}'),
        "steps[0].rotate: expected yaw/pitch/roll or axis/angle, got both",
    ),
    (steps('{"rotate": {"axis": [0, 0]}}'), "'angle' is missing"),
    (steps('{"rotate": {}}'), "got neither"),
    (steps('{"power": {"n": 0}}'), "steps[0].power:"),
    (steps('{"map": {"expr": "__import__(\'os\')"}}'), "steps[0].map:"),
    (
        steps('{"rotate": {"yaw": 1}, "zoom": {}}'),
        "steps[0]: expected one effect",
    ),
    ('{"spherewarp": 1, "steps": [], "loop": true}', "loop: a loop needs a 'duration'"),
    (
        '{"spherewarp": 1, "steps": [], "options": {"interp": "cubic"}}',
        "options.interp: expected one of",
    ),
    (
        '{"spherewarp": 1, "steps": [], "view": {"sise": [2, 1]}}',
        "view.sise: unknown field (did you mean 'size'?)",
    ),
    ('{"spherewarp": 1, "spherewarp": 1, "steps": []}', "spherewarp: given twice"),
    ('{"spherewarp": 1, "steps": [', "not JSON"),
    ("[" * 100000 + "]" * 100000, "nested at most 32 deep"),
    ("[" * 40 + "]" * 40, "nested at most 32 deep"),
    (" " * 2_000_000, "at most 1000000 bytes"),
    (
        factor('{"keyframes": [[0, {"keyframes": []}]]}'),
        "a track inside a track",
    ),
    (
        factor('{"keyframes": [[0, 0.5], [1, 2]], "easing": "geometric", "x": 1}'),
        "factor.x: unknown track field",
    ),
    (steps('{"mobius": {"matrix": [1, 2, 2, 4]}}'), "steps[0].mobius:"),
]


@pytest.mark.parametrize("text, message", BAD, ids=[str(k) for k in range(len(BAD))])
def test_bad_recipes_name_the_field(text, message):
    with pytest.raises(RecipeError) as info:
        Recipe.loads(text)
    assert message in str(info.value)
    assert "\n" not in str(info.value)


def test_error_is_the_project_value_error():
    from spherewarp.errors import InvalidValueError

    assert issubclass(RecipeError, InvalidValueError) and issubclass(RecipeError, ValueError)


def test_python_data_is_checked_too():
    with pytest.raises(RecipeError, match="finite"):
        Recipe.from_dict({"spherewarp": 1, "steps": [{"rotate": {"yaw": float("nan")}}]})
    deep: list = []
    for _ in range(50):
        deep = [deep]
    with pytest.raises(RecipeError, match="nested"):
        Recipe.from_dict({"spherewarp": 1, "steps": deep})


def test_large_file_refused_before_reading(tmp_path):
    p = tmp_path / "big.json"
    with p.open("wb") as fh:
        fh.truncate(50 * 1024 * 1024)
    with pytest.raises(RecipeError, match="at most 1000000 bytes"):
        Recipe.load(p)


def test_schema_file_is_shipped_and_describes_every_effect():
    from importlib import resources

    schema = json.loads(
        resources.files("spherewarp.recipe").joinpath("recipe.schema.json").read_text()
    )
    assert schema["$schema"].startswith("https://json-schema.org/")
    assert set(schema["required"]) == {"spherewarp", "steps"}
    effects = schema["$defs"]["step"]["oneOf"]
    names = {next(iter(e["properties"])) for e in effects}
    assert names == set(EFFECTS)
    for e in effects:
        ((name, body),) = e["properties"].items()
        assert set(body["properties"]) == set(EFFECTS[name].params), name
        assert body["additionalProperties"] is False


def test_shipped_schema_is_the_generated_one():
    from importlib import resources

    from spherewarp.recipe.schema import schema_text

    shipped = resources.files("spherewarp.recipe").joinpath("recipe.schema.json")
    assert shipped.read_text(encoding="utf-8") == schema_text()


def _check(schema, value, root):
    """A small JSON Schema checker for the keywords the recipe schema uses."""
    if "$ref" in schema:
        return _check(root["$defs"][schema["$ref"].rsplit("/", 1)[1]], value, root)
    if "oneOf" in schema:
        return sum(_check(s, value, root) for s in schema["oneOf"]) == 1
    if "const" in schema and value != schema["const"]:
        return False
    if "enum" in schema and value not in schema["enum"]:
        return False
    types = schema.get("type")
    if types is not None:
        types = [types] if isinstance(types, str) else types
        kinds = {
            "number": isinstance(value, (int, float)) and not isinstance(value, bool),
            "integer": isinstance(value, int) and not isinstance(value, bool),
            "string": isinstance(value, str),
            "boolean": isinstance(value, bool),
            "array": isinstance(value, list),
            "object": isinstance(value, dict),
            "null": value is None,
        }
        if not any(kinds[t] for t in types):
            return False
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        if "minimum" in schema and value < schema["minimum"]:
            return False
        if "maximum" in schema and value > schema["maximum"]:
            return False
        if "exclusiveMinimum" in schema and value <= schema["exclusiveMinimum"]:
            return False
        if "exclusiveMaximum" in schema and value >= schema["exclusiveMaximum"]:
            return False
    if isinstance(value, str) and not (
        schema.get("minLength", 0) <= len(value) <= schema.get("maxLength", 1 << 60)
    ):
        return False
    if isinstance(value, list):
        if not schema.get("minItems", 0) <= len(value) <= schema.get("maxItems", 1 << 60):
            return False
        prefix = schema.get("prefixItems", [])
        for k, v in enumerate(value):
            s = prefix[k] if k < len(prefix) else schema.get("items")
            if s is not None and not _check(s, v, root):
                return False
    if isinstance(value, dict):
        props = schema.get("properties", {})
        if any(k not in value for k in schema.get("required", [])):
            return False
        for k, v in value.items():
            if k in props:
                if not _check(props[k], v, root):
                    return False
            elif schema.get("additionalProperties", True) is False:
                return False
    return True


GOOD = [
    {"spherewarp": 1, "steps": []},
    {"spherewarp": 1, "steps": [{"rotate": {"yaw": 30, "pitch": -10}}]},
    {"spherewarp": 1, "steps": [{"rotate": {"axis": [-163, 5], "angle": 45}}]},
    {
        "spherewarp": 1,
        "duration": 2,
        "inputs": ["room.jpg"],
        "steps": [
            {"rotate": {"yaw": {"keyframes": [[0, 0], [2, 90]], "easing": "ease-in-out"}}},
            {"zoom": {"at": [{"keyframes": [[0, 0], [2, 30]]}, 5], "factor": 3, "center": True}},
        ],
        "view": {"size": [256, 128]},
        "options": {"interp": "bicubic", "antialias": 4, "background": "white"},
    },
    {"spherewarp": 1, "steps": [{"mobius": {"matrix": [1, [0.5, 0.5], 0, 1]}}]},
    {
        "spherewarp": 1,
        "steps": [
            {"mobius": {"from": [[0, 0], [90, 0], [0, 90]], "to": [[0, 0], [60, 0], [0, 60]]}}
        ],
    },
    {"spherewarp": 1, "steps": [{"power": {"n": 3, "branch_points": [[0, 0], [180, 0]]}}]},
    {"spherewarp": 1, "steps": [{"exp": {"lam": 2, "look_at": [180, 0]}}]},
    {"spherewarp": 1, "steps": [{"map": {"expr": "z**2", "chart": "front"}}]},
    {"spherewarp": 1, "steps": [{"lattes": {"alpha": "1+w", "lattice": "hex"}}]},
    {
        "spherewarp": 1,
        "duration": 2,
        "loop": True,
        "steps": [
            {
                "droste": {
                    "center": [0, 0],
                    "inner_radius": 20,
                    "scale": 4,
                    "phase": {"keyframes": [[0, 0], [2, 1]]},
                }
            }
        ],
    },
]


@pytest.mark.parametrize("data", GOOD, ids=[str(k) for k in range(len(GOOD))])
def test_good_recipes_validate_against_the_schema_and_the_library(data):
    from spherewarp.recipe.schema import json_schema

    schema = json_schema()
    assert _check(schema, data, schema)
    Recipe.from_dict(data)


@pytest.mark.parametrize(
    "data",
    [
        {"spherewarp": 2, "steps": []},
        {"spherewarp": 1},
        {"spherewarp": 1, "steps": [{"zooom": {}}]},
        {"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factor": -1}}]},
        {"spherewarp": 1, "steps": [{"zoom": {"at": [0, 0], "factr": 2}}]},
        {"spherewarp": 1, "steps": [{"zoom": {"at": [0, 95], "factor": 2}}]},
        {"spherewarp": 1, "steps": [], "extra": 1},
    ],
)
def test_bad_recipes_fail_the_schema_too(data):
    from spherewarp.recipe.schema import json_schema

    schema = json_schema()
    assert not _check(schema, data, schema)


def test_the_readme_recipe_is_valid():
    import re
    from pathlib import Path

    from spherewarp.recipe.schema import json_schema

    text = (Path(__file__).resolve().parents[2] / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```json\n(.*?)^```", text, re.MULTILINE | re.DOTALL)
    assert blocks
    schema = json_schema()
    assert len(blocks) >= 2
    for block in blocks:
        data = json.loads(block)
        assert _check(schema, data, schema)
        Recipe.from_dict(data)
    r = Recipe.from_dict(json.loads(blocks[0]))
    assert r.animated and r.duration == 4
    assert r.step_values(1, 4.0)["factor"] == pytest.approx(8.0)
    # the Schottky loop: every kind of field (a generator of each form, a phase track, the view)
    r = Recipe.from_dict(json.loads(blocks[1]))
    assert r.loop and r.step_values(0, 1.0)["phase"] == pytest.approx(0.5)
    data = json.loads(blocks[1])
    data["view"]["size"] = [32, 32]
    out = Recipe.from_dict(data).render(np.zeros((32, 64, 3), np.uint8), t=0.5)
    assert out.shape == (32, 32, 3)


def test_mobius_amount_moves_at_constant_speed_along_its_group():
    amount = {"keyframes": [[0, 0], [1, 1]]}
    m = [[1 + 1j, 0.3], [0.2, 1 - 0.5j]]
    step = {"mobius": {"matrix": [[1, 1], 0.3, 0.2, [1, -0.5]], "amount": amount}}
    r = recipe(step, duration=1)
    assert r.map_at(0.0).is_identity(1e-12)
    assert r.map_at(1.0) == Mobius(m).inverse()
    times = r.frame_times(10)
    steps = [
        r.map_at(b).inverse() @ r.map_at(a) for a, b in zip(times[:-1], times[1:], strict=True)
    ]
    tenth = Mobius(m) ** 0.1
    for s in steps:
        assert np.allclose(s.matrix / s.matrix[0, 0], tenth.matrix / tenth.matrix[0, 0])


def test_pose_follows_the_moebius_steps_only():
    r = recipe({"rotate": {"yaw": 30}}, {"zoom": {"at": [0, 0], "factor": 2}})
    assert r.at().pose == Mobius.from_yaw_pitch_roll(30, 0, 0).inverse()
    assert recipe({"power": {"n": 2}}).at().pose is None
    assert recipe({"rotate": {"yaw": 30}}, {"exp": {}}).at().pose is None


@pytest.mark.parametrize("t", [None, "1", 1j, True])
def test_a_time_that_is_not_a_number_is_a_recipe_error(t):
    r = Recipe.loads('{"spherewarp": 1, "steps": []}')
    with pytest.raises(RecipeError, match="time: expected a finite time"):
        r.at(t)
    assert r.at(np.float32(1.0)).map.is_identity()


def test_the_size_limit_counts_utf8_bytes():
    text = '{"spherewarp": 1, "steps": [], "inputs": ["' + "é" * 600_000 + '"]}'
    with pytest.raises(RecipeError, match="at most 1000000 bytes, got 12000[0-9][0-9] bytes"):
        Recipe.loads(text)


def test_a_mask_that_is_a_folder_is_not_said_to_be_missing(tmp_path):
    with pytest.raises(RecipeError, match="not a regular file"):
        Recipe.from_dict({"spherewarp": 1, "steps": [{"droste": {"mask": str(tmp_path)}}]})


def test_steps_fine_alone_but_out_of_range_together_are_named():
    steps = [{"zoom": {"at": [0, 0], "factor": 1e9}}, {"zoom": {"at": [10, 0], "factor": 1e9}}]
    with pytest.raises(RecipeError, match="steps: steps 0 to 1 together: .*singular"):
        Recipe.from_dict({"spherewarp": 1, "steps": steps})
