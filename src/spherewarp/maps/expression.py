"""Maps given by a formula in ``z``: safe expression maps and Python callables.

:class:`ExpressionMap` pulls back by a complex expression such as ``"z**2"``,
``"(z-1)/(z+1)"``, ``"exp(z)"`` or ``"z**3 + 0.5*z"``. The text is parsed
with :mod:`ast` and checked against a whitelist, then turned into a tree of
vectorised NumPy operations; nothing is ever passed to ``eval``. Allowed:

* numbers (``2``, ``0.5``, ``1e-3``, ``2j``, and ``2i`` meaning ``2j``),
* the names ``z``, ``i`` and ``j`` (the imaginary unit), ``pi`` and ``e``,
* ``+ - * / **`` and unary ``+ -``, parentheses,
* calls of ``exp log sqrt sin cos tan sinh cosh tanh abs conj`` with one
  argument (NumPy's principal branches: ``log`` and ``sqrt`` are cut along
  the negative real axis).

Anything else (attribute access, other names, lambdas, subscripts, strings,
keyword arguments, ``^``...) is refused with a one-line
:class:`~spherewarp.errors.InvalidValueError` naming the offending token and
its column. Expressions are limited to :data:`MAX_LENGTH` characters and
:data:`MAX_DEPTH` levels of nesting.

:class:`FunctionMap` does the same for any Python callable of complex arrays.

Convention: ``z`` is the coordinate of a chart of the Riemann sphere:
``"zenith"`` (the default chart of :mod:`spherewarp.coords`: 0 at the
zenith, infinity at the nadir, -1 at the front) or ``"front"`` (0 at the
front, infinity at the back, 1 at longitude 90 and i at the zenith), or any
:class:`~spherewarp.maps.Mobius` map into the chart. Results that overflow or
are NaN become the point at infinity; the point at infinity is fed to the
formula as ``1e100`` in its direction, and a result there beyond ``1e50``
(below ``1e-50``) is taken as infinity (0).

Examples
--------
>>> import numpy as np
>>> from spherewarp.maps import ExpressionMap, Power
>>> m = ExpressionMap("z**2")
>>> np.round(m([2j, np.inf]), 12)
array([-4.+0.j, inf+0.j])
>>> zw = coords.cp1_from_lonlat(np.radians([[10.0, 20.0], [-70.0, -5.0]]))
>>> bool(np.allclose(m.pull_cp1(zw), Power(2).pull_cp1(zw), rtol=0, atol=1e-15))
True
>>> ExpressionMap("z.real")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
spherewarp.errors.InvalidValueError: expression 'z.real': attribute access ('.real') at column 2 ...
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import coords
from ..errors import InvalidTypeError, InvalidValueError
from .base import SphereMap, register_map
from .mobius import Mobius

__all__ = ["CHARTS", "FUNCTIONS", "MAX_DEPTH", "MAX_LENGTH", "ExpressionMap", "FunctionMap"]

ComplexArray = NDArray[np.complex128]
FloatArray = NDArray[np.float64]

#: longest accepted expression, in characters
MAX_LENGTH = 500
#: deepest accepted nesting of operations
MAX_DEPTH = 50
#: the functions an expression may call
FUNCTIONS = ("exp", "log", "sqrt", "sin", "cos", "tan", "sinh", "cosh", "tanh", "abs", "conj")
#: the named charts
CHARTS = ("zenith", "front")

_NAMES = {"i": 1j, "j": 1j, "pi": math.pi, "e": math.e}
_BIG = 1e100  # stands in for the point at infinity
_SNAP = 1e50  # at infinity, results beyond this (or below its inverse) are taken as inf (or 0)

# A numeric literal directly followed by "i" (2i, 0.5i, 1e-3i) means the imaginary unit.
_IMAG_I = re.compile(r"(?<![\w.])((?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)i\b")

_BINOPS: dict[type, str] = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.Pow: "**",
}
_REFUSED_OPS: dict[type, str] = {
    ast.BitXor: "'^' (use ** for powers)",
    ast.FloorDiv: "'//'",
    ast.Mod: "'%'",
    ast.MatMult: "'@'",
    ast.BitAnd: "'&'",
    ast.BitOr: "'|'",
    ast.LShift: "'<<'",
    ast.RShift: "'>>'",
}

_Value = Callable[[ComplexArray], Any]
_Dual = Callable[[ComplexArray], tuple[Any, Any]]


def _front_chart() -> Mobius:
    return Mobius.from_points([(0.0, 0.0), (180.0, 0.0), (90.0, 0.0)], [0.0, complex("inf"), 1.0])


def _resolve_chart(chart: Any) -> tuple[str | None, Mobius | None]:
    """(name or None, Möbius map into the chart or None for the default chart)."""
    if chart is None:
        return "zenith", None
    if isinstance(chart, str):
        name = chart.strip().lower()
        if name == "zenith":
            return "zenith", None
        if name == "front":
            return "front", _front_chart()
        raise InvalidValueError(f"unknown chart {chart!r}; expected one of: {', '.join(CHARTS)}")
    if isinstance(chart, dict):
        chart = Mobius._from_params(chart)
    if isinstance(chart, Mobius):
        return None, None if chart.is_identity(1e-15) else chart
    raise InvalidTypeError(
        f"expected the chart as 'zenith', 'front' or a Mobius map, got {type(chart).__name__}"
    )


def _plane_for_formula(zw: ComplexArray) -> ComplexArray:
    """Plane points of unit pairs, with infinity replaced by ``_BIG`` in its direction."""
    a, b = zw[..., 0], zw[..., 1]
    z = coords.plane_from_cp1(zw)
    at_inf = b == 0
    if np.any(at_inf):
        direction = np.exp(1j * np.angle(a))
        z = np.where(at_inf, _BIG * direction, z)
    return z


def _cp1_of_result(w: Any, shape: tuple[int, ...], at_inf: Any = None) -> ComplexArray:
    w = np.broadcast_to(np.asarray(w, dtype=np.complex128), shape)
    if at_inf is not None and np.any(at_inf):
        # The value at infinity is a limit: snap what grows like a pole to infinity
        # and what decays like a zero to 0.
        size = np.abs(w)
        w = np.where(at_inf & (size > _SNAP), complex(np.inf, 0.0), w)
        w = np.where(at_inf & (size < 1.0 / _SNAP), 0.0, w)
    return coords.cp1_from_plane(w)  # any non-finite value becomes infinity


@register_map
class FunctionMap(SphereMap):
    """Pull back by a Python function of complex numbers, vectorised over arrays.

    Parameters
    ----------
    func : callable
        ``func(z) -> w`` on complex NumPy arrays (any shape, returns the same
        shape or a scalar). Overflow and NaN results become infinity.
    chart : {"zenith", "front"} or Mobius
        The chart ``z`` lives in (see the module docstring).

    Notes
    -----
    A map built from a callable has a plain-data form that names the
    callable but cannot be read back (:func:`map_from_dict` raises); use
    :class:`ExpressionMap` for maps that must be saved. The local scale is a
    finite-difference estimate.

    Examples
    --------
    >>> m = FunctionMap(lambda z: z**3 - 1)
    >>> m([2.0, 0.0, np.inf])
    array([ 7.+0.j, -1.+0.j, inf+0.j])
    """

    kind = "function"

    def __init__(self, func: Callable[[ComplexArray], Any], chart: Any = "zenith"):
        if not callable(func):
            raise InvalidTypeError(f"expected a callable, got {type(func).__name__}")
        self._func = func
        self._chart_name, self._chart = _resolve_chart(chart)

    @property
    def chart(self) -> Mobius:
        """The Möbius map into the chart of the formula."""
        return Mobius.identity() if self._chart is None else self._chart

    def _evaluate(self, z: ComplexArray) -> Any:
        with np.errstate(all="ignore"):
            return self._func(z)

    def pull_cp1(self, zw: ComplexArray) -> ComplexArray:
        zw = coords.normalize_cp1(np.asarray(zw, dtype=np.complex128))
        inner = zw if self._chart is None else self._chart.pull_cp1(zw)
        at_inf = inner[..., 1] == 0
        out = _cp1_of_result(self._evaluate(_plane_for_formula(inner)), inner.shape[:-1], at_inf)
        return out if self._chart is None else self._chart.inverse().pull_cp1(out)

    def _chart_param(self) -> Any:
        if self._chart_name is not None:
            return self._chart_name
        return self.chart.params()

    def params(self) -> dict[str, Any]:
        """Describes the map (the callable by name); :func:`map_from_dict` cannot rebuild it."""
        name = getattr(self._func, "__qualname__", type(self._func).__name__)
        return {"func": name, "chart": self._chart_param()}

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> SphereMap:
        raise InvalidValueError(
            f"a FunctionMap of a Python callable ({params.get('func', '?')}) cannot be rebuilt "
            "from plain data; use ExpressionMap for maps that must be saved"
        )

    def __repr__(self) -> str:
        name = getattr(self._func, "__name__", type(self._func).__name__)
        chart = self._chart_param() if self._chart_name else "<Mobius>"
        return f"FunctionMap({name}, chart={chart!r})"


def _shown(text: str) -> str:
    return repr(text) if len(text) <= 60 else repr(text[:57] + "...")


def _fail(text: str, node: ast.AST | None, what: str, hint: str = "") -> InvalidValueError:
    where = ""
    if node is not None and hasattr(node, "col_offset"):
        where = f" at column {node.col_offset + 1}"
    return InvalidValueError(
        f"expression {_shown(text)}: {what}{where}" + (f"; {hint}" if hint else "")
    )


def _segment(text: str, node: ast.AST) -> str:
    seg = ast.get_source_segment(text, node) or ""
    return seg if len(seg) <= 30 else seg[:27] + "..."


def _depth(tree: ast.AST) -> int:
    deepest = 0
    stack = [(tree, 1)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend((child, d + 1) for child in ast.iter_child_nodes(node))
    return deepest


class _Compiler:
    """Checks an expression's AST against the whitelist and builds evaluators."""

    def __init__(self, text: str, source: str):
        self.text = text  # as typed (for messages)
        self.source = source  # after the 2i -> 2j rewrite (same columns)
        self.holomorphic = True

    # -- checking ---------------------------------------------------------
    def check(self, node: ast.AST) -> None:
        if isinstance(node, ast.Expression):
            self.check(node.body)
        elif isinstance(node, ast.Constant):
            v = node.value
            if isinstance(v, bool) or not isinstance(v, (int, float, complex)):
                raise _fail(self.text, node, f"{_segment(self.source, node)} is not a number")
            try:
                finite = np.isfinite(complex(v))
            except OverflowError:
                finite = False
            if not finite:
                raise _fail(self.text, node, "number too large")
        elif isinstance(node, ast.Name):
            if node.id != "z" and node.id not in _NAMES:
                if node.id in FUNCTIONS:
                    raise _fail(
                        self.text,
                        node,
                        f"function {node.id!r} without an argument",
                        f"call it, as in {node.id}(z)",
                    )
                raise _fail(
                    self.text, node, f"unknown name {node.id!r}", "expected z, i, j, pi or e"
                )
        elif isinstance(node, ast.BinOp):
            if type(node.op) not in _BINOPS:
                what = _REFUSED_OPS.get(type(node.op), type(node.op).__name__)
                raise InvalidValueError(
                    f"expression {_shown(self.text)}: operator {what} at column "
                    f"{_operator_column(self.source, node)} is not allowed"
                )
            self.check(node.left)
            self.check(node.right)
        elif isinstance(node, ast.UnaryOp):
            if not isinstance(node.op, (ast.UAdd, ast.USub)):
                op = "'~'" if isinstance(node.op, ast.Invert) else "'not'"
                raise _fail(self.text, node, f"operator {op} is not allowed")
            self.check(node.operand)
        elif isinstance(node, ast.Call):
            func = node.func
            if not isinstance(func, ast.Name):
                if isinstance(func, ast.Attribute):
                    raise _attribute_error(self.text, func)
                raise _fail(
                    self.text,
                    func,
                    f"calling {_segment(self.source, func)!r} is not allowed",
                    f"expected one of: {', '.join(FUNCTIONS)}",
                )
            if func.id not in FUNCTIONS:
                raise _fail(
                    self.text,
                    func,
                    f"unknown function {func.id!r}",
                    f"expected one of: {', '.join(FUNCTIONS)}",
                )
            if node.keywords or len(node.args) != 1 or isinstance(node.args[0], ast.Starred):
                raise _fail(self.text, node, f"{func.id}() takes exactly one argument")
            if func.id in ("abs", "conj"):
                self.holomorphic = False
            self.check(node.args[0])
        elif isinstance(node, ast.Attribute):
            raise _attribute_error(self.text, node)
        else:
            raise _fail(
                self.text,
                node,
                f"{_describe(node)} ({_segment(self.source, node)!r}) is not allowed",
            )

    # -- building -----------------------------------------------------------
    def value(self, node: ast.AST) -> _Value:
        """A function z -> value (a NumPy array or a Python number)."""
        if isinstance(node, ast.Expression):
            return self.value(node.body)
        if isinstance(node, ast.Constant):
            c = _constant(node.value)
            return lambda z: c
        if isinstance(node, ast.Name):
            if node.id == "z":
                return lambda z: z
            c = _NAMES[node.id]
            return lambda z: c
        if isinstance(node, ast.UnaryOp):
            f = self.value(node.operand)
            if isinstance(node.op, ast.USub):
                return lambda z: -f(z)
            return f
        if isinstance(node, ast.BinOp):
            lf, rf = self.value(node.left), self.value(node.right)
            op = type(node.op)
            if op is ast.Add:
                return lambda z: lf(z) + rf(z)
            if op is ast.Sub:
                return lambda z: lf(z) - rf(z)
            if op is ast.Mult:
                return lambda z: lf(z) * rf(z)
            if op is ast.Div:
                return lambda z: np.divide(_cx(lf(z)), rf(z))
            return lambda z: np.power(_cx(lf(z)), rf(z))
        assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
        g = _FUNCS[node.func.id]
        f = self.value(node.args[0])
        return lambda z: g(_cx(f(z)))

    def dual(self, node: ast.AST) -> _Dual:
        """A function z -> (value, derivative) for holomorphic expressions."""
        if isinstance(node, ast.Expression):
            return self.dual(node.body)
        if isinstance(node, ast.Constant):
            c = _constant(node.value)
            return lambda z: (c, 0.0)
        if isinstance(node, ast.Name):
            if node.id == "z":
                return lambda z: (z, 1.0)
            c = _NAMES[node.id]
            return lambda z: (c, 0.0)
        if isinstance(node, ast.UnaryOp):
            f = self.dual(node.operand)
            if isinstance(node.op, ast.USub):

                def neg(z: ComplexArray) -> tuple[Any, Any]:
                    v, d = f(z)
                    return -v, -d

                return neg
            return f
        if isinstance(node, ast.BinOp):
            lf, rf = self.dual(node.left), self.dual(node.right)
            op = type(node.op)
            const_right = not _depends_on_z(node.right)

            def binop(z: ComplexArray) -> tuple[Any, Any]:
                u, du = lf(z)
                v, dv = rf(z)
                if op is ast.Add:
                    return u + v, du + dv
                if op is ast.Sub:
                    return u - v, du - dv
                if op is ast.Mult:
                    return u * v, du * v + u * dv
                if op is ast.Div:
                    q = np.divide(_cx(u), v)
                    return q, np.divide(_cx(du) - q * dv, v)
                p = np.power(_cx(u), v)
                if const_right:
                    return p, v * np.power(_cx(u), v - 1) * du
                return p, p * (dv * np.log(_cx(u)) + v * np.divide(_cx(du), u))

            return binop
        assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
        g = _FUNCS[node.func.id]
        dg = _DERIVS[node.func.id]
        f = self.dual(node.args[0])

        def call(z: ComplexArray) -> tuple[Any, Any]:
            u, du = f(z)
            u = _cx(u)
            return g(u), dg(u) * du

        return call


