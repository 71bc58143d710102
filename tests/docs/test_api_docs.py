"""The top-level API documents itself: numpy-style sections, every parameter named and typed, a runnable example.

The examples themselves run as doctests (pyproject: testpaths include the package, --doctest-modules);
this module checks that they and the sections are there, for every public object of ``hhscatter``.
"""

import inspect
import re
from pathlib import Path

import pytest

import hhscatter

PUBLIC = [
    n for n in hhscatter.__all__ if inspect.isfunction(getattr(hhscatter, n)) or inspect.isclass(getattr(hhscatter, n))
]


def sections(doc: str) -> dict[str, str]:
    """{section title: body} of a numpy-style docstring (title line followed by a line of dashes)."""
    parts = re.split(r"^(\w[\w ]*)\n-{3,}\n", doc, flags=re.M)
    return {parts[i].strip(): parts[i + 1] for i in range(1, len(parts) - 1, 2)}


def documented_names(body: str) -> set[str]:
    """Names of the entries of a Parameters/Attributes section: 'a, b : type' or '**kwargs' at the margin."""
    names = set()
    for line in body.splitlines():
        m = re.match(r"^(\*{0,2}\w+(?:, \*{0,2}\w+)*)(?: :|$)", line)
        if m and not line.startswith(" "):
            names |= {n.strip().lstrip("*") for n in m.group(1).split(",")}
    return names


def parameters(obj) -> list[inspect.Parameter]:
    try:
        sig = inspect.signature(obj)
    except ValueError:  # a builtin-derived exception class
        return []
    return [p for p in sig.parameters.values() if p.name not in ("self", "cls")]


def test_sections_helper_parses_a_numpy_docstring():
    doc = "Sum.\n\nParameters\n----------\na, b : float\n    Terms.\n**kw\n    More.\n\nReturns\n-------\nfloat\n"
    s = sections(doc)
    assert list(s) == ["Parameters", "Returns"]
    assert documented_names(s["Parameters"]) == {"a", "b", "kw"}


def test_the_public_api_is_not_empty():
    assert {"Scene", "simulate", "read_lifetimes", "survival", "escape_rates"} <= set(PUBLIC)


@pytest.mark.parametrize("name", PUBLIC)
def test_public_object_has_sections_and_an_example(name):
    obj = getattr(hhscatter, name)
    doc = inspect.getdoc(obj) or ""
    s = sections(doc)
    assert doc.split("\n")[0].strip(), f"{name}: no one-line summary"
    assert "Examples" in s and ">>> " in s["Examples"], f"{name}: no Examples section with a doctest"
    params = [p for p in parameters(obj)]
    if params:
        key = "Parameters" if "Parameters" in s else "Attributes"
        assert key in s, f"{name}: takes {[p.name for p in params]} but has no Parameters/Attributes section"
        missing = {p.name for p in params} - documented_names(s[key])
        assert not missing, f"{name}: parameters not documented: {sorted(missing)}"
    if inspect.isfunction(obj):
        assert "Returns" in s, f"{name}: no Returns section"


@pytest.mark.parametrize("name", PUBLIC)
def test_public_object_is_fully_typed(name):
    obj = getattr(hhscatter, name)
    params = parameters(obj)
    untyped = [p.name for p in params if p.annotation is inspect.Parameter.empty]
    assert not untyped, f"{name}: parameters without a type hint: {untyped}"
    if inspect.isfunction(obj):
        assert inspect.signature(obj).return_annotation is not inspect.Signature.empty, f"{name}: no return type"


METHODS = [
    f"{n}.{m}"
    for n in PUBLIC
    if inspect.isclass(getattr(hhscatter, n))
    for m, v in vars(getattr(hhscatter, n)).items()
    if not m.startswith("_") and inspect.isfunction(v)
]


def test_public_classes_have_public_methods():
    assert {"SurvivalCurves.to_frame", "EscapeRates.plot", "HenonHeiles.potential", "Scene.replace"} <= set(METHODS)


@pytest.mark.parametrize("name", METHODS)
def test_public_method_is_fully_typed(name):
    cls, meth = name.split(".")
    sig = inspect.signature(getattr(getattr(hhscatter, cls), meth))
    untyped = [
        p.name
        for p in sig.parameters.values()
        if p.name not in ("self", "cls") and p.annotation is inspect.Parameter.empty
    ]
    assert not untyped, f"{name}: parameters without a type hint: {untyped}"
    assert sig.return_annotation is not inspect.Signature.empty, f"{name}: no return type"


def test_the_api_index_names_every_top_level_name():
    """The API index's list of the names `import hhscatter` offers is hhscatter.__all__, nothing more or less."""
    page = (Path(__file__).resolve().parents[2] / "docs" / "api" / "index.md").read_text()
    listed = page.split("`import hhscatter` is cheap and has no side effects; the top-level names")[1]
    listed = listed.split("are imported lazily")[0]
    assert set(re.findall(r"`(\w+)`", listed)) == set(hhscatter.__all__)
