"""Each analysis subpackage exports the public names of its modules, each the object its module defines."""

import importlib

import pytest

PACKAGES = [f"hhscatter.analysis.{sub}" for sub in ("stats", "survival", "dissipative", "geometry", "noise")] + [
    "hhscatter.reproduction.claims"
]


@pytest.mark.parametrize("name", PACKAGES)
def test_subpackage_exports_its_modules_public_names(name):
    pkg = importlib.import_module(name)
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


@pytest.mark.parametrize("name", PACKAGES)
def test_every_name_a_module_declares_in_all_exists(name):
    import pkgutil

    pkg = importlib.import_module(name)
    for info in pkgutil.iter_modules(pkg.__path__):
        mod = importlib.import_module(f"{pkg.__name__}.{info.name}")
        missing = [n for n in getattr(mod, "__all__", []) if not hasattr(mod, n)]
        assert not missing, (mod.__name__, missing)


def test_the_export_map_is_generated_from_what_the_modules_define(tmp_path):
    """A new public function is exported by defining it; private names, imports and module names are not."""
    from hhscatter._exports import module_exports

    (tmp_path / "rates.py").write_text("import math\nfrom os import path\nK = 1\n_P = 2\ndef rate(): ...\n")
    (tmp_path / "fits.py").write_text("def fit(): ...\ndef rates(): ...\nclass Fit: ...\n")
    (tmp_path / "_private.py").write_text("def hidden(): ...\n")
    assert module_exports(tmp_path) == {"Fit": "fits", "K": "rates", "fit": "fits", "rate": "rates"}
    (tmp_path / "more.py").write_text("def rate(): ...\n")
    with pytest.raises(ValueError, match="'rate' is defined by two modules"):
        module_exports(tmp_path)


def test_every_public_function_of_a_module_is_exported():
    from hhscatter.analysis import survival

    assert survival._EXPORTS["kappa_law_summary"] == "kappa_energy"
    assert survival._EXPORTS["binned_hazard"] == "effective_rate"


def test_the_survival_models_module_gathers_every_public_name_of_its_modules():
    """``dissipative.models`` gathers the public names its modules define (read from their source, not from a
    list): κ0(E), the homogeneous model, the mixture, the comparison of fits, and the energy path's two functions;
    each is the object its module defines, and nothing is gathered twice."""
    from pathlib import Path

    from hhscatter._exports import defined_names
    from hhscatter.analysis.dissipative import models

    gathered = [
        "hhscatter.analysis.survival.kappa_law",
        "hhscatter.analysis.dissipative.survival_model",
        "hhscatter.analysis.dissipative.mixture",
        "hhscatter.analysis.dissipative.model_comparison",
    ]
    expected = {"energy_path", "time_to_energy"}
    for name in gathered:
        module = importlib.import_module(name)
        for public in defined_names(Path(module.__file__).read_text()):
            expected.add(public)
            assert getattr(models, public) is getattr(module, public), public
    assert {"profile_interval", "HomogeneousProblem"} <= set(models.__all__)
    assert expected <= set(models.__all__) and len(models.__all__) == len(set(models.__all__))
