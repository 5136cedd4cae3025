"""Coefficient fields over Γ_C: a number, or an expression in x, y, z evaluated at the contact points.

``contact.friction = "where(hypot(x, y) < 0.05, 0, 0.4)"`` gives μ(x) = 0 on a disc of radius 0.05 and 0.4 elsewhere.
An expression may also name the state at the point, :data:`STATE`: T (the surface temperature), p (the pressure),
v (the sliding speed); ``contact.friction = "0.42 - 0.0004 * max(T - 250, 0)"`` fades above 250 degrees.
The grammar is fixed (Python's precedence and associativity, so ``-2**2 = -4`` and ``2**3**2 = 2**9``)::

    number     := arithmetic of numbers, x, y, z, pi, T, p, v with + - * / ** (unary + and - too) and parentheses,
                  sqrt exp log sin cos abs (one argument), atan2 hypot (two), min max (two or more),
                  where(condition, number, number)
    condition  := number (< | <= | > | >= | == | !=) number (chains as in 0 < x < 1),
                  condition and condition, condition or condition, not condition, (condition)

Line breaks (in a TOML multi-line string) are spaces, as inside Python's parentheses (``0.3``, a line break,
``+ 5`` is 5.3); ``#`` is refused (Python would silently drop the rest as a comment).

The text is parsed with :func:`ast.parse` (a parser only: nothing is compiled or run) and the tree is checked against
a whitelist of node types, names and arities, and typed (number or condition), before anything is evaluated; the
evaluation walks the checked tree with numpy only.  Text longer than :data:`MAX_LENGTH` characters or nested deeper
than :data:`MAX_DEPTH` is refused before the walk.  A value that comes out non-finite (1e308*10, log(-1), 1/0) is
refused by :func:`check_values`, which also checks the key's range, with one line naming the key, the value and the
first offending point.
"""
from __future__ import annotations

import ast
import math
import operator
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property, lru_cache, reduce

import numpy as np

from .keys import SceneError

MAX_LENGTH = 1000
"""Longest expression text accepted (characters)."""
MAX_DEPTH = 60
"""Deepest syntax tree accepted (``ast`` levels; ``sqrt(x)`` is 4 deep, each operator or call adds 1–2)."""

STATE = ("T", "p", "v")
"""The names of the state at a contact point: its temperature, pressure and sliding speed."""
NAMES = ("x", "y", "z", "pi", *STATE)
FUNCTIONS: dict[str, tuple[int, int | None, Callable]] = {
    # name: (fewest arguments, most arguments (None: any), numpy function)
    "sqrt": (1, 1, np.sqrt), "exp": (1, 1, np.exp), "log": (1, 1, np.log), "sin": (1, 1, np.sin),
    "cos": (1, 1, np.cos), "abs": (1, 1, np.abs), "atan2": (2, 2, np.arctan2), "hypot": (2, 2, np.hypot),
    "min": (2, None, np.minimum), "max": (2, None, np.maximum), "where": (3, 3, np.where),
}
_ALLOWED = f"allowed: {', '.join(NAMES + tuple(FUNCTIONS))}"
_ARITHMETIC = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide, ast.Pow: np.power}
_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
            ast.Eq: operator.eq, ast.NotEq: operator.ne}
_REFUSED = {  # what a user most likely meant by a Python construct outside the grammar
    ast.Attribute: "attribute access", ast.Subscript: "subscripts", ast.Lambda: "lambda",
    ast.IfExp: "'a if c else b' (write where(c, a, b))", ast.BitXor: "'^' (write ** for a power)",
    ast.FloorDiv: "'//'", ast.Mod: "'%'", ast.Starred: "starred arguments", ast.NamedExpr: "':='",
    ast.ListComp: "comprehensions", ast.GeneratorExp: "comprehensions", ast.SetComp: "comprehensions",
    ast.DictComp: "comprehensions", ast.Tuple: "tuples", ast.List: "lists", ast.Dict: "dicts", ast.Set: "sets",
    ast.JoinedStr: "strings", ast.Is: "'is'", ast.IsNot: "'is not'", ast.In: "'in'", ast.NotIn: "'not in'",
}
NUMBER, CONDITION = "a number", "a condition"


