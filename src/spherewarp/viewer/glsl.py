"""A recipe's map as the browser shader runs it: compiled stages, expression maps as GLSL.

The shader (``viewer/src/shader.js``) runs the compiled stages of
:mod:`spherewarp.render.stages`, the rows the CPU kernels read. Two things are
added here for the page:

* **expression maps** (:class:`~spherewarp.maps.ExpressionMap`, the recipe's
  ``map`` effect) have no CPU stage; each becomes an ``expression`` stage
  (:data:`EXPRESSION`, a stage only the shader has) and a GLSL function made
  from the expression's syntax tree, the tree the map itself is built from
  (:func:`spherewarp.maps.expression._parse`, which checks it against the
  whitelist). The function is made only of fixed GLSL text, one temporary per
  node of the tree; the numbers of the expression go into the stage's row (its
  ``constants``), so no character the user typed ever reaches the shader's
  source (:func:`expression_glsl`);
* the labels of a masked Schottky group (``schottky_mask``) can be millions of
  floats: they are left out of the stage's row and served once as a texture
  (:func:`shader_spec` gives their key, :meth:`ShaderSpec.labels`).

Examples
--------
>>> from spherewarp.maps import ExpressionMap
>>> code, consts = expression_glsl("z**2 + 0.5*z", 0)
>>> "0.5" in code, consts
(False, [2.0, 0.0, 0.5, 0.0])
>>> print(code.splitlines()[0])
vec2 expr0(int s, vec2 z) {
>>> spec = shader_spec(ExpressionMap("(z - 1)/(z + 1)"))
>>> spec.codes, spec.rows[0]
([64], [0.0, 1.0, 0.0, 1.0, 0.0])
"""

from __future__ import annotations

import ast
import hashlib
from dataclasses import dataclass, field
from functools import reduce
from typing import Any

import numpy as np

from ..render import stages as _st

__all__ = [
    "EXPRESSION",
    "GLSL_FUNCTIONS",
    "ShaderSpec",
    "expression_glsl",
    "glsl_header",
    "shader_spec",
]

#: the stage of an expression map, run only by the shader (code 64: after every CPU stage,
#: so the table can grow): ``slot`` is the index of its GLSL function ``expr<slot>``, the
#: ``constants`` tail the expression's numbers as (re, im) pairs in the order of the tree
EXPRESSION = _st.Stage(
    "expression", 64, ("slot",), tail="constants", tail_record=("re", "im"),
    doc="an expression map (maps.ExpressionMap) in its chart's coordinate: w = expr<slot>(z), "
    "a GLSL function made from the expression's tree; the numbers in the tail",
)  # fmt: skip

#: the expression language's functions and their GLSL complex counterparts (shader.js)
GLSL_FUNCTIONS: dict[str, str] = {
    "exp": "cexp", "log": "clog", "sqrt": "csqrt", "sin": "csin", "cos": "ccos",
    "tan": "ctan", "sinh": "csinh", "cosh": "ccosh", "tanh": "ctanh", "abs": "cabs",
    "conj": "cconj",
}  # fmt: skip
_GLSL_BINOPS = {
    ast.Add: "cadd",
    ast.Sub: "csub",
    ast.Mult: "cmul",
    ast.Div: "cdiv",
    ast.Pow: "cpow",
}
_NAMES = {"i": 1j, "j": 1j, "pi": np.pi, "e": np.e}


def glsl_header() -> str:
    """The stage table's ``#define`` lines, the shader-only :data:`EXPRESSION` stage's too.

    Examples
    --------
    >>> "#define STAGE_EXPRESSION 64" in glsl_header()
    True
    """
    return _st.glsl_header(extra=(EXPRESSION,))


def expression_glsl(expr: str, slot: int) -> tuple[str, list[float]]:
    """The GLSL function ``vec2 expr<slot>(int s, vec2 z)`` of an expression, and its numbers.

    The expression is parsed and checked by the expression maps' own parser
    (:mod:`spherewarp.maps.expression`: anything outside the whitelist raises its
    :class:`~spherewarp.errors.InvalidValueError`); each node of the tree becomes one
    line of fixed text (``vec2 tN = cmul(tA, tB);``), each number (and ``i``, ``pi``,
    ``e``) a read of the stage's row, ``K(s, k)``. The function's text depends only on
    the shape of the tree.

    Examples
    --------
    >>> print(expression_glsl("exp(i*z)", 3)[0])
    vec2 expr3(int s, vec2 z) {
      vec2 t0 = K(s, 0);
      vec2 t1 = z;
      vec2 t2 = cmul(t0, t1);
      vec2 t3 = cexp(t2);
      return t3;
    }
    >>> expression_glsl("z.real", 0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    spherewarp.errors.InvalidValueError: expression 'z.real': attribute access ...
    """
    from ..maps.expression import _parse

    tree, _ = _parse(expr)  # the whitelist check of the maps themselves
    lines: list[str] = []
    consts: list[float] = []

    def const(c: complex) -> str:
        consts.extend((float(c.real), float(c.imag)))
        return f"K(s, {len(consts) - 2})"

    def emit(rhs: str) -> str:
        lines.append(f"  vec2 t{len(lines)} = {rhs};")
        return f"t{len(lines) - 1}"

    def walk(node: ast.AST) -> str:
        # every node kind is named here: anything else is refused (a second check)
        if isinstance(node, ast.Expression):
            return walk(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float, complex)):
            return emit(const(complex(node.value)))
        if isinstance(node, ast.Name) and node.id == "z":
            return emit("z")
        if isinstance(node, ast.Name) and node.id in _NAMES:
            return emit(const(complex(_NAMES[node.id])))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
            a = walk(node.operand)
            return emit(f"-{a}") if isinstance(node.op, ast.USub) else a
        if isinstance(node, ast.BinOp) and type(node.op) in _GLSL_BINOPS:
            a, b = walk(node.left), walk(node.right)
            return emit(f"{_GLSL_BINOPS[type(node.op)]}({a}, {b})")
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id in GLSL_FUNCTIONS
            and len(node.args) == 1
            and not node.keywords
        ):
            a = walk(node.args[0])
            return emit(f"{GLSL_FUNCTIONS[node.func.id]}({a})")
        raise ValueError(f"no GLSL for {type(node).__name__}")  # pragma: no cover - checked

    out = walk(tree)
    body = "\n".join(lines)
    return f"vec2 expr{int(slot)}(int s, vec2 z) {{\n{body}\n  return {out};\n}}", consts


