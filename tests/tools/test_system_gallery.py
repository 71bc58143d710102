"""tools/system_gallery.py shows every built-in of the registry, at parameters the built-in has."""

import importlib.util
from pathlib import Path

from hhscatter.model.builtins import BUILTINS

spec = importlib.util.spec_from_file_location(
    "system_gallery", Path(__file__).resolve().parents[2] / "tools" / "system_gallery.py"
)
gallery = importlib.util.module_from_spec(spec)
spec.loader.exec_module(gallery)


def test_the_gallery_is_the_registry_in_its_order():
    assert [s["name"] for s in gallery.gallery()] == list(BUILTINS)


def test_a_builtin_added_to_the_registry_joins_the_gallery(monkeypatch):
    monkeypatch.setitem(BUILTINS, "quartic_toy", BUILTINS["barbanis"])
    assert gallery.gallery()[-1] == {"name": "quartic_toy"}


def test_the_parameters_shown_are_the_builtins_own():
    for name, params in gallery.SHOWN_WITH.items():
        assert name in BUILTINS
        assert set(params) <= set(BUILTINS[name].params)
