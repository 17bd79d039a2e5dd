"""Expression maps: the safe parser, agreement with the built-in maps, charts, infinity."""

from __future__ import annotations

import builtins
import json

import numpy as np
import pytest

import tolerances
from spherewarp import coords
from spherewarp.errors import InvalidTypeError, InvalidValueError
from spherewarp.maps import (
    ExpMap,
    ExpressionMap,
    FunctionMap,
    Mobius,
    Power,
    SphereMap,
    map_from_dict,
    map_from_json,
)
from spherewarp.maps.expression import MAX_DEPTH, MAX_LENGTH
from spherewarp.render import warp

INF = complex("inf")


def chordal(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    p, q = coords.normalize_cp1(p), coords.normalize_cp1(q)
    return np.abs(p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0])


@pytest.fixture(scope="module")
def points() -> np.ndarray:
    gen = np.random.default_rng(11)
    xyz = gen.normal(size=(2000, 3))
    xyz /= np.linalg.norm(xyz, axis=1, keepdims=True)
    return coords.cp1_from_xyz(xyz)


# ------------------------------------------------------------------ agreement with built-ins


@pytest.mark.parametrize(
    "expr, builtin",
    [
        ("z**2", Power(2)),
        ("z*z*z", Power(3)),
        ("z**5", Power(5)),
        ("1/z", Power(-1)),
        ("z**-2", Power(-2)),
        ("sqrt(z)", Power(0.5, cut=0)),
        ("z**0.5", Power(0.5, cut=0)),
        ("-exp(-4*(1+z)/(1-z))", ExpMap(4)),
        ("(2*z + 1j)/(3 - 1j*z)", Mobius([[2, 1j], [-1j, 3]])),
    ],
)
def test_agrees_with_builtin_maps(points, expr, builtin):
    z = coords.plane_from_cp1(points)
    keep = np.abs(z - 1) > 1e-2  # away from the exp variant's singularity
    if "sqrt" in expr or "0.5" in expr:
        keep &= np.abs(np.angle(z) - np.pi) > 1e-6  # and from the root's cut
    m = ExpressionMap(expr)
    err = chordal(m.pull_cp1(points[keep]), builtin.pull_cp1(points[keep]))
    assert err.max() < 1e-13


def test_agreement_on_rendered_images(random_image):
    img = random_image(32)
    a = warp(img, ExpressionMap("z**2")).astype(int)
    b = warp(img, Power(2)).astype(int)
    assert np.abs(a - b).max() <= tolerances.rounding(img.dtype)


def test_local_scale_is_exact_for_holomorphic_expressions(points):
    for expr, builtin in [
        ("z**2", Power(2)),
        ("z**-3", Power(-3)),
        ("-exp(-3*(1+z)/(1-z))", ExpMap(3)),
    ]:
        a, b = ExpressionMap(expr).local_scale(points), builtin.local_scale(points)
        ok = b < 1e6
        assert np.allclose(a[ok], b[ok], rtol=1e-9, atol=1e-300)
    for expr in ["z**3 + 0.5*z", "sin(z)/(z+2)", "tanh(z) * exp(z/3)", "log(z + 3)", "sqrt(z+2j)"]:
        m = ExpressionMap(expr, chart="front")
        exact, fd = m.local_scale(points), SphereMap.local_scale(m, points)
        ok = (exact > 1e-3) & (exact < 1e3)
        assert np.allclose(exact[ok], fd[ok], rtol=1e-4), expr


def test_non_holomorphic_expressions_use_finite_differences(points):
    m = ExpressionMap("conj(z)")
    assert np.allclose(m.local_scale(points), 1.0, rtol=1e-6)  # a reflection: an isometry
    assert np.all(np.isfinite(ExpressionMap("abs(z) + z").local_scale(points)))


# ------------------------------------------------------------------ infinity, overflow, charts