@dataclass(frozen=True)
class Expression:
    """A checked expression of x, y, z (and of the state T, p, v) for the scene key ``key``; build it with :meth:`parse`.

    Attributes
    ----------
    text : str
        The expression as the user wrote it.
    key : str
        The dotted scene key it belongs to (e.g. ``contact.friction``), named by every error.
    """

    text: str
    key: str
    tree: ast.expression = field(repr=False, compare=False)

    @classmethod
    def parse(cls, text: str, key: str) -> Expression:
        """Parse and check ``text``; a :class:`SceneError` naming ``key``, the position and the token otherwise.

        Remembered (the time loop evaluates a coefficient of the state every step).
        """
        if not isinstance(text, str):
            raise SceneError(f"{key}: must be a number or an expression string (got {text!r})")
        return _parsed(cls, text, key)

    @classmethod
    def _parse(cls, text: str, key: str) -> Expression:
        if len(text) > MAX_LENGTH:
            raise SceneError(f"{key}: expression longer than {MAX_LENGTH} characters (got {len(text)})")
        flat = "".join(" " if c.isspace() else c for c in text)   # one line: positions are columns
        if not flat.strip():
            raise SceneError(f"{key}: empty expression (give a number or an expression in x, y, z)")
        control = next((i for i, c in enumerate(flat) if not c.isprintable()), None)
        if control is not None:
            shown = "".join(c if c.isprintable() else "?" for c in flat)
            raise SceneError(f"{key}: control character at position {control + 1} in \"{_shown(shown)}\"")
        if "#" in flat:                                             # Python's comment: the rest would vanish
            raise SceneError(f"{key}: '#' at position {flat.index('#') + 1} in \"{_shown(flat)}\" (an expression "
                             "has no comments)")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", SyntaxWarning)      # "1and x" is refused, not read as "1 and x"
                tree = ast.parse(flat, mode="eval")
        except SyntaxError as err:
            raise SceneError(f"{key}: invalid syntax at position {err.offset} in \"{_shown(flat)}\" ({err.msg})") \
                from None
        except (ValueError, MemoryError, RecursionError) as err:   # the parser's own limits
            raise SceneError(f"{key}: cannot parse \"{_shown(flat)}\" ({err})") from None
        _Checker(text, key).run(tree)
        return cls(text, key, tree)

    @cached_property
    def state(self) -> frozenset[str]:
        """The names of :data:`STATE` the expression uses (empty: a field of x, y, z alone)."""
        return frozenset(n.id for n in ast.walk(self.tree) if isinstance(n, ast.Name)) & set(STATE)

    def evaluate(self, points: np.ndarray, state: dict[str, np.ndarray] | None = None) -> np.ndarray:
        """The values at ``points`` (n × d, d = 2 or 3; z = 0 in 2D), shape (n,), float64.

        ``state``: the arrays (n,) of the names of :attr:`state` at the points (``{"T": ..., "p": ...}``).
        Non-finite values (overflow, log of a negative number, division by zero) are returned as they are:
        :func:`check_values` refuses them.
        """
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] not in (2, 3):
            raise ValueError(f"{self.key}: points must be an (n, 2) or (n, 3) array (got shape {pts.shape})")
        missing = sorted(self.state - set(state or ()))
        if missing:
            raise ValueError(f"{self.key}: depends on {', '.join(missing)}: give its values at the points")
        coords = {"x": pts[:, 0], "y": pts[:, 1], "z": pts[:, 2] if pts.shape[1] == 3 else np.zeros(len(pts)),
                  "pi": np.pi, **{name: np.asarray(state[name], dtype=float) for name in self.state}}
        with np.errstate(all="ignore"):
            values = _evaluate(self.tree.body, coords)
        return np.broadcast_to(np.asarray(values, dtype=float), (len(pts),)).copy()


@lru_cache(maxsize=256)
def _parsed(cls, text: str, key: str) -> Expression:
    return cls._parse(text, key)


