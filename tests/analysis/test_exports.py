"""Each analysis subpackage exports the public names of its modules, each the object its module defines."""

import importlib

import pytest


@pytest.mark.parametrize("sub", ["stats", "survival", "dissipative", "geometry", "claims", "noise"])
def test_subpackage_exports_its_modules_public_names(sub):
    pkg = importlib.import_module(f"hhscatter.analysis.{sub}")
    assert pkg.__all__ and set(pkg.__all__) <= set(dir(pkg))
    for name in pkg.__all__:
        obj = getattr(pkg, name)
        home = importlib.import_module(f"{pkg.__name__}.{pkg._EXPORTS[name]}")
        assert getattr(home, name) is obj, name
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        pkg.no_such_name  # noqa: B018


def test_a_name_is_exported_from_the_module_that_defines_it():
    from hhscatter.analysis import geometry, survival

    assert survival._EXPORTS["survival_curve"] == "kaplan_meier" and geometry._EXPORTS["UnitSet"] == "paired_distance"


@pytest.mark.parametrize("sub", ["stats", "survival", "dissipative", "geometry", "claims", "noise"])
def test_every_name_a_module_declares_in_all_exists(sub):
    import pkgutil

    pkg = importlib.import_module(f"hhscatter.analysis.{sub}")
    for info in pkgutil.iter_modules(pkg.__path__):
        mod = importlib.import_module(f"{pkg.__name__}.{info.name}")
        missing = [n for n in getattr(mod, "__all__", []) if not hasattr(mod, n)]
        assert not missing, (mod.__name__, missing)