def test_values_at_infinity():
    assert ExpressionMap("z**2")(INF) == INF
    assert ExpressionMap("1/z")(INF) == 0
    assert ExpressionMap("(z - 1)/(z + 1)")(INF) == 1
    assert ExpressionMap("z**3 + 0.5*z")(np.array([0, INF])).tolist() == [0, INF]


@pytest.mark.parametrize(
    "expr", ["exp(z)", "exp(z**3)", "log(z)", "1/(z - z)", "z/z", "tan(z)**9", "exp(exp(z))"]
)
def test_overflow_and_nan_become_points(points, expr):
    m = ExpressionMap(expr)
    special = coords.cp1_from_plane(np.array([0, 1, -1, 1j, INF, 1e300, 1e-300]))
    for zw in (points, special):
        out = m.pull_cp1(zw)
        assert np.all(np.isfinite(out))
        assert np.allclose(np.linalg.norm(out, axis=-1), 1.0)
        assert np.all(np.isfinite(m.local_scale(zw)))
    assert ExpressionMap("1/(z - z)")(0.5) == INF


def test_front_chart():
    # 0 at the front, infinity at the back, 1 on the right (lon 90), i up (the zenith)
    ident = ExpressionMap("z", chart="front")
    ll = np.array([[10.0, 20.0], [-100.0, -30.0]])
    assert np.allclose(ident.apply_lonlat(ll), ll)
    turn = ExpressionMap("1j*z", chart="front")  # a quarter turn about the front: right -> up
    assert np.allclose(turn.apply_lonlat([[10.0, 0.0]]), [[0.0, 10.0]], atol=1e-9)
    sq = ExpressionMap("z**2", chart="front")
    assert np.allclose(sq.apply_lonlat([[0.0, 0.0], [180.0, 0.0]]), [[0.0, 0.0], [180.0, 0.0]])
    custom = ExpressionMap("z**2", chart=sq.chart)
    assert custom.to_dict()["chart"]["matrix"]


def test_unknown_chart():
    with pytest.raises(InvalidValueError, match="zenith, front"):
        ExpressionMap("z", chart="back")
    with pytest.raises(InvalidTypeError):
        ExpressionMap("z", chart=3)


# ------------------------------------------------------------------ the parser


@pytest.mark.parametrize(
    "text, same",
    [
        ("2i*z", "2j*z"),
        ("0.5i + z", "0.5j + z"),
        ("i*z", "1j*z"),
        ("j*z", "1j*z"),
        ("exp(i*pi)*z", "-z"),
        ("e**z", "exp(z)"),
        ("  z ** 2 ", "z**2"),
        ("+z", "z"),
        ("((z))", "z"),
    ],
)
def test_accepted_spellings(points, text, same):
    a, b = ExpressionMap(text), ExpressionMap(same)
    assert chordal(a.pull_cp1(points), b.pull_cp1(points)).max() < 1e-13


@pytest.mark.parametrize(
    "text, message, column",
    [
        ("__import__('os')", "unknown function '__import__'", 1),
        ("__import__('os').system('ls')", "attribute access ('.system')", 17),
        ("z.real", "attribute access ('.real')", 2),
        ("z.__class__", "attribute access", 2),
        ("().__class__.__bases__", "attribute access", None),
        ("lambda z: z", "a lambda", 1),
        ("open('x')", "unknown function 'open'", 1),
        ("getattr(z, 'real')", "unknown function 'getattr'", 1),
        ("z if z else 1", "'if'/'else'", 1),
        ("[z]", "a list", 1),
        ("z[0]", "indexing", 1),
        ("'a'", "is not a number", 1),
        ("x + 1", "unknown name 'x'", 1),
        ("z + exp", "function 'exp' without an argument", 5),
        ("z^2", "'^' (use ** for powers)", 2),
        ("z // 2", "'//'", 3),
        ("z @ z", "'@'", 3),
        ("~z", "'~'", 1),
        ("not z", "'not'", 1),
        ("z < 1", "a comparison", 1),
        ("exp(z, 1)", "exactly one argument", 1),
        ("exp(z=1)", "exactly one argument", 1),
        ("exp(*z)", "exactly one argument", 1),
        ("1e999 * z", "number too large", 1),
        ("True", "is not a number", 1),
        ("None", "is not a number", 1),
        ("z +* 2", "invalid syntax", 4),
        ("(z", "never closed", 1),
        ("z = 1", "invalid syntax", None),
        ("f'{z}'", "f-string", 1),
    ],
)
def test_refused_with_a_one_line_message(text, message, column):
    with pytest.raises(InvalidValueError) as info:
        ExpressionMap(text)
    msg = str(info.value)
    assert message in msg
    assert "\n" not in msg
    if column is not None:
        assert f"column {column}" in msg