def values_at(value, key: str, points: np.ndarray, state: dict | None = None, t: float | None = None,
              **bounds) -> np.ndarray:
    """The coefficient ``value`` at ``points``, checked by :func:`check_values` with ``bounds``.

    ``value``: a number, an expression string (or :class:`Expression`), an array with one value per point, or a
    callable ``f(points) -> (n,)``.  ``state``: the state's arrays at the points (an expression of T, p, v), named
    with the time ``t`` by a refusal.
    """
    pts = np.asarray(points, dtype=float)
    if isinstance(value, str):
        value = Expression.parse(value, key)
    if isinstance(value, Expression):
        values = value.evaluate(pts, state)
    elif callable(value):
        values = np.asarray(value(pts), dtype=float)
    else:
        values = np.asarray(value, dtype=float)
    values = np.broadcast_to(values, (len(pts),)) if values.ndim == 0 else values
    if values.shape != (len(pts),):
        raise SceneError(f"{key}: must give one value per contact point ({len(pts)}) (got shape {values.shape})")
    return check_values(key, values, pts, state=state, t=t, **bounds)


def check_values(key: str, values: np.ndarray, points: np.ndarray, *, lo: float | None = None,
                 hi: float | None = None, lo_open: bool = False, hi_open: bool = False, state: dict | None = None,
                 t: float | None = None) -> np.ndarray:
    """``values`` if each is finite and in the range; else one line naming the key, the value and the first point.

    The range is lo ≤ v ≤ hi (strict where ``lo_open`` / ``hi_open``), either end optional.  ``state`` (arrays
    at the points) and the time ``t``, where given, are named too.  Returns ``values``.
    """
    values = np.asarray(values, dtype=float)
    bad = ~np.isfinite(values)
    rule = "finite"
    if not bad.any():
        if lo is not None:
            bad |= values <= lo if lo_open else values < lo
        if hi is not None:
            bad |= values >= hi if hi_open else values > hi
        rule = " and ".join(r for r in (lo is not None and f"{'>' if lo_open else '>='} {lo:g}",
                                        hi is not None and f"{'<' if hi_open else '<='} {hi:g}") if r)
    if bad.any():
        i = int(np.argmax(bad))
        where = ", ".join(f"{c:.6g}" for c in np.asarray(points, dtype=float)[i])
        there = ", ".join(f"{name} = {np.asarray(v)[i]:.6g}" for name, v in (state or {}).items())
        there = (f" with {there}" if there else "") + ("" if t is None else f" at t = {t:.6g}")
        raise SceneError(f"{key}: must be {rule} at every contact point (got {values[i]:.6g} at ({where}){there})")
    return values


