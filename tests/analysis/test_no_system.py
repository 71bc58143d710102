"""A system is data: the estimators' code knows no particular system.

No module of ``hhscatter.analysis`` imports a concrete system (Hénon–Heiles, the built-ins, the factory that
makes them): it may import only the system's contract and the generic machinery that reads any system's
potential. Its code (docstrings aside) writes no Hénon–Heiles value — E_c = 1/6 of ω = λ = 1, the
coefficients of the reference κ0(E) law — and no public estimator falls back on a default system. A docstring
example may build any system, Hénon–Heiles included, as the input of a computation with a closed-form answer:
that is a use of the estimator, not knowledge inside it.
"""

from __future__ import annotations

import ast
import inspect
import math
from pathlib import Path

import pytest
from _walk import docstring_ids, public_callables

import hhscatter.analysis

ROOT = Path(hhscatter.analysis.__file__).parent
MODULES = sorted(ROOT.rglob("*.py"))

#: what of hhscatter.model an estimator may import: the contract of a system and the generic reading of a potential
ALLOWED_MODULES = {"hhscatter.model.base", "hhscatter.model.landscape", "hhscatter.model.parse"}
ALLOWED_FROM_MODEL = {"System", "Exit", "DISSIPATIONS"}

#: Hénon–Heiles values, from their closed forms (not from the model's code): E_c = ω⁶/(6λ²) at ω = λ = 1, and the
#: coefficients a2 = 13.63 and slope = 1.41 of the reference κ0(E) law (Burton, Dullin & Altmann 2023)
SYSTEM_VALUES = (1.0 / 6.0, 13.63, 1.41)


def model_imports(source: str) -> list[tuple[int, str]]:
    """(line, what) of every import of hhscatter.model outside the allowed contract, at any depth of the code."""
    bad = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names if a.name.startswith("hhscatter.model")]
            bad += [(node.lineno, m) for m in names if m not in ALLOWED_MODULES]
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("hhscatter.model"):
            if node.module == "hhscatter.model":
                bad += [
                    (node.lineno, f"hhscatter.model.{a.name}") for a in node.names if a.name not in ALLOWED_FROM_MODEL
                ]
            elif node.module not in ALLOWED_MODULES:
                bad += [(node.lineno, f"{node.module}.{a.name}") for a in node.names]
    return bad


def system_values(source: str) -> list[tuple[int, str]]:
    """(line, what) of every Hénon–Heiles value or name the code writes: a number equal to one of
    :data:`SYSTEM_VALUES`, the quotient 1/6 of two literals, a name or a string (docstrings aside) that says
    Hénon–Heiles."""
    tree = ast.parse(source)
    docs = docstring_ids(tree)
    hits = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and id(node) not in docs:
            v = node.value
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                if any(math.isclose(v, s, rel_tol=1e-9) for s in SYSTEM_VALUES):
                    hits.append((node.lineno, repr(v)))
            elif isinstance(v, str) and ("henon" in v.lower() or "hénon" in v.lower()):
                hits.append((node.lineno, repr(v)))
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div):
            if all(isinstance(s, ast.Constant) for s in (node.left, node.right)):
                if (node.left.value, node.right.value) == (1, 6):
                    hits.append((node.lineno, ast.unparse(node)))
        elif isinstance(node, ast.Name) and "henon" in node.id.lower():
            hits.append((node.lineno, node.id))
        elif isinstance(node, ast.Attribute) and "henon" in node.attr.lower():
            hits.append((node.lineno, node.attr))
    return hits


def test_the_import_check_sees_a_concrete_system():
    source = (
        "from hhscatter.model import HenonHeiles, System\n"
        "def f():\n"
        "    from hhscatter.model.builtins import make_system  # deferred\n"
        "    import hhscatter.model.henon_heiles\n"
        "from hhscatter.model.base import System\n"
        "from hhscatter.model.landscape import Landscape\n"
    )
    assert model_imports(source) == [
        (1, "hhscatter.model.HenonHeiles"),
        (3, "hhscatter.model.builtins.make_system"),
        (4, "hhscatter.model.henon_heiles"),
    ]


def test_the_value_check_sees_a_system_value_in_code_not_in_a_docstring():
    source = (
        '"""E_c = 1/6 for Hénon–Heiles: a docstring may explain."""\n'
        "E_C = 1 / 6\n"
        "def f(a2=13.63, slope=1.41, x=0.1667):\n"
        '    """>>> f(E_c=1 / 6)"""\n'
        "    return HenonHeiles().critical_energy or 0.16666666666666666 or 'Hénon–Heiles'\n"
    )
    found = sorted(system_values(source))
    assert found == [
        (2, "1 / 6"),
        (3, "1.41"),
        (3, "13.63"),
        (5, "'Hénon–Heiles'"),
        (5, "0.16666666666666666"),
        (5, "HenonHeiles"),
    ]


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_estimator_imports_a_concrete_system(path):
    bad = [f"{path.relative_to(ROOT)}:{n} {what}" for n, what in model_imports(path.read_text())]
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_estimator_writes_a_henon_heiles_value(path):
    bad = [f"{path.relative_to(ROOT)}:{n} {what}" for n, what in system_values(path.read_text())]
    assert not bad, "\n".join(bad)


def test_no_public_estimator_defaults_its_system():
    """A parameter that takes a system (``system``, ``model``) has no default: the caller names the system."""
    seen, bad = 0, []
    for sub, _, stem, name, obj in public_callables():
        try:
            params = inspect.signature(obj).parameters
        except (TypeError, ValueError):
            continue
        for p in params.values():
            if p.name in ("system", "model"):
                seen += 1
                if p.default is not p.empty:
                    bad.append(f"{sub}.{stem}.{name}({p.name}={p.default!r})")
    assert seen >= 10  # the check reads the estimators that take a system
    assert not bad, bad


def test_the_kappa_law_has_no_default_coefficients():
    """The piecewise κ0(E) law is the data of a fit or of a reference: every coefficient is required."""
    from hhscatter.analysis.survival.kappa_law import PiecewiseKappa

    params = inspect.signature(PiecewiseKappa).parameters
    assert list(params) == ["E_c", "a2", "a1", "slope", "E_switch"]
    assert all(p.default is p.empty for p in params.values())
    with pytest.raises(TypeError, match="a2"):
        PiecewiseKappa(E_c=0.25)
