"""The safe parser of declared potentials: only numbers, x, y, pi, declared parameters, arithmetic and heyoka's
functions; never eval of user text."""

import pytest

from hhscatter.errors import ConfigError
from hhscatter.model.parse import FUNCTIONS, check_params, parse_potential, substitute, symbols, to_heyoka


def test_parses_a_potential_with_parameters():
    import sympy as sp

    x, y = symbols()
    eps = sp.Symbol("eps", real=True)
    e = parse_potential("0.5*(x**2 + y**2) - eps*x**2*y**2", {"eps": 0.25})
    assert sp.simplify(e - (sp.Rational(1, 2) * (x**2 + y**2) - eps * x**2 * y**2)) == 0
    # parameter values go in as the exact shortest decimal: 0.1 -> 1/10
    assert substitute(parse_potential("eps*x**2 + y**2", {"eps": 0.1}), {"eps": 0.1}) == x**2 / 10 + y**2


def test_every_whitelisted_function_parses_and_converts_to_heyoka():
    import heyoka as hy

    hx, hy_ = hy.make_vars("x", "y")
    for name, nargs in FUNCTIONS.items():
        arg = "0.3*x + 0.1" if nargs == 1 else "y + 2, x + 3"
        e = parse_potential(f"x**2 + y**2 + 0.01*{name}({arg})")
        assert name in str(to_heyoka(e, hx, hy_, hy)) or name == "sqrt"  # sqrt may print as a power


@pytest.mark.parametrize(
    "text, match",
    [
        ("__import__('os')", "unknown function '__import__'"),
        ("x.__class__", "Attribute is not allowed"),
        ("(lambda: 1)()", "only plain function calls"),
        ("lambda x: x", "Lambda is not allowed"),
        ("[x for x in (1,)]", "ListComp is not allowed"),
        ("x[0]", "Subscript is not allowed"),
        ("open('f')", "unknown function 'open'"),
        ("x**2 + z", "unknown symbol 'z'"),
        ("x^2", r"'\^' is not a power"),
        ("x if y else 0", "IfExp is not allowed"),
        ("x == y", "Compare is not allowed"),
        ("'text'", "not a real number"),
        ("True*x", "not a real number"),
        ("x**10**10", "exponent .* out of range"),
        ("sin(x, y)", r"sin\(\) takes 1 argument"),
        ("exp(x=1)", "positional arguments only"),
        ("x +", "is not a Python expression"),
        ("x/0", "division by zero"),
        ("3", "depends on neither x nor y"),
        ("sqrt(x**2) + y**2", r"Abs \('Abs\(x\)'\) is not allowed"),  # sympy's rewrite of sqrt(x**2), caught too
    ],
)
def test_refuses_anything_outside_the_whitelist(text, match):
    with pytest.raises(ConfigError, match=match):
        parse_potential(text)


def test_parser_never_executes_the_text(tmp_path, monkeypatch):
    import builtins

    called = []
    monkeypatch.setattr(builtins, "eval", lambda *a, **k: called.append(a))
    with pytest.raises(ConfigError):
        parse_potential(f"__import__('pathlib').Path('{tmp_path}/x').touch()")
    assert not (tmp_path / "x").exists() and not called


def test_parameter_errors_name_the_parameter():
    with pytest.raises(ConfigError, match=r"parameter\(s\) \['eps'\] have no value"):
        parse_potential("x**2 + y**2 - eps*x*y**2", {"epsilon": 0.1})
    with pytest.raises(ConfigError, match=r"\['lam'\] are not used"):
        parse_potential("x**2 + y**2 - eps*x*y**2", {"eps": 0.1, "lam": 1.0})
    with pytest.raises(ConfigError, match="'eps' must be finite"):
        check_params({"eps": float("nan")})
    with pytest.raises(ConfigError, match="'eps' must be a number"):
        check_params({"eps": "0.1"})
    with pytest.raises(ConfigError, match="'x' is reserved"):
        check_params({"x": 1.0})
    with pytest.raises(ConfigError, match="not a plain identifier"):
        check_params({"a b": 1.0})


def test_accepts_sympy_and_heyoka_expressions_checked_alike():
    import heyoka as hy
    import sympy as sp

    x, y, eps = sp.symbols("x y eps")
    e = parse_potential(x**2 / 2 + y**2 / 2 - eps * x * y**2, {"eps": 0.5})
    assert str(e) == "-eps*x*y**2 + x**2/2 + y**2/2"
    hx, hy_ = hy.make_vars("x", "y")
    e2 = parse_potential(0.5 * hx**2 + 0.5 * hy_**2 + hx**2 * hy_)
    assert sp.simplify(e2 - (x**2 / 2 + y**2 / 2 + x**2 * y).subs({x: symbols()[0], y: symbols()[1]})) == 0
    with pytest.raises(ConfigError, match="unknown symbol 'z'"):
        parse_potential(x**2 + sp.Symbol("z"))
    with pytest.raises(ConfigError, match="Abs"):
        parse_potential(sp.Abs(x) + y**2)
    with pytest.raises(ConfigError, match="must be text, a sympy or a heyoka expression"):
        parse_potential(3.0)