class _Checker:
    """Walks a parsed tree once: whitelist, arity, types (number or condition), depth."""

    def __init__(self, text: str, key: str):
        self.text, self.key = text, key

    def run(self, tree: ast.expression) -> None:
        if _depth(tree) > MAX_DEPTH:
            raise SceneError(f"{self.key}: expression nested deeper than {MAX_DEPTH} levels in \"{_shown(self.text)}\"")
        if self.kind(tree.body) != NUMBER:
            self.fail(tree.body, "a condition where a number is needed", "write where(condition, a, b)")

    def fail(self, node: ast.AST, what: str, hint: str = ""):
        column = len(self.text.encode()[:getattr(node, "col_offset", 0)].decode(errors="ignore")) + 1
        raise SceneError(f"{self.key}: {what} at position {column} in \"{_shown(self.text)}\""
                         + (f" ({hint})" if hint else ""))

    def expect(self, node: ast.AST, kind: str, where: str) -> None:
        got = self.kind(node)
        if got != kind:
            self.fail(node, f"{where} must be {kind} (got {got})")

    def kind(self, node: ast.AST) -> str:
        """NUMBER or CONDITION; refuses anything outside the grammar."""
        if isinstance(node, ast.Constant):
            if type(node.value) not in (int, float):
                self.fail(node, f"{_literal(node.value)} not allowed", "only numbers, x, y, z, pi")
            if not math.isfinite(_float(node.value)):
                self.fail(node, f"number {_shown(ast.get_source_segment(self.text, node), 20)} out of range",
                          "beyond ±1.8e308")
            return NUMBER
        if isinstance(node, ast.Name):
            if node.id in FUNCTIONS:
                self.fail(node, f"'{node.id}' is a function", f"call it: {node.id}(...)")
            if node.id not in NAMES:
                self.fail(node, f"unknown name '{node.id}'", _ALLOWED)
            return NUMBER
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.Not):
                self.expect(node.operand, CONDITION, "the operand of 'not'")
                return CONDITION
            if not isinstance(node.op, (ast.UAdd, ast.USub)):
                self.fail(node, "'~' not allowed")
            self.expect(node.operand, NUMBER, "the operand of unary minus")
            return NUMBER
        if isinstance(node, ast.BinOp):
            if type(node.op) not in _ARITHMETIC:
                self.fail(node, f"{_REFUSED.get(type(node.op), 'this operator')} not allowed")
            for side in (node.left, node.right):
                self.expect(side, NUMBER, "an operand of an arithmetic operator")
            return NUMBER
        if isinstance(node, ast.Compare):
            for op in node.ops:
                if type(op) not in _COMPARE:
                    self.fail(node, f"{_REFUSED.get(type(op), 'this comparison')} not allowed")
            for side in (node.left, *node.comparators):
                self.expect(side, NUMBER, "a side of a comparison")
            return CONDITION
        if isinstance(node, ast.BoolOp):
            word = "and" if isinstance(node.op, ast.And) else "or"
            for side in node.values:
                self.expect(side, CONDITION, f"an operand of '{word}'")
            return CONDITION
        if isinstance(node, ast.Call):
            return self.call(node)
        self.fail(node, f"{_REFUSED.get(type(node), repr(ast.get_source_segment(self.text, node)))} not allowed")

    def call(self, node: ast.Call) -> str:
        if not isinstance(node.func, ast.Name):
            self.fail(node, "only the named functions can be called")
        name = node.func.id
        if name not in FUNCTIONS:
            what = f"'{name}' is not a function" if name in NAMES else f"unknown function '{name}'"
            self.fail(node, what, _ALLOWED)
        if node.keywords:
            self.fail(node, f"keyword arguments not allowed ({node.keywords[0].arg}=...)")
        if any(isinstance(a, ast.Starred) for a in node.args):
            self.fail(node, "starred arguments not allowed")
        fewest, most, _ = FUNCTIONS[name]
        n = len(node.args)
        if n < fewest or (most is not None and n > most):
            wanted = f"{fewest}" if fewest == most else f"{fewest} or more"
            self.fail(node, f"{name} takes {wanted} argument{'s' if wanted != '1' else ''} (got {n})")
        for i, arg in enumerate(node.args):
            kind = CONDITION if name == "where" and i == 0 else NUMBER
            self.expect(arg, kind, f"argument {i + 1} of {name}")
        return NUMBER


def _depth(tree: ast.AST) -> int:
    """Depth of the tree, without recursion (a deep tree is what is being guarded against)."""
    stack, deepest = [(tree, 1)], 0
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        if d <= MAX_DEPTH:
            stack.extend((child, d + 1) for child in ast.iter_child_nodes(node))
    return deepest


def _shown(text: str, width: int = 80) -> str:
    """``text`` cut to ``width`` characters for a one-line message."""
    return text if len(text) <= width else text[:width - 1] + "…"


def _float(value: int | float) -> float:
    try:
        return float(value)
    except OverflowError:   # an integer literal beyond the float range
        return math.inf


def _literal(value) -> str:
    return {str: "strings", bytes: "strings", bool: "True/False", type(None): "None"}.get(
        type(value), f"the literal {value!r}")


def _evaluate(node: ast.AST, coords: dict):
    """Value of a checked node: arrays or floats (numbers), bool arrays (conditions)."""
    if isinstance(node, ast.Constant):
        return float(node.value)
    if isinstance(node, ast.Name):
        return coords[node.id]
    if isinstance(node, ast.UnaryOp):
        value = _evaluate(node.operand, coords)
        return np.logical_not(value) if isinstance(node.op, ast.Not) else (-value if isinstance(node.op, ast.USub)
                                                                          else +value)
    if isinstance(node, ast.BinOp):
        return _ARITHMETIC[type(node.op)](_evaluate(node.left, coords), _evaluate(node.right, coords))
    if isinstance(node, ast.Compare):
        sides = [_evaluate(s, coords) for s in (node.left, *node.comparators)]
        return reduce(np.logical_and, [_COMPARE[type(op)](a, b) for op, a, b in zip(node.ops, sides, sides[1:])])
    if isinstance(node, ast.BoolOp):
        combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
        return reduce(combine, [_evaluate(v, coords) for v in node.values])
    args = [_evaluate(a, coords) for a in node.args]                       # ast.Call, the only node left
    function = FUNCTIONS[node.func.id][2]
    return reduce(function, args) if node.func.id in ("min", "max") else function(*args)