def _attribute_error(text: str, node: ast.Attribute) -> InvalidValueError:
    # Point at the dot: the end of the object the attribute is taken from.
    col = getattr(node.value, "end_col_offset", node.col_offset)
    return InvalidValueError(
        f"expression {text!r}: attribute access ('.{node.attr}') at column {col + 1} is not allowed"
    )


def _operator_column(source: str, node: ast.BinOp) -> int:
    """1-based column of a binary operator: the first non-blank, non-')' after the left operand."""
    col = getattr(node.left, "end_col_offset", None)
    if col is None:
        return node.col_offset + 1
    while col < len(source) and source[col] in " )":
        col += 1
    return col + 1


def _describe(node: ast.AST) -> str:
    names = {
        ast.Lambda: "a lambda",
        ast.Subscript: "indexing",
        ast.Compare: "a comparison",
        ast.BoolOp: "'and'/'or'",
        ast.IfExp: "'if'/'else'",
        ast.Tuple: "a tuple",
        ast.List: "a list",
        ast.Dict: "a dict",
        ast.Set: "a set",
        ast.JoinedStr: "an f-string",
        ast.NamedExpr: "':='",
        ast.Starred: "'*'",
        ast.GeneratorExp: "a generator",
        ast.ListComp: "a comprehension",
        ast.Await: "'await'",
        ast.Slice: "a slice",
    }
    return names.get(type(node), type(node).__name__)


