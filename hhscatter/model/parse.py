"""Safe parsing of a declared potential V(x, y): text, a sympy expression or a heyoka expression → sympy.

A potential given as text (a scene file's ``[system] potential = "…"``, the CLI's ``--system``) is never
handed to ``eval`` or ``sympify``: :func:`parse_potential` walks Python's :mod:`ast` of the text and accepts
only

- numbers (int or float literals),
- the names ``x``, ``y``, ``pi`` and the declared parameters,
- ``+ - * / **`` and unary ``-``/``+``,
- calls of the functions heyoka integrates (:data:`FUNCTIONS`), positional arguments only.

Anything else (attribute access, subscripts, lambdas, comprehensions, keywords, ``^``, a name or function not
in the lists, a power with an exponent beyond ±:data:`MAX_EXPONENT`) is a
:class:`~hhscatter.errors.ConfigError` naming the offending piece. A sympy expression or a heyoka expression
(converted with ``heyoka.to_sympy``) is checked node by node against the same lists.

Parameters are kept as symbols in the parsed expression (for the provenance); :func:`substitute` puts in
their values as exact rationals (the shortest decimal of each float: 0.1 → 1/10), so the symbolic
derivation (:mod:`hhscatter.model.derive`) works on exact polynomials.

sympy is imported on first use (it takes ~0.3 s to import).
"""

from __future__ import annotations

import ast
import functools
import keyword
import math
import sys
from collections.abc import Mapping
from typing import Any

from hhscatter.errors import ConfigError

#: the functions a potential may call: name → number of arguments (all integrated by heyoka)
FUNCTIONS = {
    "sin": 1,
    "cos": 1,
    "tan": 1,
    "asin": 1,
    "acos": 1,
    "atan": 1,
    "atan2": 2,
    "sinh": 1,
    "cosh": 1,
    "tanh": 1,
    "asinh": 1,
    "acosh": 1,
    "atanh": 1,
    "exp": 1,
    "log": 1,
    "sqrt": 1,
    "erf": 1,
}
#: the names a potential may use besides its parameters
VARIABLES = ("x", "y")
CONSTANTS = ("pi",)
#: largest |exponent| of a power with a constant exponent (``x**10**10`` would hang the symbolic algebra)
MAX_EXPONENT = 64
#: longest accepted potential text (characters)
MAX_TEXT = 10_000
#: most syntax-tree nodes and deepest nesting of a potential's text: beyond, parsing alone exhausts Python's parser
#: (9000 nested unary minus signs: MemoryError) and the symbolic algebra slows down without bound
MAX_NODES, MAX_DEPTH = 2_000, 200
#: largest polynomial degree of a potential (an upper bound from its expression: sums take the largest, products
#: add, powers multiply): the symbolic derivation's cost grows steeply with it (a dense degree-9 polynomial ≈ 7 s)
MAX_DEGREE = 16
#: largest magnitude of a constant, as a power of two: a double's range (≈ 1.8e308); a constant beyond it would
#: be inf in the integrator, and exact integer powers such as ((9**64)**64)**64 run for minutes in the algebra
MAX_CONSTANT_BITS = 1023

_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}


def symbols():
    """(x, y): the real sympy symbols every parsed potential is written in."""
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    return sp.Symbol("x", real=True), sp.Symbol("y", real=True)


def _sympy_functions() -> dict[str, Any]:
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    return {name: getattr(sp, name) for name in FUNCTIONS}


def check_params(params: Mapping[str, Any] | None) -> dict[str, float]:
    """Check the parameters' names and values: name → finite float.

    Parameters
    ----------
    params : mapping of str to float, or None
        The potential's parameters.

    Returns
    -------
    dict of str to float
        The same parameters as floats.

    Raises
    ------
    ConfigError
        A name that is not an identifier, a keyword, ``x``, ``y``, ``pi`` or a function's name; a value that
        is not a finite real number.

    Examples
    --------
    >>> check_params({"eps": 0.25})
    {'eps': 0.25}
    """
    out: dict[str, float] = {}
    for name, value in dict(params or {}).items():
        if not isinstance(name, str) or not name.isidentifier() or keyword.iskeyword(name) or name.startswith("_"):
            raise ConfigError(f"system parameter name {name!r} is not a plain identifier")
        if name in VARIABLES or name in CONSTANTS or name in FUNCTIONS:
            raise ConfigError(
                f"system parameter name {name!r} is reserved (the variables x, y, the constant pi "
                f"and the functions {', '.join(FUNCTIONS)})"
            )
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"system parameter {name!r} must be a number, got {value!r}")
        if not math.isfinite(value):
            raise ConfigError(f"system parameter {name!r} must be finite, got {value!r}")
        out[name] = float(value)
    return out


