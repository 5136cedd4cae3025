"""Coefficient expressions in x, y, z: values against numpy, the grammar's precedence, every refusal, and fuzzing."""
import numpy as np
import pytest

from ngwear.model.expressions import MAX_DEPTH, MAX_LENGTH, Expression, check_values, values_at
from ngwear.model.scene import SceneError

RNG = np.random.default_rng(7)
POINTS = np.column_stack([RNG.uniform(0.1, 2, 50), RNG.uniform(-1, 1, 50), RNG.uniform(-1, 1, 50)])
X, Y, Z = POINTS.T


def value(text, points=POINTS):
    return Expression.parse(text, "contact.friction").evaluate(points)


def refusal(text, key="contact.friction"):
    with pytest.raises(SceneError) as err:
        Expression.parse(text, key)
    return str(err.value)


@pytest.mark.parametrize("text, expected", [
    ("x + y", X + Y), ("x - y", X - Y), ("x * y", X * Y), ("x / y", X / Y), ("x ** y", X ** Y),
    ("-x", -X), ("+x", X), ("(x + y) * z", (X + Y) * Z), ("pi * z", np.pi * Z), ("2.5e-1 * x", 0.25 * X),
    ("sqrt(x)", np.sqrt(X)), ("exp(y)", np.exp(Y)), ("log(x)", np.log(X)), ("sin(y)", np.sin(Y)),
    ("cos(z)", np.cos(Z)), ("abs(y)", np.abs(Y)), ("atan2(y, x)", np.arctan2(Y, X)), ("hypot(x, y)", np.hypot(X, Y)),
    ("min(x, y)", np.minimum(X, Y)), ("max(x, y, z)", np.maximum(np.maximum(X, Y), Z)),
    ("min(x, 0.5, y, z)", np.minimum.reduce([X, np.full_like(X, 0.5), Y, Z])),
])
def test_operators_and_functions_match_numpy(text, expected):
    np.testing.assert_allclose(value(text), expected, rtol=1e-15, atol=0)


@pytest.mark.parametrize("text, expected", [
    ("-2**2", -4.0), ("(-2)**2", 4.0), ("2**3**2", 512.0), ("(2**3)**2", 64.0), ("2**-1", 0.5), ("-2**-2", -0.25),
    ("2 + 3 * 4", 14.0), ("(2 + 3) * 4", 20.0), ("8 / 4 / 2", 1.0), ("1 - 2 - 3", -4.0), ("--3", 3.0),
    ("-3 * -2", 6.0), ("2 * 3 ** 2", 18.0), ("-pi", -np.pi),
])
def test_precedence_and_associativity_are_pythons(text, expected):
    """** binds tighter than unary minus and groups to the right; * / + - group to the left."""
    np.testing.assert_array_equal(value(text), np.full(len(POINTS), expected))


def test_zones_with_where_and_conditions():
    np.testing.assert_array_equal(value("where(hypot(x, y) < 1, 0, 0.4)"), np.where(np.hypot(X, Y) < 1, 0, 0.4))
    np.testing.assert_array_equal(value("where(0.5 < x <= 1.5, 1, 2)"), np.where((0.5 < X) & (X <= 1.5), 1, 2))
    np.testing.assert_array_equal(value("where(y > 0 and not z > 0 or x >= 1.9, x, -x)"),
                                  np.where(((Y > 0) & ~(Z > 0)) | (X >= 1.9), X, -X))
    np.testing.assert_array_equal(value("where(x == x and y != y, 1, where(y < 0, 2, 3))"), np.where(Y < 0, 2, 3))
    np.testing.assert_array_equal(value("where(1 < 2, x, 0)"), X)             # a constant condition broadcasts


def test_2d_points_have_z_zero_and_constants_broadcast():
    pts = POINTS[:, :2]
    np.testing.assert_array_equal(value("x + 10 * y + 100 * z", pts), X + 10 * Y)
    out = value("0.3", pts)
    assert out.shape == (len(pts),) and out.dtype == np.float64 and np.all(out == 0.3)
    with pytest.raises(ValueError, match=r"contact.friction: points must be an \(n, 2\) or \(n, 3\) array"):
        value("x", POINTS[:, 0])