def _depends_on_z(node: ast.AST) -> bool:
    return any(isinstance(n, ast.Name) and n.id == "z" for n in ast.walk(node))


def _constant(v: Any) -> complex | float | int:
    # Integers stay integers (exact integer powers); everything else is complex.
    if isinstance(v, int) and abs(v) < 2**53:
        return v
    return complex(v)


def _cx(v: Any) -> Any:
    return (
        v
        if isinstance(v, np.ndarray) and v.dtype == np.complex128
        else np.asarray(v, dtype=np.complex128)
    )


def _cabs(u: ComplexArray) -> ComplexArray:
    return np.abs(u).astype(np.complex128)


_FUNCS: dict[str, Callable[[ComplexArray], ComplexArray]] = {
    "exp": np.exp,
    "log": np.log,
    "sqrt": np.sqrt,
    "sin": np.sin,
    "cos": np.cos,
    "tan": np.tan,
    "sinh": np.sinh,
    "cosh": np.cosh,
    "tanh": np.tanh,
    "abs": _cabs,
    "conj": np.conj,
}

_DERIVS: dict[str, Callable[[ComplexArray], Any]] = {
    "exp": np.exp,
    "log": lambda u: np.divide(1.0, u),
    "sqrt": lambda u: np.divide(0.5, np.sqrt(u)),
    "sin": np.cos,
    "cos": lambda u: -np.sin(u),
    "tan": lambda u: np.divide(1.0, np.cos(u) ** 2),
    "sinh": np.cosh,
    "cosh": np.sinh,
    "tanh": lambda u: np.divide(1.0, np.cosh(u) ** 2),
}