def _rational(value: float):
    """The shortest decimal of a float as an exact sympy Rational (0.1 → 1/10)."""
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    return sp.Rational(repr(float(value)))


class _Walker:
    """Builds the sympy expression of a parsed ``ast`` node by node, refusing everything not whitelisted."""

    def __init__(self, names: set[str]):
        import sympy as sp  # deferred: sympy takes ~0.3 s to import

        self.sp = sp
        x, y = symbols()
        self.names = {"x": x, "y": y, "pi": sp.pi}
        self.names.update({n: sp.Symbol(n, real=True) for n in names})
        self.functions = _sympy_functions()

    def __call__(self, node: ast.AST):
        sp = self.sp
        if isinstance(node, ast.Expression):
            return self(node.body)
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                raise ConfigError(f"potential: the constant {node.value!r} is not a real number")
            if isinstance(node.value, float) and not math.isfinite(node.value):
                raise ConfigError(f"potential: the constant {node.value!r} is not finite")
            return sp.Integer(node.value) if isinstance(node.value, int) else _rational(node.value)
        if isinstance(node, ast.Name):
            if node.id not in self.names:
                raise ConfigError(
                    f"potential: unknown symbol {node.id!r} (allowed: x, y, pi and the parameters "
                    f"{sorted(set(self.names) - {'x', 'y', 'pi'}) or 'none declared'}; "
                    "declare a parameter in [system.params])"
                )
            return self.names[node.id]
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            v = self(node.operand)
            return -v if isinstance(node.op, ast.USub) else v
        if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
            a, b = self(node.left), self(node.right)
            if isinstance(node.op, ast.Add):
                return a + b
            if isinstance(node.op, ast.Sub):
                return a - b
            if isinstance(node.op, ast.Mult):
                return a * b
            if isinstance(node.op, ast.Div):
                if b == 0:
                    raise ConfigError("potential: division by zero")
                return a / b
            if b.is_number and (not b.is_real or abs(float(b)) > MAX_EXPONENT):
                raise ConfigError(f"potential: the exponent {b} is out of range (|exponent| ≤ {MAX_EXPONENT})")
            if a.is_number and b.is_number and _log2_abs(a) * abs(float(b)) > MAX_CONSTANT_BITS:
                raise ConfigError(
                    f"potential: the constant {ast.unparse(node)[:60]!r} is out of range (beyond a "
                    f"double's ≈ 1.8e308 or below its smallest normal number)"
                )
            return a**b
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitXor):
            raise ConfigError("potential: '^' is not a power in Python syntax; write x**2, not x^2")
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name):
                raise ConfigError(f"potential: only plain function calls are allowed, not {ast.unparse(node.func)!r}")
            name = node.func.id
            if name not in FUNCTIONS:
                raise ConfigError(f"potential: unknown function {name!r} (allowed: {', '.join(FUNCTIONS)})")
            if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
                raise ConfigError(f"potential: {name}() takes positional arguments only")
            if len(node.args) != FUNCTIONS[name]:
                raise ConfigError(f"potential: {name}() takes {FUNCTIONS[name]} argument(s), got {len(node.args)}")
            return self.functions[name](*(self(a) for a in node.args))
        raise ConfigError(
            f"potential: {type(node).__name__} is not allowed in a potential "
            f"({ast.unparse(node)[:60]!r}); use numbers, x, y, parameters, + - * / ** and "
            f"the functions {', '.join(FUNCTIONS)}"
        )


def _log2_abs(v) -> float:
    """|log2 |v|| of a sympy number, without evaluating it as a double (exact integers may be huge)."""
    if v == 0:
        return 0.0
    if v.is_Rational:
        return abs(abs(int(v.p)).bit_length() - int(v.q).bit_length())
    try:
        return abs(math.log2(abs(float(v))))
    except (OverflowError, ValueError):
        return math.inf