@pytest.mark.parametrize("text, message", [
    ("0.3*foo", "unknown name 'foo' at position 5 in \"0.3*foo\" (allowed: x, y, z, pi, T, p, v, sqrt, exp, log, sin, cos,"),
    ("__import__('os')", "unknown function '__import__' at position 1"),
    ("x.__class__", "attribute access not allowed at position 1"),
    ("().__class__.__bases__[0]", "subscripts not allowed"), ("().__class__", "attribute access not allowed"),
    ("x[0]", "subscripts not allowed"),
    ("(lambda: 1)()", "only the named functions can be called"),
    ("lambda: 1", "lambda not allowed"),
    ("[t for t in x]", "comprehensions not allowed"),
    ("sum(t for t in (1, 2))", "unknown function 'sum'"),
    ("max(t for t in (1, 2))", "max takes 2 or more arguments (got 1)"),
    ("min(1, *[x])", "starred arguments not allowed"),
    ("'a'", "strings not allowed at position 1 in \"'a'\" (only numbers, x, y, z, pi)"),
    ("f'{x}'", "strings not allowed"),
    ("sqrt(x=1)", "keyword arguments not allowed (x=...)"),
    ("sqrt(x, y)", "sqrt takes 1 argument (got 2) at position 1"),
    ("atan2(x)", "atan2 takes 2 arguments (got 1)"),
    ("where(x < 1, 2)", "where takes 3 arguments (got 2)"),
    ("min(x)", "min takes 2 or more arguments (got 1)"),
    ("where(x, 1, 2)", "argument 1 of where must be a condition (got a number) at position 7"),
    ("where(x < 1, y > 0, 2)", "argument 2 of where must be a number (got a condition)"),
    ("x < 1", "a condition where a number is needed at position 1 in \"x < 1\" (write where(condition, a, b))"),
    ("(x < 1) + 1", "an operand of an arithmetic operator must be a number (got a condition)"),
    ("where(x and y, 1, 2)", "an operand of 'and' must be a condition (got a number)"),
    ("where(not x, 1, 2)", "the operand of 'not' must be a condition (got a number)"),
    ("-(x < 1)", "the operand of unary minus must be a number (got a condition)"),
    ("where((x < 1) < 2, 1, 2)", "a side of a comparison must be a number (got a condition)"),
    ("x if y else 1", "'a if c else b' (write where(c, a, b)) not allowed"),
    ("x ^ 2", "'^' (write ** for a power) not allowed"),
    ("x // 2", "'//' not allowed"), ("x % 2", "'%' not allowed"), ("~x", "'~' not allowed"),
    ("x in y", "'in' not allowed"), ("x is y", "'is' not allowed"),
    ("(a := 1)", "':=' not allowed at position 2"), ("(x, y)", "tuples not allowed"), ("[x]", "lists not allowed"),
    ("{x: 1}", "dicts not allowed"), ("True", "True/False not allowed"), ("None", "None not allowed"),
    ("1j", "the literal 1j not allowed"), ("...", "the literal Ellipsis not allowed"),
    ("sqrt", "'sqrt' is a function at position 1 in \"sqrt\" (call it: sqrt(...))"),
    ("x(1)", "'x' is not a function at position 1"), ("e", "unknown name 'e'"),
    ("0.3*(x", "invalid syntax at position 5 in \"0.3*(x\" ('(' was never closed)"),
    ("x +", "invalid syntax at position"), ("import os", "invalid syntax at position 1"),
    ("x; y", "invalid syntax"), ("", "empty expression"), ("  \n ", "empty expression"),
    ("1e999", "number 1e999 out of range at position 1"), ("9" * 400, "out of range"),
    ("x\0", "control character at position 2 in \"x?\""), ("x\x1b[2J", "control character at position 2"),
    ("1and x", "invalid syntax at position 1 in \"1and x\" (invalid decimal literal)"),
])
def test_refusals_name_the_key_the_token_and_the_position(text, message):
    got = refusal(text)
    assert got.startswith("contact.friction: ") and message in got and "\n" not in got, got


def test_refusals_of_non_strings():
    assert refusal(3.0, "contact.wear") == "contact.wear: must be a number or an expression string (got 3.0)"


def test_length_and_depth_are_limited():
    assert refusal("x+" * MAX_LENGTH + "x") == f"contact.friction: expression longer than {MAX_LENGTH} characters " \
                                               f"(got {2 * MAX_LENGTH + 1})"
    deep = "-" * 200 + "x"
    assert refusal(deep).startswith(f"contact.friction: expression nested deeper than {MAX_DEPTH} levels in \"---")
    assert "too many nested parentheses" in refusal("(" * 300 + "x" + ")" * 300)
    assert len(refusal("(" * 300 + "x" + ")" * 300)) < 250                       # the echo of the text is cut
    np.testing.assert_array_equal(value("-" * 20 + "x"), X)                          # reasonable nesting is fine


def test_overflow_and_domain_errors_are_refused_as_non_finite():
    pts = np.array([[0.5, 0.1, 0.0], [0.13, -0.02, 0.0]])
    for text, got in (("1e308*10", "inf at (0.5, 0.1, 0)"), ("exp(2000*x)", "inf at (0.5, 0.1, 0)"),
                      ("log(y)", "nan at (0.13, -0.02, 0)"), ("1/(x-0.5)", "inf at (0.5, 0.1, 0)"),
                      ("sqrt(-x)", "nan at (0.5, 0.1, 0)"), ("10**400", "inf at (0.5, 0.1, 0)"),
                      ("-1e200*1e200", "-inf at (0.5, 0.1, 0)"), ("1e308*10 - 1e308*10", "nan at (0.5, 0.1, 0)")):
        with pytest.raises(SceneError) as err:
            values_at(text, "contact.wear", pts, lo=0)
        assert str(err.value) == f"contact.wear: must be finite at every contact point (got {got})"