def _parse(expr: str) -> tuple[ast.Expression, _Compiler]:
    if not isinstance(expr, str):
        raise InvalidTypeError(f"expected the expression as a string, got {type(expr).__name__}")
    text = expr
    if not text.strip():
        raise InvalidValueError("expected an expression in z such as 'z**2', got an empty string")
    if len(text) > MAX_LENGTH:
        raise InvalidValueError(
            f"expression too long: {len(text)} characters, at most {MAX_LENGTH} are allowed"
        )
    if "\n" in text or "\r" in text:
        raise InvalidValueError(f"expression {_shown(text)}: expected a single line")
    source = _IMAG_I.sub(lambda m: m.group(1) + "j", text)
    lead = len(source) - len(source.lstrip())  # columns are counted in the text as given
    try:
        tree = ast.parse(source.lstrip(), mode="eval")
    except SyntaxError as exc:
        msg = (exc.msg or "invalid syntax").split("\n")[0]
        col = (exc.offset or 1) + lead
        raise InvalidValueError(f"expression {_shown(text)}: {msg} at column {col}") from None
    except (RecursionError, MemoryError, ValueError):
        raise InvalidValueError(f"expression {_shown(text)}: too complex to parse") from None
    if lead:
        for node in ast.walk(tree):
            for attr in ("col_offset", "end_col_offset"):
                if getattr(node, attr, None) is not None:
                    setattr(node, attr, getattr(node, attr) + lead)
    depth = _depth(tree) - 1
    if depth > MAX_DEPTH:
        raise InvalidValueError(
            f"expression {_shown(text)}: nested too deeply ({depth} levels, at most {MAX_DEPTH})"
        )
    comp = _Compiler(text, source)
    comp.check(tree)
    return tree, comp