def test_limits():
    ExpressionMap("+".join(["z"] * 40))  # long but fine
    with pytest.raises(InvalidValueError, match=f"at most {MAX_LENGTH}"):
        ExpressionMap("z" + "+z" * MAX_LENGTH)
    with pytest.raises(InvalidValueError, match=f"at most {MAX_DEPTH}"):
        ExpressionMap("exp(" * 60 + "z" + ")" * 60)
    with pytest.raises(InvalidValueError, match="nested too deeply"):
        ExpressionMap("-" * 120 + "z")
    with pytest.raises(InvalidValueError, match="nested too deeply"):
        ExpressionMap("**".join(["z"] * 80))
    with pytest.raises(InvalidValueError, match="empty"):
        ExpressionMap("   ")
    with pytest.raises(InvalidValueError, match="single line"):
        ExpressionMap("z\n+1")
    with pytest.raises(InvalidTypeError):
        ExpressionMap(2)  # type: ignore[arg-type]


def test_huge_powers_do_not_hang():
    m = ExpressionMap("2**2**2**2**2**2 * z")  # never evaluated with Python integers
    assert m(0.5) == INF


def test_no_python_eval(monkeypatch, points):
    import ast

    real_compile = builtins.compile

    def refuse(*args, **kwargs):
        raise AssertionError("eval/exec must not be used")

    def ast_only(source, filename, mode, flags=0, *args, **kwargs):
        assert flags & ast.PyCF_ONLY_AST, "only parsing to an AST is allowed"
        return real_compile(source, filename, mode, flags, *args, **kwargs)

    monkeypatch.setattr(builtins, "eval", refuse)
    monkeypatch.setattr(builtins, "exec", refuse)
    monkeypatch.setattr(builtins, "compile", ast_only)
    m = ExpressionMap("sin(z)**2 + 0.5*z")
    assert np.all(np.isfinite(m.pull_cp1(points)))


# ------------------------------------------------------------------ plain data, callables


def test_round_trip(points):
    for m in (ExpressionMap("z**2 + 1j"), ExpressionMap("exp(z)", chart="front")):
        back = map_from_json(m.to_json())
        assert back == m
        assert chordal(back.pull_cp1(points), m.pull_cp1(points)).max() < 1e-15
    m = ExpressionMap("z**2", chart=Mobius.rotation((10, 20), 30))
    assert map_from_dict(json.loads(m.to_json())) == m
    assert repr(ExpressionMap("z**2")) == "ExpressionMap('z**2', chart='zenith')"


def test_function_map(points):
    m = FunctionMap(lambda z: z**2)
    assert chordal(m.pull_cp1(points), Power(2).pull_cp1(points)).max() < 1e-13
    assert "FunctionMap" in repr(m) and "function" in repr(m @ Power(2))
    with pytest.raises(InvalidValueError, match="cannot be rebuilt"):
        map_from_json(m.to_json())
    with pytest.raises(InvalidTypeError, match="callable"):
        FunctionMap("z**2")  # type: ignore[arg-type]
    const = FunctionMap(lambda z: 2.0)
    assert np.allclose(const(np.array([0, 1j, INF])), 2.0)