def _check_tree(tree: ast.AST) -> None:
    """ConfigError for a syntax tree beyond MAX_NODES nodes or MAX_DEPTH levels (checked without recursion)."""
    count, stack = 0, [(tree, 0)]
    while stack:
        node, depth = stack.pop()
        count += 1
        if depth > MAX_DEPTH:
            raise ConfigError(f"potential: the expression is nested more than {MAX_DEPTH} levels deep")
        if count > MAX_NODES:
            raise ConfigError(f"potential: the expression has more than {MAX_NODES} terms and operations")
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))


def degree_bound(expr) -> int:
    """An upper bound of the polynomial degree of a sympy expression in x, y, from its tree: sums take the largest,
    products add, a power multiplies by |exponent| (its ceiling), a function keeps its arguments' largest.

    Examples
    --------
    >>> degree_bound(parse_potential("x**2/2 + y**2/2 + x**2*y - y**3/3"))
    3
    """
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    def deg(e) -> int:
        if e.is_Symbol:
            return 1 if e.name in VARIABLES else 0
        if e.is_number:
            return 0
        if isinstance(e, sp.Add):
            return max(deg(a) for a in e.args)
        if isinstance(e, sp.Mul):
            return sum(deg(a) for a in e.args)
        if isinstance(e, sp.Pow):
            base = deg(e.base)
            if e.exp.is_number:
                return base * math.ceil(abs(float(e.exp)))
            return base + deg(e.exp)
        return max((deg(a) for a in e.args), default=0)

    return deg(expr)


def _check_sympy(expr, names: set[str]):
    """Check a sympy expression node by node against the whitelist; return it in the real symbols x, y, params."""
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    allowed_functions = tuple(f for f in _sympy_functions().values() if isinstance(f, type))  # sqrt is a Pow
    x, y = symbols()
    for node in sp.preorder_traversal(expr):
        if isinstance(node, sp.Symbol):
            if node.name not in {"x", "y", *names}:
                raise ConfigError(
                    f"potential: unknown symbol {node.name!r} (allowed: x, y and the parameters "
                    f"{sorted(names) or 'none declared'})"
                )
        elif isinstance(node, sp.Number):
            if not node.is_finite or not node.is_real:
                raise ConfigError(f"potential: the constant {node} is not a finite real number")
            if _log2_abs(node) > MAX_CONSTANT_BITS:
                raise ConfigError(
                    f"potential: the constant {str(node)[:40]} is out of range (beyond a double's "
                    "≈ 1.8e308 or below its smallest normal number)"
                )
        elif isinstance(node, (sp.NumberSymbol, sp.Add, sp.Mul, sp.Pow)):  # NumberSymbol: pi, E
            if isinstance(node, sp.Pow) and node.exp.is_number and abs(float(node.exp)) > MAX_EXPONENT:
                raise ConfigError(f"potential: the exponent {node.exp} is out of range (|exponent| ≤ {MAX_EXPONENT})")
        elif not isinstance(node, allowed_functions):
            raise ConfigError(
                f"potential: {type(node).__name__} ({str(node)[:60]!r}) is not allowed "
                f"(allowed functions: {', '.join(FUNCTIONS)})"
            )
    real = {s: sp.Symbol(s.name, real=True) for s in expr.free_symbols}
    return expr.xreplace(real)