@register_map
class ExpressionMap(FunctionMap):
    """Pull back by a complex expression in ``z``, parsed safely (see the module docstring).

    Parameters
    ----------
    expr : str
        The formula, e.g. ``"z**2"``, ``"(z-1)/(z+1)"``, ``"exp(z)"``.
    chart : {"zenith", "front"} or Mobius
        The chart ``z`` lives in.

    Raises
    ------
    InvalidValueError
        For anything outside the whitelist, with the offending token's column.

    Notes
    -----
    For expressions without ``abs`` and ``conj`` (holomorphic ones) the local
    scale ``|f'(z)| (1 + |z|^2) / (1 + |f(z)|^2)`` is computed exactly by
    forward-mode differentiation; otherwise by finite differences.

    Examples
    --------
    >>> m = ExpressionMap("(z - 1)/(z + 1)", chart="front")
    >>> m.expr, m.to_dict()["chart"]
    ('(z - 1)/(z + 1)', 'front')
    >>> ExpressionMap("__import__('os')")    # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: expression "__import__('os')": unknown function ...
    """

    kind = "expression"

    def __init__(self, expr: str, chart: Any = "zenith"):
        tree, comp = _parse(expr)
        self._expr = expr
        self._holomorphic = comp.holomorphic
        value = comp.value(tree)
        self._dual = comp.dual(tree) if comp.holomorphic else None
        super().__init__(value, chart)

    @property
    def expr(self) -> str:
        """The expression, as given."""
        return self._expr

    def local_scale(self, zw: ComplexArray) -> FloatArray:
        if self._dual is None:
            return super().local_scale(zw)
        zw = coords.normalize_cp1(np.asarray(zw, dtype=np.complex128))
        inner = zw if self._chart is None else self._chart.pull_cp1(zw)
        z = _plane_for_formula(inner)
        shape = inner.shape[:-1]
        with np.errstate(all="ignore"):
            w, dw = self._dual(z)
            w = np.broadcast_to(np.asarray(w, dtype=np.complex128), shape)
            dw = np.broadcast_to(np.asarray(dw, dtype=np.complex128), shape)
            # |f'| (1 + |z|^2) / (1 + |f|^2), in logs so that nothing overflows on the way.
            scale = np.exp(np.log(np.abs(dw)) + np.log1p(np.abs(z) ** 2) - np.log1p(np.abs(w) ** 2))
        if self._chart is not None:
            out = _cp1_of_result(w, shape)
            scale = scale * self._chart.local_scale(zw)
            scale = scale * self._chart.inverse().local_scale(out)
        scale = np.array(scale, dtype=np.float64)
        bad = ~np.isfinite(scale)
        if np.any(bad):  # the formula failed (overflow, 0 * inf): finite differences there
            scale[bad] = SphereMap.local_scale(self, zw[bad])
        return scale

    def params(self) -> dict[str, Any]:
        return {"expr": self._expr, "chart": self._chart_param()}

    @classmethod
    def _from_params(cls, params: dict[str, Any]) -> ExpressionMap:
        return cls(params["expr"], params.get("chart", "zenith"))

    def __reduce__(self) -> tuple[Any, ...]:
        # The compiled closures do not pickle; the formula and the chart rebuild them (so a
        # map can go to another process, e.g. a Dask worker).
        return (_expression_from_params, (self.params(),))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ExpressionMap):
            return NotImplemented
        if self._expr != other._expr:
            return False
        a, b = self._chart, other._chart
        return (a is None and b is None) or (a is not None and b is not None and a.isclose(b))

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        chart = self._chart_param() if self._chart_name else "<Mobius>"
        return f"ExpressionMap({self._expr!r}, chart={chart!r})"


def _expression_from_params(params: dict[str, Any]) -> ExpressionMap:
    """Rebuild a pickled :class:`ExpressionMap` from its parameters."""
    return ExpressionMap._from_params(params)