def test_range_messages_name_the_key_the_value_and_the_first_point():
    pts = np.array([[0.5, 0.1, 0.0], [0.13, -0.02, 0.0], [0.1, -0.3, 0.0]])
    with pytest.raises(SceneError) as err:
        values_at("x - 0.33", "contact.wear", pts, lo=0)
    assert str(err.value) == "contact.wear: must be >= 0 at every contact point (got -0.2 at (0.13, -0.02, 0))"
    with pytest.raises(SceneError, match=r"^contact.stiffness: must be > 0 at every contact point \(got 0 at \(0.5, "):
        values_at("where(x > 0.4, 0, 1)", "contact.stiffness", pts, lo=0, lo_open=True)
    with pytest.raises(SceneError, match=r"^contact.friction: must be >= 0 and <= 2 at every contact point \(got 5 "):
        check_values("contact.friction", np.array([1.0, 5.0, 1.0]), pts, lo=0, hi=2)
    np.testing.assert_array_equal(values_at("x", "k", pts, lo=0, hi=0.5), pts[:, 0])   # the ends are allowed
    with pytest.raises(SceneError, match=r"^k: must be < 0.5 at every contact point \(got 0.5 at \(0.5, 0.1, 0\)\)"):
        values_at("x", "k", pts, hi=0.5, hi_open=True)


def test_values_at_takes_numbers_expressions_arrays_and_callables():
    pts = POINTS[:4]
    np.testing.assert_array_equal(values_at(0.3, "contact.friction", pts, lo=0), np.full(4, 0.3))
    np.testing.assert_array_equal(values_at("2*x", "contact.friction", pts), 2 * pts[:, 0])
    np.testing.assert_array_equal(values_at(Expression.parse("2*x", "k"), "contact.friction", pts), 2 * pts[:, 0])
    np.testing.assert_array_equal(values_at([1, 2, 3, 4], "contact.friction", pts), [1, 2, 3, 4])
    np.testing.assert_array_equal(values_at(lambda p: p[:, 1] ** 2, "contact.friction", pts), pts[:, 1] ** 2)
    with pytest.raises(SceneError, match=r"^contact.wear: must give one value per contact point \(4\) \(got shape"):
        values_at([1.0, 2.0], "contact.wear", pts)
    with pytest.raises(SceneError, match=r"^contact.wear: must be >= 0 at every contact point \(got -1 at"):
        values_at(lambda p: -np.ones(len(p)), "contact.wear", pts, lo=0)


def random_expression(rng, depth):
    """A random well-typed expression and its value at POINTS, built side by side with numpy."""
    if depth == 0 or rng.random() < 0.2:
        choice = rng.integers(5)
        if choice == 4:
            c = round(float(rng.uniform(0.5, 2)), 3)
            return repr(c), np.full(len(POINTS), c)
        return ("x", "y", "z", "pi")[choice], (X, Y, Z, np.full(len(X), np.pi))[choice]
    kind = rng.integers(6)
    a, va = random_expression(rng, depth - 1)
    b, vb = random_expression(rng, depth - 1)
    if kind == 0:
        op = ("+", "-", "*")[rng.integers(3)]
        return f"({a} {op} {b})", {"+": va + vb, "-": va - vb, "*": va * vb}[op]
    if kind == 1:
        return f"({a}) / (2 + cos({b}))", va / (2 + np.cos(vb))
    if kind == 2:
        return f"-sin({a})**2", -np.sin(va) ** 2
    if kind == 3:
        return f"hypot({a}, {b})", np.hypot(va, vb)
    if kind == 4:
        return f"max({a}, {b}, 0.1)", np.maximum(np.maximum(va, vb), 0.1)
    return f"where({a} < {b} or not {b} > 0, {a}, {b})", np.where((va < vb) | ~(vb > 0), va, vb)


def test_fuzz_random_expressions_match_numpy():
    rng = np.random.default_rng(11)
    for _ in range(200):
        text, expected = random_expression(rng, 3)
        np.testing.assert_allclose(value(text), expected, rtol=1e-12, atol=1e-14, err_msg=text)


def test_fuzz_random_token_strings_parse_or_refuse_in_one_line():
    """Any string is either an expression that evaluates to n floats, or refused with a one-line SceneError."""
    tokens = ["x", "y", "z", "pi", "1", "2.5", "1e400", "+", "-", "*", "/", "**", "(", ")", ",", "<", "==", "and",
              "or", "not", "sqrt(", "log(", "min(", "where(", "atan2(", "__import__(", ".", "[", "]", "'", "lambda",
              ":", "=", "if", "else", "*", " ", "abs(", "e"]
    rng = np.random.default_rng(3)
    accepted = 0
    for _ in range(3000):
        text = "".join(rng.choice(tokens, size=rng.integers(1, 12)))
        try:
            out = Expression.parse(text, "contact.wear").evaluate(POINTS)
        except SceneError as err:
            assert str(err).startswith("contact.wear: ") and "\n" not in str(err)
        else:
            accepted += 1
            assert out.shape == (len(POINTS),) and out.dtype == np.float64
    assert accepted > 30      # the parser sees well-formed input too, not only garbage