@dataclass
class ShaderSpec:
    """A map as the shader runs it.

    Attributes
    ----------
    codes : list of int
        The stage codes, in order.
    rows : list of list of float
        One parameter row per stage (a ``schottky_mask`` row without its labels).
    glsl : str
        The GLSL functions of the expression stages ("" if none).
    labels : dict
        The left-out labels by key: ``{key: (width, height, int16 array)}``.
    label_stage : list
        ``{"stage", "key", "width", "height"}`` for each ``schottky_mask`` stage.
    """

    codes: list[int] = field(default_factory=list)
    rows: list[list[float]] = field(default_factory=list)
    glsl: str = ""
    labels: dict[str, tuple[int, int, np.ndarray]] = field(default_factory=dict)
    label_stage: list[dict[str, Any]] = field(default_factory=list)

    def as_json(self) -> dict[str, Any]:
        """What ``/api/stages`` sends (the labels themselves go by their key)."""
        return {
            "codes": self.codes,
            "rows": self.rows,
            "glsl": self.glsl,
            "labels": self.label_stage,
        }


def _leaves(m: Any) -> list[Any]:
    """The parts of a map in the order they are applied (composites flattened)."""
    from ..maps.base import Composite

    if isinstance(m, Composite):
        return [leaf for part in reversed(m.maps) for leaf in _leaves(part)]
    return [m]


def shader_spec(m: Any) -> ShaderSpec | None:
    """The map as the shader's stages, or None if some part of it has none.

    The parts between expression maps are compiled as the CPU renderer compiles
    them (:func:`spherewarp.render.fast.kernel_spec`: adjacent Möbius maps, the
    expression maps' charts included, are multiplied into one stage).

    Examples
    --------
    >>> from spherewarp.maps import ExpressionMap, Mobius, Power
    >>> m = Mobius.zoom((10, 0), 2) @ ExpressionMap("z**3", chart="front") @ Power(2)
    >>> shader_spec(m).codes
    [2, 1, 64, 1]
    """
    from ..maps.expression import ExpressionMap
    from ..maps.mobius import Mobius
    from ..render.fast import kernel_spec

    parts: list[Any] = []  # maps and ("expression", ExpressionMap) markers
    for leaf in _leaves(m):
        if isinstance(leaf, ExpressionMap):
            chart = leaf.chart
            parts += [chart, ("expression", leaf), chart.inverse()]
        else:
            parts.append(leaf)
    spec = ShaderSpec()
    run: list[Any] = []

    def flush() -> bool:
        if not run:
            return True
        ks = kernel_spec(reduce(lambda a, b: b @ a, run))
        run.clear()
        if ks is None:
            return False
        for code, row in zip(ks.codes.tolist(), ks.params, strict=True):
            if code == _st.STAGE_MOBIUS and np.allclose(row[:16], np.eye(4).ravel(), atol=1e-15):
                continue  # an identity chart
            spec.codes.append(int(code))
            spec.rows.append(_trim(code, row, spec))
        return True

    slot = 0
    for p in parts:
        if isinstance(p, tuple):
            if not flush():
                return None
            code, consts = expression_glsl(p[1].expr, slot)
            spec.codes.append(EXPRESSION.code)
            spec.rows.append([float(slot), *consts])
            spec.glsl += code + "\n"
            slot += 1
        elif isinstance(p, Mobius) and p.is_identity(1e-15):
            continue
        else:
            run.append(p)
    if not flush():
        return None
    return spec


def _trim(code: int, row: np.ndarray, spec: ShaderSpec) -> list[float]:
    """A kernel row for the page: its used length; a mask's labels kept aside by key."""
    stage = _st.BY_CODE[code]
    if stage is _st.SCHOTTKY_MASK:
        count, w, h = (
            int(row[_st.SCHOTTKY_MASK_COUNT]),
            int(row[_st.SCHOTTKY_MASK_WIDTH]),
            int(row[_st.SCHOTTKY_MASK_HEIGHT]),
        )
        lab0 = _st.SCHOTTKY_MASK_DATA + 32 * count
        labels = row[lab0 : lab0 + w * h].astype(np.int16)
        key = hashlib.sha256(labels.tobytes() + f"{w}x{h}".encode()).hexdigest()[:16]
        spec.labels[key] = (w, h, labels)
        spec.label_stage.append({"stage": len(spec.rows), "key": key, "width": w, "height": h})
        return row[:lab0].tolist()
    used = row.tolist()
    if stage.tail is None:
        return used[: len(stage.fields)]
    while used and used[-1] == 0.0:  # kernel_spec's padding (the page pads with zeros again)
        used.pop()
    return used