def parse_potential(source: Any, params: Mapping[str, Any] | None = None):
    """Parse a potential V(x, y) safely into a sympy expression in x, y and the parameters' symbols.

    Parameters
    ----------
    source : str, sympy.Expr or heyoka.expression
        The potential: Python-syntax text (``"0.5*(x**2 + y**2) - eps*x**2*y**2"``), a sympy expression or a
        heyoka expression, in the variables x, y and the parameters' names.
    params : mapping of str to float, optional
        The parameters' values; every parameter the potential uses must have one, and every one given must be
        used (an unused parameter is most likely a misspelt one).

    Returns
    -------
    sympy.Expr
        V with the parameters as (real) symbols; :func:`substitute` puts in their values.

    Raises
    ------
    ConfigError
        Text that is not a Python expression, an unknown symbol or function, a construct outside the whitelist
        (module docstring), a parameter without a value or not used, a non-finite parameter.

    Examples
    --------
    >>> parse_potential("0.5*(x**2 + y**2) - eps*x**2*y**2", {"eps": 0.25})
    -eps*x**2*y**2 + x**2/2 + y**2/2
    >>> parse_potential("__import__('os')")
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: potential: unknown function '__import__' (allowed: sin, cos, tan, asin, acos, atan, atan2, sinh, cosh, tanh, asinh, acosh, atanh, exp, log, sqrt, erf)
    """
    values = check_params(params)
    names = set(values)
    if isinstance(source, str):
        if len(source) > MAX_TEXT:
            raise ConfigError(f"potential: the text is longer than {MAX_TEXT} characters")
        try:
            tree = ast.parse(source.strip(), mode="eval")
        except SyntaxError as e:
            raise ConfigError(f"potential: {source[:60]!r} is not a Python expression ({e.msg})") from None
        except (MemoryError, RecursionError):  # Python's parser gives up on very deep nesting
            raise ConfigError(f"potential: the expression is nested more than {MAX_DEPTH} levels deep") from None
        _check_tree(tree)
        # every name the text uses, so that a missing parameter is named as such (not as an unknown symbol)
        used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        called = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
        free = used - called - set(VARIABLES) - set(CONSTANTS)
        missing = sorted(free - names)
        if missing and values:  # parameters declared, but not these: a missing value, not a stray name
            raise ConfigError(
                f"potential: parameter(s) {missing} have no value; give them in [system.params] "
                f"(given: {sorted(names)})"
            )
        try:
            expr = _Walker(names)(tree)
        except RecursionError:
            raise ConfigError("potential: the expression is nested too deeply") from None
        # sympy may have rewritten a part outside the whitelist (real x: sqrt(x**2) -> Abs(x)): check again
        expr = _check_sympy(expr, names)
    else:
        mod = type(source).__module__ or ""
        if mod.startswith("heyoka"):
            # a heyoka expression was given, so heyoka is loaded: its module is taken from it, not imported here
            hy = sys.modules[mod.partition(".")[0]]
            try:
                source = hy.to_sympy(source)
            except (TypeError, ValueError) as e:
                raise ConfigError(f"potential: the heyoka expression cannot be converted to sympy ({e})") from None
        elif not mod.startswith("sympy"):
            raise ConfigError(f"potential must be text, a sympy or a heyoka expression, got {type(source).__name__}")
        expr = _check_sympy(source, names)
    used_names = {s.name for s in expr.free_symbols} - set(VARIABLES)
    missing = sorted(used_names - names)
    if missing:
        raise ConfigError(f"potential: parameter(s) {missing} have no value; give them in [system.params]")
    unused = sorted(names - used_names)
    if unused:
        raise ConfigError(
            f"system parameter(s) {unused} are not used in the potential {str(expr)!r} "
            "(misspelt? remove them or use them)"
        )
    if not ({s.name for s in expr.free_symbols} & set(VARIABLES)):
        raise ConfigError(f"potential: {str(expr)!r} depends on neither x nor y")
    if (d := degree_bound(expr)) > MAX_DEGREE:
        raise ConfigError(
            f"potential: its degree is up to {d}, more than {MAX_DEGREE} (the derivation's cost grows "
            "steeply with the degree)"
        )
    return expr


def substitute(expr, params: Mapping[str, float]):
    """V with the parameters' values put in as exact rationals (the shortest decimal of each float).

    Parameters
    ----------
    expr : sympy.Expr
        A potential from :func:`parse_potential`.
    params : mapping of str to float
        The parameters' values.

    Returns
    -------
    sympy.Expr
        V in x and y only.

    Examples
    --------
    >>> substitute(parse_potential("x**2/2 + y**2/2 - eps*x*y**2", {"eps": 0.1}), {"eps": 0.1})
    x**2/2 - x*y**2/10 + y**2/2
    """
    subs = {s: _rational(params[s.name]) for s in expr.free_symbols if s.name in params}
    return expr.xreplace(subs)


def to_heyoka(expr, x, y, hy):
    """The heyoka expression of a sympy expression in x, y (parameters already substituted), built by walking it.

    Rationals become double constants; integer powers stay integer powers (heyoka expands squares and small
    powers cheaply); ``Pow(·, ±1/2)`` becomes ``sqrt``.

    Parameters
    ----------
    expr : sympy.Expr
        A potential or force in x and y only (:func:`substitute`).
    x, y : heyoka.expression
        The heyoka variables.
    hy : module
        The heyoka module (the engine hands it in: the model does not import heyoka).

    Returns
    -------
    heyoka.expression

    Examples
    --------
    >>> import heyoka as hy
    >>> hx, hy_ = hy.make_vars("x", "y")
    >>> e = substitute(parse_potential("0.5*x**2 - eps*x*y", {"eps": 2}), {"eps": 2})
    >>> print(to_heyoka(e, hx, hy_, hy))
    ((0.50000000000000000 * x**2.0000000000000000) - (2.0000000000000000 * (x * y)))
    """
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    funcs = {getattr(sp, n): getattr(hy, n) for n in FUNCTIONS}
    names = {"x": x, "y": y}

    def walk(e):
        if isinstance(e, sp.Symbol):
            if e.name not in names:
                raise ConfigError(f"potential: symbol {e.name!r} has no value")
            return names[e.name]
        if e.is_Number or e.is_NumberSymbol:
            return hy.expression(float(e))
        if isinstance(e, sp.Add):
            terms = [walk(a) for a in _ordered(e.args)]
            out = terms[0]
            for t in terms[1:]:
                out = out + t
            return out
        if isinstance(e, sp.Mul):
            coeff, rest = e.as_coeff_Mul()
            if coeff == -1:
                return -walk(rest)
            if coeff != 1:
                return float(coeff) * walk(rest)
            factors = [walk(a) for a in _ordered(e.args)]
            out = factors[0]
            for f in factors[1:]:
                out = out * f
            return out
        if isinstance(e, sp.Pow):
            base, ex = walk(e.base), e.exp
            if ex == sp.Rational(1, 2):
                return hy.sqrt(base)
            if ex == sp.Rational(-1, 2):
                return 1.0 / hy.sqrt(base)
            if ex.is_Integer and int(ex) < 0:
                return 1.0 / base ** int(-ex)
            return base ** (int(ex) if ex.is_Integer else walk(ex))
        if type(e) in funcs:
            return funcs[type(e)](*(walk(a) for a in e.args))
        raise ConfigError(f"potential: cannot convert {type(e).__name__} ({e}) to heyoka")

    return walk(expr)


def _ordered(args):
    """sympy's printing order of an Add's or Mul's arguments (deterministic whatever the hash seed)."""
    import sympy as sp  # deferred: sympy takes ~0.3 s to import

    return sorted(args, key=sp.default_sort_key)


__all__ = [
    "CONSTANTS",
    "FUNCTIONS",
    "MAX_CONSTANT_BITS",
    "MAX_DEGREE",
    "MAX_DEPTH",
    "MAX_EXPONENT",
    "MAX_NODES",
    "VARIABLES",
    "check_params",
    "parse_potential",
    "substitute",
    "symbols",
    "to_heyoka",
    "degree_bound",
]


@functools.lru_cache(maxsize=16)
def force_source(text: str, params: tuple[tuple[str, float], ...]) -> tuple[str, str]:
    """force_source(V as text, ((name, value), ...)) -> (F_x, F_y) = −∇V as Python source in x, y (functions of
    the ``math`` module), for a compiled integrator that takes the force as code (cached per text and parameters).

    Examples
    --------
    V = (x² + y²)/2 + a x²y gives F = (−x − 2axy, −y − ax²); at (0.3, 0.2) with a = 1, (−0.42, −0.29):

    >>> fx, fy = force_source("(x**2 + y**2)/2 + a*x**2*y", (("a", 1.0),))
    >>> [round(eval(f, {"x": 0.3, "y": 0.2}), 12) for f in (fx, fy)]
    [-0.42, -0.29]
    """
    model_params = dict(params)
    import sympy as sp  # deferred: sympy takes ~0.3 s to import
    from sympy.printing.pycode import PythonCodePrinter  # deferred: with sympy

    V = substitute(parse_potential(text, model_params), model_params)
    x, y = sp.Symbol("x", real=True), sp.Symbol("y", real=True)
    names = {s.name: s for s in V.free_symbols}
    V = V.subs({names[n]: s for n, s in (("x", x), ("y", y)) if n in names})
    printer = PythonCodePrinter({"fully_qualified_modules": True})
    return printer.doprint(-sp.diff(V, x)), printer.doprint(-sp.diff(V, y))
